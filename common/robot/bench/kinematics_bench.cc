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

// The graph manager's reach facts (world::reachesRegion, 24 attempts) ask IK for a point over every
// region from every location: mostly far out of reach. Arg 0: a target 2 m ahead (outside the reach
// sphere: rejected before any attempt); arg 1: a target inside the sphere that no configuration
// reaches with that orientation (every attempt runs).
void BM_InverseKinematicsUnreachable(benchmark::State& state) {
  Eigen::Isometry3d target = Eigen::Isometry3d::Identity();
  target.linear() = Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitY()).toRotationMatrix();
  const RobotModel::ReachSphere reach = model().armReach();
  target.translation() = state.range(0) == 0 ? Eigen::Vector3d(2.0, 0.0, 0.85)
                                             : reach.centre + Eigen::Vector3d(0.0, 0.0, -0.95 * reach.radius);
  IkOptions opt;
  opt.max_attempts = 24;
  const auto seed = model().defaultState().arm;
  std::size_t solved = 0, attempts = 0;
  for (auto _ : state) {
    const IkResult r = model().inverseKinematics(target, seed, opt);
    solved += r.ok();
    attempts += static_cast<std::size_t>(r.attempts);
  }
  state.counters["solved"] = static_cast<double>(solved) / static_cast<double>(state.iterations());
  state.counters["attempts"] = static_cast<double>(attempts) / static_cast<double>(state.iterations());
}
BENCHMARK(BM_InverseKinematicsUnreachable)->Arg(0)->Arg(1)->Unit(benchmark::kMicrosecond);

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
