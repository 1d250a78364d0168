// QueryMemo (issue 12, replanning latency): an identical question is answered from memory, a
// different one is not, failures are not kept, and a cleared memo forgets.
#include <gtest/gtest.h>

#include "tamp/graph_manager/query_memo.h"

namespace tamp::graph_manager {
namespace {

MotionQuery baseQuery() {
  MotionQuery q;
  q.group = Group::kBase;
  q.mode = Mode::kFull;
  q.start.base = Pose2D{1.0, 2.0, 0.5};
  q.start.arm = {0.1, 0.2};
  q.goal_base = Pose2D{4.0, 2.0, 0.0};
  return q;
}

MotionAnswer solved(double length) {
  MotionAnswer a;
  a.status = MotionOutcome::kSolved;
  a.path_length = length;
  return a;
}

TEST(QueryMemoTest, AnIdenticalMotionQuestionIsAnsweredFromMemory) {
  QueryMemo memo;
  memo.keep(baseQuery(), solved(3.5));
  const MotionAnswer* kept = memo.motion(baseQuery());
  ASSERT_NE(kept, nullptr);
  EXPECT_DOUBLE_EQ(kept->path_length, 3.5);
}

TEST(QueryMemoTest, AnyFieldThatChangesTheAnswerChangesTheKey) {
  QueryMemo memo;
  memo.keep(baseQuery(), solved(3.5));
  std::vector<MotionQuery> others(11, baseQuery());
  others[0].mode = Mode::kLazy;
  others[1].start.base.x += 0.01;
  others[2].start.arm[1] += 0.01;
  others[3].goal_base.theta += 0.01;
  others[4].held.object_id = "box";
  others[5].overrides.push_back(ObjectOverride{"box", false, Eigen::Isometry3d::Identity()});
  others[6].overrides.push_back(ObjectOverride{"box", true, Eigen::Isometry3d::Identity()});
  others[7].movable_cost_weight = 1.0;
  others[8].ignored = {"box"};
  others[9].fixed = {"box"};
  others[10].straight_only = true;
  for (std::size_t i = 0; i < others.size(); ++i) EXPECT_EQ(memo.motion(others[i]), nullptr) << "variant " << i;
  MotionQuery moved = baseQuery();
  moved.overrides.push_back(ObjectOverride{"box", false, Eigen::Isometry3d::Identity()});
  MotionQuery elsewhere = moved;
  elsewhere.overrides[0].pose.translation().x() = 0.5;
  EXPECT_NE(QueryMemo::key(moved), QueryMemo::key(elsewhere));
}

TEST(QueryMemoTest, AFailureIsNotKept) {
  QueryMemo memo;
  MotionAnswer timeout;
  timeout.status = MotionOutcome::kTimeout;
  memo.keep(baseQuery(), timeout);
  EXPECT_EQ(memo.motion(baseQuery()), nullptr);
  GraspQuery g;
  g.object_id = "box";
  memo.keep(g, std::vector<GraspOption>{});
  EXPECT_EQ(memo.grasps(g), nullptr);
  EXPECT_EQ(memo.size(), 0u);
}

TEST(QueryMemoTest, GraspsFromAGivenBaseAndSampledOnesAreDifferentQuestions) {
  QueryMemo memo;
  GraspQuery sampled;
  sampled.object_id = "box";
  GraspOption o;
  o.base_pose = Pose2D{1.0, 1.0, 0.0};
  memo.keep(sampled, {o});
  GraspQuery from_base = sampled;
  from_base.base = Pose2D{1.0, 1.0, 0.0};
  EXPECT_EQ(memo.grasps(from_base), nullptr);
  ASSERT_NE(memo.grasps(sampled), nullptr);
  EXPECT_EQ(memo.grasps(sampled)->size(), 1u);
}

TEST(QueryMemoTest, ClearForgetsEverything) {
  QueryMemo memo;
  memo.keep(baseQuery(), solved(1.0));
  GraspQuery g;
  g.object_id = "box";
  memo.keep(g, {GraspOption{}});
  EXPECT_EQ(memo.size(), 2u);
  memo.clear();
  EXPECT_EQ(memo.motion(baseQuery()), nullptr);
  EXPECT_EQ(memo.grasps(g), nullptr);
}

}  // namespace
}  // namespace tamp::graph_manager
