// The mission journal: atomic records read back whole, clear errors on a file that is not one,
// and the journaling executor's order (in flight on disk before the command goes out).
#include "tamp/graph_manager/journal.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <fstream>

namespace tamp::graph_manager {
namespace {

namespace fs = std::filesystem;

class JournalTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("tamp_journal_test_" + std::to_string(::getpid()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  static MissionRecord sample() {
    MissionRecord r;
    r.mission_id = "mission-7";
    r.scenario_path = "/x/namo_corridor.yaml";
    r.policy = "infeasible";
    r.seed = 9;
    r.max_replans = 3;
    r.goal = {"(robot-at goal)"};
    r.resumptions = 1;
    ExecutedAction a;
    a.command_id = "m0-e1";
    a.action = "(move_base start goal)";
    a.variant = "around";
    a.predicted_s = 12.5;
    a.measured_s = 13.25;
    a.outcome = "succeeded";
    r.actions.push_back(a);
    r.in_flight = "m1-e4";
    r.in_flight_action = "(pick box floor over_box)";
    r.in_flight_budget_s = 40.0;
    return r;
  }
  fs::path dir_;
};

TEST_F(JournalTest, ARecordIsReadBackWhole) {
  const MissionJournal j(dir_ / "journal.json");
  ASSERT_TRUE(j.write(sample()).ok());
  auto back = j.read();
  ASSERT_TRUE(back.ok()) << back.error().toString();
  ASSERT_TRUE(back->has_value());
  const MissionRecord& r = **back;
  EXPECT_EQ(r.mission_id, "mission-7");
  EXPECT_EQ(r.policy, "infeasible");
  EXPECT_EQ(r.seed, 9u);
  EXPECT_EQ(r.max_replans, 3);
  EXPECT_EQ(r.goal, std::vector<std::string>{"(robot-at goal)"});
  EXPECT_FALSE(r.finished);
  EXPECT_EQ(r.resumptions, 1);
  ASSERT_EQ(r.actions.size(), 1u);
  EXPECT_EQ(r.actions[0].variant, "around");
  EXPECT_DOUBLE_EQ(r.actions[0].measured_s, 13.25);
  EXPECT_EQ(r.in_flight, "m1-e4");
  EXPECT_DOUBLE_EQ(r.in_flight_budget_s, 40.0);
  EXPECT_FALSE(fs::exists(dir_ / "journal.json.tmp")) << "the temporary file is renamed over the journal";
}

TEST_F(JournalTest, NoFileIsNoRecord) {
  auto r = MissionJournal(dir_ / "none.json").read();
  ASSERT_TRUE(r.ok());
  EXPECT_FALSE(r->has_value());
}

TEST_F(JournalTest, AFileThatIsNoJournalIsAnErrorNamingTheFileAndField) {
  std::ofstream(dir_ / "garbage.json") << "{\"format\": \"tamp-mission-journal-1\", \"mission_id\": ";
  auto r = MissionJournal(dir_ / "garbage.json").read();
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.error().toString().find("garbage.json"), std::string::npos) << r.error().toString();

  const MissionJournal j(dir_ / "journal.json");
  ASSERT_TRUE(j.write(sample()).ok());
  std::string text;
  {
    std::ifstream in(dir_ / "journal.json");
    text.assign(std::istreambuf_iterator<char>(in), {});
  }
  const auto at = text.find("\"outcome\": \"succeeded\"");
  ASSERT_NE(at, std::string::npos) << text;
  text.replace(at, std::string("\"outcome\": \"succeeded\"").size(), "\"outcome\": 3");
  std::ofstream(dir_ / "journal.json", std::ios::trunc) << text;
  r = j.read();
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.error().toString().find("actions[0].outcome"), std::string::npos) << r.error().toString();
}

/// Checks, while "executing", what the journal on disk says.
class PeekingExecutor : public Executor {
 public:
  explicit PeekingExecutor(const MissionJournal& j) : journal_(j) {}
  ExecutionReport execute(const EdgeCommand& c, double) override {
    ++calls;
    auto r = journal_.read();
    if (r.ok() && r->has_value()) in_flight_on_disk = (*r)->in_flight == c.command_id;
    ExecutionReport rep;
    rep.outcome = ExecOutcome::kFailed;
    rep.measured_s = 2.5;
    rep.reason = "missed";
    return rep;
  }
  ExecutionReport await(const std::string& id, double) override {
    awaited = id;
    ExecutionReport rep;
    rep.outcome = ExecOutcome::kSucceeded;
    rep.measured_s = 4.0;
    return rep;
  }
  int calls{0};
  bool in_flight_on_disk{false};
  std::string awaited;

 private:
  const MissionJournal& journal_;
};

TEST_F(JournalTest, ACommandIsInFlightOnDiskBeforeItGoesOutAndRecordedWithItsOutcome) {
  const MissionJournal j(dir_ / "journal.json");
  MissionRecord rec = sample();
  rec.in_flight.clear();
  PeekingExecutor robot(j);
  JournalingExecutor x(robot, j, rec);
  EdgeCommand c;
  c.command_id = "r1-m2-e5";
  c.action = "(pick box floor over_box)";
  const ExecutionReport rep = x.execute(c, 30.0);
  EXPECT_EQ(robot.calls, 1);
  EXPECT_TRUE(robot.in_flight_on_disk);
  EXPECT_EQ(rep.outcome, ExecOutcome::kFailed);
  auto back = j.read();
  ASSERT_TRUE(back.ok() && back->has_value());
  EXPECT_TRUE((*back)->in_flight.empty());
  ASSERT_EQ((*back)->actions.size(), 2u);
  EXPECT_EQ((*back)->actions[1].command_id, "r1-m2-e5");
  EXPECT_EQ((*back)->actions[1].outcome, "failed");
  EXPECT_EQ((*back)->actions[1].reason, "missed");
}

TEST_F(JournalTest, TheCommandInFlightIsAwaitedNotSentAgain) {
  const MissionJournal j(dir_ / "journal.json");
  MissionRecord rec = sample();
  PeekingExecutor robot(j);
  JournalingExecutor x(robot, j, rec);
  const ExecutionReport rep = x.await(rec.in_flight, rec.in_flight_budget_s);
  EXPECT_EQ(robot.calls, 0);
  EXPECT_EQ(robot.awaited, "m1-e4");
  EXPECT_EQ(rep.outcome, ExecOutcome::kSucceeded);
  auto back = j.read();
  ASSERT_TRUE(back.ok() && back->has_value());
  ASSERT_EQ((*back)->actions.size(), 2u);
  EXPECT_EQ((*back)->actions[1].action, "(pick box floor over_box)");
  EXPECT_TRUE((*back)->in_flight.empty());
}

TEST_F(JournalTest, ACommandIsNotSentWhenTheJournalCannotBeWritten) {
  const MissionJournal j(dir_ / "missing_folder" / "journal.json");
  MissionRecord rec = sample();
  PeekingExecutor robot(j);
  JournalingExecutor x(robot, j, rec);
  EdgeCommand c;
  c.command_id = "m0-e1";
  const ExecutionReport rep = x.execute(c, 30.0);
  EXPECT_EQ(robot.calls, 0);
  EXPECT_EQ(rep.outcome, ExecOutcome::kUnavailable);
  EXPECT_NE(rep.reason.find("journal"), std::string::npos) << rep.reason;
}

}  // namespace
}  // namespace tamp::graph_manager
