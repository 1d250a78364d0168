#include "tamp/core/format.h"
#include "tamp/motion_planner/params.h"

#include <cmath>
#include <cstdio>
#include <map>
#include <vector>

#include "tamp/config/yaml_reader.h"
#include "tamp/core/paths.h"

namespace tamp::motion_planner {
namespace {

/// One check of one field: section ("" = top level), key, ok?, message.
struct Rule {
  std::string section;
  std::string key;
  bool ok;
  std::string message;
};

bool pos(double v) { return std::isfinite(v) && v > 0; }
bool nonneg(double v) { return std::isfinite(v) && v >= 0; }

std::vector<Rule> rules(const MotionPlannerParams& p) {
  const auto P = [](const std::string& s, const std::string& k, double v) {
    return Rule{s, k, pos(v), "must be positive, got " + formatNumber(v)};
  };
  const auto N = [](const std::string& s, const std::string& k, double v) {
    return Rule{s, k, nonneg(v), "must be >= 0, got " + formatNumber(v)};
  };
  const auto I = [](const std::string& s, const std::string& k, int v, int lo) {
    return Rule{s, k, v >= lo, "must be >= " + std::to_string(lo) + ", got " + std::to_string(v)};
  };
  const auto& S = p.sampling;
  const auto& L = p.lazy;
  const auto& C = p.cost;
  const auto& R = p.proof;
  const auto& T = p.timing;
  const auto& PL = p.placement;
  const auto& G = p.grasp;
  return {
      P("sampling", "validity_resolution", S.validity_resolution),
      P("sampling", "kpiece_cell_size", S.kpiece_cell_size),
      P("sampling", "arm_cell_size", S.arm_cell_size),
      N("sampling", "range", S.range),
      P("sampling", "goal_position_tolerance", S.goal_position_tolerance),
      P("sampling", "goal_orientation_tolerance", S.goal_orientation_tolerance),
      N("sampling", "workspace_margin", S.workspace_margin),
      I("lazy", "roadmap_samples", L.roadmap_samples, 0),
      I("lazy", "roadmap_neighbors", L.roadmap_neighbors, 2),
      I("lazy", "roadmap_bridge_samples", L.roadmap_bridge_samples, 0),
      P("lazy", "roadmap_bridge_distance", L.roadmap_bridge_distance),
      P("lazy", "path_node_spacing", L.path_node_spacing),
      I("lazy", "roadmap_max_evaluations", L.roadmap_max_evaluations, 1),
      I("lazy", "roadmap_max_new_invalid", L.roadmap_max_new_invalid, 1),
      I("lazy", "roadmap_growth_samples", L.roadmap_growth_samples, 0),
      I("lazy", "roadmap_max_nodes", L.roadmap_max_nodes, 1),
      I("lazy", "roadmap_max_request_nodes", L.roadmap_max_request_nodes, 2),
      I("lazy", "object_ring_samples", L.object_ring_samples, 0),
      I("lazy", "roadmap_cache_entries", L.roadmap_cache_entries, 0),
      P("lazy", "optimize_budget_s", L.optimize_budget_s),
      I("lazy", "shortcut_attempts", L.shortcut_attempts, 0),
      P("lazy", "contact_resolution", L.contact_resolution),
      P("lazy", "swept_spacing", L.swept_spacing),
      P("cost", "base_speed", C.base_speed),
      P("cost", "arm_speed", C.arm_speed),
      N("cost", "approach_distance", C.approach_distance),
      N("cost", "retreat_distance", C.retreat_distance),
      N("cost", "transfer_distance", C.transfer_distance),
      Rule{"cost", "non_graspable_factor", std::isfinite(C.non_graspable_factor) && C.non_graspable_factor >= 1,
           "must be >= 1, got " + formatNumber(C.non_graspable_factor)},
      P("proof", "cell_size", R.cell_size),
      Rule{"proof", "min_cell_size", pos(R.min_cell_size) && R.min_cell_size <= R.cell_size,
           "must be in (0, cell_size], got " + formatNumber(R.min_cell_size)},
      I("proof", "max_cells", R.max_cells, 1),
      P("timing", "base_linear_speed", T.base_linear_speed),
      P("timing", "base_linear_accel", T.base_linear_accel),
      P("timing", "base_angular_speed", T.base_angular_speed),
      P("timing", "base_angular_accel", T.base_angular_accel),
      P("timing", "arm_accel", T.arm_accel),
      Rule{"timing", "arm_speed_scale", pos(T.arm_speed_scale) && T.arm_speed_scale <= 1,
           "must be in (0, 1], got " + formatNumber(T.arm_speed_scale)},
      P("timing", "sample_period", T.sample_period),
      I("placement", "max_attempts", PL.max_attempts, 1),
      N("placement", "support_margin", PL.support_margin),
      P("placement", "base_distance_min", PL.base_distance_min),
      Rule{"placement", "base_distance_max", pos(PL.base_distance_max) && PL.base_distance_max >= PL.base_distance_min,
           "must be >= base_distance_min, got " + formatNumber(PL.base_distance_max)},
      I("placement", "base_poses_per_placement", PL.base_poses_per_placement, 1),
      P("placement", "planar_reach", PL.planar_reach),
      N("placement", "tool_clearance", PL.tool_clearance),
      P("grasp", "approach_distance", G.approach_distance),
      N("grasp", "retreat_distance", G.retreat_distance),
      N("grasp", "finger_margin", G.finger_margin),
      Rule{"grasp", "side_height_fraction", nonneg(G.side_height_fraction) && G.side_height_fraction <= 1,
           "must be in [0, 1], got " + formatNumber(G.side_height_fraction)},
      I("grasp", "cylinder_yaw_samples", G.cylinder_yaw_samples, 1),
      P("grasp", "base_distance_min", G.base_distance_min),
      Rule{"grasp", "base_distance_max", pos(G.base_distance_max) && G.base_distance_max >= G.base_distance_min,
           "must be >= base_distance_min, got " + formatNumber(G.base_distance_max)},
      I("grasp", "base_poses", G.base_poses, 1),
  };
}

void readPlanner(config::FieldReader& r, const std::string& key, PlannerKind& out) {
  std::string name;
  if (!r.optional(key, name)) return;
  if (auto k = plannerKindFromString(name)) {
    out = *k;
  } else {
    r.fail(key, "unknown planner '" + name + "' (expected one of: lbkpiece, kpiece, rrtconnect)");
  }
}

}  // namespace

std::string_view toString(PlannerKind kind) {
  switch (kind) {
    case PlannerKind::kLbkpiece: return "lbkpiece";
    case PlannerKind::kKpiece: return "kpiece";
    case PlannerKind::kRrtConnect: return "rrtconnect";
  }
  return "?";
}

std::optional<PlannerKind> plannerKindFromString(std::string_view name) {
  for (auto k : {PlannerKind::kLbkpiece, PlannerKind::kKpiece, PlannerKind::kRrtConnect}) {
    if (toString(k) == name) return k;
  }
  return std::nullopt;
}

Status MotionPlannerParams::validate() const {
  std::vector<Error> errors;
  for (const Rule& r : rules(*this)) {
    if (r.ok) continue;
    errors.emplace_back(ErrorCode::kInvalidArgument, r.message,
                        SourceLocation{"", 0, 0, r.section.empty() ? r.key : r.section + "." + r.key});
  }
  if (errors.empty()) return Status::Ok();
  return Error(ErrorCode::kInvalidArgument, "invalid motion planner parameters:\n" + joinErrors(errors));
}

Result<MotionPlannerParams> parseMotionPlannerParams(const std::string& yaml_text, const std::string& name,
                                                     const std::vector<std::string>& foreign_sections) {
  auto doc = config::parseYaml(yaml_text, name);
  if (!doc) return doc.error();
  MotionPlannerParams p;
  config::FieldReader r(*doc);
  if (doc->root.IsNull()) return p;  // an empty file: the defaults
  if (!r.isMap()) return Error(ErrorCode::kParseError, name + ": expected a mapping of parameters");
  for (const auto& key : foreign_sections) r.ignore(key);
  r.optional("seed", p.seed);
  std::map<std::string, config::FieldReader> sections;
  auto section = [&](const std::string& key) -> config::FieldReader& {
    auto it = sections.find(key);
    if (it == sections.end()) {
      it = sections.emplace(key, r.child(key, false)).first;
      const YAML::Node& n = it->second.node();
      if (n.IsDefined() && !n.IsNull() && !n.IsMap()) r.fail(key, "expected a mapping of parameters");
    }
    return it->second;
  };
  {
    auto& s = section("sampling");
    s.optional("validity_resolution", p.sampling.validity_resolution);
    s.optional("kpiece_cell_size", p.sampling.kpiece_cell_size);
    s.optional("arm_cell_size", p.sampling.arm_cell_size);
    s.optional("range", p.sampling.range);
    s.optional("goal_position_tolerance", p.sampling.goal_position_tolerance);
    s.optional("goal_orientation_tolerance", p.sampling.goal_orientation_tolerance);
    s.optional("workspace_margin", p.sampling.workspace_margin);
    readPlanner(s, "lazy_planner", p.sampling.lazy_planner);
    readPlanner(s, "full_planner", p.sampling.full_planner);
    readPlanner(s, "arm_planner", p.sampling.arm_planner);
  }
  {
    auto& s = section("lazy");
    s.optional("optimize", p.lazy.optimize);
    s.optional("roadmap_samples", p.lazy.roadmap_samples);
    s.optional("roadmap_neighbors", p.lazy.roadmap_neighbors);
    s.optional("roadmap_bridge_samples", p.lazy.roadmap_bridge_samples);
    s.optional("roadmap_bridge_distance", p.lazy.roadmap_bridge_distance);
    s.optional("path_node_spacing", p.lazy.path_node_spacing);
    s.optional("roadmap_max_evaluations", p.lazy.roadmap_max_evaluations);
    s.optional("roadmap_max_new_invalid", p.lazy.roadmap_max_new_invalid);
    s.optional("roadmap_growth_samples", p.lazy.roadmap_growth_samples);
    s.optional("roadmap_max_nodes", p.lazy.roadmap_max_nodes);
    s.optional("roadmap_max_request_nodes", p.lazy.roadmap_max_request_nodes);
    s.optional("object_ring_samples", p.lazy.object_ring_samples);
    s.optional("roadmap_cache_entries", p.lazy.roadmap_cache_entries);
    s.optional("roadmap_first", p.lazy.roadmap_first);
    s.optional("optimize_budget_s", p.lazy.optimize_budget_s);
    s.optional("shortcut_attempts", p.lazy.shortcut_attempts);
    s.optional("contact_resolution", p.lazy.contact_resolution);
    s.optional("swept_spacing", p.lazy.swept_spacing);
  }
  {
    auto& s = section("cost");
    s.optional("base_speed", p.cost.base_speed);
    s.optional("arm_speed", p.cost.arm_speed);
    s.optional("approach_distance", p.cost.approach_distance);
    s.optional("retreat_distance", p.cost.retreat_distance);
    s.optional("transfer_distance", p.cost.transfer_distance);
    s.optional("non_graspable_factor", p.cost.non_graspable_factor);
  }
  {
    auto& s = section("proof");
    s.optional("enabled", p.proof.enabled);
    s.optional("cell_size", p.proof.cell_size);
    s.optional("min_cell_size", p.proof.min_cell_size);
    s.optional("max_cells", p.proof.max_cells);
  }
  {
    auto& s = section("timing");
    s.optional("base_linear_speed", p.timing.base_linear_speed);
    s.optional("base_linear_accel", p.timing.base_linear_accel);
    s.optional("base_angular_speed", p.timing.base_angular_speed);
    s.optional("base_angular_accel", p.timing.base_angular_accel);
    s.optional("arm_accel", p.timing.arm_accel);
    s.optional("arm_speed_scale", p.timing.arm_speed_scale);
    s.optional("sample_period", p.timing.sample_period);
  }
  {
    auto& s = section("placement");
    s.optional("max_attempts", p.placement.max_attempts);
    s.optional("support_margin", p.placement.support_margin);
    s.optional("base_distance_min", p.placement.base_distance_min);
    s.optional("base_distance_max", p.placement.base_distance_max);
    s.optional("base_poses_per_placement", p.placement.base_poses_per_placement);
    s.optional("planar_reach", p.placement.planar_reach);
    s.optional("tool_clearance", p.placement.tool_clearance);
  }
  {
    auto& s = section("grasp");
    s.optional("approach_distance", p.grasp.approach_distance);
    s.optional("retreat_distance", p.grasp.retreat_distance);
    s.optional("finger_margin", p.grasp.finger_margin);
    s.optional("side_height_fraction", p.grasp.side_height_fraction);
    s.optional("cylinder_yaw_samples", p.grasp.cylinder_yaw_samples);
    s.optional("base_distance_min", p.grasp.base_distance_min);
    s.optional("base_distance_max", p.grasp.base_distance_max);
    s.optional("base_poses", p.grasp.base_poses);
  }
  for (const Rule& rule : rules(p)) {
    if (rule.ok) continue;
    if (rule.section.empty()) {
      r.fail(rule.key, rule.message);
    } else {
      section(rule.section).fail(rule.key, rule.message);
    }
  }
  for (auto& [key, s] : sections) {
    if (s.isMap()) s.refuseUnknownKeys();
  }
  r.refuseUnknownKeys();
  if (!r.ok()) return r.status().error();
  return p;
}

Result<MotionPlannerParams> loadMotionPlannerParams(const std::filesystem::path& file,
                                                    const std::vector<std::string>& foreign_sections) {
  auto text = readTextFile(file);
  if (!text) return text.error();
  return parseMotionPlannerParams(*text, file.string(), foreign_sections);
}

}  // namespace tamp::motion_planner
