// Online replanning ("On-Line Replanning" of the paper): a sub-task from the robot's node that
// re-joins the next healthy nodes of the branch, invalidation of motions near what changed, and
// pricing again from refitted models.
#include <algorithm>
#include <cmath>
#include <set>

#include "tamp/core/log.h"
#include "tamp/graph_manager/contact.h"
#include "tamp/graph_manager/graph_manager.h"
#include "object_geometry.h"
#include "state_atoms.h"
#include "tamp/world/polygon.h"

namespace tamp::graph_manager {
namespace {
using detail::applyChange;
using detail::exactly;
using detail::mentions;

double pointSegment(const Eigen::Vector2d& p, const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
  const Eigen::Vector2d ab = b - a;
  const double t = ab.squaredNorm() > 1e-12 ? std::clamp((p - a).dot(ab) / ab.squaredNorm(), 0.0, 1.0) : 0.0;
  return (a + t * ab - p).norm();
}

/// Distance from `p` to the base path (x, y of the path's waypoints), infinite without one.
double distanceToBasePath(const Eigen::Vector2d& p, const JointPath& path) {
  const int ix = path.indexOf("base_x"), iy = path.indexOf("base_y");
  if (ix < 0 || iy < 0 || path.waypoints.empty()) return kInfinity;
  auto at = [&](std::size_t i) {
    return Eigen::Vector2d(path.waypoints[i][static_cast<std::size_t>(ix)], path.waypoints[i][static_cast<std::size_t>(iy)]);
  };
  double d = (at(0) - p).norm();
  for (std::size_t i = 1; i < path.waypoints.size(); ++i) d = std::min(d, pointSegment(p, at(i - 1), at(i)));
  return d;
}

/// Forgets the motion (and the arm motions per next edge) an edge was priced with: planned again
/// when a branch reaches it.
void forgetMotion(Edge& e) {
  e.motion.reset();
  e.motion_by_next.clear();
  e.effort_by_next.clear();
  e.state = EdgeState::kUnevaluated;
  e.effort_mean_s = kInfinity;
  e.reason.clear();
}

}  // namespace

std::string_view toString(EventKind k) {
  switch (k) {
    case EventKind::kActionFailed: return "action_failed";
    case EventKind::kActionBlocked: return "action_blocked";
    case EventKind::kObjectDropped: return "object_dropped";
    case EventKind::kNewObstacle: return "new_obstacle";
    case EventKind::kObjectMoved: return "object_moved";
    case EventKind::kOverrun: return "overrun";
    case EventKind::kNotPrepared: return "not_prepared";
    case EventKind::kHandNotEmpty: return "hand_not_empty";
  }
  return "?";
}

std::vector<NodeId> GraphManager::rejoin(NodeId current, const std::vector<EdgeId>& ahead,
                                         const std::vector<std::string>& new_objects, const std::string& origin) {
  std::vector<NodeId> joined;
  const std::vector<std::string> cur = graph_.node(current).atoms;
  std::vector<std::string> carried;
  for (const auto& a : cur)
    if (mentions(a, new_objects)) carried.push_back(a);
  for (std::size_t i = 0; i < ahead.size() && static_cast<int>(joined.size()) < params_.max_rejoin_targets; ++i) {
    const NodeId target = graph_.edge(ahead[i]).to;
    if (!graph_.node(target).healthy) continue;
    // The branch from `target` on, in states that keep what is known now about the new objects.
    const NodeId join = carried.empty() ? target : carryAhead(target, ahead, i + 1, carried, origin);
    if (join == current) {
      joined.push_back(join);
      break;
    }
    auto plan = planFrom(current, exactly(cur, graph_.node(join).atoms), origin + ": re-join n" + std::to_string(join));
    if (!plan) {
      log::get("graph_manager")->info("no re-join of n{} from n{}: {}", join, current, plan.error().message);
      continue;
    }
    const NodeId end = plan->empty() ? current : graph_.edge(plan->back()).to;
    if (end != join) continue;  // the planner reached another state (cannot happen with exact goals)
    ++counters_.subtasks;
    joined.push_back(join);
  }
  return joined;
}

NodeId GraphManager::carryAhead(NodeId target, const std::vector<EdgeId>& ahead, std::size_t first,
                                const std::vector<std::string>& carried, const std::string& origin,
                                Contingency::Plan* record) {
  std::vector<std::string> actions;
  std::vector<std::vector<std::string>> states;
  std::vector<std::string> s = graph_.node(target).atoms;
  s.insert(s.end(), carried.begin(), carried.end());
  std::sort(s.begin(), s.end());
  s.erase(std::unique(s.begin(), s.end()), s.end());
  states.push_back(s);
  for (std::size_t j = first; j < ahead.size(); ++j) {
    const Edge& e = graph_.edge(ahead[j]);
    actions.push_back(e.action);
    states.push_back(applyChange(states.back(), graph_.node(e.from).atoms, graph_.node(e.to).atoms));
  }
  const NodeId join = graph_.addNode(states.front(), origin);
  if (!actions.empty()) (void)graph_.addPlan(actions, states, origin + " (the branch ahead, with what is new)");
  if (record) *record = {actions, states};
  return join;
}

int GraphManager::invalidateNear(const std::vector<world::Object>& objects) {
  if (objects.empty()) return 0;
  const double robot = abstraction_.robot().baseRadius();
  int n = 0;
  auto near = [&](const JointPath& path) {
    for (const auto& o : objects) {
      const Eigen::Vector2d c = o.pose.translation().head<2>();
      if (distanceToBasePath(c, path) <= robot + detail::footprintRadius(o) + params_.keep_clear_margin_m) return true;
    }
    return false;
  };
  for (const Edge& ce : graph_.edges()) {
    Edge& e = graph_.edge(ce.id);
    if (e.kind != ActionKind::kMoveBase || !e.motion) continue;
    if (e.state == EdgeState::kExecuted || e.state == EdgeState::kExecuting) continue;
    if (!near(e.motion->lazy_path) && !near(e.motion->trajectory.path())) continue;
    forgetMotion(e);  // a base edge: no arm motions per next edge
    e.subtasks_spawned = false;
    ++n;
  }
  return n;
}

bool GraphManager::widenHeldMargin(const std::string& held, const std::string& blocker) {
  const double was = held_padding_m_;
  held_padding_m_ = std::min(params_.held_padding_max_m, held_padding_m_ + params_.held_padding_step_m);
  if (held_padding_m_ <= was) {
    log::get("graph_manager")->warn("stopped before '{}' holding '{}': the held object's margin is already {:.2f} m",
                                    blocker, held, was);
    return false;
  }
  int n = 0;
  for (const Edge& ce : graph_.edges()) {
    Edge& e = graph_.edge(ce.id);
    if (e.state == EdgeState::kExecuted || e.state == EdgeState::kExecuting) continue;
    if (e.kind != ActionKind::kMoveBase && e.kind != ActionKind::kMoveArm) continue;
    if (heldAt(e.from).empty() || isPush(e)) continue;
    forgetMotion(e);
    ++n;
  }
  log::get("graph_manager")->info("stopped before '{}' holding '{}': held objects planned {:.2f} m larger from now on "
                                  "({} motions to plan again)",
                                  blocker, held, held_padding_m_, n);
  return true;
}

namespace {
/// The world model seeing a corrected object this much farther from where it had it when the
/// robot stopped (m) has seen it anew: the correction ends. Below it, estimate noise.
constexpr double kCorrectionHoldM = 0.03;
}  // namespace

std::optional<ContactCorrection> GraphManager::correctByContact(const world::World& perceived, world::World& live,
                                                                const std::string& object,
                                                                const robot::RobotState& stop) {
  const world::Object* o = live.findObject(object);
  const world::Object* p = perceived.findObject(object);
  if (!o || !p || o->kind != world::ObjectKind::kMovable || !(params_.contact_correction_max_m > 0)) return std::nullopt;
  const Eigen::Isometry3d seen = p->pose;
  auto c = touchingPose(*o, abstraction_.robot(), stop, params_.contact_correction_max_m);
  if (!c) {
    log::get("graph_manager")->info("stopped before '{}': its estimate agrees with the stop (or is too far off to tell)", object);
    return std::nullopt;
  }
  const Eigen::Vector3d a = o->pose.translation(), b = c->pose.translation();
  (void)live.setObjectPose(object, c->pose);
  corrections_[object] = ContactCorrected{c->pose, seen};
  log::get("graph_manager")
      ->info("stopped before '{}': it stands {:.3f} m {} the robot than the world model has it; planned at ({:.3f}, "
             "{:.3f}) instead of ({:.3f}, {:.3f}) until the world model sees it move",
             object, std::abs(c->shift_m), c->shift_m > 0 ? "nearer" : "farther from", b.x(), b.y(), a.x(), a.y());
  return c;
}

void GraphManager::applyContactCorrections(const world::World& perceived, world::World& live) {
  for (auto it = corrections_.begin(); it != corrections_.end();) {
    const world::Object* o = perceived.findObject(it->first);
    if (!o || (o->pose.translation() - it->second.seen.translation()).norm() > kCorrectionHoldM) {
      log::get("graph_manager")->info("'{}': the world model {}; its contact correction ends", it->first,
                                      o ? "sees it moved" : "lost it");
      it = corrections_.erase(it);
      continue;
    }
    if (live.findObject(it->first)) (void)live.setObjectPose(it->first, it->second.pose);
    ++it;
  }
}

std::string GraphManager::heldAt(NodeId n) const {
  for (const auto& a : graph_.node(n).atoms) {
    const auto t = atomTokens(a);
    if (t.size() == 2 && t[0] == "holding") return t[1];
  }
  return {};
}

double GraphManager::heldMassAt(NodeId n) const {
  const std::string held = heldAt(n);
  if (held.empty()) return 0.0;
  const world::Object* o = abstraction_.world().findObject(held);
  return o ? o->mass : 0.0;
}

void GraphManager::reprice() {
  std::vector<EffortQuery> queries;
  std::vector<std::pair<EdgeId, EdgeId>> owners;  // edge, next (-2: the edge's own motion)
  for (const Edge& e : graph_.edges()) {
    if (e.state == EdgeState::kExecuted || e.state == EdgeState::kExecuting) continue;
    EffortQuery q;
    q.object_mass = heldMassAt(e.from);
    if (isPush(e) && e.motion) q.object_mass = e.motion->object_mass;
    if (e.kind == ActionKind::kMoveBase && e.state == EdgeState::kFeasible && e.motion) {
      q.kind = ActionKind::kMoveBase;
      q.path = e.motion->lazy_path;
      queries.push_back(q);
      owners.emplace_back(e.id, -2);
    } else if (e.kind == ActionKind::kMoveArm) {
      for (const auto& [next, m] : e.motion_by_next) {
        if (m.trajectory.empty() || !e.effort_by_next.count(next)) continue;
        q.kind = ActionKind::kMoveArm;
        q.path = m.lazy_path;
        queries.push_back(q);
        owners.emplace_back(e.id, next);
      }
    }
  }
  if (queries.empty()) return;
  counters_.effort_calls += static_cast<int>(queries.size());
  const std::vector<EffortAnswer> answers = services_.effort(queries);
  for (std::size_t i = 0; i < answers.size() && i < owners.size(); ++i) {
    if (!answers[i].ok) continue;
    Edge& e = graph_.edge(owners[i].first);
    if (owners[i].second == -2) {
      e.effort_mean_s = answers[i].mean_s;
      e.effort_stddev_s = answers[i].stddev_s;
    } else {
      e.effort_by_next[owners[i].second] = {answers[i].mean_s, answers[i].stddev_s};
    }
  }
}

}  // namespace tamp::graph_manager
