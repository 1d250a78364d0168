#include "tamp/graph_manager/journal.h"

#include <nlohmann/json.hpp>

#include "tamp/core/paths.h"

namespace tamp::graph_manager {
namespace {

using nlohmann::json;

json toJson(const ExecutedAction& a) {
  return json{{"command_id", a.command_id}, {"action", a.action},       {"variant", a.variant},
              {"predicted_s", a.predicted_s}, {"predicted_stddev_s", a.predicted_stddev_s},
              {"measured_s", a.measured_s}, {"outcome", a.outcome},     {"reason", a.reason}};
}

json toJson(const MissionRecord& r) {
  json actions = json::array();
  for (const auto& a : r.actions) actions.push_back(toJson(a));
  return json{{"format", "tamp-mission-journal-1"},
              {"mission_id", r.mission_id},
              {"scenario_path", r.scenario_path},
              {"policy", r.policy},
              {"seed", r.seed},
              {"max_replans", r.max_replans},
              {"goal", r.goal},
              {"finished", r.finished},
              {"outcome", r.outcome},
              {"reason", r.reason},
              {"resumptions", r.resumptions},
              {"actions", actions},
              {"in_flight", r.in_flight},
              {"in_flight_action", r.in_flight_action},
              {"in_flight_budget_s", r.in_flight_budget_s}};
}

/// Reads fields of one JSON object in turn; the first error (naming the file and the field) is
/// kept and the later reads are skipped.
class FieldReader {
 public:
  FieldReader(const json& j, const std::filesystem::path& file, std::string where)
      : j_(j), file_(file), where_(std::move(where)) {}
  template <typename T>
  FieldReader& get(const std::string& key, T& out) {
    if (!status_) return *this;
    const std::string name = where_.empty() ? key : where_ + "." + key;
    if (!j_.contains(key)) {
      status_ = Error(ErrorCode::kParseError, "missing field", SourceLocation{file_.string(), 0, 0, name});
      return *this;
    }
    try {
      out = j_.at(key).get<T>();
    } catch (const json::exception& e) {
      status_ = Error(ErrorCode::kParseError, std::string("wrong type: ") + e.what(),
                      SourceLocation{file_.string(), 0, 0, name});
    }
    return *this;
  }
  const Status& status() const { return status_; }

 private:
  const json& j_;
  const std::filesystem::path& file_;
  std::string where_;
  Status status_ = Status::Ok();
};

Result<MissionRecord> fromJson(const json& j, const std::filesystem::path& file) {
  MissionRecord r;
  std::string format;
  if (Status s = FieldReader(j, file, "").get("format", format).status(); !s) return s.error();
  if (format != "tamp-mission-journal-1")
    return Error(ErrorCode::kParseError, "unknown journal format '" + format + "'", SourceLocation{file.string(), 0, 0, "format"});
  FieldReader f(j, file, "");
  f.get("mission_id", r.mission_id).get("scenario_path", r.scenario_path).get("policy", r.policy).get("seed", r.seed);
  f.get("max_replans", r.max_replans).get("goal", r.goal).get("finished", r.finished).get("outcome", r.outcome);
  f.get("reason", r.reason).get("resumptions", r.resumptions).get("in_flight", r.in_flight);
  f.get("in_flight_action", r.in_flight_action).get("in_flight_budget_s", r.in_flight_budget_s);
  if (!f.status()) return f.status().error();
  if (r.mission_id.empty())
    return Error(ErrorCode::kParseError, "empty mission id", SourceLocation{file.string(), 0, 0, "mission_id"});
  if (!j.contains("actions") || !j["actions"].is_array())
    return Error(ErrorCode::kParseError, "missing or not a list", SourceLocation{file.string(), 0, 0, "actions"});
  for (std::size_t i = 0; i < j["actions"].size(); ++i) {
    ExecutedAction x;
    FieldReader a(j["actions"][i], file, "actions[" + std::to_string(i) + "]");
    a.get("command_id", x.command_id).get("action", x.action).get("variant", x.variant).get("predicted_s", x.predicted_s);
    a.get("predicted_stddev_s", x.predicted_stddev_s).get("measured_s", x.measured_s).get("outcome", x.outcome);
    a.get("reason", x.reason);
    if (!a.status()) return a.status().error();
    r.actions.push_back(std::move(x));
  }
  return r;
}

}  // namespace

Status MissionJournal::write(const MissionRecord& record) const {
  return writeFileAtomically(file_, toJson(record).dump(1) + "\n", "the mission journal");
}

Result<std::optional<MissionRecord>> MissionJournal::read() const {
  std::error_code ec;
  if (!std::filesystem::exists(file_, ec)) return std::optional<MissionRecord>{};
  auto text = readTextFile(file_);
  if (!text) return text.error();
  const json j = json::parse(*text, nullptr, false);
  if (j.is_discarded() || !j.is_object())
    return Error(ErrorCode::kParseError, "not a JSON object", SourceLocation{file_.string()});
  auto r = fromJson(j, file_);
  if (!r) return r.error();
  return std::optional<MissionRecord>(std::move(*r));
}

ExecutionReport JournalingExecutor::record(const std::string& command_id, const std::string& action,
                                           ExecutionReport rep) {
  ExecutedAction a;
  a.command_id = command_id;
  a.action = action;
  a.measured_s = rep.measured_s;
  a.outcome = std::string(toString(rep.outcome));
  a.reason = rep.reason;
  record_.actions.push_back(std::move(a));
  record_.in_flight.clear();
  record_.in_flight_action.clear();
  record_.in_flight_budget_s = 0.0;
  if (Status s = journal_.write(record_); !s) {
    // The outcome stands (the robot did it); the next command will not go out unjournaled.
    rep.reason += rep.reason.empty() ? "" : "; ";
    rep.reason += "journal: " + s.error().message;
  }
  return rep;
}

ExecutionReport JournalingExecutor::execute(const EdgeCommand& command, double budget_s) {
  record_.in_flight = command.command_id;
  record_.in_flight_action = command.action;
  record_.in_flight_budget_s = budget_s;
  if (Status s = journal_.write(record_); !s) {
    ExecutionReport r;
    r.outcome = ExecOutcome::kUnavailable;
    r.reason = "not sent: the mission journal cannot be written: " + s.error().message;
    record_.in_flight.clear();
    return r;
  }
  ExecutionReport rep = inner_.execute(command, budget_s);
  // predicted_s is the Run's to record in its report; the journal keeps what happened.
  return record(command.command_id, command.action, std::move(rep));
}

ExecutionReport JournalingExecutor::await(const std::string& command_id, double budget_s) {
  const std::string action = record_.in_flight == command_id ? record_.in_flight_action : std::string();
  return record(command_id, action, inner_.await(command_id, budget_s));
}

}  // namespace tamp::graph_manager
