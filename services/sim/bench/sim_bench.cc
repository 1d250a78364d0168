// Benchmarks of the simulator (issue 6): simulated depth frames at three resolutions, and the
// cost of simulation steps. Results go into docs/benchmarks.md ("Simulated depth sensor").
//
//   build/<dir>/bin/tamp_sim_bench [--benchmark_repetitions=3]
#include <cmath>
#include <random>

#include <benchmark/benchmark.h>

#include "tamp/core/log.h"

#include "tamp/sim/depth_sensor.h"
#include "tamp/sim/setup.h"
#include "tamp/sim/simulator.h"

namespace {

using tamp::world::Object;
using tamp::world::Shape;

const tamp::robot::RobotModel& robotModel() {
  static const tamp::robot::RobotModel m = [] {
    auto r = tamp::robot::RobotModel::loadFile(std::filesystem::path(TAMP_SOURCE_DIR) /
                                               "config/robots/mobile_manipulator.urdf");
    if (!r) throw std::runtime_error(r.error().toString());
    return std::move(r).value();
  }();
  return m;
}

Object make(const std::string& id, Shape shape, double x, double y, double z, double yaw,
            bool movable) {
  Object o;
  o.id = id;
  o.kind = movable ? tamp::world::ObjectKind::kMovable : tamp::world::ObjectKind::kStatic;
  o.mass = movable ? 1.0 : 0.0;
  o.shape = std::move(shape);
  o.pose = Eigen::Isometry3d::Identity();
  o.pose.translation() = Eigen::Vector3d(x, y, z);
  o.pose.linear() = Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  return o;
}

/// A 10 m x 10 m room: 4 walls, an L-shaped (non-convex prism) partition, 2 tables, 40 movable
/// boxes, cylinders and spheres on the floor and tables (fixed seed).
tamp::world::World room() {
  tamp::world::World w("bench_room");
  auto add = [&](Object o) {
    if (!w.addObject(std::move(o))) throw std::runtime_error("bench world");
  };
  add(make("wall_n", Shape::box(10, 0.2, 2.5), 0, 5, 1.25, 0, false));
  add(make("wall_s", Shape::box(10, 0.2, 2.5), 0, -5, 1.25, 0, false));
  add(make("wall_e", Shape::box(0.2, 10, 2.5), 5, 0, 1.25, 0, false));
  add(make("wall_w", Shape::box(0.2, 10, 2.5), -5, 0, 1.25, 0, false));
  add(make("partition",
           Shape::prism({{0, 0}, {3, 0}, {3, 0.2}, {0.2, 0.2}, {0.2, 2}, {0, 2}}, 2.0), 1.5, -3,
           1.0, 0.3, false));
  add(make("table_1", Shape::box(1.2, 0.8, 0.75), 2.5, 1.0, 0.375, 0, false));
  add(make("table_2", Shape::box(1.2, 0.8, 0.75), -2.0, 2.5, 0.375, 0.5, false));
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> xy(-4.5, 4.5), yaw(-M_PI, M_PI), s(0.05, 0.3);
  for (int i = 0; i < 40; ++i) {
    const double x = xy(rng), y = xy(rng);
    if (std::hypot(x, y) < 1.0) continue;  // keep the robot's spot free
    Shape sh = i % 3 == 0   ? Shape::box(s(rng), s(rng), s(rng))
               : i % 3 == 1 ? Shape::cylinder(s(rng) / 2, s(rng))
                            : Shape::sphere(s(rng) / 2);
    add(make("obj_" + std::to_string(i), sh, x, y, sh.halfHeight(), yaw(rng), true));
  }
  return w;
}

void BM_DepthFrame(benchmark::State& state) {
  static const tamp::world::World w = room();
  tamp::sim::DepthSensorParams p;
  p.width = static_cast<int>(state.range(0));
  p.height = static_cast<int>(state.range(1));
  p.see_robot = state.range(2) != 0;
  tamp::sim::DepthSensor sensor(p);
  // Looking from the room's centre towards the tables and the partition.
  const auto rs = robotModel().defaultState(tamp::Pose2D{0.0, 0.0, 0.4});
  std::size_t valid = 0;
  for (auto _ : state) {
    auto f = sensor.capture(w, robotModel(), rs, 0);
    benchmark::DoNotOptimize(f.xyz.data());
    valid = 0;
    for (std::size_t i = 0; i < f.size(); ++i) valid += f.valid(i);
  }
  const double pixels = static_cast<double>(p.width) * p.height;
  state.counters["points/s"] =
      benchmark::Counter(pixels * state.iterations(), benchmark::Counter::kIsRate);
  state.counters["valid_frac"] = valid / pixels;
  state.counters["objects"] = static_cast<double>(w.objectCount());
}
BENCHMARK(BM_DepthFrame)
    ->Args({160, 120, 0})
    ->Args({320, 240, 0})
    ->Args({640, 480, 0})
    ->Args({640, 480, 1})
    ->Unit(benchmark::kMillisecond);

tamp::sim::SimParams exact() {
  tamp::sim::SimParams p;
  p.duration_noise = 0.0;
  p.realtime_factor = 0.0;
  return p;
}

tamp::sim::ActionCommand drive(const std::string& id, double x0, double x1, double y) {
  tamp::sim::ActionCommand c;
  c.command_id = id;
  c.kind = tamp::ActionKind::kMoveBase;
  c.trajectory.joint_names = {"base_x", "base_y", "base_theta"};
  c.trajectory.points = {{0.0, {x0, y, x1 > x0 ? 0.0 : M_PI}, {}}, {1.0, {x1, y, x1 > x0 ? 0.0 : M_PI}, {}}};
  return c;
}

/// Accepting a move_base of `range(0)` decimetres across the bench room: validation, the
/// execution timeline and the swept collision check of the whole motion (1 cm resolution: one
/// full-robot collision query per centimetre of the farthest robot point's travel).
void BM_SubmitMoveBase(benchmark::State& state) {
  const double d = static_cast<double>(state.range(0)) / 10.0;
  tamp::world::World w = room();
  // Clear a corridor at y = 4.2 for the drive (keep the walls and the other objects).
  std::vector<std::string> in_way;
  for (const auto& o : w.objects()) {
    if (o.kind == tamp::world::ObjectKind::kMovable && std::abs(o.pose.translation().y() - 4.2) < 0.8) {
      in_way.push_back(o.id);
    }
  }
  for (const auto& id : in_way) (void)w.removeObject(id);
  tamp::robot::RobotState start = robotModel().defaultState(tamp::Pose2D{-4.0, 4.2, 0.0});
  start.arm.assign(robotModel().armDof(), 0.0);
  tamp::sim::Simulator sim(w, robotModel(), start, exact());
  int i = 0;
  bool forward = true;
  for (auto _ : state) {
    const double x = sim.robotState().state.base.x;
    const auto c = forward ? drive("d" + std::to_string(i++), x, -4.0 + d, 4.2) : drive("d" + std::to_string(i++), x, -4.0, 4.2);
    if (!sim.submit(c)) state.SkipWithError("submit failed");
    state.PauseTiming();
    while (sim.busy()) (void)sim.step(10.0);
    forward = !forward;
    // Heading flips at the ends (a turn in place); submit the turn separately, untimed.
    const auto s = sim.robotState().state.base;
    tamp::sim::ActionCommand turn;
    turn.command_id = "t" + std::to_string(i++);
    turn.kind = tamp::ActionKind::kMoveBase;
    turn.trajectory.joint_names = {"base_x", "base_y", "base_theta"};
    turn.trajectory.points = {{0.0, {s.x, s.y, s.theta}, {}}, {1.0, {s.x, s.y, forward ? 0.0 : M_PI}, {}}};
    if (!sim.submit(turn)) state.SkipWithError("turn failed");
    while (sim.busy()) (void)sim.step(10.0);
    state.ResumeTiming();
  }
  state.counters["metres"] = d;
  state.counters["objects"] = static_cast<double>(w.objectCount());
}
BENCHMARK(BM_SubmitMoveBase)->Arg(10)->Arg(50)->Unit(benchmark::kMillisecond);

/// One simulation step (50 ms of simulated time) while a drive is in progress: the robot state
/// on the timeline, the held-object bookkeeping and the state sample with velocities.
void BM_StepDuringAction(benchmark::State& state) {
  tamp::sim::Simulator sim(tamp::sim::emptyRoom(40.0), robotModel(), robotModel().defaultState(tamp::Pose2D{-15, 0, 0}),
                           exact());
  int i = 0;
  for (auto _ : state) {
    if (!sim.busy()) {
      state.PauseTiming();
      const double x = sim.robotState().state.base.x;
      const double theta = sim.robotState().state.base.theta;
      tamp::sim::ActionCommand c;
      c.command_id = "s" + std::to_string(i++);
      c.kind = tamp::ActionKind::kMoveBase;
      c.trajectory.joint_names = {"base_x", "base_y", "base_theta"};
      const double to = x < 0 ? 15.0 : -15.0;
      const double heading = to > x ? 0.0 : M_PI;
      c.trajectory.points = {{0.0, {x, 0, theta}, {}}, {1.0, {to, 0, heading}, {}}};
      if (!sim.submit(c)) state.SkipWithError("submit failed");
      state.ResumeTiming();
    }
    auto e = sim.step(0.05);
    benchmark::DoNotOptimize(e);
    auto s = sim.robotState();
    benchmark::DoNotOptimize(s);
  }
}
BENCHMARK(BM_StepDuringAction)->Unit(benchmark::kMicrosecond);

}  // namespace

int main(int argc, char** argv) {
  tamp::log::setLevel("warn");  // one info line per simulated action otherwise
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
