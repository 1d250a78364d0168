#pragma once
/// @file
/// The mobile manipulator: a URDF model (urdfdom) with forward and inverse kinematics (KDL), joint
/// limits, grasp bookkeeping and the per-link collision geometry for tamp::collision.
///
/// Frames: the planar base moves through the virtual joints `base_x`, `base_y`, `base_theta`
/// (tamp::kBaseJointNames) that are not in the URDF: world_T_base = RobotState::base as an
/// isometry at z = 0. Everything else comes from the URDF (config/robots/mobile_manipulator.urdf):
/// the arm chain runs from `RobotModelOptions::base_link` to `tool_link` (the tool centre point,
/// whose z axis is the approach direction); its movable joints are the "arm joints", in chain
/// order. The gripper is one prismatic joint (`gripper_joint`, metres per finger, 0 = closed);
/// mimic joints follow it.
///
/// Kinematics: `toolPose()` is KDL's ChainFkSolverPos_recursive on a KDL::Chain converted from the
/// urdfdom model here (no kdl_parser, which pulls ROS 1 on Debian). `inverseKinematics()` runs
/// KDL's ChainIkSolverPos_LMA from the seed, then from random configurations within the limits
/// (fixed RNG seed), wraps revolute joints into their limits and verifies the result by FK; it
/// returns a status, it does not throw. `linkPoses()` is a direct Eigen tree walk (fast, for
/// collision checking); both agree to 1e-12 (tested).
///
/// Units: metres, radians, seconds.

#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <optional>
#include <random>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include <Eigen/Geometry>

#include "tamp/collision/scene.h"
#include "tamp/core/error.h"
#include "tamp/core/geometry.h"
#include "tamp/core/termination.h"
#include "tamp/world/polygon.h"
#include "tamp/world/world.h"

namespace tamp::robot {

enum class JointType { kFixed, kRevolute, kContinuous, kPrismatic };
std::string_view toString(JointType type);

struct JointLimits {
  double lower{0.0};     ///< rad or m; -inf for continuous joints
  double upper{0.0};     ///< rad or m; +inf for continuous joints
  double velocity{0.0};  ///< rad/s or m/s (max speed)
  double effort{0.0};    ///< N m or N
};

/// One URDF joint.
struct Joint {
  std::string name;
  JointType type{JointType::kFixed};
  std::string parent_link;
  std::string child_link;
  Eigen::Isometry3d parent_T_joint{Eigen::Isometry3d::Identity()};  ///< the URDF <origin>
  Eigen::Vector3d axis{Eigen::Vector3d::UnitZ()};                   ///< unit, joint frame
  JointLimits limits;
  std::string mimic;             ///< joint this one follows, or empty
  double mimic_multiplier{1.0};  ///< value = multiplier * mimic + offset
  double mimic_offset{0.0};
};

/// Which URDF frames play which role, and named configurations (the robot description YAML,
/// config/robots/mobile_manipulator.yaml, next to the URDF).
struct RobotModelOptions {
  std::string base_link{"base_link"};    ///< root of the arm chain, on the floor
  std::string tool_link{"gripper_tcp"};  ///< tip of the arm chain (tool centre point)
  std::string gripper_joint{"gripper_finger_left_joint"};  ///< empty: no gripper
  std::string camera_frame{"camera_optical_frame"};        ///< empty: no sensor
  double gripper_open{0.04};   ///< gripper joint value when open (m per finger)
  double gripper_closed{0.0};  ///< gripper joint value when closed
  /// kg, >= 0: the heaviest object the robot may grasp and carry (the description's required
  /// `payload`). 0 for a model loaded from a URDF alone: it grasps nothing.
  double payload{0.0};
  /// kg, >= 0: the heaviest object the base may push along the floor (the description's optional
  /// `push_limit`; its drive force against the object's friction). 0: it pushes nothing.
  double push_limit{0.0};
  /// Named arm configurations (arm joints in chain order), e.g. "stow" (the PDDL constant).
  std::vector<std::pair<std::string, std::vector<double>>> named_configurations;
};

/// A full configuration of the robot.
struct RobotState {
  Pose2D base;              ///< base_link in the world plane
  std::vector<double> arm;  ///< one value per arm joint, in `armJointNames()` order
  double gripper{0.0};      ///< gripper joint value (m per finger; 0 = closed)
};

enum class IkStatus {
  kSolved,        ///< `q` reaches the target within the tolerances and limits
  kNoSolution,    ///< no attempt converged within limits (target out of reach or rejected)
  kTimeout,       ///< the termination condition fired first
  kInvalidInput,  ///< non-finite target or a seed of the wrong size
};
std::string_view toString(IkStatus status);

struct IkOptions {
  int max_attempts{64};                ///< seeded attempt + random restarts; must be >= 1
  double position_tolerance{1e-4};     ///< m
  double orientation_tolerance{1e-3};  ///< rad (angle of the residual rotation)
  std::uint32_t seed{1};               ///< RNG seed of the restarts
  /// Optional extra acceptance test on a solution (e.g. collision-free); rejected solutions
  /// count as failed attempts.
  std::function<bool(const std::vector<double>&)> accept;
};

struct IkResult {
  IkStatus status{IkStatus::kNoSolution};
  std::vector<double> q;          ///< arm joints when kSolved (else the best attempt, or empty)
  double position_error{0.0};     ///< m, of `q`
  double orientation_error{0.0};  ///< rad, of `q`
  int attempts{0};
  bool ok() const { return status == IkStatus::kSolved; }
};

class RobotModel {
 public:
  /// Loads a URDF file. Errors: kNotFound/kIo (file), kParseError (XML or URDF structure, with
  /// file:line where known), kUnsupported (mesh collision geometry), kInvalidArgument (a frame
  /// named in `options` missing, bad limits) -- all naming the file, line and element.
  static Result<RobotModel> loadFile(const std::filesystem::path& file,
                                     const RobotModelOptions& options = {});
  /// Same from text; `source_name` is used as the file name in messages.
  static Result<RobotModel> fromUrdfString(const std::string& xml, const std::string& source_name,
                                           const RobotModelOptions& options = {});
  /// Loads a robot description YAML (urdf path relative to it, frame roles, gripper values,
  /// named configurations; see config/robots/mobile_manipulator.yaml). Errors name the YAML's
  /// file, line and field, or the URDF's. Named configurations must have one value per arm joint
  /// within the limits.
  static Result<RobotModel> loadDescription(const std::filesystem::path& yaml_file);
  /// The project's robot: configDir()/robots/mobile_manipulator.yaml.
  static Result<RobotModel> loadDefault();

  RobotModel(const RobotModel& other);
  RobotModel& operator=(const RobotModel& other);
  RobotModel(RobotModel&&) noexcept;
  RobotModel& operator=(RobotModel&&) noexcept;
  ~RobotModel();

  const std::string& name() const;
  const std::string& sourceFile() const;
  const RobotModelOptions& options() const;
  /// Every link, root first (parents before children).
  const std::vector<std::string>& linkNames() const;
  /// Every joint, in the order of their child links.
  const std::vector<Joint>& joints() const;
  const Joint* findJoint(std::string_view name) const;
  int linkIndex(std::string_view name) const;  ///< -1 when absent

  // ---- joints ----------------------------------------------------------------------------------
  const std::vector<std::string>& armJointNames() const;
  std::size_t armDof() const { return armJointNames().size(); }
  const std::vector<JointLimits>& armLimits() const;
  const std::string& gripperJointName() const;  ///< empty when no gripper
  JointLimits gripperLimits() const;
  /// kg: the heaviest object the robot may grasp (`options().payload`). Objects above it are
  /// never graspable (world::Object::graspable; the scenario and NAMO loaders enforce it).
  double payload() const { return options().payload; }
  /// kg: the heaviest object the base may push (`options().push_limit`; 0: none).
  double pushLimit() const { return options().push_limit; }
  /// m: the widest object the open gripper closes around: twice the gripper joint's upper limit
  /// (two symmetric fingers, one following the other as a mimic joint, that meet at 0); 0
  /// without a gripper.
  double maxGraspWidth() const;
  /// base_x, base_y, base_theta, the arm joints, then the gripper joint (if any): the joint-name
  /// convention of JointPath / Trajectory.
  std::vector<std::string> fullJointNames() const;
  /// The state as values over `fullJointNames()`.
  std::vector<double> toJointValues(const RobotState& s) const;
  /// A state from values over `names` (any order, unknown names rejected); joints not named keep
  /// the value of `defaults`. kInvalidArgument naming the joint on a mismatch.
  Result<RobotState> fromJointValues(const std::vector<std::string>& names,
                                     std::span<const double> values,
                                     const RobotState& defaults) const;
  /// True when every arm value is within its limits (+ `tolerance`).
  bool withinLimits(std::span<const double> arm, double tolerance = 1e-9) const;
  /// A uniformly random arm configuration within the limits.
  std::vector<double> randomArmConfiguration(std::mt19937& rng) const;
  /// A state with the base at `base`, the arm at "stow" if named (else zero clamped into the
  /// limits), gripper closed.
  RobotState defaultState(const Pose2D& base = {}) const;
  /// A named arm configuration, or nullopt.
  std::optional<std::vector<double>> namedConfiguration(std::string_view name) const;
  /// Names of the named configurations, in file order.
  std::vector<std::string> namedConfigurationNames() const;

  // ---- kinematics ------------------------------------------------------------------------------
  /// base_link_T_tool for the arm joints (KDL). Throws std::invalid_argument on a wrong size.
  Eigen::Isometry3d toolPose(std::span<const double> arm) const;
  /// world_T_tool.
  Eigen::Isometry3d toolPoseInWorld(const RobotState& s) const;
  /// World pose of any link; kNotFound for an unknown name.
  Result<Eigen::Isometry3d> linkPoseInWorld(std::string_view link, const RobotState& s) const;
  /// World poses of every link, in `linkNames()` order (Eigen tree walk). `out` is resized.
  /// Throws std::invalid_argument when `s.arm` has the wrong size.
  void linkPoses(const RobotState& s, std::vector<Eigen::Isometry3d>& out) const;
  /// A sphere in base_link that holds the tool's position in every configuration: centred on the
  /// first arm joint's axis, its radius the sum of the distances between consecutive joint axes
  /// and to the tool, plus the prismatic joints' travel (infinite when a travel is unbounded).
  struct ReachSphere {
    Eigen::Vector3d centre;
    double radius;
  };
  ReachSphere armReach() const;
  /// Arm joints reaching base_link_T_tool `target` (see the file comment). Never throws. A target
  /// outside armReach() is kNoSolution at once, with no attempt.
  IkResult inverseKinematics(const Eigen::Isometry3d& target, std::span<const double> seed,
                             const IkOptions& options = {},
                             const Termination& termination = {}) const;

  // ---- geometry --------------------------------------------------------------------------------
  /// Collision model for tamp::collision::Scene: `links` equals `linkNames()` (so `linkPoses()`
  /// feeds `Scene::setLinkPoses()` directly); parts from the URDF <collision> elements; allowed
  /// self-collision pairs: links of one rigid group (fixed joints), adjacent groups, and pairs
  /// touching in the zero configuration with the gripper closed or open.
  const collision::RobotGeometry& collisionGeometry() const;
  /// The base's footprint polygon in base_link (projection of base_link's collision shapes).
  const world::Polygon2& baseFootprint() const;
  /// Largest distance from the base_link origin to a footprint vertex (m).
  double baseRadius() const;

  // ---- grasping --------------------------------------------------------------------------------
  /// The held-object record for an object at `world_T_object` grasped in state `s`:
  /// link = tool link, link_T_object = world_T_tool^-1 * world_T_object.
  world::HeldObject hold(const std::string& object_id, const RobotState& s,
                         const Eigen::Isometry3d& world_T_object) const;
  /// World pose of a held object in state `s` (world_T_link * link_T_object); kNotFound when the
  /// held object's link is not a link of this robot.
  Result<Eigen::Isometry3d> heldObjectPose(const RobotState& s,
                                           const world::HeldObject& held) const;

 private:
  RobotModel();
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace tamp::robot
