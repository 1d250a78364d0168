// The graph manager's executor over DDS (node/dds_clients.cc): commands are volatile, so an
// execution monitor restarted while a command was out never received it. The executor sends the
// command again when a new reader matches, and the restarted monitor answers it (from its journal
// or the robot's results: never executed twice, node_test.cc of the execution monitor).
#include <atomic>
#include <future>
#include <memory>
#include <thread>

#include <gtest/gtest.h>

#include "dds_clients.h"
#include "tamp/dds/topics.h"
#include "test_util.h"

namespace tamp::graph_manager {
namespace {

using dds::testing::makeParticipant;

EdgeCommand aCommand() {
  EdgeCommand c;
  c.command_id = "m1-e10";
  c.action = "(move_arm place_box stow over_box_floor)";
  c.kind = ActionKind::kMoveArm;
  c.expected_s = 1.0;
  return c;
}

TEST(DdsExecutorTest, ACommandOutWhenTheMonitorRestartedIsSentToTheNewOne) {
  auto gm = makeParticipant();
  ASSERT_TRUE(gm);
  DdsExecutor executor(gm, "mission-1");
  // The monitor that receives the command and dies with it (it stays matched until its lease ends).
  auto killed = makeParticipant();
  ASSERT_TRUE(killed);
  std::promise<void> received;
  std::atomic<bool> once{false};
  auto first = std::make_unique<dds::Reader<msg::ExecuteCommand>>(
      killed, dds::topics::kExecuteCommand, [&](const msg::ExecuteCommand&, const dds::SampleMeta&) {
        if (!once.exchange(true)) received.set_value();
      });
  auto outcome = std::async(std::launch::async, [&] { return executor.execute(aCommand(), 20.0); });
  ASSERT_EQ(received.get_future().wait_for(std::chrono::seconds(15)), std::future_status::ready)
      << "the first monitor never received the command";
  // The restarted monitor: a new participant, which answers every command it receives.
  auto restarted = makeParticipant();
  ASSERT_TRUE(restarted);
  dds::Writer<msg::ExecuteStatus> status(restarted, dds::topics::kExecuteStatus);
  std::atomic<int> seen{0};
  dds::Reader<msg::ExecuteCommand> second(
      restarted, dds::topics::kExecuteCommand, [&](const msg::ExecuteCommand& c, const dds::SampleMeta&) {
        ++seen;
        msg::ExecuteStatus s;
        s.command_id(c.command_id());
        s.state(msg::ExecState::EXEC_SUCCEEDED);
        s.measured_duration_s(1.5);
        s.reason("executed before (the robot's result)");
        (void)status.write(s);
      });
  const ExecutionReport r = outcome.get();
  EXPECT_EQ(r.outcome, ExecOutcome::kSucceeded) << r.reason;
  EXPECT_DOUBLE_EQ(r.measured_s, 1.5);
  EXPECT_GE(seen.load(), 1);
}

// A stop reaches the graph manager with what stopped the robot: the robot itself at contact
// (evidence of where the object is: contact.h), or the monitor on a prediction.
TEST(DdsExecutorTest, ABlockedOutcomeSaysWhetherTheRobotStoppedAtContact) {
  auto gm = makeParticipant();
  ASSERT_TRUE(gm);
  DdsExecutor executor(gm, "mission-1");
  auto monitor = makeParticipant();
  ASSERT_TRUE(monitor);
  dds::Writer<msg::ExecuteStatus> status(monitor, dds::topics::kExecuteStatus);
  std::atomic<bool> at_contact{true};
  dds::Reader<msg::ExecuteCommand> commands(
      monitor, dds::topics::kExecuteCommand, [&](const msg::ExecuteCommand& c, const dds::SampleMeta&) {
        msg::ExecuteStatus s;
        s.command_id(c.command_id());
        s.state(msg::ExecState::EXEC_BLOCKED);
        s.blocking_object_id("crate");
        s.stopped_at_contact(at_contact.load());
        s.reason("blocked");
        (void)status.write(s);
      });
  for (bool contact : {true, false}) {
    at_contact = contact;
    EdgeCommand c = aCommand();
    c.command_id += contact ? "-contact" : "-monitor";
    const ExecutionReport r = executor.execute(c, 20.0);
    EXPECT_EQ(r.outcome, ExecOutcome::kBlocked) << r.reason;
    EXPECT_EQ(r.blocking_object_id, "crate");
    EXPECT_EQ(r.stopped_at_contact, contact);
  }
}

}  // namespace
}  // namespace tamp::graph_manager
