// The graph manager's motion client over DDS (node/dds_clients.cc) against a scripted motion
// server: a planner that has not received the world version a question names answers
// `unavailable` after waiting for it (on a lossy link between hosts the world arrives late). The
// client asks again, a bounded number of times, instead of taking the first such answer for the
// question's failure (which made a whole mission fail at its first query).
#include <atomic>
#include <memory>

#include <gtest/gtest.h>

#include "dds_clients.h"
#include "tamp/core/paths.h"
#include "tamp/dds/topics.h"
#include "tamp/world/scenario.h"
#include "test_util.h"

namespace tamp::graph_manager {
namespace {

using dds::testing::makeParticipant;

robot::RobotModel corridorRobot() {
  auto sc = world::loadScenario(configDir() / "scenarios" / "namo_corridor.yaml");
  if (!sc) throw std::runtime_error(sc.error().toString());
  auto robot = robot::RobotModel::loadDescription(sc->robot.description);
  if (!robot) throw std::runtime_error(robot.error().toString());
  return *robot;
}

/// A motion server whose world arrives after `lagging_answers` questions: until then it answers
/// as the motion planner does for a version it has not received; then `no path`.
/// `code` is what it answers meanwhile (the motion planner's: STATUS_NOT_READY).
struct LaggingPlanner {
  int lagging_answers{0};
  msg::StatusCode code{msg::STATUS_NOT_READY};
  std::atomic<int> calls{0};
  std::unique_ptr<dds::RpcServer<msg::MotionRequest, msg::MotionReply>> server;

  LaggingPlanner(std::shared_ptr<dds::Participant> p, int lagging, msg::StatusCode answer)
      : lagging_answers(lagging), code(answer) {
    server = std::make_unique<dds::RpcServer<msg::MotionRequest, msg::MotionReply>>(
        p, dds::services::kMotion, [this](const msg::MotionRequest& req, const dds::RequestContext&) {
          msg::MotionReply rep;
          if (calls++ < lagging_answers) {
            rep.header().code(code);
            rep.header().message("world_version: " + std::to_string(req.world_version()) + " not received (latest 0)");
            return rep;
          }
          rep.status(msg::MotionStatus::MOTION_NO_PATH);
          rep.reason("scripted: no path");
          rep.world_version(req.world_version());
          return rep;
        });
  }
};

MotionQuery aQuestion() {
  MotionQuery q;
  q.group = Group::kBase;
  q.mode = Mode::kFull;
  q.start.base = Pose2D{1.5, 1.2, 0.0};
  q.start.arm.assign(corridorRobot().armDof(), 0.0);
  q.goal_base = Pose2D{8.5, 1.2, 0.0};
  q.world_version = 7;
  q.budget_s = 5.0;
  return q;
}

/// One motion question to a planner whose world arrives after `lagging` answers; how many
/// questions it was asked goes to `calls`.
MotionAnswer askALaggingPlanner(int lagging, int& calls, msg::StatusCode answer = msg::STATUS_NOT_READY) {
  auto gm = makeParticipant();
  auto planner = makeParticipant();
  if (!gm || !planner) throw std::runtime_error("no DDS participant");
  LaggingPlanner server(planner, lagging, answer);
  DdsServiceClients clients(gm, corridorRobot());
  const MotionAnswer a = clients.motion(aQuestion());
  calls = server.calls.load();
  return a;
}

TEST(DdsClientsTest, AQuestionWhoseWorldHasNotArrivedIsAskedAgain) {
  int calls = 0;
  const MotionAnswer a = askALaggingPlanner(2, calls);
  EXPECT_EQ(a.status, MotionOutcome::kNoPath) << a.reason;
  EXPECT_EQ(calls, 3);
}

TEST(DdsClientsTest, AWorldThatNeverArrivesIsUnavailableAfterABoundedNumberOfQuestions) {
  int calls = 0;
  const MotionAnswer a = askALaggingPlanner(1000, calls);
  EXPECT_EQ(a.status, MotionOutcome::kUnavailable);
  EXPECT_NE(a.reason.find("world_version: 7 not received"), std::string::npos) << a.reason;
  EXPECT_EQ(calls, 3);
}

// Only the status says that the world has not arrived: an unavailable planner is not asked
// again by the client, whatever its message reads (the RPC layer's own retries aside).
TEST(DdsClientsTest, AnUnavailablePlannerIsNotAskedAgainWhateverItsMessageSays) {
  int calls = 0;
  const MotionAnswer a = askALaggingPlanner(1000, calls, msg::STATUS_UNAVAILABLE);
  EXPECT_EQ(a.status, MotionOutcome::kUnavailable);
  EXPECT_EQ(calls, 1);
}

}  // namespace
}  // namespace tamp::graph_manager
