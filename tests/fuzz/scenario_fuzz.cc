// libFuzzer target: the scenario loader (YAML, FieldReader validation, references, robot and
// NAMO loading, PDDL atom checks) must return an error, never crash, on any input. The text is
// parsed as if it were config/scenarios/fuzz.yaml, so relative paths resolve like a shipped
// scenario's.
#include <cstddef>
#include <cstdint>
#include <string>

#include "tamp/core/paths.h"
#include "tamp/world/scenario.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const std::string kName = (tamp::configDir() / "scenarios" / "fuzz.yaml").string();
  const std::string text(reinterpret_cast<const char*>(data), size);
  (void)tamp::world::parseScenario(text, kName);
  return 0;
}
