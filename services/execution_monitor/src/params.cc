#include "tamp/execution_monitor/params.h"

#include "tamp/config/schema.h"
#include "tamp/core/paths.h"

namespace tamp::execution_monitor {
namespace {

using config::Ends;
using config::inRange;
using config::nonNegative;
using config::positive;

const config::Schema<MonitorParams>& schema() {
  using P = MonitorParams;
  static const config::Schema<P> kSchema = [] {
    config::Schema<P> s;
    s.root()
        .field("robot_description", &P::robot_description)
        .field("world_id", &P::world_id,
               [](const std::string& v) -> std::optional<std::string> {
                 if (v.empty()) return "must not be empty";
                 return std::nullopt;
               })
        .field("object_tolerance_m", &P::object_tolerance_m, positive())
        .field("moved_tolerance_m", &P::moved_tolerance_m, positive())
        .field("input_wait_s", &P::input_wait_s, nonNegative("s"))
        .field("result_wait_s", &P::result_wait_s, positive())
        .field("state_wait_s", &P::state_wait_s, positive())
        .field("status_period_s", &P::status_period_s, positive())
        .field("forward_unmatched_records", &P::forward_unmatched_records);
    s.section("start_tolerance", &P::start_tolerance)
        .field("position_m", &StartTolerance::position_m, positive())
        .field("angle_rad", &StartTolerance::angle_rad, positive());
    s.section("path_check", &P::path_check)
        .field("step_m", &PathCheckParams::step_m, inRange(0, 1, Ends::kOpenClosed, "m"))
        .field("step_rad", &PathCheckParams::step_rad, inRange(0, 1, Ends::kOpenClosed, "rad"))
        .field("tolerance_m", &PathCheckParams::tolerance_m, inRange(0, 0.05, Ends::kClosed, "m"))
        .field("start_contact_m", &PathCheckParams::start_contact_m,
               inRange(0, 0.05, Ends::kClosed, "m"));
    s.section("timeout", &P::timeout)
        .field("stddevs", &TimeoutParams::stddevs, nonNegative())
        .field("margin_s", &TimeoutParams::margin_s, positive())
        .field("stall_s", &TimeoutParams::stall_s, positive())
        .field("max_factor", &TimeoutParams::max_factor, config::atLeast(1.0));
    return s;
  }();
  return kSchema;
}

}  // namespace

Status MonitorParams::validate() const {
  const std::vector<Error> errors = schema().errors(*this);
  if (errors.empty()) return Status::Ok();
  return Error(ErrorCode::kInvalidArgument,
               "invalid execution monitor parameters:\n" + joinErrors(errors),
               errors.front().where);
}

Result<MonitorParams> parseMonitorParams(const std::string& yaml_text, const std::string& name) {
  auto doc = config::parseYaml(yaml_text, name);
  if (!doc) return doc.error();
  MonitorParams p;
  if (doc->root.IsNull()) return p;  // an empty file: every default
  config::FieldReader r(*doc);
  if (!r.isMap()) {
    return Error(ErrorCode::kParseError, "expected a mapping of execution monitor parameters",
                 SourceLocation{name});
  }
  schema().read(r, p);
  r.refuseUnknownKeys();
  if (!r.ok()) return r.status().error();
  return p;
}

Result<MonitorParams> loadMonitorParams(const std::filesystem::path& file) {
  auto text = readTextFile(file);
  if (!text) return text.error();
  auto p = parseMonitorParams(*text, file.string());
  if (p && !p->robot_description.empty()) {
    p->robot_description = resolveRelativeTo(file, p->robot_description).string();
  }
  return p;
}

}  // namespace tamp::execution_monitor
