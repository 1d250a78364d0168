#pragma once
/// @file
/// Execution faults: scripted in a scenario (fire at a simulated time or during an action step)
/// or injected by a test harness at run time (`FaultInjection` on DDS). They are the unknown
/// events of the paper's execution loop: a dropped object, an obstacle that appears, an action
/// that fails.

#include <optional>
#include <string>
#include <string_view>

#include <Eigen/Geometry>

#include "tamp/core/error.h"
#include "tamp/core/trajectory.h"
#include "tamp/world/world.h"

namespace tamp::sim {

enum class FaultType {
  kDropHeldObject,  ///< the gripper loses its object: it falls onto the surface below
  kSpawnObject,     ///< `object` appears in the world (e.g. a person leaves a box in the way)
  kFailAction,      ///< the action in progress (or the next one) stops and reports failure
  kRemoveObject,    ///< `object_id` disappears from the world
};
std::string_view toString(FaultType type);  ///< "drop_held_object", "spawn_object", ...
std::optional<FaultType> faultTypeFromString(std::string_view name);

/// When a scripted fault fires: at a simulated time, or during the `step`-th action the simulator
/// executes (0-based, counting every accepted command) once `fraction` of its duration has
/// elapsed (at the latest when that action ends). Exactly one of `time_s` and `step` is set.
struct FaultTrigger {
  std::optional<double> time_s;  ///< simulated seconds since the simulator started; >= 0
  std::optional<int> step;       ///< >= 0
  double fraction{0.5};          ///< in [0, 1]; with `step`: 0 = when the action starts
};

struct Fault {
  std::string id;            ///< for logs and events
  FaultType type{FaultType::kFailAction};
  FaultTrigger trigger;      ///< scripted faults only; injected ones fire at once
  world::Object object;      ///< kSpawnObject: the object (a valid, new id)
  std::string object_id;     ///< kRemoveObject: which object
  /// kFailAction: only an action of this kind fails; when the action at the trigger is another
  /// kind (or none runs), the first matching action at or after the trigger fails.
  /// kDropHeldObject (step trigger only): the drop waits for the first action of this kind, at or
  /// after the trigger's step, that starts with an object in the gripper ("it slips while
  /// carried"), and fires at `fraction` of it.
  std::optional<ActionKind> action;
  std::string reason;        ///< free text reported with the failure

  /// Ok, or kInvalidArgument naming the field ("trigger.step", "object.id", ...). `scripted`
  /// requires a trigger.
  Status validate(bool scripted) const;
};

/// Something that happened to the world outside the robot's control (reported by `step()`).
struct FaultEvent {
  std::string fault_id;
  FaultType type{FaultType::kFailAction};
  std::string object_id;  ///< object dropped, spawned or removed (empty for kFailAction)
  double time_s{0.0};     ///< simulated time it fired
  std::string description;
};

}  // namespace tamp::sim
