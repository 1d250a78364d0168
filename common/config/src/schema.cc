#include "tamp/config/schema.h"

namespace tamp::config {

Check<double> positive() {
  return that<double>([](double v) { return std::isfinite(v) && v > 0; }, "must be positive");
}

Check<double> nonNegative(const std::string& note) {
  return that<double>([](double v) { return std::isfinite(v) && v >= 0; },
                      "must be >= 0" + (note.empty() ? "" : " " + note));
}

Check<double> inRange(double lo, double hi, Ends ends, const std::string& note) {
  const bool lo_in = ends == Ends::kClosed || ends == Ends::kClosedOpen;
  const bool hi_in = ends == Ends::kClosed || ends == Ends::kOpenClosed;
  std::string message = std::string("must be in ") + (lo_in ? "[" : "(") + formatNumber(lo) + ", " +
                        formatNumber(hi) + (hi_in ? "]" : ")") + (note.empty() ? "" : " " + note);
  return that<double>(
      [=](double v) {
        return std::isfinite(v) && (lo_in ? v >= lo : v > lo) && (hi_in ? v <= hi : v < hi);
      },
      std::move(message));
}

}  // namespace tamp::config
