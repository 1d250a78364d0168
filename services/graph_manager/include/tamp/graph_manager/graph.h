#pragma once
/// @file
/// The reachability graph of the paper (Algorithm 2, `RGraph(P)` and `updateRGraph`): nodes are
/// symbolic states (their dynamic atoms; the geometric binding follows from them through the
/// Abstraction), edges are ground actions with their motion, their effort and a state. Equal
/// states are one node, so plans found from different places merge where they meet.

#include <cstdint>
#include <deque>
#include <limits>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "tamp/core/trajectory.h"
#include "tamp/graph_manager/clients.h"

namespace tamp::graph_manager {

using NodeId = int;
using EdgeId = int;
inline constexpr double kInfinity = std::numeric_limits<double>::infinity();

enum class EdgeState { kUnevaluated, kLazy, kFeasible, kInfeasible, kExecuting, kExecuted, kFailed };
std::string_view toString(EdgeState s);

/// How an edge's motion is obtained.
enum class Variant {
  kDirect,  ///< the lazy path (crossing no movable, or crossing movables moved away by the branch)
  kAround,  ///< a full-mode path around every known object (the "avoid" alternative)
};
std::string_view toString(Variant v);

struct Node {
  NodeId id{-1};
  std::vector<std::string> atoms;  ///< sorted dynamic atoms
  bool healthy{true};
  std::string origin;              ///< which plan or sub-task created it
};

/// The motion of an edge once evaluated.
struct EdgeMotion {
  Trajectory trajectory;        ///< what the robot executes
  JointPath lazy_path;          ///< the static-only lazy path (base moves)
  std::vector<std::string> blocking;  ///< movables the lazy path crosses
  std::vector<Crossing> crossings;
  std::string object_id;        ///< pick/place
  std::string region_id;
  std::optional<Eigen::Isometry3d> object_target;
  double approach_m{0.0};
  double retreat_m{0.0};
  double object_mass{0.0};
  Eigen::Isometry3d gripper_in_object{Eigen::Isometry3d::Identity()};  ///< pick: the grasp
  /// move_arm into a manipulation: the manipulation it prepares (pre-grasp / pre-place, the
  /// grasp or place configuration, the grasp, the place pose).
  std::optional<GraspOption> prepared;
  std::optional<Eigen::Isometry3d> prepared_place;
  /// Priced without a grasp: in the branch's hypothetical world (objects moved by earlier edges)
  /// the grasp service, which sees the world as it is, found none. Planned for real when the
  /// edge is about to run.
  bool deferred{false};
  /// pick/place without a move_arm before it: the arm motion to the pre-grasp, executed first
  /// as its own move_arm; its effort is part of the edge's.
  Trajectory transfer;
  double transfer_effort_s{0.0};
  double transfer_stddev_s{0.0};
  /// The context the motion was planned in (GraphManager::contextKey): a motion planned in the
  /// robot's own context, in the world as it is, is not planned again before it is sent.
  std::string planned_in;
};

struct Edge {
  EdgeId id{-1};

  NodeId from{-1};
  NodeId to{-1};
  std::string action;              ///< "(move_base start goal)"
  std::vector<std::string> tokens; ///< {"move_base", "start", "goal"}
  ActionKind kind{ActionKind::kMoveBase};
  Variant variant{Variant::kDirect};
  EdgeState state{EdgeState::kUnevaluated};
  std::string origin;              ///< "plan 0", "sub-task: move box (slot_box_1)", ...
  double lower_bound_s{0.0};       ///< admissible: before any motion is known
  double effort_mean_s{kInfinity}; ///< predicted execution time once evaluated
  double effort_stddev_s{0.0};
  std::string reason;              ///< why infeasible / failed
  /// The motion planner's outcome of the last motion asked for this edge (kSolved: none failed).
  /// Policy `infeasible` moves objects only once a way round is kNoPath (proven, not timed out).
  MotionOutcome motion_outcome{MotionOutcome::kSolved};
  std::optional<EdgeMotion> motion;
  /// move_arm edges: the motion depends on the manipulation that follows (the pre-grasp of the
  /// object picked next); evaluated per next edge.
  std::map<EdgeId, EdgeMotion> motion_by_next;
  std::map<EdgeId, std::pair<double, double>> effort_by_next;  ///< mean, stddev
  bool cut{false};                 ///< pruned by the branch-and-bound at least once
  bool subtasks_spawned{false};
  int failures{0};  ///< failed or blocked executions of this move edge in this mission (manipulations: per object)
};

/// Whether `e` is a push: a base motion that moves an object ahead of the base.
bool isPush(const Edge& e);
/// Whether a domain text declares the `push` action and the `push-to` predicate (any case and spacing).
bool pushesIn(const std::string& domain_pddl);

class ReachabilityGraph {
 public:
  /// The node of `atoms` (sorted and deduplicated here), created if new.
  NodeId addNode(std::vector<std::string> atoms, const std::string& origin);
  std::optional<NodeId> findNode(const std::vector<std::string>& sorted_atoms) const;

  /// `updateRGraph(G, p)`: adds the plan's states as nodes (merging equal ones) and its actions as
  /// edges (an edge equal in from, to, action and variant is reused). `states` has one more entry
  /// than `actions`; states[0] must be the state of an existing node or is added. Returns the
  /// edges along the plan.
  std::vector<EdgeId> addPlan(const std::vector<std::string>& actions,
                              const std::vector<std::vector<std::string>>& states, const std::string& origin);
  /// A parallel edge of `e` with another variant (reused when it exists).
  EdgeId addVariant(EdgeId e, Variant v, const std::string& origin);

  const Node& node(NodeId id) const { return nodes_.at(static_cast<std::size_t>(id)); }
  Node& node(NodeId id) { return nodes_.at(static_cast<std::size_t>(id)); }
  const Edge& edge(EdgeId id) const { return edges_.at(static_cast<std::size_t>(id)); }
  Edge& edge(EdgeId id) { return edges_.at(static_cast<std::size_t>(id)); }
  const std::deque<Node>& nodes() const { return nodes_; }
  const std::deque<Edge>& edges() const { return edges_; }
  /// Out-edges of a node, in insertion order.
  const std::vector<EdgeId>& out(NodeId n) const;
  std::uint64_t version() const { return version_; }

  /// Graphviz text: efforts on edges, `chosen` highlighted, cut and infeasible edges greyed.
  std::string toDot(const std::vector<EdgeId>& chosen, NodeId current) const;

 private:
  // Deques: a reference to a node or an edge stays valid while the graph grows (Traverse and the
  // conditional branches hold them across sub-task insertions).
  std::deque<Node> nodes_;
  std::deque<Edge> edges_;
  std::map<std::vector<std::string>, NodeId> index_;
  std::map<NodeId, std::vector<EdgeId>> out_;
  std::uint64_t version_{0};
};

/// The action kind of a ground action's name ("move_base" ...), if one of the robot's.
std::optional<ActionKind> actionKindOf(const std::string& action_name);

}  // namespace tamp::graph_manager
