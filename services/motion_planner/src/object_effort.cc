// The price of moving an object out of the way (CostParams), from the effort estimator's time
// models: their defaults, or fitted parameter values.
#include <cmath>

#include "tamp/core/format.h"
#include "tamp/effort_model/models.h"
#include "tamp/motion_planner/motion_planner.h"

namespace tamp::motion_planner {
namespace {

namespace ee = tamp::effort_model;

/// Parameter vectors (modelSpec order) of the three models an object's effort uses.
struct EffortModels {
  std::vector<double> pick = ee::modelSpec(ActionKind::kPick).defaults();
  std::vector<double> place = ee::modelSpec(ActionKind::kPlace).defaults();
  std::vector<double> move_base = ee::modelSpec(ActionKind::kMoveBase).defaults();
};

double objectEffort(const world::Object& object, const CostParams& params,
                    const EffortModels& models) {
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
  double t = ee::predictDuration(pick, models.pick) + ee::predictDuration(place, models.place);
  if (params.transfer_distance > 0) t += ee::predictDuration(drive, models.move_base);
  return object.graspable ? t : t * params.non_graspable_factor;
}

}  // namespace

double defaultObjectEffort(const world::Object& object, const CostParams& params) {
  static const EffortModels defaults;
  return objectEffort(object, params, defaults);
}

Result<ObjectEffortFn> fittedObjectEffort(const CostParams& params,
                                          const std::vector<TimeModelValues>& models) {
  EffortModels m;
  for (std::size_t i = 0; i < models.size(); ++i) {
    const TimeModelValues& tm = models[i];
    const std::string field = "models[" + std::to_string(i) + "]";
    std::vector<double>* target = tm.kind == ActionKind::kPick       ? &m.pick
                                  : tm.kind == ActionKind::kPlace    ? &m.place
                                  : tm.kind == ActionKind::kMoveBase ? &m.move_base
                                                                     : nullptr;
    if (tm.names.size() != tm.values.size()) {
      return Error(ErrorCode::kInvalidArgument, field + ": " + std::to_string(tm.values.size()) +
                                                    " values for " +
                                                    std::to_string(tm.names.size()) + " names");
    }
    if (!target) continue;  // move_arm: not part of an object's effort
    const ee::ModelSpec& spec = ee::modelSpec(tm.kind);
    for (std::size_t k = 0; k < tm.names.size(); ++k) {
      const int idx = spec.indexOf(tm.names[k]);
      if (idx < 0) {
        return Error(ErrorCode::kInvalidArgument, field + ".names[" + std::to_string(k) + "]: '" +
                                                      tm.names[k] +
                                                      "' is not a parameter of the model");
      }
      const double v = tm.values[k];
      if (!std::isfinite(v) || v <= 0) {
        return Error(ErrorCode::kInvalidArgument,
                     field + ".values[" + std::to_string(k) + "] (" + tm.names[k] +
                         "): must be finite and > 0, got " + formatNumber(v));
      }
      (*target)[static_cast<std::size_t>(idx)] = v;
    }
  }
  return ObjectEffortFn([params, m](const world::Object& o) { return objectEffort(o, params, m); });
}

}  // namespace tamp::motion_planner
