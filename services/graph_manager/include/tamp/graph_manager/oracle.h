#pragma once
/// @file
/// The `oracle` policy's knowledge and its pure pieces (docs/architecture.md, "Policies").
///
/// The oracle is the lower bound the `effort` and `infeasible` policies are measured against
/// (issue 12 part 4): it knows what the simulator knows. The graph manager library does not see
/// the simulator: it asks `ServiceClients::oracle()` (the node answers it over DDS from the
/// simulator, which serves the truth only in an evaluation run) and prices efforts with
/// `ServiceClients::effort()`, which the node points at the simulator's true nominal durations
/// under this policy. What the library does with the knowledge:
/// - hidden objects are in the world the first plan is made in (the node adds them to the world
///   source; see OracleWorldSource in the node);
/// - a scripted action failure is priced as the retry it will cost (`faultRetryPenalty`: the
///   action it strikes is paid twice), added to each complete branch;
/// - remove-or-avoid is exhaustive: for an edge blocked by n movable objects, every subset of up
///   to `oracle_max_objects` of them is a removal sub-task (`removalSubsets`), the objects not in
///   it are gone round, and Traverse cuts no branch on its bound.

#include <cstddef>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "tamp/core/trajectory.h"
#include "tamp/world/world.h"

namespace tamp::graph_manager {

/// A scripted fault of the simulator as the oracle reveals it.
struct OracleFault {
  enum class Type { kDropHeldObject, kSpawnObject, kFailAction, kRemoveObject };
  std::string id;
  Type type{Type::kFailAction};
  std::optional<double> time_s;      ///< fires at this simulated time, or
  std::optional<int> step;           ///< during the step-th command the simulator accepts (0-based)
  std::optional<ActionKind> action;  ///< kFailAction: only this kind (none: any)
  std::string object_id;             ///< spawn/remove
};

/// What the simulator knows and the planner's view does not.
struct OracleKnowledge {
  std::vector<world::Object> hidden;  ///< hidden objects (their true kind, `hidden` false)
  std::vector<OracleFault> faults;    ///< every scripted fault
  int action_count{0};                ///< commands the simulator accepted when asked
  double sim_time_s{0.0};
};

/// Every subset of {0, ..., n-1} with 1 to `max_size` elements, smaller subsets first, each in
/// increasing order (lexicographic within a size). n = 3, max_size = 2: {0} {1} {2} {0,1} {0,2}
/// {1,2}. Empty for n = 0 or max_size < 1.
std::vector<std::vector<std::size_t>> removalSubsets(std::size_t n, int max_size);

/// `live` with the oracle's hidden objects added, except those the live world already has: under
/// the same id, or as an object of perception's own (an object's centre lies within the hidden
/// one's bounding box, or a movable's footprint box overlaps it). Their `hidden` flag is off.
/// With `found`: the ids of hidden objects found so far, never added again (an object the robot
/// has moved away from where it was hidden is not there twice); those found now are inserted.
world::World withHidden(const world::World& live, const std::vector<world::Object>& hidden,
                        std::set<std::string>* found = nullptr);

/// One action of a branch as the robot will execute it.
struct BranchStep {
  ActionKind kind{ActionKind::kMoveBase};
  double effort_s{0.0};  ///< its predicted duration
  int commands{1};       ///< commands it sends the robot (a pick with a transfer arm motion: 2)
};

/// What scripted action failures will cost a branch that starts when the simulator has accepted
/// `action_count` commands: each kFailAction fault with a step trigger not yet reached strikes
/// the first action of its kind at or after its step, which is then executed twice (the failed
/// attempt and the retry): its effort is added once. Faults with a time trigger and other fault
/// types cost nothing here (a drop or an appearing object is not a fixed price). With
/// `max_failures` > 0 (the graph manager's `max_action_failures`): an action struck by that many
/// faults or more will be given up, so the branch will not be executed as planned; it costs
/// `kGivenUpPenaltyS` on top, which any branch that avoids it beats.
inline constexpr double kGivenUpPenaltyS = 1e6;
double faultRetryPenalty(const std::vector<OracleFault>& faults, int action_count,
                         const std::vector<BranchStep>& branch, int max_failures = 0);

}  // namespace tamp::graph_manager
