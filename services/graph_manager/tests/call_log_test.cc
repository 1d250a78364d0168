// LoggedServiceClients (call_log.h) is a transparent wrapper: every ServiceClients call reaches
// the inner clients, with its answer unchanged, and the planning calls are logged. A forgotten
// override answers with the base class's default instead (policy oracle lost its knowledge so:
// the wrapper did not forward `oracle()`).
#include <gtest/gtest.h>

#include "tamp/graph_manager/call_log.h"

namespace tamp::graph_manager {
namespace {

class Inner : public ServiceClients {
 public:
  int plans{0}, motions{0}, placement_calls{0}, grasp_calls{0}, effort_calls{0}, oracle_calls{0};
  TaskPlan plan(const TaskQuery&) override {
    ++plans;
    TaskPlan p;
    p.status = TaskStatus::kSolved;
    p.actions = {"(move_base a b)"};
    return p;
  }
  MotionAnswer motion(const MotionQuery&) override {
    ++motions;
    MotionAnswer a;
    a.status = MotionOutcome::kSolved;
    a.path_length = 2.5;
    return a;
  }
  Result<std::vector<PlacementOption>> placements(const PlacementQuery&) override {
    ++placement_calls;
    return std::vector<PlacementOption>(3);
  }
  Result<std::vector<GraspOption>> grasps(const GraspQuery&) override {
    ++grasp_calls;
    return std::vector<GraspOption>(2);
  }
  std::vector<EffortAnswer> effort(const std::vector<EffortQuery>& q) override {
    ++effort_calls;
    return std::vector<EffortAnswer>(q.size(), EffortAnswer{true, 4.0, 0.5, ""});
  }
  Result<OracleKnowledge> oracle() override {
    ++oracle_calls;
    OracleKnowledge k;
    k.action_count = 7;
    return k;
  }
};

TEST(LoggedServiceClientsTest, EveryCallReachesTheInnerClientsWithItsAnswer) {
  Inner inner;
  LoggedServiceClients logged(inner);
  const std::size_t m = logged.mark();
  EXPECT_EQ(logged.plan(TaskQuery{}).actions.size(), 1u);
  EXPECT_DOUBLE_EQ(logged.motion(MotionQuery{}).path_length, 2.5);
  EXPECT_EQ(logged.placements(PlacementQuery{})->size(), 3u);
  EXPECT_EQ(logged.grasps(GraspQuery{})->size(), 2u);
  EXPECT_DOUBLE_EQ(logged.effort({EffortQuery{}, EffortQuery{}}).at(1).mean_s, 4.0);
  auto k = logged.oracle();
  ASSERT_TRUE(k) << k.error().toString();
  EXPECT_EQ(k->action_count, 7);
  EXPECT_EQ(inner.plans + inner.motions + inner.placement_calls + inner.grasp_calls + inner.effort_calls, 5);
  EXPECT_EQ(inner.oracle_calls, 1);
  const CallSummary s = CallSummary::of(logged.since(m));
  EXPECT_EQ(s.calls(), 5) << "the five planning calls are logged";
  EXPECT_EQ(s.effort.calls, 1);
}

}  // namespace
}  // namespace tamp::graph_manager
