// libFuzzer target: the execution monitor driven by arbitrary events as they arrive from DDS
// (after the message conversion): commands of any kind (invalid ones too) with known, unknown and
// duplicated joints, NaN / inf / huge values and times, repeated and cancelled ids; robot states
// anywhere (held objects appearing and vanishing); world models with an object anywhere; robot
// results of any outcome and stamp; ticks at any time. Must never crash or throw, and:
//  - an id is sent to the robot for execution at most once, and never while another runs;
//  - a final status of an id never changes afterwards;
//  - failed and blocked statuses give a reason; progress is in [0, 1].
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <set>
#include <string>

#include "fuzz_input.h"
#include "tamp/core/log.h"
#include "tamp/execution_monitor/monitor.h"

namespace {

namespace em = tamp::execution_monitor;
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

tamp::world::Object box(const std::string& id, double x, double y, bool movable) {
  tamp::world::Object o;
  o.id = id;
  o.kind = movable ? tamp::world::ObjectKind::kMovable : tamp::world::ObjectKind::kStatic;
  o.mass = movable ? 1.0 : 0.0;
  o.graspable = movable;
  o.shape = tamp::world::Shape::box(0.3, 0.3, 0.3);
  o.pose = Eigen::Isometry3d::Identity();
  o.pose.translation() = Eigen::Vector3d(x, y, 0.15);
  return o;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  Reader r{data, size};
  em::MonitorParams params;
  params.path_check.step_m = 0.1;  // coarse sweeps keep the fuzzer fast
  params.path_check.step_rad = 0.1;
  em::ExecutionMonitor monitor(params, robotModel());
  static const std::vector<std::string> kNames = [] {
    auto n = robotModel().fullJointNames();
    n.push_back("no_such_joint");
    n.push_back("base_x");  // a duplicate
    return n;
  }();
  static const char* kObjects[] = {"crate", "ghost", "", "wall"};
  std::set<std::string> executed;
  std::map<std::string, em::ExecState> finals;
  std::string running;
  double now = 0.0;
  std::int64_t stamp = 0;
  auto check = [&](const em::Outputs& out) {
    // Statuses first: a final status and the next command's start come in one output.
    for (const auto& s : out.statuses) {
      if (!(s.progress >= 0.0 && s.progress <= 1.0)) std::abort();
      if ((s.state == em::ExecState::kFailed || s.state == em::ExecState::kBlocked) &&
          s.reason.empty()) {
        std::abort();
      }
      const auto it = finals.find(s.command_id);
      if (it != finals.end() && it->second != s.state) std::abort();  // a final status changed
      if (em::isFinal(s.state)) {
        finals[s.command_id] = s.state;
        if (s.command_id == running) running.clear();
      }
    }
    for (const auto& q : out.robot) {
      if (q.type == em::RobotRequest::Type::kExecute) {
        if (!executed.insert(q.command.command_id).second) std::abort();  // executed twice
        if (!running.empty()) std::abort();                               // two at once
        if (finals.count(q.command.command_id)) std::abort();             // started after its end
        running = q.command.command_id;
      }
    }
  };
  while (r.n > 0) {
    now += r.byte() % 8 == 0 ? std::abs(r.value(20.0)) : r.byte() / 32.0;
    if (!std::isfinite(now)) now = 1e6;
    switch (r.byte() % 6) {
      case 0: {  // a command
        em::ExecutionCommand c;
        c.command_id = "c" + std::to_string(r.byte() % 6);
        c.kind = static_cast<tamp::ActionKind>(r.byte() % 5);  // 4 = invalid
        c.cancel = r.byte() % 6 == 0;
        const int joints = r.byte() % 5;
        for (int j = 0; j < joints; ++j)
          c.trajectory.joint_names.push_back(kNames[r.byte() % kNames.size()]);
        const int points = r.byte() % 4;
        double t = 0;
        for (int i = 0; i < points; ++i) {
          tamp::TrajectoryPoint p;
          t += r.byte() % 8 == 0 ? r.number() : r.byte() / 64.0;
          p.time_from_start = t;
          const int n = r.byte() % 16 == 0 ? joints + 1 : joints;
          for (int j = 0; j < n; ++j) p.positions.push_back(r.value(0.0));
          c.trajectory.points.push_back(std::move(p));
        }
        c.object_id = kObjects[r.byte() % 4];
        if (r.byte() % 2 == 0) {
          Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
          pose.translation() = Eigen::Vector3d(r.value(1.0), r.value(0.0), r.value(0.15));
          c.object_target = pose;
        }
        c.expected_duration_s = r.value(2.0);
        c.expected_stddev_s = r.value(0.2);
        c.world_version = r.byte() % 4;
        check(monitor.onCommand(c, now));
        break;
      }
      case 1: {  // a robot state
        em::RobotObservation o;
        o.state = robotModel().defaultState(tamp::Pose2D{r.value(0.0), r.value(0.0), r.value(0.0)});
        if (!std::isfinite(o.state.base.x) || !std::isfinite(o.state.base.y) ||
            !std::isfinite(o.state.base.theta)) {
          break;  // the node refuses non-finite states
        }
        o.held_object_id = kObjects[r.byte() % 4];
        o.stamp_ns = stamp += r.byte();
        check(monitor.onRobotState(o, now));
        break;
      }
      case 2: {  // a world model
        tamp::world::World w;
        (void)w.addObject(box("wall", 3.0, 0.0, false));
        if (r.byte() % 2 == 0) {
          const double x = r.value(1.0), y = r.value(0.0);
          if (std::isfinite(x) && std::isfinite(y)) (void)w.addObject(box("crate", x, y, true));
        }
        check(monitor.onWorld(w, r.byte() % 4, now));
        break;
      }
      case 3: {  // a robot result
        em::RobotResult res;
        res.command_id = r.byte() % 4 == 0 ? "c" + std::to_string(r.byte() % 6) : running;
        res.outcome = static_cast<em::RobotOutcome>(r.byte() % 4);
        res.duration_s = std::abs(r.value(1.0));
        res.progress = std::clamp(r.value(0.5), 0.0, 1.0);
        if (!std::isfinite(res.progress)) res.progress = 0.0;
        res.blocking_object_id = kObjects[r.byte() % 4];
        res.stamp_ns = stamp += r.byte();
        check(monitor.onRobotResult(res, now));
        break;
      }
      case 4:
        (void)monitor.onRobotRecord("c" + std::to_string(r.byte() % 6), "");
        break;
      default:
        check(monitor.onTick(now));
        break;
    }
  }
  return 0;
}
