// Crash recovery over real processes (issue 13, part 3): the graph manager is killed (SIGKILL)
// while the robot executes one of its commands. `tamp run`'s supervisor restarts it; it takes the
// mission up from its journal, awaits the command that was in flight instead of sending it again,
// plans from the live state and finishes the mission. Judged by the simulator's final world and
// action log (what physically happened), the report and the journal.
#include <signal.h>

#include <atomic>
#include <fstream>
#include <chrono>
#include <map>
#include <mutex>
#include <set>
#include <thread>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "mission_util.h"
#include "tamp/core/termination.h"
#include "tamp/dds/heartbeat.h"
#include "tamp/dds/participant.h"
#include "tamp/dds/topics.h"
#include "tamp/dds/endpoint.h"
#include "tamp/process/supervisor.h"

namespace tamp::integration {
namespace {

/// Polls `pred` (and the supervisor) until it holds or `seconds` pass.
bool waitUntil(const std::function<bool()>& pred, double seconds, process::Supervisor& sup) {
  const Deadline d = Deadline::in(seconds);
  while (!d.expired()) {
    sup.poll();
    if (pred()) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  return pred();
}

/// `tamp run` of namo_corridor (effort), every service a process, on `domain` with `deployment`,
/// its output in OUT/tamp-run.out; not restarted when it ends.
process::ProcessSpec corridorRun(const fs::path& out, int domain, const fs::path& deployment, const std::string& run_id) {
  process::ProcessSpec run;
  run.name = "tamp-run";
  run.executable = binDir() / "tamp-run";
  run.args = {(configDir() / "scenarios" / "namo_corridor.yaml").string(), "--out", out.string(), "--domain",
              std::to_string(domain), "--deployment", deployment.string(), "--run-id", run_id, "--policy", "effort"};
  run.log_file = out / "tamp-run.out";
  run.restart = false;
  return run;
}

/// The pid of the live `service` its heartbeats name (0: none heard).
pid_t livePid(dds::HeartbeatMonitor& beats, const std::string& service) {
  pid_t pid = 0;
  for (const auto& s : beats.services())
    if (s.name == service && s.alive) pid = static_cast<pid_t>(s.pid);
  return pid;
}

/// Polls the supervisor until the process `name` is no longer running (600 s at most).
bool waitForEnd(process::Supervisor& sup, const std::string& name) {
  return waitUntil(
      [&] {
        auto st = sup.status(name);
        return st && st->phase != process::ProcessPhase::kRunning;
      },
      600.0, sup);
}

TEST(RecoveryTest, AGraphManagerKilledMidActionTakesTheMissionUpWithoutRepeatingIt) {
  const fs::path out = tempFile("tamp_recovery");
  fs::remove_all(out);
  fs::create_directories(out / "deploy" / "store");
  const fs::path deployment = fastDeployment(out / "deploy", 2.0);
  const int domain = isolatedDomain();
  const std::string run_id = "recovery-" + std::to_string(::getpid());

  // The test listens to the run as any client would: the monitor's statuses, the heartbeats.
  auto participant = dds::Participant::create({domain, dds::kProfileDefault, "recovery-test", {}}, run_id);
  ASSERT_TRUE(participant.ok()) << participant.error().toString();
  std::mutex m;
  std::vector<std::string> running;  // command ids the monitor reported running, in order
  dds::Reader<msg::ExecuteStatus> statuses(*participant, dds::topics::kExecuteStatus,
                                           [&](const msg::ExecuteStatus& s, const dds::SampleMeta&) {
                                             if (s.state() != msg::ExecState::EXEC_RUNNING) return;
                                             std::lock_guard g(m);
                                             if (std::find(running.begin(), running.end(), s.command_id()) == running.end())
                                               running.push_back(s.command_id());
                                           });
  dds::HeartbeatMonitor beats(*participant);

  process::Supervisor sup;
  const process::ProcessSpec run = corridorRun(out, domain, deployment, run_id);
  sup.add(run);
  ASSERT_TRUE(sup.startAll().ok());

  // The second command the robot runs: kill -9 the graph manager while it executes.
  std::string victim;
  ASSERT_TRUE(waitUntil(
      [&] {
        std::lock_guard g(m);
        if (running.size() < 2) return false;
        victim = running[1];
        return true;
      },
      300.0, sup))
      << readFile(run.log_file);
  const pid_t gm = livePid(beats, "graph_manager");
  ASSERT_GT(gm, 0) << "no live graph manager heard";
  ASSERT_EQ(::kill(gm, SIGKILL), 0);

  ASSERT_TRUE(waitForEnd(sup, "tamp-run")) << readFile(run.log_file);
  const auto st = sup.status("tamp-run");
  const fs::path run_dir = out / run_id;
  const std::string output = readFile(run.log_file);
  ASSERT_EQ(st->last_exit_code, 0) << output << readFile(run_dir / "graph_manager.log");

  // The supervisor restarted the graph manager it lost.
  const std::string events = readFile(run_dir / "events.jsonl");
  EXPECT_NE(events.find("\"restarted\""), std::string::npos) << events;

  // The mission ended where the user wanted it, in the simulator's world.
  const auto truth = nlohmann::json::parse(readFile(run_dir / "sim_final_world.json"), nullptr, false);
  ASSERT_TRUE(truth.is_object()) << output;
  EXPECT_LT(distance(truth["robot"], 8.5, 1.2), 0.10) << truth.dump();
  // Nothing physically done twice: every command id once in the action log, the victim included.
  std::map<std::string, int> executions;
  for (const auto& a : truth["action_log"])
    ++executions[a.is_object() ? a["command_id"].get<std::string>() : a.get<std::string>()];
  for (const auto& [id, n] : executions) EXPECT_EQ(n, 1) << id << " executed " << n << " times";
  EXPECT_EQ(executions[victim], 1) << truth["action_log"].dump(1);

  // The report: one resumption; the command in flight appears once, with the robot's outcome.
  const auto report = nlohmann::json::parse(readFile(run_dir / "report.json"), nullptr, false);
  ASSERT_TRUE(report.is_object()) << output;
  EXPECT_EQ(report["status"], "succeeded") << report.dump(1);
  EXPECT_EQ(report["resumptions"], 1) << report.dump(1);
  const std::string local_id = victim.substr(victim.find('/') + 1);
  int listed = 0;
  std::set<std::string> ids;
  for (const auto& a : report["actions"]) {
    const std::string id = a["command_id"].get<std::string>();
    if (id.empty()) continue;  // not prepared: never sent
    EXPECT_TRUE(ids.insert(id).second) << "command " << id << " listed twice: " << report["actions"].dump(1);
    if (id == local_id) {
      ++listed;
      EXPECT_NE(a["outcome"], "timeout") << "the monitor's outcome was awaited: " << a.dump();
    }
  }
  EXPECT_EQ(listed, 1) << local_id << " in " << report["actions"].dump(1);

  // The journal: the mission finished, every command with its outcome, none in flight.
  const auto journal = nlohmann::json::parse(readFile(run_dir / "graph_manager.journal.json"), nullptr, false);
  ASSERT_TRUE(journal.is_object());
  EXPECT_TRUE(journal["finished"].get<bool>());
  EXPECT_EQ(journal["outcome"], "succeeded");
  EXPECT_EQ(journal["resumptions"], 1);
  EXPECT_EQ(journal["in_flight"], "");
  sup.stopAll(5.0);
  if (!HasFailure()) fs::remove_all(out);
}

// The robot driver (the simulator) killed (SIGKILL) while the robot moves during the second command
// of namo_corridor. The physical world does not restart with the driver: the restarted simulator
// resumes from its checkpoint in the run folder (the robot, the box, the action log), ends the
// command it was running as failed ("robot driver restarted mid-action") instead of executing it
// again, and the graph manager replans from where the robot stands. Judged by the simulator's final
// world (the robot at the goal) and its action log (every command id at most once, the killed
// command once, failed), and the restart in events.jsonl.
TEST(RecoveryTest, ASimulatorKilledMidActionResumesTheWorldAndTheMissionReachesTheGoal) {
  const fs::path out = tempFile("tamp_sim_recovery");
  fs::remove_all(out);
  fs::create_directories(out / "deploy" / "store");
  const fs::path deployment = fastDeployment(out / "deploy", 2.0);
  const int domain = isolatedDomain();
  const std::string run_id = "simrecovery-" + std::to_string(::getpid());

  auto participant = dds::Participant::create({domain, dds::kProfileDefault, "sim-recovery-test", {}}, run_id);
  ASSERT_TRUE(participant.ok()) << participant.error().toString();
  std::mutex m;
  std::vector<std::string> running;  // command ids the monitor reported running, in order
  bool moving_in_second = false;     // a robot state with the robot moving, after the second began
  dds::Reader<msg::ExecuteStatus> statuses(*participant, dds::topics::kExecuteStatus,
                                           [&](const msg::ExecuteStatus& s, const dds::SampleMeta&) {
                                             if (s.state() != msg::ExecState::EXEC_RUNNING) return;
                                             std::lock_guard g(m);
                                             if (std::find(running.begin(), running.end(), s.command_id()) == running.end())
                                               running.push_back(s.command_id());
                                           });
  dds::Reader<msg::RobotState> states(*participant, dds::topics::kRobotState,
                                      [&](const msg::RobotState& s, const dds::SampleMeta&) {
                                        std::lock_guard g(m);
                                        if (running.size() >= 2 && s.moving()) moving_in_second = true;
                                      });
  dds::HeartbeatMonitor beats(*participant);

  process::Supervisor sup;
  const process::ProcessSpec run = corridorRun(out, domain, deployment, run_id);
  sup.add(run);
  ASSERT_TRUE(sup.startAll().ok());

  std::string victim;
  ASSERT_TRUE(waitUntil(
      [&] {
        std::lock_guard g(m);
        if (!moving_in_second) return false;
        victim = running[1];
        return true;
      },
      300.0, sup))
      << readFile(run.log_file);
  const pid_t sim = livePid(beats, "sim");
  ASSERT_GT(sim, 0) << "no live simulator heard";
  ASSERT_EQ(::kill(sim, SIGKILL), 0);

  ASSERT_TRUE(waitForEnd(sup, "tamp-run")) << readFile(run.log_file);
  const auto st = sup.status("tamp-run");
  const fs::path run_dir = out / run_id;
  const std::string output = readFile(run.log_file);
  const std::string sim_log = readFile(run_dir / "sim.log");
  EXPECT_EQ(st->last_exit_code, 0) << output << readFile(run_dir / "graph_manager.log");

  const std::string events = readFile(run_dir / "events.jsonl");
  EXPECT_NE(events.find("\"restarted\""), std::string::npos) << events;
  EXPECT_NE(sim_log.find("resumed from checkpoint"), std::string::npos) << sim_log;

  // The mission ended at the goal of the world the robot really is in.
  const auto truth = nlohmann::json::parse(readFile(run_dir / "sim_final_world.json"), nullptr, false);
  ASSERT_TRUE(truth.is_object()) << output;
  EXPECT_LT(distance(truth["robot"], 8.5, 1.2), 0.10) << truth.dump();
  // Nothing physically done twice; the command the driver died in is there once, failed.
  std::map<std::string, int> executions;
  std::map<std::string, std::string> outcomes;
  for (const auto& a : truth["action_log"]) {
    ++executions[a["command_id"].get<std::string>()];
    outcomes[a["command_id"].get<std::string>()] = a["outcome"].get<std::string>();
  }
  for (const auto& [id, n] : executions) EXPECT_EQ(n, 1) << id << " executed " << n << " times";
  const std::string local_id = victim.substr(victim.find('/') + 1);
  std::string logged_victim;
  for (const auto& [id, n] : executions)
    if (id == victim || id == local_id || id.ends_with("/" + local_id)) logged_victim = id;
  ASSERT_FALSE(logged_victim.empty()) << victim << " not in " << truth["action_log"].dump(1);
  EXPECT_EQ(outcomes[logged_victim], "failed") << truth["action_log"].dump(1);

  const auto report = nlohmann::json::parse(readFile(run_dir / "report.json"), nullptr, false);
  ASSERT_TRUE(report.is_object()) << output;
  EXPECT_EQ(report["status"], "succeeded") << report.dump(1);
  sup.stopAll(5.0);
  if (!HasFailure()) fs::remove_all(out);
}

// A deployment started again long after its graph manager stopped must not set the robot moving
// on the old mission: a journal older than resume_max_age_s is closed as aborted, not resumed.
TEST(RecoveryTest, AnOldUnfinishedMissionIsClosedNotResumed) {
  const fs::path dir = tempFile("tamp_recovery_old");
  fs::remove_all(dir);
  fs::create_directories(dir);
  const fs::path journal = dir / "graph_manager.journal.json";
  nlohmann::json j{{"format", "tamp-mission-journal-1"}, {"mission_id", "mission-old"},
                   {"scenario_path", (configDir() / "scenarios" / "namo_corridor.yaml").string()},
                   {"policy", "effort"}, {"seed", 0}, {"max_replans", 0}, {"goal", nlohmann::json::array()},
                   {"finished", false}, {"outcome", ""}, {"reason", ""}, {"resumptions", 0},
                   {"actions", nlohmann::json::array()}, {"in_flight", "m0-e1"}, {"in_flight_action", "(move_base a b)"},
                   {"in_flight_budget_s", 30.0}};
  std::ofstream(journal) << j.dump(1);
  fs::last_write_time(journal, fs::file_time_type::clock::now() - std::chrono::hours(1));

  process::Supervisor sup;
  process::ProcessSpec gm = serviceSpec("tamp_graph_manager_service", "graph_manager", isolatedDomain());
  gm.env["TAMP_RUN_DIR"] = dir.string();
  sup.add(gm);
  ASSERT_TRUE(sup.startAll().ok());
  nlohmann::json back;
  ASSERT_TRUE(waitUntil(
      [&] {
        back = nlohmann::json::parse(readFile(journal), nullptr, false);
        return back.is_object() && back.value("finished", false);
      },
      30.0, sup))
      << readFile(gm.log_file);
  EXPECT_EQ(back["outcome"], "aborted");
  EXPECT_NE(back["reason"].get<std::string>().find("not resumed"), std::string::npos) << back.dump(1);
  EXPECT_EQ(readFile(gm.log_file).find("resuming it"), std::string::npos) << readFile(gm.log_file);
  sup.stopAll(5.0);
  fs::remove_all(dir);
}

}  // namespace
}  // namespace tamp::integration
