#pragma once
/// @file
/// The mission journal (issue 13, part 3): what a restarted graph manager needs to resume the
/// mission it was running, kept on disk. One JSON file, replaced atomically at every step (written
/// to a temporary file, fsynced, renamed over the journal, the folder fsynced), so that a crash at
/// any instant leaves the previous record or the next, never a torn one.
///
/// What is journaled: the mission command (so the mission can be taken up again without its
/// sender), every command sent with its outcome, and the command in flight (sent, no outcome
/// recorded yet). What is not: the reachability graph. A restarted graph manager builds it again
/// from the live state (the world model and the robot's report), which a crash may have outdated
/// anyway: the robot went on executing the command in flight, perception went on watching. The
/// command in flight is awaited, never sent again, and the commands of a resumed run are numbered
/// apart (`r<resumption>-...`), so no action is executed twice.

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "tamp/core/error.h"
#include "tamp/graph_manager/graph_manager.h"

namespace tamp::graph_manager {

/// One mission as the journal knows it.
struct MissionRecord {
  // The command, as received.
  std::string mission_id;
  std::string scenario_path;
  std::string policy;               ///< "effort" | "infeasible"
  std::uint32_t seed{0};
  int max_replans{0};               ///< 0: the parameters' value
  std::vector<std::string> goal;    ///< the command's own goal atoms (empty: the scenario's)
  // Where it stands.
  bool finished{false};
  std::string outcome;              ///< when finished: succeeded, failed, ...
  std::string reason;               ///< when finished
  int resumptions{0};               ///< how many times a restarted graph manager took it up
  std::vector<ExecutedAction> actions;  ///< every command with an outcome, in order (no paths)
  /// Sent, no outcome recorded: the robot may be executing it. Its action and budget too.
  std::string in_flight;
  std::string in_flight_action;
  double in_flight_budget_s{0.0};
};

/// The journal file of one graph manager.
class MissionJournal {
 public:
  explicit MissionJournal(std::filesystem::path file) : file_(std::move(file)) {}
  const std::filesystem::path& file() const { return file_; }

  /// Replaces the journal with `record`, atomically and durably. kIo naming the file on failure.
  Status write(const MissionRecord& record) const;
  /// The journal's record; none when there is no journal file. kParseError naming the file and
  /// the field when it is not a journal (a torn record cannot happen: see write()).
  Result<std::optional<MissionRecord>> read() const;

 private:
  std::filesystem::path file_;
};

/// An Executor that journals every command before it goes out (in flight) and its outcome when
/// it comes back, around another executor. A journal that cannot be written stops the command
/// (outcome kUnavailable): an action the journal does not know could be executed twice.
class JournalingExecutor : public Executor {
 public:
  JournalingExecutor(Executor& inner, const MissionJournal& journal, MissionRecord& record)
      : inner_(inner), journal_(journal), record_(record) {}
  ExecutionReport execute(const EdgeCommand& command, double budget_s) override;
  ExecutionReport await(const std::string& command_id, double budget_s) override;

 private:
  ExecutionReport record(const std::string& command_id, const std::string& action, ExecutionReport rep);
  Executor& inner_;
  const MissionJournal& journal_;
  MissionRecord& record_;
};

}  // namespace tamp::graph_manager
