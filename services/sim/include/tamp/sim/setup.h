#pragma once
/// @file
/// What a simulator is built from: the ground-truth world, the robot, where it starts, the
/// scripted faults and the parameters, from the scenario named in the simulator's parameters
/// (tamp::world::loadScenario: config/scenarios/*.yaml, or a NAMO world file).
///
/// The scenario's `sim` block is the robot's truth and overrides the service configuration:
/// | scenario `sim` key        | simulator time parameter                                   |
/// |---------------------------|------------------------------------------------------------|
/// | base_max_linear_speed     | move_base.max_linear_speed                                 |
/// | base_linear_accel         | move_base.max_linear_accel                                 |
/// | base_max_angular_speed    | move_base.max_angular_speed                                |
/// | base_angular_accel        | move_base.max_angular_accel                                |
/// | segment_stop_time         | move_base.settle_time, move_arm.settle_time                |
/// | arm_max_joint_speed       | move_arm.max_joint_speed                                   |
/// | arm_joint_accel           | move_arm.max_joint_accel                                   |
/// | grasp_duration            | pick.gripper_time                                          |
/// | release_duration          | place.gripper_time                                         |
/// | duration_noise_stddev     | duration_noise (stddev of log duration)                    |
/// | seed                      | seed                                                       |
/// The other parameters (overheads, payload slowdowns, approach speed and acceleration) are not
/// in the scenario schema and keep the service configuration's values.
///
/// Scenario faults map to simulator faults: drop_held -> kDropHeldObject, object_appears ->
/// kSpawnObject, action_fails -> kFailAction (with its action-kind filter); `at_step` faults fire
/// half-way through that step.

#include <vector>

#include "tamp/core/error.h"
#include "tamp/robot/robot_model.h"
#include "tamp/sim/faults.h"
#include "tamp/sim/params.h"
#include "tamp/world/scenario.h"
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

/// `params` with the scenario's true time parameters, noise and seed (table above).
SimParams withScenarioParameters(SimParams params, const world::SimParameters& sim);

/// The scenario's scripted faults as simulator faults (ids "fault_<i>"). kInvalidArgument
/// naming "faults[i]" when one cannot be represented.
Result<std::vector<Fault>> scenarioFaults(const world::Scenario& scenario);

/// The setup of a loaded scenario: its world (hidden objects included), its robot description,
/// start state and faults.
Result<SimSetup> setupFromScenario(const world::Scenario& scenario);

/// Loads `params.scenario` (empty: an empty room with the project's robot at the origin). On
/// success `params` gets the scenario's parameters (withScenarioParameters). Errors name the file.
Result<SimSetup> loadSetup(SimParams& params);

}  // namespace tamp::sim
