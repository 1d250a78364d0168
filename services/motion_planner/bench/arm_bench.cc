// Arm motions near objects: planning time, and how many planned paths touch something between
// the planner's checked states, with and without the swept arm check (SamplingParams::
// arm_swept_step).
//
// For each graspable object of each scenario: stand poses from the planner's own grasp generator
// (sampled base poses), then fixed-seed random tool targets around the object (the tool towards
// it, turned up to 0.6 rad about z, up to 30 cm off). Per target: a full-mode arm motion from the
// scenario's start arm configuration to the target, and back (lazy mode too, timed only). Each
// solved full-mode path is re-checked in a scene built here (the scenario's truth, every object,
// the floor at z = 0) at 1 mrad of joint motion per step: a "clipped" path touches something
// between two states the planner checked, which a robot that sweeps its commanded motion at 1 cm
// (the simulator) stops before.
//
// Usage: tamp_motion_planner_arm_bench [--targets 12] [--seed 1] [--planners] [SCENARIO.yaml ...]
//   --planners: one row per arm planner (sampling.arm_planner and arm_full_planner both) at the
//   default swept step
//   default scenarios: config/scenarios/{namo_corridor_slippery,occluded_can,holding_start}.yaml
// Exits 2 on bad arguments, 1 when nothing was planned.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <numeric>
#include <optional>
#include <random>
#include <string>
#include <vector>

#include "tamp/collision/scene.h"
#include "tamp/core/paths.h"
#include "tamp/core/stats.h"
#include "tamp/motion_planner/motion_planner.h"
#include "tamp/robot/robot_model.h"
#include "tamp/world/scenario.h"

namespace mp = tamp::motion_planner;
using namespace tamp;

namespace {

struct Tally {
  std::vector<double> full_ms, lazy_ms, duration_s, length_rad;
  int requests = 0, solved = 0, clipped = 0, repaired = 0;
  std::string first_clip;
};

/// The first contact (object id, "floor" or "self") along `path`, re-checked densely.
std::string denseContact(collision::Scene& scene, const robot::RobotModel& model, const robot::RobotState& start,
                         const JointPath& path) {
  std::vector<Eigen::Isometry3d> poses;
  const auto& geo = model.collisionGeometry();
  for (std::size_t i = 0; i + 1 < path.waypoints.size(); ++i) {
    const auto& a = path.waypoints[i];
    const auto& b = path.waypoints[i + 1];
    double d = 0;
    for (std::size_t j = 0; j < a.size(); ++j) d = std::max(d, std::abs(b[j] - a[j]));
    const int n = std::max(1, static_cast<int>(std::ceil(d / 0.001)));
    for (int k = 1; k <= n; ++k) {
      std::vector<double> q(a.size());
      for (std::size_t j = 0; j < a.size(); ++j) q[j] = a[j] + (b[j] - a[j]) * k / n;
      auto s = model.fromJointValues(path.joint_names, q, start);
      if (!s.ok()) return "bad path: " + s.error().message;
      model.linkPoses(*s, poses);
      scene.setLinkPoses(poses);
      const auto hit = scene.robotCollisions();
      if (!hit.empty()) return hit.front();
      for (const auto& part : geo.parts) {
        if (part.link == 0) continue;  // the base stands on the floor
        if (part.shape.aabb(poses[static_cast<std::size_t>(part.link)] * part.link_T_shape).min.z() < -1e-4)
          return "floor";
      }
    }
  }
  return "";
}

double ms(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

void runScenario(const world::Scenario& sc, double swept_step, std::optional<mp::PlannerKind> arm_planner, int targets,
                 unsigned seed, Tally& t) {
  auto model = robot::RobotModel::loadDescription(sc.robot.description);
  if (!model.ok()) {
    std::fprintf(stderr, "%s: %s\n", sc.file.c_str(), model.error().toString().c_str());
    return;
  }
  mp::MotionPlannerParams params;
  params.sampling.arm_swept_step = swept_step;
  if (arm_planner) params.sampling.arm_planner = params.sampling.arm_full_planner = *arm_planner;
  mp::MotionPlanner planner(*model, params);
  const world::World view = sc.plannerWorld();
  planner.setWorld(view);
  collision::Scene check(sc.world);
  check.setRobot(model->collisionGeometry());
  robot::RobotState start = model->defaultState(sc.robot.start);
  if (!sc.robot.arm.empty()) start.arm = sc.robot.arm;
  start.gripper = sc.robot.gripper;
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> off(-0.30, 0.30), up(-0.05, 0.30), turn(-0.6, 0.6);
  for (const auto& o : view.objects()) {
    if (o.kind != world::ObjectKind::kMovable || !o.graspable || (view.held() && view.held()->object_id == o.id))
      continue;
    mp::GraspRequest g;
    g.object_id = o.id;
    g.start_arm = start.arm;
    g.max_grasps = 2;
    auto grasps = planner.generateGrasps(g, Termination::after(10.0));
    if (!grasps.ok() || grasps->empty()) continue;
    robot::RobotState at = start;
    at.base = grasps->front().base_pose;
    // The tool towards the object from the stand pose, level.
    const Eigen::Vector2d to = (o.pose.translation() - at.base.toIsometry().translation()).head<2>();
    const double yaw = std::atan2(to.y(), to.x());
    for (int i = 0; i < targets; ++i) {
      Eigen::Isometry3d target = Eigen::Isometry3d::Identity();
      target.translation() = o.pose.translation() + Eigen::Vector3d(off(rng), off(rng), up(rng));
      target.linear() = (Eigen::AngleAxisd(yaw + turn(rng), Eigen::Vector3d::UnitZ()) *
                         Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitY()))
                            .toRotationMatrix();
      mp::MotionRequest req;
      req.group = mp::PlanningGroup::kArm;
      req.mode = mp::MotionMode::kLazy;
      req.start = at;
      req.goal = mp::MotionGoal::endEffectorGoal(target);
      auto t0 = std::chrono::steady_clock::now();
      const auto lazy = planner.plan(req, Termination::after(5.0));
      if (lazy.ok()) t.lazy_ms.push_back(ms(t0));
      req.mode = mp::MotionMode::kFull;
      for (int leg = 0; leg < 2; ++leg) {
        ++t.requests;
        t0 = std::chrono::steady_clock::now();
        const auto r = planner.plan(req, Termination::after(5.0));
        const double took = ms(t0);
        if (!r.ok()) break;
        ++t.solved;
        if (r.stats.swept_repairs > 0) ++t.repaired;
        t.full_ms.push_back(took);
        t.duration_s.push_back(r.trajectory.duration());
        t.length_rad.push_back(r.path_length);
        const std::string hit = denseContact(check, *model, req.start, r.path);
        if (!hit.empty() && ++t.clipped == 1)
          t.first_clip = sc.name + " '" + o.id + "' target " + std::to_string(i) + (leg ? " back" : " out") + ": " + hit;
        // Back to the start configuration from where the path ended.
        auto end = model->fromJointValues(r.path.joint_names, r.path.waypoints.back(), at);
        if (!end.ok()) break;
        req.start = *end;
        req.goal = mp::MotionGoal::configurationGoal(at.arm);
      }
    }
  }
}

}  // namespace

int main(int argc, char** argv) {
  int targets = 12;
  unsigned seed = 1;
  bool planners = false;
  std::vector<std::string> files;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--planners") {
      planners = true;
    } else if ((a == "--targets" || a == "--seed") && i + 1 < argc) {
      const int v = std::atoi(argv[++i]);
      if (v < 1) {
        std::fprintf(stderr, "%s must be a positive integer\n", a.c_str());
        return 2;
      }
      if (a == "--targets") targets = v;
      else seed = static_cast<unsigned>(v);
    } else if (!a.empty() && a[0] == '-') {
      std::fprintf(stderr, "unknown option %s\nusage: %s [--targets N] [--seed S] [--planners] [SCENARIO.yaml ...]\n", a.c_str(), argv[0]);
      return 2;
    } else {
      files.push_back(a);
    }
  }
  if (files.empty()) {
    for (const char* n : {"namo_corridor_slippery", "occluded_can", "holding_start"})
      files.push_back((configDir() / "scenarios" / (std::string(n) + ".yaml")).string());
  }
  std::vector<world::Scenario> scenarios;
  for (const auto& f : files) {
    auto sc = world::loadScenario(f);
    if (!sc.ok()) {
      std::fprintf(stderr, "%s\n", sc.error().toString().c_str());
      return 2;
    }
    scenarios.push_back(std::move(*sc));
  }
  // The rows: the swept check off and on (default), or with --planners each arm planner at the
  // default swept step.
  struct Row {
    std::string label;
    double step;
    std::optional<mp::PlannerKind> planner;  // both modes; none: the defaults
  };
  const mp::SamplingParams defaults;
  std::vector<Row> rows;
  if (planners) {
    // Not LBKPIECE1: in joint space its trees grow deep, and OMPL 1.5's recursive
    // LBKPIECE1::removeMotion overflowed the stack here (namo_corridor_slippery, 20 targets).
    for (auto k : {mp::PlannerKind::kKpiece, mp::PlannerKind::kRrtConnect})
      rows.push_back({std::string(mp::toString(k)), defaults.arm_swept_step, k});
    rows.push_back({"defaults: lazy " + std::string(mp::toString(defaults.arm_planner)) + ", full " +
                        std::string(mp::toString(defaults.arm_full_planner)),
                    defaults.arm_swept_step, std::nullopt});
  } else {
    rows = {{"off", 0.0, std::nullopt}, {"0.01 m", 0.01, std::nullopt}, {"0.0025 m", 0.0025, std::nullopt}};
  }
  std::printf("| %s | full requests | solved | re-planned segments in | clipped | full median ms | full p95 ms | full max ms | lazy median ms | lazy p95 ms | trajectory median / total s | path median / total rad |\n",
              planners ? "arm_planner" : "arm_swept_step");
  std::printf("|---|---|---|---|---|---|---|---|---|---|---|---|\n");
  int solved = 0;
  for (const Row& row : rows) {
    Tally t;
    for (const auto& sc : scenarios) runScenario(sc, row.step, row.planner, targets, seed, t);
    solved += t.solved;
    auto pct = [](const std::vector<double>& v, double q) { return v.empty() ? 0.0 : interpolatedPercentile(v, q); };
    auto sum = [](const std::vector<double>& v) { return std::accumulate(v.begin(), v.end(), 0.0); };
    std::printf("| %s | %d | %d | %d | %d | %.1f | %.1f | %.1f | %.1f | %.1f | %.2f / %.1f | %.2f / %.1f |\n", row.label.c_str(),
                t.requests, t.solved, t.repaired, t.clipped, pct(t.full_ms, 0.5), pct(t.full_ms, 0.95), pct(t.full_ms, 1.0),
                pct(t.lazy_ms, 0.5), pct(t.lazy_ms, 0.95), pct(t.duration_s, 0.5), sum(t.duration_s), pct(t.length_rad, 0.5),
                sum(t.length_rad));
    if (!t.first_clip.empty()) std::printf("  first clipped path: %s\n", t.first_clip.c_str());
  }
  if (solved == 0) {
    std::fprintf(stderr, "no arm motion was planned\n");
    return 1;
  }
  return 0;
}
