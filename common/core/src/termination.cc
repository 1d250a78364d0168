#include "tamp/core/termination.h"

namespace tamp {

Deadline Deadline::in(double seconds) {
  if (!(seconds < 1e9)) return never();  // also catches +inf and NaN: treat as "no deadline"
  return Deadline(Clock::now() + std::chrono::duration_cast<Clock::duration>(
                                     std::chrono::duration<double>(seconds)));
}

double Deadline::secondsLeft() const {
  if (isNever()) return std::numeric_limits<double>::infinity();
  return std::chrono::duration<double>(t_ - Clock::now()).count();
}

}  // namespace tamp
