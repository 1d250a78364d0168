// Leaving a start that touches movable objects (see internal.h, escapeStart).

#include <algorithm>

#include <ompl/base/StateSampler.h>

#include "internal.h"

namespace tamp::motion_planner::detail {

bool escapeStart(const ob::SpaceInformationPtr& free_si, const ob::SpaceInformationPtr& escape_si,
                 const ob::State* start, double max_distance, int attempts, ob::State* out) {
  if (!(max_distance > 0.0) || attempts < 1) return false;
  constexpr int kRings = 4;
  const ob::StateSamplerPtr sampler = free_si->allocStateSampler();
  int left = attempts;
  for (int ring = 1; ring <= kRings && left > 0; ++ring) {
    const int n = ring == kRings ? left : std::max(1, attempts / kRings);
    const double radius = max_distance * ring / kRings;
    for (int i = 0; i < n && left > 0; ++i, --left) {
      sampler->sampleUniformNear(out, start, radius);
      free_si->enforceBounds(out);
      if (free_si->isValid(out) && escape_si->checkMotion(start, out)) return true;
    }
  }
  return false;
}

}  // namespace tamp::motion_planner::detail
