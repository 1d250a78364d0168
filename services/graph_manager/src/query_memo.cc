#include "tamp/graph_manager/query_memo.h"

#include <cstdio>

#include <Eigen/Geometry>

namespace tamp::graph_manager {
namespace {

void put(std::string& k, double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.4f,", v);
  k += buf;
}

void put(std::string& k, const Pose2D& p) {
  put(k, p.x);
  put(k, p.y);
  put(k, p.theta);
}

void put(std::string& k, const Eigen::Isometry3d& t) {
  for (int i = 0; i < 3; ++i) put(k, t.translation()[i]);
  const Eigen::Quaterniond r(t.rotation());
  // q and -q are one rotation: one sign, so that equal rotations give equal keys.
  const double s = r.w() < 0 ? -1.0 : 1.0;
  for (double c : {r.w(), r.x(), r.y(), r.z()}) put(k, s * c);
}

void put(std::string& k, const std::vector<ObjectOverride>& overrides) {
  for (const auto& o : overrides) {
    k += "|" + o.object_id + (o.removed ? "-" : "@");
    if (!o.removed) put(k, o.pose);
  }
}

/// Added objects by id and pose (their shapes are the oracle's, fixed for a mission).
void put(std::string& k, const std::vector<world::Object>& added) {
  for (const auto& o : added) {
    k += "|add " + o.id + "@";
    put(k, o.pose);
  }
}

}  // namespace

std::string QueryMemo::key(const MotionQuery& q) {
  std::string k = q.group == Group::kBase ? "base:" : "arm:";
  k += q.mode == Mode::kLazy ? "lazy:" : "full:";
  put(k, q.start.base);
  for (double v : q.start.arm) put(k, v);
  put(k, q.start.gripper);
  k += ">";
  if (q.group == Group::kBase) put(k, q.goal_base);
  for (double v : q.goal_arm) put(k, v);
  k += "|held " + q.held.object_id + " " + q.held.link + " ";
  if (!q.held.object_id.empty()) put(k, q.held.link_T_object);
  if (q.held_padding_m > 0) {
    k += "|pad";
    put(k, q.held_padding_m);
  }
  for (const auto& id : q.ignored) k += "|ignore " + id;
  for (const auto& id : q.fixed) k += "|fixed " + id;
  if (q.straight_only) k += "|straight";
  put(k, q.overrides);
  put(k, q.added);
  k += "|w";
  put(k, q.movable_cost_weight);
  put(k, q.budget_s);
  return k;
}

std::string QueryMemo::key(const GraspQuery& q) {
  std::string k = q.object_id + ":";
  if (q.base) put(k, *q.base);
  else k += "sampled";
  k += "|n" + std::to_string(q.max_grasps) + "|";
  put(k, q.budget_s);
  put(k, q.overrides);
  put(k, q.added);
  return k;
}

const MotionAnswer* QueryMemo::motion(const MotionQuery& q) const {
  auto it = motions_.find(key(q));
  return it == motions_.end() ? nullptr : &it->second;
}

void QueryMemo::keep(const MotionQuery& q, const MotionAnswer& a) {
  if (a.ok()) motions_.insert_or_assign(key(q), a);
}

const std::vector<GraspOption>* QueryMemo::grasps(const GraspQuery& q) const {
  auto it = grasps_.find(key(q));
  return it == grasps_.end() ? nullptr : &it->second;
}

void QueryMemo::keep(const GraspQuery& q, const std::vector<GraspOption>& g) {
  if (!g.empty()) grasps_.insert_or_assign(key(q), g);
}

void QueryMemo::clear() {
  motions_.clear();
  grasps_.clear();
}

}  // namespace tamp::graph_manager
