#include "tamp/graph_manager/params.h"

#include <vector>

#include "tamp/config/schema.h"
#include "tamp/core/paths.h"

namespace tamp::graph_manager {

std::string_view toString(Policy p) {
  switch (p) {
    case Policy::kEffort: return "effort";
    case Policy::kInfeasible: return "infeasible";
    case Policy::kOracle: return "oracle";
  }
  return "?";
}

std::optional<Policy> policyFromString(std::string_view s) {
  if (s == "effort") return Policy::kEffort;
  if (s == "infeasible") return Policy::kInfeasible;
  if (s == "oracle") return Policy::kOracle;
  return std::nullopt;
}

namespace {
using config::atLeast;
using config::positive;

const config::Schema<GraphManagerParams>& schema() {
  using P = GraphManagerParams;
  static const config::Schema<P> kSchema = [] {
    config::Schema<P> s;
    s.root()
        .convert<std::string>("policy", &P::policy,
                              config::byName<Policy>(policyFromString, "policy", "effort, infeasible, oracle"))
        .field("seed", &P::seed)
        .field("max_evaluations", &P::max_evaluations, atLeast(1))
        .field("traverse_budget_s", &P::traverse_budget_s, positive())
        .field("max_replans", &P::max_replans, atLeast(0))
        .field("max_subtask_depth", &P::max_subtask_depth, atLeast(0))
        .field("max_blocking_objects", &P::max_blocking_objects, atLeast(1))
        .field("oracle_max_objects", &P::oracle_max_objects, config::that<int>([](const int& v) { return v >= 1 && v <= 4; }, "must be in [1, 4]"))
        .field("placements_per_object", &P::placements_per_object, atLeast(1))
        .field("push_step_m", &P::push_step_m, positive())
        .field("push_max_m", &P::push_max_m, positive())
        .field("push_gap_m", &P::push_gap_m, config::nonNegative("m"))
        .field("push_backoff_m", &P::push_backoff_m, config::nonNegative("m"))
        .field("pushes_per_object", &P::pushes_per_object, atLeast(0))
        .field("push_budget_s", &P::push_budget_s, positive())
        .field("keep_clear_margin_m", &P::keep_clear_margin_m, config::nonNegative("m"))
        .field("held_padding_step_m", &P::held_padding_step_m, config::nonNegative("m"))
        .field("held_padding_max_m", &P::held_padding_max_m,
               config::inRange(0.0, 0.25, config::Ends::kClosed, "m"))
        .field("contact_correction_max_m", &P::contact_correction_max_m,
               config::inRange(0.0, 0.5, config::Ends::kClosed, "m"))
        .field("rest_wait_s", &P::rest_wait_s, config::nonNegative("s"))
        .field("lower_bound_base_speed", &P::lower_bound_base_speed, positive())
        .field("model_bounds", &P::model_bounds)
        .field("goal_bound", &P::goal_bound)
        .field("approach_m", &P::approach_m, positive())
        .field("plan_budget_s", &P::plan_budget_s, positive())
        .field("motion_budget_s", &P::motion_budget_s, positive())
        .field("execution_margin_s", &P::execution_margin_s, positive())
        .field("start_tolerance", &P::start_tolerance, positive())
        .field("stowed_tolerance_rad", &P::stowed_tolerance_rad, positive())
        .field("resume_max_age_s", &P::resume_max_age_s, positive())
        .field("clear_path_stretch", &P::clear_path_stretch, config::atLeast(1.0))
        .field("turn_first_ratio", &P::turn_first_ratio, config::atLeast(1.0))
        .field("overrun_sigma", &P::overrun_sigma, positive())
        .field("refit_wait_s", &P::refit_wait_s, config::nonNegative("s"))
        .field("max_rejoin_targets", &P::max_rejoin_targets, atLeast(1))
        .field("replan_first_edge", &P::replan_first_edge)
        .field("first_edge_at_start", &P::first_edge_at_start)
        .field("concurrent_motions", &P::concurrent_motions)
        .field("memoise_answers", &P::memoise_answers)
        .field("max_contingencies", &P::max_contingencies, atLeast(0))
        .field("held_object_wait_s", &P::held_object_wait_s, positive())
        .field("max_action_failures", &P::max_action_failures, atLeast(1))
        .field("moved_object_tolerance_m", &P::moved_object_tolerance_m, positive())
        .field("drop_settle_timeout_s", &P::drop_settle_timeout_s, atLeast(0.0))
        .field("drop_confirm_s", &P::drop_confirm_s, atLeast(0.0));
    return s;
  }();
  return kSchema;
}
}  // namespace

std::optional<std::string> GraphManagerParams::invalidReason() const {
  const std::vector<Error> errors = schema().errors(*this);
  if (errors.empty() && push_backoff_m >= push_step_m + push_gap_m)
    return "push_backoff_m must be below push_step_m + push_gap_m (" + std::to_string(push_step_m + push_gap_m) + "), got " +
           std::to_string(push_backoff_m);
  if (errors.empty() && push_max_m < push_step_m)
    return "push_max_m must be at least push_step_m (" + std::to_string(push_step_m) + "), got " + std::to_string(push_max_m);
  if (errors.empty()) return std::nullopt;
  return joinErrors(errors);
}

Result<GraphManagerParams> parseParams(const std::string& yaml_text, const std::string& name) {
  auto doc = config::parseYaml(yaml_text, name);
  if (!doc) return doc.error();
  GraphManagerParams p;
  config::FieldReader r(*doc);
  schema().read(r, p);
  r.refuseUnknownKeys();
  if (!r.ok()) return r.status().error();
  if (auto why = p.invalidReason()) return Error(ErrorCode::kInvalidArgument, name + ": " + *why);
  return p;
}

Result<GraphManagerParams> loadParams(const std::filesystem::path& file) {
  auto text = readTextFile(file);
  if (!text) return text.error();
  return parseParams(*text, file.string());
}

}  // namespace tamp::graph_manager
