#pragma once
/// @file
/// The simulator: a stand-in for the robot's drivers and the physical world behind the same
/// messages a real robot would use (Conditional TAMP through an effort-based approach,
/// spec/conditional-tamp-effort-based.tex: the execution loop of section 4, whose measured
/// durations feed the effort estimator and whose unexpected events trigger online replanning).
///
/// Design overview
/// - **Ground truth.** The simulator owns the true `world::World`, hidden objects included, and
///   a `collision::Scene` over all of it; the planner only ever sees `plannerView()`.
/// - **Kinematics.** The robot is the URDF `robot::RobotModel`: link poses by FK, collision
///   geometry from the URDF, held objects attached to the tool link.
/// - **Time.** The simulator's own dynamics (dynamics.h, `SimParams::dynamics`), not the effort
///   estimator's models: every move a jerk-limited S-curve, a held mass slowing it, seeded random
///   stalls after a move, the whole timeline times a log-normal factor exp(sigma * N(0, 1))
///   (sigma = `SimParams::duration_noise`, median 1). The motion follows the commanded path:
///   The geometry is the commanded one (the robot is position-controlled): only the timing is
///   the simulator's own.
///   - move_base: latency, then stop-and-turn along `effort_model::baseSteps` (the segmentation
///     the motion planner and the execution monitor check): a turn in place to each straight
///     run's heading and a drive along the run's waypoints, a settle pause after each, and a
///     final turn to the last waypoint's heading;
///   - move_arm: latency, then each run (consecutive segments bending by at most
///     `ArmDynamics::corner_threshold_rad`) as one S-curve along the commanded polyline, through
///     every waypoint (each joint within min(max_speed, speed_fraction * URDF limit) / f,
///     f = 1 + per_kg * held mass), and a settle pause;
///   - pick/place: the trajectory's waypoints up to the *grasp waypoint* (the one whose tool
///     position is farthest from the first waypoint's) are the approach, travelled at the
///     approach speed along the tool path; then the gripper acts (`hand.close_s`/`open_s`); the rest is
///     the retreat. approach_m / retreat_m are the tool-path lengths.
///   The commanded times are validated but not followed: the robot runs at its own true speed.
/// - **Contacts.** Before (and, if the world changes, during) an action, the whole motion is
///   swept at a resolution such that no robot point (base, arm links, held object) moves more
///   than `max_step_m` between checks, against every object, hidden ones included. The robot
///   stops at the last collision-free sample (before contact) and the action ends kBlocked with
///   the blocking object's id. Contacts that are part of the task are allowed: the gripper with
///   the object it picks, a manipulated object with the surface it rests on or is placed on.
///   Objects already touching the robot when an action starts do not block it. The floor plane
///   z = 0 blocks too (reported as `kFloorId`). Self-collisions of the arm are not simulated.
/// - **Manipulation.** A pick succeeds when, at the grasp waypoint, the object exists, is movable
///   and graspable, is where the command says (within tolerance), the tool centre point is at it,
///   it fits between the fingers and is not too heavy; the closing fingers then centre it between
///   them along the tool's y axis (and turn a box that is within 0.35 rad of square flat against
///   the pads), and it is attached to the tool link and removed from its support region. Otherwise the gripper closes on nothing and the action
///   fails after its retreat. A place releases the held object where the gripper is; it settles
///   onto the support below (a table region or the floor) and the action succeeds when it ends
///   upright, on a region, near the commanded pose and not in collision.
/// - **Faults.** Scripted faults fire at a simulated time or during an action step; injected ones
///   (`inject()`) fire at the next `step()`. A failed action stops the robot where it is.
/// - **Records.** Every finished action yields an `effort_model::ExecutionRecord` (kind, path
///   or approach/retreat distances, true object mass, measured duration, success).
///
/// Time is simulated: `step(dt)` advances it; `SimulationLoop` (loop.h) paces it against the wall
/// clock. The class is not thread-safe: one thread drives it (the loop serialises access).

#include <cstdint>
#include <memory>
#include <map>
#include <optional>
#include <string>
#include <unordered_map>
#include <vector>

#include <Eigen/Geometry>

#include "tamp/core/error.h"
#include "tamp/core/point_cloud.h"
#include "tamp/core/trajectory.h"
#include "tamp/effort_model/records.h"
#include "tamp/robot/robot_model.h"
#include "tamp/sim/faults.h"
#include "tamp/sim/params.h"
#include "tamp/world/world.h"

namespace tamp::sim {

/// `ActionResult::blocking_object_id` when the robot would have gone through the floor.
inline constexpr const char* kFloorId = "__floor__";

/// One command for the robot: a trajectory to execute as an action of kind `kind`.
struct ActionCommand {
  std::string command_id;  ///< non-empty, unique per command (results and records carry it)
  ActionKind kind{ActionKind::kMoveBase};
  /// move_base: over exactly base_x, base_y, base_theta. move_arm / pick / place: over arm joints
  /// (and optionally the gripper joint), no base joints. At least one point; the first point must
  /// match the robot's current state (`SimParams::start_tolerance`); times strictly increasing.
  Trajectory trajectory;
  std::string object_id;  ///< pick/place: the object
  /// pick: where the sender believes the object is (optional; checked when given).
  /// place: where the object must go (required).
  std::optional<Eigen::Isometry3d> object_pose;
};

enum class Outcome { kSucceeded, kBlocked, kFailed, kCancelled };
std::string_view toString(Outcome outcome);  ///< "succeeded", "blocked", "failed", "cancelled"

struct ActionResult {
  std::string command_id;
  Outcome outcome{Outcome::kFailed};
  double duration_s{0.0};          ///< simulated time from start to stop
  double progress{0.0};            ///< [0, 1]: fraction of the action's planned duration done
  std::string blocking_object_id;  ///< kBlocked: the object the robot would have hit
  std::string reason;              ///< empty on success; otherwise why (names the field for bad input)
};

/// One action the robot accepted (the simulator's action log: what physically happened).
struct ActionLogEntry {
  std::string command_id;
  ActionKind kind{ActionKind::kMoveBase};
  int step{0};          ///< its index among the accepted actions
  double start_s{0.0};  ///< simulated time it started
  std::optional<ActionResult> result;  ///< nullopt while it runs
};

/// The robot's state as its drivers would report it.
struct RobotStateSample {
  double time_s{0.0};                ///< simulated seconds since the start
  robot::RobotState state;
  std::vector<double> joint_velocities;  ///< over `RobotModel::fullJointNames()`
  std::string held_object_id;        ///< empty: gripper empty
  bool moving{false};
};

/// What happened during a `step()`.
struct StepEvents {
  std::vector<ActionResult> results;
  std::vector<effort_model::ExecutionRecord> records;
  std::vector<FaultEvent> faults;
  bool world_changed{false};  ///< objects moved, appeared or disappeared (not just the robot)
};

/// What a robot driver that is restarted needs to resume the physical world where it stood
/// (issue 13: the robot and the world do not restart with the driver's process): the robot's
/// state, what the gripper holds, every object (hidden ones included, wherever faults, pushes and
/// places left them) and the simulator's memory of command ids (the action log), so that an id
/// accepted before the restart is still never executed again. Written by `snapshot()`, taken up by
/// `resume()`; the node keeps it in the run folder (node/checkpoint.h).
/// Not in it: objects that fell onto the robot and ride on it (they stay where they were), the
/// random streams (execution noise after a restart is drawn afresh from `SimParams::seed`), and
/// injected faults not fired yet.
struct SimSnapshot {
  double time_s{0.0};                     ///< simulated time of the snapshot
  /// Wall-clock time (s since the Unix epoch) of simulated time 0: stamps are epoch_s + time, so
  /// a resumed simulator's stamps go on from where they were instead of jumping back (readers
  /// such as perception drop a frame older than the previous one).
  double epoch_s{0.0};
  robot::RobotState robot;                ///< base, arm and gripper joints
  std::optional<world::HeldObject> held;  ///< the object in the gripper (held by the tool link)
  std::vector<world::Object> objects;     ///< every object of the ground truth, hidden ones included
  std::vector<std::string> fired_faults;    ///< ids of the scripted faults that have fired
  std::vector<std::string> pending_faults;  ///< ids of fail-action faults waiting for their kind
  /// Every accepted command in order; the one running at the snapshot has no result.
  std::vector<ActionLogEntry> log;
  /// The commanding side's names of objects it perceived itself, bound to the truth's ids
  /// (commanded id -> truth id; see `submit`).
  std::map<std::string, std::string> names;
};

/// The reason given for a command that was running when the robot driver was restarted.
inline constexpr const char* kRestartedMidAction = "robot driver restarted mid-action";

/// The URDF velocity limit of each arm joint, by name (the `joint_speed` of dynamics.h).
std::unordered_map<std::string, double> armSpeedLimits(const robot::RobotModel& robot);

class Simulator {
 public:
  /// @param truth the ground-truth world (hidden objects included). Its `held()` object, if any,
  ///   must be held by the robot's tool link.
  /// @param initial where the robot starts.
  /// @param faults scripted faults.
  /// @throws std::invalid_argument when `params` or a fault is invalid, the initial state does
  ///   not fit the robot, or the held object is inconsistent (the message names the field).
  Simulator(world::World truth, robot::RobotModel robot, robot::RobotState initial,
            SimParams params, std::vector<Fault> faults = {});
  ~Simulator();
  Simulator(const Simulator&) = delete;
  Simulator& operator=(const Simulator&) = delete;

  /// Starts executing `command`. Idempotent on `command_id`: an id accepted before is never
  /// executed again (Ok; while it runs the caller joins it, after it ended its recorded result is
  /// emitted again by the next `step()`, without a second record). Rejections (kInvalidArgument naming the field: unknown or
  /// duplicate joint, NaN, non-monotonic times, a start away from the current state, a missing
  /// object pose, joint limits; kUnavailable while another action runs) leave the robot idle and
  /// produce no record. An accepted command's outcome comes from later `step()` calls.
  /// Object ids: the physical world has none. A pick or place naming an object the truth does not
  /// know (perception's own id for an object it found) acts on the truth's movable object that the
  /// command's object pose lies in, and that name stays bound to it: later commands, the held
  /// object of `robotState()` and a blocked action's `blocking_object_id` use it.
  Status submit(const ActionCommand& command);
  /// The true nominal duration of `command` started now (no noise, no stall; deterministic and
  /// without touching the random streams): the oracle's answer. The same validation as submit().
  Result<double> nominalDuration(const ActionCommand& command);
  /// Stops the action `command_id` where the robot is; its result (kCancelled) comes with the
  /// next `step()`. kNotFound when it is not the action in progress.
  Status cancel(const std::string& command_id);
  /// Queues a fault to fire at the next `step()`. kFailAction fails the action in progress, or
  /// the next action at `trigger.fraction` of its duration when idle. kInvalidArgument for an
  /// invalid fault (e.g. a spawned object with a taken id).
  Status inject(Fault fault);

  /// Advances simulated time by `dt` >= 0 seconds (throws std::invalid_argument otherwise).
  StepEvents step(double dt);
  /// Simulated seconds since construction (since the start of the run after `resume()`).
  double time() const;
  /// Wall-clock seconds since the Unix epoch at simulated time 0 (construction, or the resumed
  /// snapshot's): a stamp of simulated time t is epoch() + t (records; SimulationLoop::stampNs).
  double epoch() const;
  bool busy() const;
  /// Time left of the action in progress (0 when idle), simulated seconds.
  double remainingActionTime() const;
  /// Number of actions accepted so far (the next action's step index).
  int actionCount() const;
  /// Every accepted action in order, with its result once it ended.
  const std::vector<ActionLogEntry>& actionLog() const;

  /// The physical state and the action log now (see SimSnapshot). The robot state is the one an
  /// action in progress has reached; that action is in the log without a result.
  SimSnapshot snapshot() const;
  /// Takes up `snapshot` (a simulator killed and restarted): the world's objects, the held object
  /// and the robot's state are the snapshot's (regions and locations stay this simulator's),
  /// simulated time and the stamps' epoch go on from the snapshot's, the scripted faults that fired stay fired, and
  /// the action log is the snapshot's. The command that was running is not resumed (the robot
  /// stopped where it stood): it ends kFailed with `kRestartedMidAction` in its reason, reported by
  /// the next `step()` and again to a sender that repeats its id; no record is made for it.
  /// kInvalidArgument naming the field (`robot.arm`, `held`, `objects[id]`, `fired_faults[i]`,
  /// `log[i].command_id`) when the snapshot does not fit this simulator; then nothing changed.
  /// @throws std::logic_error when this simulator has accepted a command already.
  Status resume(const SimSnapshot& snapshot);

  RobotStateSample robotState() const;
  /// The ground truth (hidden objects included; the held object at its current pose).
  const world::World& world() const;
  const robot::RobotModel& robot() const;
  const SimParams& params() const;

  /// A depth frame from the robot's sensor now; `stamp_ns` is stored in the frame.
  PointCloudFrame captureCloud(std::int64_t stamp_ns, GroundTruthLabels* labels = nullptr);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace tamp::sim
