#pragma once
/// @file
/// Scenarios: one YAML file (config/scenarios/*.yaml, schema in docs/scenarios.md) naming the
/// PDDL domain, the robot and its start state, the world (inline, or a NAMO benchmark world plus
/// inline additions), hidden objects only the simulator knows, the goal (PDDL atoms and/or
/// geometric conditions), scripted faults, the simulator's true time parameters and perception
/// priors.
///
/// Loading validates everything it can and reports every error with file, line, column and field
/// (tamp::config::FieldReader; unknown keys are refused): ids, references between objects,
/// regions and locations, shapes, the arm configuration against the URDF's joint limits, the held
/// object, fault timing, PDDL atom syntax and names, and graspability against the robot
/// description's payload and gripper opening (a `graspable: true` above the payload is an error;
/// without the flag an object is graspable when movable, within the payload and no wider than the
/// open gripper; docs/scenarios.md). Paths inside a scenario are relative to the
/// scenario file; `${TAMP_BENCHMARKS_DIR}` and `${TAMP_CONFIG_DIR}` prefixes expand to
/// tamp::benchmarksDir() / tamp::configDir(); any other `${...}` is an error.
///
/// `toPddlProblem()` derives the PDDL problem the world implies for the mobile-manipulation
/// domain (objects, init facts, goal): `reaches` from inverse kinematics at each location,
/// `occludes` from the geometry of objects sharing a support region, `on` from each object's
/// region, `holding`/`hand-empty` from the gripper.

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "tamp/core/error.h"
#include "tamp/core/geometry.h"
#include "tamp/robot/robot_model.h"
#include "tamp/world/namo.h"
#include "tamp/world/world.h"

namespace tamp::world {

/// The robot and its start state.
struct ScenarioRobot {
  std::filesystem::path description;  ///< robot description YAML (resolved path)
  Pose2D start;                       ///< base pose
  std::string start_location;         ///< the location id the robot starts at (PDDL robot-at)
  std::vector<double> arm;            ///< arm joints (chain order)
  std::string arm_configuration;      ///< name of `arm` when given by name ("stow"), else empty
  double gripper{0.0};                ///< gripper joint value (m per finger)
};

/// The simulator's true time parameters (unknown to the planner; the effort estimator learns them).
struct SimParameters {
  double base_max_linear_speed{0.5};   ///< m/s
  double base_linear_accel{0.5};       ///< m/s^2
  double base_max_angular_speed{1.0};  ///< rad/s
  double base_angular_accel{1.5};      ///< rad/s^2
  double arm_max_joint_speed{1.0};     ///< rad/s
  double arm_joint_accel{2.0};         ///< rad/s^2
  double grasp_duration{1.5};          ///< s, closing the gripper and lifting
  double release_duration{1.0};        ///< s
  double segment_stop_time{0.2};       ///< s, pause at the end of each path segment
  double duration_noise_stddev{0.05};  ///< relative (multiplicative) noise on every duration
  std::uint32_t seed{1};               ///< RNG seed of that noise
  /// Empty when usable; else why not (names the field).
  std::optional<std::string> invalidReason() const;
};

/// What perception may assume (priors of its detectors).
struct PerceptionPriors {
  double max_range{4.0};               ///< m, depth sensor range
  double position_stddev{0.01};        ///< m, object position noise
  double detection_probability{0.95};  ///< per visible object and frame
  std::optional<std::string> invalidReason() const;
};

enum class FaultKind { kDropHeld, kObjectAppears, kActionFails };
std::string_view toString(FaultKind kind);  ///< "drop_held", "object_appears", "action_fails"

/// A scripted fault of the simulator, triggered at a mission time or at an executed action.
struct Fault {
  FaultKind kind{FaultKind::kDropHeld};
  std::optional<double> at_time;  ///< s since the mission started
  std::optional<int> at_step;     ///< 0-based index of the executed action it hits
  std::optional<Object> object;   ///< kObjectAppears: the object (id unique in the world)
  std::string action;             ///< kActionFails: only actions of this kind ("" = any)
  std::string reason;             ///< free text reported by the failing action
};

/// The mission goal: PDDL atoms over world ids and/or geometric conditions (all must hold).
struct Goal {
  std::vector<std::string> pddl;    ///< e.g. "(on can counter)"
  std::optional<Pose2D> base;       ///< robot base within the tolerances of this pose
  std::string base_location;        ///< the location id of `base` when given by id
  double position_tolerance{0.10};  ///< m
  double angle_tolerance{0.20};     ///< rad
  std::vector<std::pair<std::string, std::string>> object_in_region;  ///< (object id, region id)
  bool empty() const { return pddl.empty() && !base && object_in_region.empty(); }
};

/// Where a NAMO world came from (when the scenario names one).
struct NamoSource {
  std::filesystem::path file;
  double scale{0.0};         ///< m per SVG unit
  double robot_radius{0.0};  ///< benchmark robot's radius at that scale, m
  std::vector<NamoGoal> goals;
};

struct Scenario {
  std::string name;  ///< valid id; matches config/pddl/problems/<name>.pddl if any
  std::string description;
  std::filesystem::path file;          ///< the YAML
  std::filesystem::path domain;        ///< PDDL domain file
  std::filesystem::path problem;       ///< hand-written PDDL problem, if named
  std::vector<std::string> pddl_init;  ///< extra init facts (added to the derived ones)
  ScenarioRobot robot;
  World world;  ///< the truth: hidden objects included, held object set
  std::optional<NamoSource> namo;
  Goal goal;
  std::vector<Fault> faults;  ///< sorted by time/step as written
  SimParameters sim;
  PerceptionPriors perception;
  std::vector<std::string> warnings;  ///< e.g. the robot starts in contact with an object

  /// The planner's view of the world (no hidden objects).
  World plannerWorld() const { return world.plannerView(); }
  /// The robot's start state.
  robot::RobotState startState() const;
};

/// Loads a scenario YAML; a NAMO world file (.json / bare .svg) is accepted too and becomes a
/// scenario with the default robot scaled in (robot_radius = the robot's base radius), the start
/// at the benchmark's start and the goal at its first goal.
Result<Scenario> loadScenario(const std::filesystem::path& file);
/// Parses scenario text; relative paths resolve against the directory of `file_name`.
Result<Scenario> parseScenario(const std::string& yaml_text, const std::string& file_name);

/// A PDDL problem for the mobile-manipulation domain.
struct PddlProblem {
  std::string name;
  std::string domain{"mobile-manipulation"};
  std::vector<std::pair<std::string, std::string>> objects;  ///< (name, type), sorted by type
  std::vector<std::string> init;  ///< atoms, sorted, without the cost fluent
  std::vector<std::string> goal;  ///< atoms
  /// The problem as PDDL text (with `(= (total-cost) 0)` and the cost metric).
  std::string text() const;
};

/// The PDDL problem the scenario's planner world implies (see the file comment). `robot` must be
/// the scenario's robot model. Errors: kInvalidArgument when a goal atom names an unknown object.
Result<PddlProblem> toPddlProblem(const Scenario& scenario, const robot::RobotModel& robot);

/// True when `x` stands in the corridor from `approach` (a base position, world xy) to `o`:
/// ahead of the approach, short of `o`, and laterally closer than the sum of their footprints'
/// circumradii (plus `margin`, m >= 0: the room a grasp of `o` needs beside it; with a margin, also
/// any `x` nearer `o` than their circumradii plus the margin). The basis of the `occludes` facts
/// (margin 0).
bool occludes(const Object& x, const Object& o, const Eigen::Vector2d& approach, double margin = 0.0);

/// True when the arm, with the base at `base`, reaches a top-down grasp 0.10 m above some point of
/// `region` (the point 0.55 m ahead of the base if inside the region, else the region's point
/// nearest to it, 5 cm inside the edge). The basis of the `reaches` facts.
bool reachesRegion(const robot::RobotModel& robot, const Pose2D& base, const Region& region);

}  // namespace tamp::world
