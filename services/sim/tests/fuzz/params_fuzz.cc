// libFuzzer target: the simulator's YAML parameters (config/services/sim.yaml). Must never crash;
// accepted parameters must validate.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string>

#include "tamp/sim/params.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  auto p = tamp::sim::parseSimParams(text, "fuzz.yaml");
  if (p && !p->validate()) std::abort();
  return 0;
}
