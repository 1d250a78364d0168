// tamp_perception_bench: perception time per cloud (by stage) for ~50k, ~300k and ~1M-point
// frames, and detection recall + pose error against the ground truth over scenes rendered by
// the simulator's depth camera. Prints Markdown tables (docs/benchmarks.md, "Perception").
//
//   tamp_perception_bench [--frames N] [--size 50k|300k|1M] [--timing-only | --accuracy-only | --scenarios-only]
//                         [--scenarios DIR] [--robot hidden|seen|filtered]
//
// Timing: a furnished room (static walls and table in the prior, 10 objects to find), frames
// pre-rendered (not timed) from a robot turning on the spot; 3 warm-up frames, then N timed.
// Accuracy: per scene, the prior is the static map only (every movable object must be found);
// each scene is run twice, with the object classes known (sizes from the scenario's objects) and
// without (size thresholds only). Ground truth objects count when the camera saw >= 100 pixels
// of them in some frame; a perceived object matches a ground-truth one within 0.15 m (Hungarian).
// Shipped scenarios (config/scenarios/*.yaml, or DIR): the truth is the scenario's world (hidden
// objects and objects that scripted faults make appear included); the robot's own camera (URDF
// `camera_optical_frame`, the simulator's default sensor: 320 x 240, noise on) looks from its
// start pose and from every named location, turning on the spot (yaw -0.55, 0, +0.55 rad),
// 3 frames per view. The prior is the static map; the held object is not counted. Matching and
// xy error use bounding-box centres (a NAMO prism's pose origin is not its centre).
// --robot: in the shipped scenarios the camera does not see the robot (`hidden`, the default and
// the simulator's default `see_robot: false`), sees it and perception gets no robot state
// (`seen`), or sees it and perception gets the robot's body and held object at each frame's
// state (`filtered`, self_filter.h).
// Diagnostics on stderr: TAMP_BENCH_VERBOSE=1 lists false and missed objects, TAMP_BENCH_PLANES=1
// the support planes of every accuracy frame.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <filesystem>
#include <map>
#include <numbers>
#include <string>
#include <vector>

#include "tamp/core/stats.h"
#include "tamp/core/termination.h"
#include "tamp/perception/assignment.h"
#include "tamp/perception/perception.h"
#include "tamp/sim/depth_sensor.h"
#include "tamp/sim/setup.h"
#include "tamp/world/scenario.h"
#include "test_scenes.h"

namespace tp = tamp::perception;
namespace tw = tamp::world;
using tamp::perception::testing::box;
using tamp::perception::testing::cylinder;

namespace {

constexpr double kPi = std::numbers::pi;

/// 0 for no samples (tables print 0, not nan).
double quantile(const std::vector<double>& v, double q) { return v.empty() ? 0.0 : tamp::interpolatedPercentile(v, q); }

tw::Object staticBox(const std::string& id, double sx, double sy, double sz, double x, double y, double yaw = 0.0) {
  return box(id, sx, sy, sz, x, y, yaw, 0.0, tw::ObjectKind::kStatic);
}

/// A 7 x 6 m room: walls, a table with two objects on it, eight objects on the floor.
tw::World room() {
  tw::World w("room");
  (void)w.addRegion(tamp::perception::testing::floorRegion());
  (void)w.addRegion(tw::Region{"table_top", "table", tw::RegionKind::kTable,
                               {{2.9, 1.0}, {4.1, 1.0}, {4.1, 1.8}, {2.9, 1.8}}, 0.75});
  (void)w.addObject(staticBox("wall_n", 7.0, 0.1, 1.5, 2.5, 3.0));
  (void)w.addObject(staticBox("wall_s", 7.0, 0.1, 1.5, 2.5, -3.0));
  (void)w.addObject(staticBox("wall_e", 0.1, 6.0, 1.5, 6.0, 0.0));
  (void)w.addObject(staticBox("table", 1.2, 0.8, 0.75, 3.5, 1.4));
  (void)w.addObject(box("crate_a", 0.4, 0.4, 0.3, 2.2, -0.8, 0.3));
  (void)w.addObject(box("crate_b", 0.4, 0.4, 0.3, 4.2, -1.2, -0.2));
  (void)w.addObject(box("parcel_a", 0.3, 0.2, 0.25, 1.7, 0.2, 0.9));
  (void)w.addObject(box("parcel_b", 0.3, 0.2, 0.25, 3.0, -0.2, 0.1));
  (void)w.addObject(box("cabinet", 0.6, 0.5, 1.0, 5.2, 1.0, 0.0));
  (void)w.addObject(cylinder("bin", 0.15, 0.5, 2.6, 0.6));
  (void)w.addObject(cylinder("bucket", 0.12, 0.3, 3.6, -2.0));
  (void)w.addObject(cylinder("post", 0.08, 0.9, 4.6, 0.3));
  (void)w.addObject(cylinder("can", 0.04, 0.12, 3.2, 1.3, 0.75));
  (void)w.addObject(box("book", 0.2, 0.15, 0.05, 3.8, 1.5, 0.4, 0.75));
  return w;
}

/// A cluttered store room seen from two sides: objects hiding each other.
tw::World storeRoom() {
  tw::World w("store_room");
  (void)w.addRegion(tamp::perception::testing::floorRegion());
  (void)w.addObject(staticBox("shelf", 0.4, 2.0, 1.8, 4.5, 0.0));
  const double yaws[] = {0.0, 0.3, -0.4, 0.7, 0.2, -0.1};
  int k = 0;
  for (double x : {2.0, 2.8, 3.5}) {
    for (double y : {-0.7, 0.6}) {
      const std::string id = "box_" + std::to_string(k);
      (void)w.addObject(box(id, 0.35, 0.25, 0.3 + 0.05 * (k % 3), x, y + 0.1 * (k % 2), yaws[k]));
      ++k;
    }
  }
  (void)w.addObject(cylinder("drum_0", 0.2, 0.6, 2.4, -1.6));
  (void)w.addObject(cylinder("drum_1", 0.2, 0.6, 3.2, 1.7));
  return w;
}

/// Tables with small things on them (cans, boxes), as in the pick-and-place scenarios.
tw::World tableTops() {
  tw::World w("table_tops");
  (void)w.addRegion(tamp::perception::testing::floorRegion());
  (void)w.addRegion(tw::Region{"table_1", "table", tw::RegionKind::kTable,
                               {{1.6, -0.9}, {2.4, -0.9}, {2.4, 0.3}, {1.6, 0.3}}, 0.75});
  (void)w.addRegion(tw::Region{"table_2", "table", tw::RegionKind::kTable,
                               {{2.0, 0.8}, {3.2, 0.8}, {3.2, 1.6}, {2.0, 1.6}}, 0.72});
  (void)w.addObject(staticBox("table_1", 0.8, 1.2, 0.75, 2.0, -0.3));
  (void)w.addObject(staticBox("table_2", 1.2, 0.8, 0.72, 2.6, 1.2));
  (void)w.addObject(cylinder("can_0", 0.04, 0.12, 1.8, -0.6, 0.75));
  (void)w.addObject(cylinder("can_1", 0.04, 0.12, 2.1, 0.0, 0.75));
  (void)w.addObject(cylinder("mug", 0.05, 0.1, 1.9, -0.2, 0.75));
  (void)w.addObject(box("cereal", 0.2, 0.07, 0.3, 2.2, -0.7, 0.5, 0.75));
  (void)w.addObject(box("tray", 0.4, 0.3, 0.06, 2.5, 1.1, 0.2, 0.72));
  (void)w.addObject(box("kettle_box", 0.2, 0.2, 0.25, 2.9, 1.35, -0.3, 0.72));
  (void)w.addObject(box("crate", 0.4, 0.4, 0.3, 1.2, 1.0, 0.6));
  return w;
}

/// The static map of a world (what perception starts from in the accuracy runs).
tw::World staticMap(const tw::World& truth) {
  tw::World w = truth.plannerView();
  std::vector<std::string> movable;
  for (const auto& o : w.objects()) {
    if (o.kind == tw::ObjectKind::kMovable) movable.push_back(o.id);
  }
  for (const auto& id : movable) (void)w.removeObject(id);
  return w;
}

/// CPU time of the calling thread, ms.
double threadCpuMs() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) * 1e3 + static_cast<double>(ts.tv_nsec) * 1e-6;
}

// ---- timing -----------------------------------------------------------------------------------

struct SizeSpec {
  const char* name;
  int width, height;
};

void runTiming(int frames, const std::string& only) {
  const tw::World truth = room();
  const tw::World prior = staticMap(truth);
  std::printf("\n### Time per cloud (ms), room scene, %d timed frames after 3 warm-up frames\n\n", frames);
  std::printf("| cloud | points (valid / cropped / voxels) | validate | transform+crop | voxel grid | planes | static map | clustering | fitting | association+tracking | visibility | occupancy | **total p50** | total p90 | max | CPU p50 |\n");
  std::printf("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n");
  const SizeSpec sizes[] = {{"50k", 256, 196}, {"300k", 640, 480}, {"1M", 1152, 864}};
  for (const auto& s : sizes) {
    if (!only.empty() && only != s.name) continue;
    tamp::perception::testing::Camera cam;
    cam.width = s.width;
    cam.height = s.height;
    std::vector<tamp::PointCloudFrame> clouds;
    for (int k = 0; k < frames + 3; ++k) {
      const double yaw = 0.25 * std::sin(0.7 * k);
      clouds.push_back(tamp::perception::testing::render(truth, tamp::perception::testing::mastCamera(0.3, 0.0, yaw), cam,
                                                         1'000'000'000LL + k * 100'000'000LL, static_cast<std::uint64_t>(k)));
    }
    tp::PerceptionParams params;
    params.classes = tp::classesFromWorld(truth);
    tp::Perception perception(prior, params);
    std::map<std::string, std::vector<double>> t;
    std::vector<double> valid, cropped, voxels;
    std::vector<double> cpu;
    for (int k = 0; k < frames + 3; ++k) {
      const double cpu0 = threadCpuMs();
      auto r = perception.processFrame(clouds[static_cast<std::size_t>(k)]);
      const double cpu_ms = threadCpuMs() - cpu0;
      if (!r) {
        std::fprintf(stderr, "frame failed: %s\n", r.error().toString().c_str());
        std::exit(1);
      }
      if (k < 3) continue;
      cpu.push_back(cpu_ms);
      const auto& T = r->times;
      t["validate"].push_back(T.validate);
      t["crop"].push_back(T.transform_crop);
      t["voxel"].push_back(T.voxel);
      t["planes"].push_back(T.planes);
      t["static"].push_back(T.static_objects);
      t["cluster"].push_back(T.clustering);
      t["fit"].push_back(T.fitting);
      t["track"].push_back(T.tracking);
      t["vis"].push_back(T.visibility);
      t["occ"].push_back(T.occupancy);
      t["total"].push_back(T.total);
      valid.push_back(static_cast<double>(r->stats.valid_points));
      cropped.push_back(static_cast<double>(r->stats.cropped_points));
      voxels.push_back(static_cast<double>(r->stats.voxel_points));
    }
    std::printf("| %s (%dx%d = %d) | %.0f / %.0f / %.0f |", s.name, s.width, s.height, s.width * s.height, quantile(valid, 0.5),
                quantile(cropped, 0.5), quantile(voxels, 0.5));
    for (const char* k : {"validate", "crop", "voxel", "planes", "static", "cluster", "fit", "track", "vis", "occ"}) {
      std::printf(" %.2f |", quantile(t[k], 0.5));
    }
    std::printf(" **%.1f** | %.1f | %.1f | %.1f |\n", quantile(t["total"], 0.5), quantile(t["total"], 0.9),
                *std::max_element(t["total"].begin(), t["total"].end()), quantile(cpu, 0.5));
    std::fflush(stdout);
  }
  std::printf("\nStage columns are medians of wall-clock time; CPU p50 is the median thread CPU time of a frame "
              "(insensitive to other load on the machine).\n");
}

// ---- accuracy ---------------------------------------------------------------------------------

/// seen[id] = the most pixels object `id` covered in any view so far (ground truth: which objects
/// are in view at all).
void keepMostPixels(const tamp::sim::GroundTruthLabels& labels, std::map<std::string, int>& seen) {
  std::map<int, int> count;
  for (auto l : labels.pixel) {
    if (l >= 0) ++count[l];
  }
  for (const auto& [l, n] : count) {
    const std::string& id = labels.ids[static_cast<std::size_t>(l)];
    seen[id] = std::max(seen[id], n);
  }
}

/// TAMP_BENCH_VERBOSE: the perceived objects no ground-truth object was assigned to.
void printFalseObjects(const std::string& where, const std::vector<const tw::Object*>& found,
                       const std::vector<int>& assign) {
  std::vector<char> used(found.size(), 0);
  for (auto a : assign) {
    if (a >= 0) used[static_cast<std::size_t>(a)] = 1;
  }
  for (std::size_t j = 0; j < found.size(); ++j) {
    if (used[j]) continue;
    const auto b = found[j]->aabb();
    std::fprintf(stderr, "  %s: false %s (%s) at (%.2f, %.2f) box (%.2f..%.2f, %.2f..%.2f, %.2f..%.2f)\n", where.c_str(),
                 found[j]->id.c_str(), found[j]->label.c_str(), found[j]->pose.translation().x(),
                 found[j]->pose.translation().y(), b.min.x(), b.max.x(), b.min.y(), b.max.y(), b.min.z(), b.max.z());
  }
}

struct Scene {
  std::string name;
  tw::World truth;
  std::vector<Eigen::Isometry3d> views;
};

struct Tally {
  int truth{0}, found{0}, perceived{0}, false_pos{0};
  std::vector<double> xy, z, yaw;
};

/// Runs one scene; returns the tally and prints a line.
Tally runScene(const Scene& scene, bool with_classes, int frames_per_view) {
  tp::PerceptionParams params;
  if (with_classes) params.classes = tp::classesFromWorld(scene.truth);
  const tw::World prior = staticMap(scene.truth);
  tp::Perception perception(prior, params);
  tamp::perception::testing::Camera cam;
  cam.width = 640;
  cam.height = 480;
  // Ground truth: movable objects of which the camera saw >= 100 pixels in some view.
  std::map<std::string, int> seen;
  {
    tamp::sim::DepthSensorParams quiet;
    quiet.width = cam.width;
    quiet.height = cam.height;
    quiet.noise_stddev_m = quiet.noise_quadratic = quiet.dropout_probability = 0.0;
    tamp::sim::DepthSensor sensor(quiet);
    for (const auto& v : scene.views) {
      tamp::sim::GroundTruthLabels labels;
      (void)sensor.capture(scene.truth, v, 0, &labels);
      keepMostPixels(labels, seen);
    }
  }
  int64_t stamp = 1'000'000'000;
  std::uint64_t index = 0;
  for (const auto& v : scene.views) {
    for (int k = 0; k < frames_per_view; ++k) {
      auto r = perception.processFrame(tamp::perception::testing::render(scene.truth, v, cam, stamp, index++));
      stamp += 200'000'000;
      if (r && std::getenv("TAMP_BENCH_PLANES") != nullptr) {
        for (const auto& pl : r->planes) {
          std::fprintf(stderr, "  %s frame %llu: plane '%s' h %.3f area %.2f inliers %d\n", scene.name.c_str(),
                       static_cast<unsigned long long>(index), pl.region.c_str(), pl.height, pl.area, pl.inliers);
        }
      }
      if (!r) {
        std::fprintf(stderr, "%s: %s\n", scene.name.c_str(), r.error().toString().c_str());
        std::exit(1);
      }
    }
  }
  std::vector<const tw::Object*> gt, found;
  for (const auto& o : scene.truth.objects()) {
    if (o.kind == tw::ObjectKind::kMovable && seen[o.id] >= 100) gt.push_back(&o);
  }
  for (const auto& o : perception.world().objects()) {
    if (prior.findObject(o.id) == nullptr) found.push_back(&o);
  }
  std::vector<std::vector<double>> cost(gt.size(), std::vector<double>(found.size(), INFINITY));
  for (std::size_t i = 0; i < gt.size(); ++i) {
    for (std::size_t j = 0; j < found.size(); ++j) {
      const double d = (gt[i]->pose.translation().head<2>() - found[j]->pose.translation().head<2>()).norm();
      if (d <= 0.15) cost[i][j] = d;
    }
  }
  const auto assign = tp::solveAssignment(cost);
  Tally t;
  t.truth = static_cast<int>(gt.size());
  t.perceived = static_cast<int>(found.size());
  std::string missed;
  for (std::size_t i = 0; i < gt.size(); ++i) {
    if (assign[i] < 0) {
      missed += " " + gt[i]->id;
      continue;
    }
    ++t.found;
    const tw::Object& f = *found[static_cast<std::size_t>(assign[i])];
    const tp::PoseError e = tp::poseError(gt[i]->shape, gt[i]->pose, f.pose);
    t.xy.push_back(e.xy);
    t.z.push_back(e.z);
    if (std::getenv("TAMP_BENCH_VERBOSE") != nullptr)
      std::fprintf(stderr, "%s %s: truth (%.3f, %.3f) perceived %s (%.3f, %.3f) size %.2f x %.2f: xy error %.3f m\n",
                   scene.name.c_str(), gt[i]->id.c_str(), gt[i]->pose.translation().x(), gt[i]->pose.translation().y(),
                   f.id.c_str(), f.pose.translation().x(), f.pose.translation().y(), f.shape.size.x(), f.shape.size.y(), e.xy);
    if (tp::yawSymmetry(gt[i]->shape) > 0) t.yaw.push_back(e.yaw);
  }
  t.false_pos = t.perceived - t.found;
  if (std::getenv("TAMP_BENCH_VERBOSE") != nullptr) printFalseObjects(scene.name, found, assign);

  std::printf("| %s | %s | %zu | %d | %d / %d | %d | %.3f / %.3f / %.3f | %.1f / %.1f | %s |\n", scene.name.c_str(),
              with_classes ? "known" : "none", scene.views.size() * static_cast<std::size_t>(frames_per_view), t.truth,
              t.found, t.truth, t.false_pos, quantile(t.xy, 0.5), quantile(t.xy, 0.9),
              t.xy.empty() ? 0.0 : *std::max_element(t.xy.begin(), t.xy.end()), quantile(t.yaw, 0.5) * 180 / kPi,
              quantile(t.yaw, 0.9) * 180 / kPi, missed.empty() ? "-" : missed.c_str());
  std::fflush(stdout);
  return t;
}

void runAccuracy() {
  using tamp::perception::testing::mastCamera;
  std::vector<Scene> scenes;
  scenes.push_back({"room", room(), {mastCamera(0.3, 0, 0), mastCamera(0.3, 0, 0.45), mastCamera(0.3, 0, -0.45),
                                     mastCamera(2.0, -2.2, 0.6), mastCamera(2.0, 2.2, -0.7)}});
  scenes.push_back({"store_room", storeRoom(), {mastCamera(0.5, 0, 0), mastCamera(2.7, -2.6, kPi / 2),
                                                 mastCamera(2.7, 2.6, -kPi / 2)}});
  scenes.push_back({"table_tops", tableTops(), {mastCamera(0.6, -0.3, 0), mastCamera(1.3, 2.6, -1.0),
                                                 mastCamera(0.4, 0.8, 0.1)}});
  std::printf("\n### Detection recall and pose error (640x480 frames, 2 frames per view)\n\n");
  std::printf("| scene | classes | frames | objects seen | found | false objects | xy error p50 / p90 / max (m) | yaw error p50 / p90 (deg) | missed |\n");
  std::printf("|---|---|---|---|---|---|---|---|---|\n");
  for (bool classes : {true, false}) {
    Tally all;
    for (const auto& s : scenes) {
      const Tally t = runScene(s, classes, 2);
      all.truth += t.truth;
      all.found += t.found;
      all.false_pos += t.false_pos;
      all.xy.insert(all.xy.end(), t.xy.begin(), t.xy.end());
      all.yaw.insert(all.yaw.end(), t.yaw.begin(), t.yaw.end());
    }
    std::printf("| **all** | %s | | %d | **%d / %d (%.0f %%)** | %d | %.3f / %.3f / %.3f | %.1f / %.1f | |\n", classes ? "known" : "none",
                all.truth, all.found, all.truth, 100.0 * all.found / std::max(all.truth, 1), all.false_pos,
                quantile(all.xy, 0.5), quantile(all.xy, 0.9), all.xy.empty() ? 0.0 : *std::max_element(all.xy.begin(), all.xy.end()),
                quantile(all.yaw, 0.5) * 180 / kPi, quantile(all.yaw, 0.9) * 180 / kPi);
  }
}

// ---- shipped scenarios ------------------------------------------------------------------------

struct ScenarioTally {
  int truth{0}, found{0}, false_pos{0}, small{0};
  std::vector<double> xy, z, yaw;
};

/// One scenario file: prints a table row per class mode; returns false when it has no object in
/// view (no row).
/// Centre of an object's bounding box in the plane (boxes and cylinders: the pose's xy).
Eigen::Vector2d centreXY(const tw::Object& o) {
  const auto b = o.aabb();
  return 0.5 * (b.min + b.max).head<2>();
}

enum class RobotView { kHidden, kSeen, kFiltered };
RobotView g_robot_view = RobotView::kHidden;

bool runScenarioFile(const std::filesystem::path& file, bool with_classes, ScenarioTally& all) {
  auto scenario = tamp::world::loadScenario(file);
  if (!scenario) {
    std::fprintf(stderr, "%s: %s\n", file.string().c_str(), scenario.error().toString().c_str());
    std::exit(1);
  }
  auto setup = tamp::sim::setupFromScenario(*scenario);
  if (!setup) {
    std::fprintf(stderr, "%s: %s\n", file.string().c_str(), setup.error().toString().c_str());
    std::exit(1);
  }
  tw::World truth = setup->world;
  int appearing = 0;
  for (const auto& f : scenario->faults) {
    if (f.kind == tamp::world::FaultKind::kObjectAppears && f.object && truth.findObject(f.object->id) == nullptr) {
      tw::Object o = *f.object;
      o.hidden = false;
      if (truth.addObject(o)) ++appearing;
    }
  }
  const std::string held = truth.held() ? truth.held()->object_id : std::string();
  // Views: the start pose and every named location, turning on the spot.
  std::vector<tamp::robot::RobotState> views;
  std::vector<tamp::Pose2D> bases{setup->initial.base};
  for (const auto& l : truth.locations()) bases.push_back(l.pose);
  for (const auto& b : bases) {
    for (double dyaw : {0.0, -0.55, 0.55}) {
      tamp::robot::RobotState s = setup->initial;
      s.base = b;
      s.base.theta += dyaw;
      views.push_back(s);
    }
  }
  tamp::sim::DepthSensorParams sensor_params;  // the simulator's default sensor (config/services/sim.yaml)
  sensor_params.see_robot = g_robot_view != RobotView::kHidden;
  std::map<std::string, int> seen;
  {
    tamp::sim::DepthSensorParams quiet = sensor_params;
    quiet.noise_stddev_m = quiet.noise_quadratic = quiet.dropout_probability = 0.0;
    tamp::sim::DepthSensor sensor(quiet);
    for (const auto& v : views) {
      tamp::sim::GroundTruthLabels labels;
      (void)sensor.capture(truth, setup->robot, v, 0, &labels);
      keepMostPixels(labels, seen);
    }
  }
  std::vector<const tw::Object*> gt;
  int small = 0;
  for (const auto& o : truth.objects()) {
    if (o.kind != tw::ObjectKind::kMovable || o.id == held) continue;
    if (seen[o.id] >= 100) {
      gt.push_back(&o);
    } else if (seen[o.id] > 0) {
      ++small;
    }
  }
  if (gt.empty()) return false;

  tp::PerceptionParams params;
  if (with_classes) params.classes = tp::classesFromWorld(truth);
  const tw::World prior = staticMap(truth);
  tp::Perception perception(prior, params);
  tamp::sim::DepthSensor sensor(sensor_params);
  int64_t stamp = 1'000'000'000;
  constexpr int kFramesPerView = 3;
  for (const auto& v : views) {
    for (int k = 0; k < kFramesPerView; ++k) {
      const tp::RobotBody body = tp::robotBodyAt(setup->robot, v, held, stamp);
      auto r = perception.processFrame(sensor.capture(truth, setup->robot, v, stamp), tamp::Termination(),
                                       g_robot_view == RobotView::kFiltered ? &body : nullptr);
      stamp += 500'000'000;
      if (!r) {
        std::fprintf(stderr, "%s: %s\n", scenario->name.c_str(), r.error().toString().c_str());
        std::exit(1);
      }
    }
  }
  // Candidates: the counted objects plus the held one (a detection of it is not a false object).
  std::vector<const tw::Object*> candidates = gt;
  if (!held.empty() && truth.findObject(held) != nullptr) candidates.push_back(truth.findObject(held));
  std::vector<const tw::Object*> found;
  for (const auto& o : perception.world().objects()) {
    if (prior.findObject(o.id) == nullptr) found.push_back(&o);
  }
  std::vector<std::vector<double>> cost(candidates.size(), std::vector<double>(found.size(), INFINITY));
  for (std::size_t i = 0; i < candidates.size(); ++i) {
    for (std::size_t j = 0; j < found.size(); ++j) {
      const double d = (centreXY(*candidates[i]) - centreXY(*found[j])).norm();
      if (d <= 0.15) cost[i][j] = d;
    }
  }
  const auto assign = tp::solveAssignment(cost);
  ScenarioTally t;
  t.truth = static_cast<int>(gt.size());
  t.small = small;
  int matched = 0;
  std::string missed;
  for (std::size_t i = 0; i < candidates.size(); ++i) {
    if (assign[i] >= 0) ++matched;
    if (i >= gt.size()) continue;  // the held object
    if (assign[i] < 0) {
      missed += " " + gt[i]->id;
      continue;
    }
    ++t.found;
    const tw::Object& f = *found[static_cast<std::size_t>(assign[i])];
    const tp::PoseError e = tp::poseError(gt[i]->shape, gt[i]->pose, f.pose);
    t.xy.push_back((centreXY(*gt[i]) - centreXY(f)).norm());  // prisms: pose origin != centre
    t.z.push_back(e.z);
    if (tp::yawSymmetry(gt[i]->shape) > 0 && tp::yawSymmetry(gt[i]->shape) < 2 * kPi - 1e-9) t.yaw.push_back(e.yaw);
  }
  t.false_pos = static_cast<int>(found.size()) - matched;
  if (std::getenv("TAMP_BENCH_VERBOSE") != nullptr) printFalseObjects(scenario->name, found, assign);

  std::string hidden;
  for (const auto* o : gt) {
    if (o->hidden) hidden += " " + o->id;
  }
  std::printf("| %s | %s | %zu | %d%s | %d / %d | %d | %.3f / %.3f | %.3f | %.1f / %.1f | %s |\n", scenario->name.c_str(),
              with_classes ? "known" : "none", views.size() * kFramesPerView, t.truth,
              (hidden.empty() && appearing == 0) ? "" : " (incl. hidden/appearing)", t.found, t.truth, t.false_pos,
              quantile(t.xy, 0.5), t.xy.empty() ? 0.0 : *std::max_element(t.xy.begin(), t.xy.end()),
              t.z.empty() ? 0.0 : *std::max_element(t.z.begin(), t.z.end()), quantile(t.yaw, 0.5) * 180 / kPi,
              t.yaw.empty() ? 0.0 : *std::max_element(t.yaw.begin(), t.yaw.end()) * 180 / kPi,
              missed.empty() ? "-" : missed.c_str());
  std::fflush(stdout);
  all.truth += t.truth;
  all.found += t.found;
  all.false_pos += t.false_pos;
  all.small += t.small;
  all.xy.insert(all.xy.end(), t.xy.begin(), t.xy.end());
  all.z.insert(all.z.end(), t.z.begin(), t.z.end());
  all.yaw.insert(all.yaw.end(), t.yaw.begin(), t.yaw.end());
  return true;
}

void runScenarios(const std::filesystem::path& dir) {
  std::vector<std::filesystem::path> files;
  for (const auto& e : std::filesystem::directory_iterator(dir)) {
    if (e.path().extension() == ".yaml") files.push_back(e.path());
  }
  std::sort(files.begin(), files.end());
  const char* robot = g_robot_view == RobotView::kHidden ? "robot not rendered"
                      : g_robot_view == RobotView::kSeen ? "robot rendered, no robot state"
                                                         : "robot rendered, filtered by its state";
  std::printf("\n### Shipped scenarios (%s): robot camera 320x240, start + every location x 3 headings, 3 frames per view, %s\n\n",
              dir.string().c_str(), robot);
  std::printf("| scenario | classes | frames | movable objects in view (>= 100 px) | found | false objects | xy error p50 / max (m) | z error max (m) | yaw error p50 / max (deg) | missed |\n");
  std::printf("|---|---|---|---|---|---|---|---|---|---|\n");
  std::vector<std::string> skipped;
  for (bool classes : {true, false}) {
    ScenarioTally all;
    for (const auto& f : files) {
      if (!runScenarioFile(f, classes, all) && classes) skipped.push_back(f.stem().string());
    }
    std::printf("| **all** | %s | | %d | **%d / %d (%.0f %%)** | %d | %.3f / %.3f | %.3f | %.1f / %.1f | |\n", classes ? "known" : "none",
                all.truth, all.found, all.truth, 100.0 * all.found / std::max(all.truth, 1), all.false_pos, quantile(all.xy, 0.5),
                all.xy.empty() ? 0.0 : *std::max_element(all.xy.begin(), all.xy.end()),
                all.z.empty() ? 0.0 : *std::max_element(all.z.begin(), all.z.end()), quantile(all.yaw, 0.5) * 180 / kPi,
                all.yaw.empty() ? 0.0 : *std::max_element(all.yaw.begin(), all.yaw.end()) * 180 / kPi);
    if (classes) {
      std::printf("| | | | (%d more movable objects seen with < 100 px, not counted) | | | | | | |\n", all.small);
    }
  }
  std::string list;
  for (const auto& s : skipped) list += (list.empty() ? "" : ", ") + s;
  std::printf("\nNo movable object in view (no row): %s.\n", list.empty() ? "none" : list.c_str());
}

}  // namespace

int main(int argc, char** argv) {
  int frames = 20;
  bool timing = true, accuracy = true, scenarios = true;
  std::string only_size;  // "50k", "300k" or "1M": time that size only
  std::filesystem::path scenario_dir = std::filesystem::path(TAMP_SOURCE_DIR) / "config" / "scenarios";
  for (int i = 1; i < argc; ++i) {
    if (!std::strcmp(argv[i], "--frames") && i + 1 < argc) {
      frames = std::max(1, std::atoi(argv[++i]));
    } else if (!std::strcmp(argv[i], "--size") && i + 1 < argc) {
      only_size = argv[++i];
    } else if (!std::strcmp(argv[i], "--timing-only")) {
      accuracy = scenarios = false;
    } else if (!std::strcmp(argv[i], "--accuracy-only")) {
      timing = scenarios = false;
    } else if (!std::strcmp(argv[i], "--scenarios-only")) {
      timing = accuracy = false;
    } else if (!std::strcmp(argv[i], "--scenarios") && i + 1 < argc) {
      scenario_dir = argv[++i];
    } else if (!std::strcmp(argv[i], "--robot") && i + 1 < argc && !std::strcmp(argv[i + 1], "hidden")) {
      g_robot_view = RobotView::kHidden;
      ++i;
    } else if (!std::strcmp(argv[i], "--robot") && i + 1 < argc && !std::strcmp(argv[i + 1], "seen")) {
      g_robot_view = RobotView::kSeen;
      ++i;
    } else if (!std::strcmp(argv[i], "--robot") && i + 1 < argc && !std::strcmp(argv[i + 1], "filtered")) {
      g_robot_view = RobotView::kFiltered;
      ++i;
    } else {
      std::fprintf(stderr, "usage: %s [--frames N] [--size 50k|300k|1M] [--timing-only | --accuracy-only | --scenarios-only] [--scenarios DIR] [--robot hidden|seen|filtered]\n",
                   argv[0]);
      return 2;
    }
  }
  if (timing) runTiming(frames, only_size);
  if (accuracy) runAccuracy();
  if (scenarios) runScenarios(scenario_dir);
  return 0;
}
