// libFuzzer target: arbitrary text as the effort estimator's YAML parameters. Must never crash;
// whatever it accepts must validate.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string>

#include "tamp/effort_estimator/params.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  auto p = tamp::effort_estimator::parseEstimatorParams(text, "fuzz.yaml");
  if (p.ok() && !p->validate().ok()) std::abort();
  return 0;
}
