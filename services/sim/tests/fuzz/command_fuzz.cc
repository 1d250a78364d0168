// libFuzzer target: arbitrary action commands and faults as they arrive from DDS (after the
// message conversion): any kind (invalid ones too), joint names (known, unknown, duplicated),
// values and times (NaN, inf, huge), object ids and poses. Must never crash or throw; a command
// is either rejected with a named field or executed to an end with a finite state.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <string>

#include "fuzz_input.h"
#include "tamp/core/log.h"
#include "tamp/sim/setup.h"
#include "tamp/sim/simulator.h"

namespace {

using Reader = tamp::fuzz::Input;

const tamp::robot::RobotModel& robotModel() {
  static const tamp::robot::RobotModel* m = [] {
    tamp::log::setLevel("off");
    auto r = tamp::robot::RobotModel::loadFile(std::filesystem::path(TAMP_SOURCE_DIR) /
                                               "config/robots/mobile_manipulator.urdf");
    if (!r) std::abort();
    return new tamp::robot::RobotModel(std::move(r).value());
  }();
  return *m;
}

tamp::world::World world() {
  tamp::world::World w = tamp::sim::emptyRoom();
  tamp::world::Object crate;
  crate.id = "crate";
  crate.kind = tamp::world::ObjectKind::kMovable;
  crate.mass = 3;
  crate.graspable = true;
  crate.shape = tamp::world::Shape::box(0.3, 0.3, 0.3);
  crate.pose.translation() = Eigen::Vector3d(1.0, 0.0, 0.15);
  crate.hidden = true;
  (void)w.addObject(crate);
  return w;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  Reader r{data, size};
  tamp::sim::SimParams params;
  params.duration_noise = 0.05;
  params.max_step_m = 0.05;  // coarser sweeps keep the fuzzer fast
  tamp::sim::Simulator sim(world(), robotModel(), robotModel().defaultState(tamp::Pose2D{}), params);
  static const std::vector<std::string> kNames = [] {
    auto n = robotModel().fullJointNames();
    n.push_back("no_such_joint");
    n.push_back("base_x");  // a duplicate
    return n;
  }();
  static const char* kObjects[] = {"crate", "ghost", "", "Bad Id"};
  for (int round = 0; round < 3 && r.n > 0; ++round) {
    tamp::sim::ActionCommand c;
    c.command_id = r.byte() % 16 == 0 ? "" : "c" + std::to_string(round);
    c.kind = static_cast<tamp::ActionKind>(r.byte() % 5);  // 4 = invalid
    const int joints = r.byte() % 6;
    for (int j = 0; j < joints; ++j) c.trajectory.joint_names.push_back(kNames[r.byte() % kNames.size()]);
    const std::vector<double> q = robotModel().toJointValues(sim.robotState().state);
    const auto& full = robotModel().fullJointNames();
    const int points = r.byte() % 6;
    double t = 0;
    for (int i = 0; i < points; ++i) {
      tamp::TrajectoryPoint p;
      t += r.byte() % 8 == 0 ? r.number() : r.byte() / 64.0;
      p.time_from_start = t;
      const int n = r.byte() % 16 == 0 ? joints + 1 : joints;
      for (int j = 0; j < n; ++j) {
        double around = 0;
        if (j < joints) {
          const auto it = std::find(full.begin(), full.end(), c.trajectory.joint_names[j]);
          if (it != full.end()) around = q[static_cast<std::size_t>(it - full.begin())];
        }
        p.positions.push_back(i == 0 && r.byte() % 2 == 0 ? around : r.value(around));
      }
      c.trajectory.points.push_back(std::move(p));
    }
    c.object_id = kObjects[r.byte() % 4];
    if (r.byte() % 2 == 0) {
      Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
      pose.translation() = Eigen::Vector3d(r.value(1.0), r.value(0.0), r.value(0.15));
      c.object_pose = pose;
    }
    if (r.byte() % 4 == 0) {
      tamp::sim::Fault f;
      f.id = "f";
      f.type = static_cast<tamp::sim::FaultType>(r.byte() % 4);
      f.object_id = kObjects[r.byte() % 4];
      f.object.id = "box" + std::to_string(round);
      f.object.shape = tamp::world::Shape::box(0.2, 0.2, 0.2);
      f.object.pose.translation() = Eigen::Vector3d(r.value(0.5), r.value(0.0), 0.1);
      f.trigger.fraction = r.byte() / 255.0;
      (void)sim.inject(f);
    }
    const tamp::Status s = sim.submit(c);
    if (!s && s.error().code == tamp::ErrorCode::kInvalidArgument && s.error().where.field.empty()) std::abort();
    for (int k = 0; k < 100000 && sim.busy(); ++k) {
      const auto e = sim.step(0.5);
      for (const auto& res : e.results) {
        if (!(res.progress >= 0 && res.progress <= 1) || !std::isfinite(res.duration_s)) std::abort();
      }
    }
    if (sim.busy()) std::abort();  // an action that never ends
    const auto st = sim.robotState();
    if (!std::isfinite(st.state.base.x) || !std::isfinite(st.state.base.y) || !std::isfinite(st.state.base.theta)) {
      std::abort();
    }
  }
  return 0;
}
