// libFuzzer target: the NAMO SVG reader (XML, transforms, path data, colour classification,
// extrusion) must return an error, never crash, on any input. The first byte selects the bare
// colour-convention loader or the JSON + SVG loader (with a fixed JSON naming SVG ids).
#include <cstddef>
#include <cstdint>
#include <string>

#include "tamp/world/namo.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size == 0) return 0;
  const std::string text(reinterpret_cast<const char*>(data) + 1, size - 1);
  if (data[0] & 1) {
    (void)tamp::world::parseNamoBareSvg(text, "fuzz.svg");
  } else {
    static const std::string kJson = R"({"geometry_scale": 0.1, "things": {"entities": [
      {"name": "robot_01", "type": "robot", "movable_whitelist": ["box"],
       "geometry": {"from": "file", "id": "robot_01", "orientation_id": "robot_01_dir"}},
      {"name": "wall", "type": "wall", "geometry": {"from": "file", "id": "wall"}},
      {"name": "box", "type": "box", "geometry": {"from": "file", "id": "box"}}],
      "zones": {"goals": [{"name": "goal_01", "geometry": {"from": "file", "id": "goal_01"}}]}}})";
    (void)tamp::world::parseNamoJson(kJson, "fuzz.json", text, "fuzz.svg");
  }
  return 0;
}
