#include "tamp/sim/setup.h"

#include <filesystem>

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

SimParams withScenarioParameters(SimParams p, const world::SimParameters& s) {
  // The scenario's robot speeds are the true robot's limits; jerk, latency, stalls and the load
  // effect keep the simulator's own values.
  DynamicsParams& d = p.dynamics;
  d.base.linear_speed = s.base_max_linear_speed;
  d.base.linear_accel = s.base_linear_accel;
  d.base.angular_speed = s.base_max_angular_speed;
  d.base.angular_accel = s.base_angular_accel;
  d.base.settle_s = s.segment_stop_time;
  d.arm.max_speed = s.arm_max_joint_speed;
  d.arm.accel = s.arm_joint_accel;
  d.arm.settle_s = s.segment_stop_time;
  d.hand.close_s = s.grasp_duration;
  d.hand.open_s = s.release_duration;
  p.duration_noise = s.duration_noise_stddev;
  p.seed = s.seed;
  return p;
}

Result<std::vector<Fault>> scenarioFaults(const world::Scenario& scenario) {
  std::vector<Fault> out;
  for (std::size_t i = 0; i < scenario.faults.size(); ++i) {
    const world::Fault& sf = scenario.faults[i];
    const std::string field = "faults[" + std::to_string(i) + "]";
    Fault f;
    f.id = "fault_" + std::to_string(i);
    f.reason = sf.reason;
    f.trigger.time_s = sf.at_time;
    f.trigger.step = sf.at_step;
    switch (sf.kind) {
      case world::FaultKind::kDropHeld:
        f.type = FaultType::kDropHeldObject;
        if (!sf.action.empty()) {
          f.action = actionKindFromString(sf.action);
          if (!f.action) {
            return Error(ErrorCode::kInvalidArgument, field + ": unknown action kind '" + sf.action + "'",
                         SourceLocation{scenario.file.string(), 0, 0, field + ".action"});
          }
        }
        break;
      case world::FaultKind::kObjectAppears:
        f.type = FaultType::kSpawnObject;
        if (!sf.object) {
          return Error(ErrorCode::kInvalidArgument, field + ": object_appears without an object",
                       SourceLocation{scenario.file.string(), 0, 0, field + ".object"});
        }
        f.object = *sf.object;
        break;
      case world::FaultKind::kActionFails:
        f.type = FaultType::kFailAction;
        if (!sf.action.empty()) {
          f.action = actionKindFromString(sf.action);
          if (!f.action) {
            return Error(ErrorCode::kInvalidArgument, field + ": unknown action kind '" + sf.action + "'",
                         SourceLocation{scenario.file.string(), 0, 0, field + ".action"});
          }
        }
        break;
    }
    if (Status s = f.validate(true); !s) {
      return Error(ErrorCode::kInvalidArgument, field + "." + s.error().message,
                   SourceLocation{scenario.file.string(), 0, 0, field});
    }
    out.push_back(std::move(f));
  }
  return out;
}

Result<SimSetup> setupFromScenario(const world::Scenario& scenario) {
  auto robot = robot::RobotModel::loadDescription(scenario.robot.description);
  if (!robot) return robot.error();
  auto faults = scenarioFaults(scenario);
  if (!faults) return faults.error();
  return SimSetup(scenario.world, std::move(robot).value(), scenario.startState(), std::move(faults).value());
}

Result<SimSetup> loadSetup(SimParams& params) {
  if (params.scenario.empty()) {
    auto robot = robot::RobotModel::loadDefault();
    if (!robot) return robot.error();
    const auto initial = robot->defaultState(Pose2D{});
    return SimSetup(emptyRoom(), std::move(robot).value(), initial);
  }
  auto scenario = world::loadScenario(params.scenario);
  if (!scenario) return scenario.error();
  auto setup = setupFromScenario(*scenario);
  if (!setup) return setup.error();
  SimParams p = withScenarioParameters(params, scenario->sim);
  if (Status s = p.validate(); !s) {
    return Error(ErrorCode::kInvalidArgument, "scenario '" + params.scenario + "': " + s.error().message,
                 SourceLocation{params.scenario, 0, 0, "sim"});
  }
  params = std::move(p);
  return setup;
}

}  // namespace tamp::sim
