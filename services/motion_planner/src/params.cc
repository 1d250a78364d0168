#include "tamp/motion_planner/params.h"

#include <cmath>

#include "tamp/config/schema.h"
#include "tamp/core/format.h"
#include "tamp/core/paths.h"

namespace tamp::motion_planner {
namespace {

using config::atLeast;
using config::Ends;
using config::inRange;
using config::nonNegative;
using config::positive;

/// base_distance_max of a placement or grasp section: positive and >= base_distance_min.
template <typename S>
std::optional<std::string> baseDistanceRange(const S& s) {
  const double max = s.base_distance_max;
  if (std::isfinite(max) && max > 0 && max >= s.base_distance_min) return std::nullopt;
  return "must be >= base_distance_min, got " + formatNumber(s.base_distance_max);
}

const config::Schema<MotionPlannerParams>& schema() {
  using P = MotionPlannerParams;
  static const config::Schema<P> kSchema = [] {
    config::Schema<P> s;
    const auto planner = config::byName<PlannerKind>(plannerKindFromString, "planner",
                                                     "lbkpiece, kpiece, rrtconnect");
    s.root().field("seed", &P::seed);
    using S = SamplingParams;
    s.section("sampling", &P::sampling)
        .field("validity_resolution", &S::validity_resolution, positive())
        .field("base_turn_in_place", &S::base_turn_in_place)
        .field("kpiece_cell_size", &S::kpiece_cell_size, positive())
        .field("arm_cell_size", &S::arm_cell_size, positive())
        .field("range", &S::range, nonNegative())
        .field("goal_position_tolerance", &S::goal_position_tolerance, positive())
        .field("goal_orientation_tolerance", &S::goal_orientation_tolerance, positive())
        .field("workspace_margin", &S::workspace_margin, nonNegative())
        .field("start_escape_distance", &S::start_escape_distance, nonNegative())
        .field("start_escape_attempts", &S::start_escape_attempts, atLeast(1))
        .field("start_escape_depth", &S::start_escape_depth, nonNegative())
        .field("direct_first", &S::direct_first)
        .field("direct_clearance", &S::direct_clearance, nonNegative())
        .field("arm_swept_step", &S::arm_swept_step, nonNegative())
        .field("base_clearance", &S::base_clearance, nonNegative())
        .field("base_clearance_near_ends", &S::base_clearance_near_ends, nonNegative())
        .field("base_clearance_time_s", &S::base_clearance_time_s, positive())
        .field("base_start_margin", &S::base_start_margin, nonNegative())
        .field("clearance_grid_resolution", &S::clearance_grid_resolution, nonNegative())
        .convert<std::string>("lazy_planner", &S::lazy_planner, planner)
        .convert<std::string>("full_planner", &S::full_planner, planner)
        .convert<std::string>("arm_planner", &S::arm_planner, planner)
        .convert<std::string>("arm_full_planner", &S::arm_full_planner, planner);
    using L = LazyParams;
    s.section("lazy", &P::lazy)
        .field("optimize", &L::optimize)
        .field("roadmap_samples", &L::roadmap_samples, atLeast(0))
        .field("roadmap_neighbors", &L::roadmap_neighbors, atLeast(2))
        .field("roadmap_bridge_samples", &L::roadmap_bridge_samples, atLeast(0))
        .field("roadmap_bridge_distance", &L::roadmap_bridge_distance, positive())
        .field("path_node_spacing", &L::path_node_spacing, positive())
        .field("roadmap_max_evaluations", &L::roadmap_max_evaluations, atLeast(1))
        .field("roadmap_max_new_invalid", &L::roadmap_max_new_invalid, atLeast(1))
        .field("roadmap_growth_samples", &L::roadmap_growth_samples, atLeast(0))
        .field("roadmap_max_nodes", &L::roadmap_max_nodes, atLeast(1))
        .field("roadmap_max_request_nodes", &L::roadmap_max_request_nodes, atLeast(2))
        .field("object_ring_samples", &L::object_ring_samples, atLeast(0))
        .field("roadmap_cache_entries", &L::roadmap_cache_entries, atLeast(0))
        .field("roadmap_first", &L::roadmap_first)
        .field("optimize_budget_s", &L::optimize_budget_s, positive())
        .field("shortcut_attempts", &L::shortcut_attempts, atLeast(0))
        .field("contact_resolution", &L::contact_resolution, positive())
        .field("swept_spacing", &L::swept_spacing, positive());
    using C = CostParams;
    s.section("cost", &P::cost)
        .field("base_speed", &C::base_speed, positive())
        .field("arm_speed", &C::arm_speed, positive())
        .field("approach_distance", &C::approach_distance, nonNegative())
        .field("retreat_distance", &C::retreat_distance, nonNegative())
        .field("transfer_distance", &C::transfer_distance, nonNegative())
        .field("non_graspable_factor", &C::non_graspable_factor, atLeast(1.0));
    using R = ProofParams;
    s.section("proof", &P::proof)
        .field("enabled", &R::enabled)
        .field("cell_size", &R::cell_size, positive())
        .field("min_cell_size", &R::min_cell_size)
        .field("max_cells", &R::max_cells, atLeast(1))
        .field("yaw_cells", &R::yaw_cells, nonNegative())
        .field("oriented_cell_size", &R::oriented_cell_size, positive())
        .field("oriented_max_cells", &R::oriented_max_cells, atLeast(1))
        .field("oriented_refinements", &R::oriented_refinements, nonNegative())
        .field("first_turn_s", &R::first_turn_s, nonNegative())
        .field("time_share", &R::time_share, nonNegative())
        .field("lazy_time_share", &R::lazy_time_share, nonNegative())
        .rule("min_cell_size", [](const R& r) -> std::optional<std::string> {
          if (std::isfinite(r.min_cell_size) && r.min_cell_size > 0 &&
              r.min_cell_size <= r.cell_size) {
            return std::nullopt;
          }
          return "must be in (0, cell_size], got " + formatNumber(r.min_cell_size);
        })
        .rule("lazy_time_share", [](const R& r) -> std::optional<std::string> {
          if (!(r.lazy_time_share <= r.time_share))
            return "must be at most time_share (" + formatNumber(r.time_share) + "), got " + formatNumber(r.lazy_time_share);
          return std::nullopt;
        });
    using T = TimingParams;
    s.section("timing", &P::timing)
        .field("base_linear_speed", &T::base_linear_speed, positive())
        .field("base_linear_accel", &T::base_linear_accel, positive())
        .field("base_angular_speed", &T::base_angular_speed, positive())
        .field("base_angular_accel", &T::base_angular_accel, positive())
        .field("arm_accel", &T::arm_accel, positive())
        .field("arm_speed_scale", &T::arm_speed_scale, inRange(0, 1, Ends::kOpenClosed))
        .field("sample_period", &T::sample_period, positive());
    using PL = PlacementParams;
    s.section("placement", &P::placement)
        .field("max_attempts", &PL::max_attempts, atLeast(1))
        .field("support_margin", &PL::support_margin, nonNegative())
        .field("base_distance_min", &PL::base_distance_min, positive())
        .field("base_distance_max", &PL::base_distance_max)
        .rule("base_distance_max", baseDistanceRange<PL>)
        .field("base_poses_per_placement", &PL::base_poses_per_placement, atLeast(1))
        .field("planar_reach", &PL::planar_reach, positive())
        .field("tool_clearance", &PL::tool_clearance, nonNegative());
    using G = GraspParams;
    s.section("grasp", &P::grasp)
        .field("approach_distance", &G::approach_distance, positive())
        .field("retreat_distance", &G::retreat_distance, nonNegative())
        .field("finger_margin", &G::finger_margin, nonNegative())
        .field("side_height_fraction", &G::side_height_fraction, inRange(0, 1, Ends::kClosed))
        .field("cylinder_yaw_samples", &G::cylinder_yaw_samples, atLeast(1))
        .field("base_distance_min", &G::base_distance_min, positive())
        .field("base_distance_max", &G::base_distance_max)
        .rule("base_distance_max", baseDistanceRange<G>)
        .field("base_poses", &G::base_poses, atLeast(1));
    return s;
  }();
  return kSchema;
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
  const std::vector<Error> errors = schema().errors(*this);
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
  schema().read(r, p);
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
