// Collision-check cost on NAMO-like worlds: the OMPL validity-checker pattern (set the robot
// pose, ask whether / what it hits) with a disc robot, for both prism representations.
#include <random>

#include <benchmark/benchmark.h>

#include "tamp/collision/scene.h"
#include "tamp/world/namo.h"

namespace tamp::collision {
namespace {

using world::Object;
using world::ObjectKind;
using world::Shape;

Object prismObject(const std::string& id, const world::Polygon2& poly, double height,
                   ObjectKind kind) {
  Object o;
  o.id = id;
  o.kind = kind;
  const Eigen::Vector2d c = world::areaCentroid(poly);
  world::Polygon2 local;
  for (const auto& p : poly) local.push_back(p - c);
  o.shape = Shape::prism(local, height);
  o.pose.translation() = Eigen::Vector3d(c.x(), c.y(), 0.5 * height);
  o.mass = kind == ObjectKind::kMovable ? 5.0 : 0.0;
  return o;
}

// A 10 x 10 m room: outer wall as one non-convex ring (slit), 6 inner wall segments, an L-shaped
// and a U-shaped obstacle, and `n_movable` boxes scattered with a fixed seed.
world::World syntheticNamo(int n_movable) {
  world::World w("synthetic_namo");
  const world::Polygon2 ring{{0, 0},     {10, 0},    {10, 10},   {0, 10},    {0, 5},   {0.2, 5},
                             {0.2, 9.8}, {9.8, 9.8}, {9.8, 0.2}, {0.2, 0.2}, {0.2, 5}, {0, 5}};
  (void)w.addObject(prismObject("outer", ring, 1.0, ObjectKind::kStatic));
  for (int i = 0; i < 6; ++i) {
    const double x = 1.5 + 1.4 * i;
    const double y0 = i % 2 == 0 ? 0.2 : 3.0, y1 = i % 2 == 0 ? 7.0 : 9.8;
    (void)w.addObject(prismObject("wall_" + std::to_string(i),
                                  {{x, y0}, {x + 0.1, y0}, {x + 0.1, y1}, {x, y1}}, 1.0,
                                  ObjectKind::kStatic));
  }
  (void)w.addObject(prismObject("ell", {{4, 4}, {5, 4}, {5, 4.3}, {4.3, 4.3}, {4.3, 5}, {4, 5}},
                                1.0, ObjectKind::kStatic));
  (void)w.addObject(prismObject(
      "you", {{6, 6}, {7, 6}, {7, 7}, {6.8, 7}, {6.8, 6.2}, {6.2, 6.2}, {6.2, 7}, {6, 7}}, 1.0,
      ObjectKind::kStatic));
  std::mt19937 rng(1);
  std::uniform_real_distribution<double> u(0.5, 9.5), a(0, M_PI);
  for (int i = 0; i < n_movable; ++i) {
    Object o;
    o.id = "box_" + std::to_string(i);
    o.kind = ObjectKind::kMovable;
    o.shape = Shape::box(0.4, 0.3, 0.5);
    o.pose = Pose2D{u(rng), u(rng), a(rng)}.toIsometry(0.25);
    o.mass = 5;
    (void)w.addObject(o);
  }
  return w;
}

std::vector<Pose2D> randomPoses(int n) {
  std::mt19937 rng(42);
  std::uniform_real_distribution<double> u(0.3, 9.7), a(-M_PI, M_PI);
  std::vector<Pose2D> out;
  for (int i = 0; i < n; ++i) out.push_back({u(rng), u(rng), a(rng)});
  return out;
}

void BM_DiscInCollision(benchmark::State& state) {
  const auto mode = state.range(0) == 0 ? Scene::PrismMode::kConvexPieces : Scene::PrismMode::kMesh;
  Scene s(syntheticNamo(static_cast<int>(state.range(1))), Scene::Options{mode});
  s.setRobot(RobotGeometry::disc(0.25, 1.0));
  const auto poses = randomPoses(4096);
  size_t i = 0, hits = 0;
  for (auto _ : state) {
    s.setBasePose(poses[i++ & 4095]);
    hits += s.robotInCollision();
  }
  state.counters["hit_rate"] = static_cast<double>(hits) / static_cast<double>(state.iterations());
  state.counters["fcl_objects"] = static_cast<double>(s.fclObjectCount());
}
BENCHMARK(BM_DiscInCollision)
    ->ArgNames({"mesh", "movables"})
    ->Args({0, 30})
    ->Args({1, 30})
    ->Args({0, 200});

void BM_DiscStaticOnly(benchmark::State& state) {
  Scene s(syntheticNamo(30));
  s.setRobot(RobotGeometry::disc(0.25, 1.0));
  const auto poses = randomPoses(4096);
  size_t i = 0;
  for (auto _ : state) {
    s.setBasePose(poses[i++ & 4095]);
    benchmark::DoNotOptimize(s.robotInCollision(Filter::staticOnly()));
  }
}
BENCHMARK(BM_DiscStaticOnly);

void BM_BoxRobotWhichMovables(benchmark::State& state) {
  Scene s(syntheticNamo(30));
  s.setRobot(RobotGeometry::box(0.6, 0.5, 1.0));
  const auto poses = randomPoses(4096);
  size_t i = 0;
  for (auto _ : state) {
    s.setBasePose(poses[i++ & 4095]);
    benchmark::DoNotOptimize(s.robotCollisions(Filter::movableOnly()));
  }
}
BENCHMARK(BM_BoxRobotWhichMovables);

void BM_DiscDistance(benchmark::State& state) {
  Scene s(syntheticNamo(30));
  s.setRobot(RobotGeometry::disc(0.25, 1.0));
  const auto poses = randomPoses(4096);
  size_t i = 0;
  for (auto _ : state) {
    s.setBasePose(poses[i++ & 4095]);
    benchmark::DoNotOptimize(s.robotDistance());
  }
}
BENCHMARK(BM_DiscDistance);

void BM_MoveOneObject(benchmark::State& state) {
  world::World w = syntheticNamo(30);
  Scene s(w);
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(0.5, 9.5);
  for (auto _ : state) {
    (void)w.setObjectPose("box_7", Pose2D{u(rng), u(rng), 0}.toIsometry(0.25));
    s.syncWorld(w);
  }
}
BENCHMARK(BM_MoveOneObject);

// Real NAMO worlds: disc robot of the benchmark's radius at random poses in the workspace.
world::NamoWorld loadNamoWorld(const std::string& rel) {
  return world::loadNamo(std::string(TAMP_BENCHMARKS_DIR) + "/namo/" + rel).value();
}

void namoBench(benchmark::State& state, const std::string& rel) {
  const world::NamoWorld nw = loadNamoWorld(rel);
  const auto mode = state.range(0) == 0 ? PrismMode::kConvexPieces : PrismMode::kMesh;
  Scene s(nw.world, Scene::Options{mode});
  s.setRobot(RobotGeometry::disc(nw.robot_radius, 1.0));
  const Aabb b = nw.world.bounds();
  std::mt19937 rng(42);
  std::uniform_real_distribution<double> ux(b.min.x(), b.max.x()), uy(b.min.y(), b.max.y());
  // Arg 1 = 1: only collision-free poses (the common case inside a planner's motion checks,
  // where no early exit helps).
  const bool free_only = state.range(1) == 1;
  std::vector<Pose2D> poses;
  while (poses.size() < 4096) {
    const Pose2D p{ux(rng), uy(rng), 0};
    if (free_only) {
      s.setBasePose(p);
      if (s.robotInCollision()) continue;
    }
    poses.push_back(p);
  }
  size_t i = 0, hits = 0;
  for (auto _ : state) {
    s.setBasePose(poses[i++ & 4095]);
    hits += s.robotInCollision();
  }
  state.counters["hit_rate"] = static_cast<double>(hits) / static_cast<double>(state.iterations());
  state.counters["objects"] = static_cast<double>(nw.world.objectCount());
  state.counters["fcl_objects"] = static_cast<double>(s.fclObjectCount());
}

void BM_NamoMoghaddam08(benchmark::State& state) {
  namoBench(state, "moghaddam_planning_2016_benchmark/moghaddam_planning_2016_benchmark_08.svg");
}
BENCHMARK(BM_NamoMoghaddam08)->ArgNames({"mesh", "free"})->Args({0, 0})->Args({1, 0})->Args({0, 1})->Args({1, 1});

void BM_NamoAfterTheFeast(benchmark::State& state) {
  namoBench(state,
            "s-namo_cases/04_after_the_feast/04_after_the_feast_omniscient_complexified.json");
}
BENCHMARK(BM_NamoAfterTheFeast)->ArgNames({"mesh", "free"})->Args({0, 0})->Args({1, 0})->Args({0, 1})->Args({1, 1});

void BM_NamoCitiSecondFloor(benchmark::State& state) {
  namoBench(state, "s-namo_cases/05_citi_second_floor/05_citi_second_floor_omniscient.json");
}
BENCHMARK(BM_NamoCitiSecondFloor)->ArgNames({"mesh", "free"})->Args({0, 0})->Args({1, 0})->Args({0, 1})->Args({1, 1});

void BM_LoadAndBuildCiti(benchmark::State& state) {
  for (auto _ : state) {
    const world::NamoWorld nw =
        loadNamoWorld("s-namo_cases/05_citi_second_floor/05_citi_second_floor_omniscient.json");
    Scene s(nw.world);
    benchmark::DoNotOptimize(s.fclObjectCount());
  }
}
BENCHMARK(BM_LoadAndBuildCiti)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace tamp::collision

BENCHMARK_MAIN();
