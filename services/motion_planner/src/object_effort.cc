// The default price of moving an object out of the way (CostParams), from the effort estimator's
// default time models.
#include <cmath>

#include "tamp/effort_estimator/models.h"
#include "tamp/motion_planner/motion_planner.h"

namespace tamp::motion_planner {

double defaultObjectEffort(const world::Object& object, const CostParams& params) {
  namespace ee = tamp::effort_estimator;
  const double mass = std::isfinite(object.mass) && object.mass > 0 ? object.mass : 0.0;
  ee::ActionFeatures pick;
  pick.kind = ActionKind::kPick;
  pick.approach_m = params.approach_distance;
  pick.retreat_m = params.retreat_distance;
  pick.object_mass_kg = mass;
  ee::ActionFeatures place = pick;
  place.kind = ActionKind::kPlace;
  // To a placement and back: drive transfer_distance, turn around, drive back, turn around.
  ee::ActionFeatures drive;
  drive.kind = ActionKind::kMoveBase;
  if (params.transfer_distance > 0) {
    drive.moves = ee::MoveSet({params.transfer_distance, params.transfer_distance});
    drive.turns = ee::MoveSet({M_PI, M_PI});
  }
  drive.object_mass_kg = 0.0;
  double t = ee::predictDuration(pick, ee::modelSpec(ActionKind::kPick).defaults()) +
             ee::predictDuration(place, ee::modelSpec(ActionKind::kPlace).defaults());
  if (params.transfer_distance > 0) t += ee::predictDuration(drive, ee::modelSpec(ActionKind::kMoveBase).defaults());
  return object.graspable ? t : t * params.non_graspable_factor;
}

}  // namespace tamp::motion_planner
