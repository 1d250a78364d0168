#include "tamp/graph_manager/report.h"

#include <cmath>

#include <nlohmann/json.hpp>

namespace tamp::graph_manager {
namespace {

nlohmann::json number(double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr); }

nlohmann::json pose(const Eigen::Isometry3d& p) {
  const Eigen::Vector3d t = p.translation();
  const double yaw = std::atan2(p.linear()(1, 0), p.linear()(0, 0));
  return {{"x", t.x()}, {"y", t.y()}, {"z", t.z()}, {"yaw", yaw}};
}

/// Service calls and where their time went: per service, in total ("critical": on the way to
/// the command that followed), and each call.
nlohmann::json callsJson(const std::vector<TimedCall>& timed) {
  const CallSummary sum = CallSummary::of(timed);
  auto per = [](const CallSummary::PerService& p) { return nlohmann::json{{"calls", p.calls}, {"s", p.s}}; };
  nlohmann::json calls = nlohmann::json::array();
  for (const auto& c : timed) calls.push_back({{"service", c.service}, {"what", c.what}, {"s", c.s}, {"server_s", c.server_s}});
  return {{"per_service",
           {{"plan", per(sum.plan)},
            {"motion", per(sum.motion)},
            {"placement", per(sum.placement)},
            {"grasp", per(sum.grasp)},
            {"effort", per(sum.effort)}}},
          {"critical_calls", sum.calls()},
          {"critical_calls_s", sum.seconds()},
          {"calls", calls}};
}

}  // namespace

std::string reportJson(const MissionReport& r, const std::string& scenario, const std::string& policy,
                       std::uint32_t seed) {
  nlohmann::json j;
  j["schema"] = "tamp-mission-report/1";
  j["scenario"] = scenario;
  j["policy"] = policy;
  j["seed"] = seed;
  j["status"] = r.status == MissionOutcome::kSucceeded ? "succeeded"
                : r.status == MissionOutcome::kAborted ? "aborted"
                                                       : "failed";
  j["outcome"] = std::string(toString(r.status));
  j["reason"] = r.reason;
  j["executed_effort_s"] = r.executed_effort_s;
  j["predicted_effort_s"] = number(r.predicted_effort_s);
  j["planning_time_s"] = r.planning_time_s;
  j["planning_time_to_first_action_s"] = r.planning_time_to_first_action_s;
  j["replans"] = r.replans;
  j["resumptions"] = r.resumptions;
  j["planner_calls"] = r.counters.planner_calls;
  j["motion_calls"] = r.counters.motion_calls;
  j["placement_calls"] = r.counters.placement_calls;
  j["grasp_calls"] = r.counters.grasp_calls;
  j["effort_calls"] = r.counters.effort_calls;
  j["edge_evaluations"] = r.counters.evaluations;
  j["subtasks"] = r.counters.subtasks;
  j["memo_hits"] = r.counters.memo_hits;
  j["objects_moved"] = r.objects_moved;
  nlohmann::json moved = nlohmann::json::array();
  for (std::size_t i = 0; i < r.moved_to.size(); ++i) {
    nlohmann::json m{{"object", r.moved_to[i].first}, {"to", pose(r.moved_to[i].second)}};
    for (const auto& [id, p] : r.moved_from)
      if (id == r.moved_to[i].first) m["from"] = pose(p);
    moved.push_back(m);
  }
  j["moves"] = moved;
  nlohmann::json perceived = nlohmann::json::array();
  for (const auto& o : r.perceived) {
    // The footprint in world coordinates (x, y), as the world model estimated it.
    const Eigen::Isometry3d& p = o.pose;
    nlohmann::json fp = nlohmann::json::array();
    for (const auto& v : o.shape.footprint(16)) {
      const Eigen::Vector3d w = p * Eigen::Vector3d(v.x(), v.y(), 0.0);
      fp.push_back({w.x(), w.y()});
    }
    perceived.push_back({{"id", o.id}, {"kind", std::string(world::toString(o.kind))}, {"pose", pose(p)}, {"footprint", fp}});
  }
  j["perceived"] = perceived;
  nlohmann::json decisions = nlohmann::json::array();
  for (const auto& d : r.decisions) {
    nlohmann::json alts = nlohmann::json::array();
    for (const auto& a : d.alternatives) {
      alts.push_back({{"alternative", a.description},
                      {"effort_s", number(a.effort_s)},
                      {"cut", a.cut},
                      {"bound_s", a.cut ? number(a.bound_s) : nlohmann::json(nullptr)},
                      {"chosen", a.chosen}});
    }
    decisions.push_back({{"node", d.node}, {"traverse", d.traverse}, {"what", d.what}, {"alternatives", alts}});
  }
  j["decisions"] = decisions;
  nlohmann::json actions = nlohmann::json::array();
  for (const auto& a : r.actions) {
    nlohmann::json path = nlohmann::json::array();
    const int ix = a.path.indexOf("base_x"), iy = a.path.indexOf("base_y");
    if (ix >= 0 && iy >= 0)
      for (const auto& w : a.path.waypoints) path.push_back({w[static_cast<std::size_t>(ix)], w[static_cast<std::size_t>(iy)]});
    actions.push_back({{"command_id", a.command_id},
                       {"action", a.action},
                       {"variant", a.variant},
                       {"predicted_s", number(a.predicted_s)},
                       {"predicted_stddev_s", number(a.predicted_stddev_s)},
                       {"measured_s", a.measured_s},
                       {"outcome", a.outcome},
                       {"reason", a.reason},
                       {"base_path", path}});
  }
  j["actions"] = actions;
  j["first_action_breakdown"] = callsJson(r.first_action_calls);
  nlohmann::json replanning = nlohmann::json::array();
  for (const auto& rp : r.replanning) {
    nlohmann::json breakdown(nullptr);
    if (rp.latency_s >= 0.0) {
      breakdown = callsJson(rp.breakdown.calls);
      breakdown["repair_s"] = rp.breakdown.repair_s;
      breakdown["traverse_s"] = rp.breakdown.traverse_s;
      breakdown["prepare_s"] = rp.breakdown.prepare_s;
      breakdown["evaluations"] = rp.breakdown.evaluations;
      breakdown["background_calls"] = rp.breakdown.background_calls;
      breakdown["background_s"] = rp.breakdown.background_s;
    }
    replanning.push_back({{"event", std::string(toString(rp.event.kind))},
                          {"action", rp.event.action},
                          {"object", rp.event.object_id},
                          {"detail", rp.event.detail},
                          {"at_node", rp.at_node},
                          {"how", rp.how},
                          {"rejoined", rp.rejoined},
                          {"held_padding_m", rp.held_padding_m},
                          {"contact_correction", rp.corrected_object.empty()
                                                     ? nlohmann::json(nullptr)
                                                     : nlohmann::json{{"object", rp.corrected_object},
                                                                      {"shift_m", rp.corrected_m}}},
                          {"planner_calls", rp.planner_calls},
                          {"motion_calls", rp.motion_calls},
                          {"planning_s", rp.planning_s},
                          {"latency_s", rp.latency_s >= 0.0 ? nlohmann::json(rp.latency_s) : nlohmann::json(nullptr)},
                          {"latency_breakdown", breakdown}});
  }
  j["replanning"] = replanning;
  nlohmann::json conditionals = nlohmann::json::array();
  auto orNull = [](auto v) { return v >= 0 ? nlohmann::json(v) : nlohmann::json(nullptr); };
  for (const auto& c : r.conditionals) {
    conditionals.push_back({{"at_node", c.at_node},
                            {"observation", c.observation},
                            {"prebuilt", c.prebuilt},
                            {"branch_node", c.branch_node.empty() ? nlohmann::json(nullptr) : nlohmann::json(c.branch_node)},
                            {"planner_calls", orNull(c.planner_calls)},
                            {"motion_calls", orNull(c.motion_calls)},
                            {"latency_s", orNull(c.latency_s)}});
  }
  j["conditionals"] = conditionals;
  return j.dump(2);
}

}  // namespace tamp::graph_manager
