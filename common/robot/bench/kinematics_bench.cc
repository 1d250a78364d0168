// Cost of the robot queries a motion planner makes per state: link poses for collision checking,
// KDL forward kinematics of the tool, inverse kinematics, and a full-state collision check.
#include <random>

#include <benchmark/benchmark.h>

#include "tamp/robot/robot_model.h"

namespace tamp::robot {
namespace {

const RobotModel& model() {
  static const RobotModel m = RobotModel::loadDefault().value();
  return m;
}

void BM_LinkPoses(benchmark::State& state) {
  std::mt19937 rng(1);
  RobotState s = model().defaultState();
  s.arm = model().randomArmConfiguration(rng);
  std::vector<Eigen::Isometry3d> out;
  for (auto _ : state) {
    model().linkPoses(s, out);
    benchmark::DoNotOptimize(out.data());
  }
}
BENCHMARK(BM_LinkPoses);

void BM_ToolPoseKdl(benchmark::State& state) {
  std::mt19937 rng(1);
  const auto q = model().randomArmConfiguration(rng);
  for (auto _ : state) benchmark::DoNotOptimize(model().toolPose(q));
}
BENCHMARK(BM_ToolPoseKdl);

void BM_InverseKinematics(benchmark::State& state) {
  std::mt19937 rng(2);
  std::vector<Eigen::Isometry3d> targets;
  for (int i = 0; i < 64; ++i)
    targets.push_back(model().toolPose(model().randomArmConfiguration(rng)));
  const auto seed = model().defaultState().arm;
  size_t i = 0, solved = 0;
  for (auto _ : state)
    solved += model().inverseKinematics(targets[i++ % targets.size()], seed).ok();
  state.counters["solved"] = static_cast<double>(solved) / static_cast<double>(state.iterations());
}
BENCHMARK(BM_InverseKinematics)->Unit(benchmark::kMicrosecond);

void BM_FullStateCollisionCheck(benchmark::State& state) {
  world::World w;
  world::Object table;
  table.id = "table";
  table.shape = world::Shape::box(0.8, 1.2, 0.75);
  table.pose.translation() = Eigen::Vector3d(0.8, 0, 0.375);
  (void)w.addObject(table);
  collision::Scene scene(w);
  scene.setRobot(model().collisionGeometry());
  std::mt19937 rng(3);
  std::vector<RobotState> states;
  for (int i = 0; i < 256; ++i) {
    RobotState s = model().defaultState({0, 0, 0});
    s.arm = model().randomArmConfiguration(rng);
    states.push_back(s);
  }
  std::vector<Eigen::Isometry3d> poses;
  size_t i = 0, hits = 0;
  for (auto _ : state) {
    model().linkPoses(states[i++ & 255], poses);
    scene.setLinkPoses(poses);
    hits += scene.robotInCollision();
  }
  state.counters["hit_rate"] = static_cast<double>(hits) / static_cast<double>(state.iterations());
}
BENCHMARK(BM_FullStateCollisionCheck);

}  // namespace
}  // namespace tamp::robot

BENCHMARK_MAIN();
