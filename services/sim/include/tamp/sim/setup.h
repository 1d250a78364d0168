#pragma once
/// @file
/// What a simulator is built from: the ground-truth world, the robot, where it starts and the
/// scripted faults, loaded from the `scenario` named in the simulator's parameters.
///
/// Sources (until the scenario loader of common/world lands, see docs/sim.md):
/// - empty `scenario`: an empty room (a 20 m x 20 m `floor` region), the robot at the origin;
/// - a NAMO benchmark world (`.svg`, or `.json` + its SVG; world/namo.h): its walls and
///   obstacles, the robot at the world's start pose;
/// - anything else is kUnsupported (named in the message).

#include <vector>

#include "tamp/core/error.h"
#include "tamp/robot/robot_model.h"
#include "tamp/sim/faults.h"
#include "tamp/sim/params.h"
#include "tamp/world/world.h"

namespace tamp::sim {

struct SimSetup {
  SimSetup(world::World w, robot::RobotModel r, robot::RobotState s, std::vector<Fault> f = {})
      : world(std::move(w)), robot(std::move(r)), initial(std::move(s)), faults(std::move(f)) {}
  world::World world;
  robot::RobotModel robot;
  robot::RobotState initial;
  std::vector<Fault> faults;
};

/// An empty room: a square `floor` region of side `size_m` centred on the origin.
world::World emptyRoom(double size_m = 20.0);

/// Loads the setup for `params.scenario` with the project's robot (RobotModel::loadDefault()).
/// Errors name the file.
Result<SimSetup> loadSetup(const SimParams& params);

}  // namespace tamp::sim
