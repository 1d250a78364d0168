#include "tamp/sim/setup.h"

#include <filesystem>

#include "tamp/world/namo.h"

namespace tamp::sim {

world::World emptyRoom(double size_m) {
  world::World w("empty_room");
  world::Region floor;
  floor.id = "floor";
  floor.label = "floor";
  floor.kind = world::RegionKind::kFloor;
  const double h = 0.5 * size_m;
  floor.polygon = {{-h, -h}, {h, -h}, {h, h}, {-h, h}};
  (void)w.addRegion(floor);
  return w;
}

Result<SimSetup> loadSetup(const SimParams& params) {
  auto robot = robot::RobotModel::loadDefault();
  if (!robot) return robot.error();
  if (params.scenario.empty()) {
    const auto initial = robot->defaultState(Pose2D{});
    return SimSetup(emptyRoom(), std::move(robot).value(), initial);
  }
  const std::filesystem::path file(params.scenario);
  const std::string ext = file.extension().string();
  if (ext == ".svg" || ext == ".json") {
    auto namo = world::loadNamo(file);
    if (!namo) return namo.error();
    const auto initial = robot->defaultState(namo->start);
    return SimSetup(std::move(namo->world), std::move(robot).value(), initial);
  }
  return Error(ErrorCode::kUnsupported,
               "scenario '" + params.scenario +
                   "': only NAMO worlds (.svg/.json) load here until the scenario loader exists",
               SourceLocation{params.scenario, 0, 0, "scenario"});
}

}  // namespace tamp::sim
