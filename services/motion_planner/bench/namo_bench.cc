// NAMO benchmark of the motion planner (issue 7), with the setup conventions of
// tests/data/benchmarks/namo/REFERENCE.md so that figures are comparable:
//  - worlds: every bare moghaddam_planning_2016_benchmark_NN.svg (robot square side 0.5 m, disc of
//    its circumradius 0.354 m, yaw free, goal within 1 cm in x, y) and the JSON worlds (disc of
//    the robot's circumradius); loaded by tamp::world::loadNamo;
//  - OMPL baselines: geometric RRTConnect, KPIECE1, LBKPIECE1 with default parameters (KPIECE
//    projection x, y with 0.25 m cells), motion-check resolution 0.02 in the SE(2) metric, raw
//    paths, static obstacles only (lazy); `rrtc+simp` = RRTConnect followed by OMPL's
//    simplification (shortcut + reduce vertices, static obstacles);
//  - counting: a path is interpolated every 5 mm and the movables the disc touches are counted
//    (here, not by the planner: a scene built by this tool);
//  - ours: MotionPlanner lazy mode (cached static roadmap searched first, LBKPIECE1 when it cannot
//    connect, effort-aware roadmap search + shortcutting) and full mode (time to a path or to a
//    proven `no path`), measured three ways:
//      `ours`      cold cache: the roadmap cache is cleared before every run (first query of a
//                  planner on a new static world);
//      `ours-warm` the benchmark query on a warm cache, as the graph manager uses the planner:
//                  the cache is cleared once, then `--warmup` queries between random states with
//                  one movable displaced, then per run one more such query and the benchmark
//                  query (movables restored), so no run repeats the query just before it;
//      `ours-any`  those random queries themselves (warm cache, arbitrary start and goal,
//                  movables changed; no baseline: times, success and their own crossings only);
//      `ours-prep` the first query after MotionPlanner::prepare() (what the DDS node does after a
//                  world update that changed the static world): per run the cache is cleared,
//                  prepare() builds the roadmap (timed separately: "prepare" table) and the
//                  benchmark query is timed alone.
//    The warm phase calls prepare() once after clearing the cache, as the node does (unless
//    --no-prepare: the warm phase then starts on an empty cache, the behaviour before prepare()).
// Fixed seeds: OMPL's global seed is set once at start; runs are in a fixed order.
//
// Usage: tamp_motion_planner_namo_bench [--runs 20] [--full-runs 3] [--time-limit 5]
//          [--warmup 5] [--filter substring] [--json out.json] [--markdown out.md] [--no-baselines]
//          [--no-prepare]
//          [--config params.yaml]   (MotionPlannerParams for our planner, e.g.
//                                    config/services/motion_planner.yaml; default: built-in defaults)
//          [WORLD.json | WORLD.svg | FOLDER ...]
//   Worlds: the files named, and the worlds under each folder (recursively: every .json, and every
//   .svg that no .json beside it names as its geometry file), short name = file stem; without any,
//   the default set above. A missing path or another kind of file is an error; a world that does
//   not load or has no goal is skipped with its reason; exit code 2 when no world was run.
#include <algorithm>
#include <cctype>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <numeric>
#include <random>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>
#include <ompl/base/SpaceInformation.h>
#include <ompl/base/ProjectionEvaluator.h>
#include <ompl/base/goals/GoalSampleableRegion.h>
#include <ompl/base/spaces/SE2StateSpace.h>
#include <ompl/geometric/PathGeometric.h>
#include <ompl/geometric/PathSimplifier.h>
#include <ompl/geometric/planners/kpiece/KPIECE1.h>
#include <ompl/geometric/planners/kpiece/LBKPIECE1.h>
#include <ompl/geometric/planners/rrt/RRTConnect.h>
#include <ompl/util/Console.h>

#include "tamp/core/error.h"
#include "tamp/core/paths.h"
#include "tamp/core/stats.h"
#include "tamp/motion_planner/motion_planner.h"
#include "tamp/world/namo.h"

namespace ob = ompl::base;
namespace og = ompl::geometric;
namespace fs = std::filesystem;
using namespace tamp;

namespace {

struct Run {
  bool success{false};
  double time_ms{0};
  double length{0};
  int crossed{0};
  double mass{0};
  double effort_s{0};  // J = xy length / base speed + effort of the crossed movables (same model for all)
  std::vector<std::string> objects;  // the movables crossed (counted by this tool)
  std::string status;  // full mode
};

/// The path cost our lazy mode minimises, computed by this tool the same way for every method:
/// xy length at the planner's base speed plus the default effort of each movable crossed.
motion_planner::CostParams g_cost;

struct WorldCase {
  std::string name;
  fs::path file;
  world::NamoWorld nw;
};


/// Movables a disc touches along a base path, every 5 mm: count, total mass and total effort.
struct Crossing {
  std::vector<std::string> ids;
  double mass{0}, effort_s{0};
};
Crossing crossed(const world::World& w, double radius, const std::vector<Pose2D>& path) {
  collision::Scene scene(w);
  scene.setRobot(collision::RobotGeometry::disc(radius, 1.0));
  std::vector<std::string> ids;
  for (std::size_t i = 0; i < path.size(); ++i) {
    const Pose2D a = path[i];
    const Pose2D b = i + 1 < path.size() ? path[i + 1] : a;
    const int n = std::max(1, static_cast<int>(std::ceil(std::hypot(b.x - a.x, b.y - a.y) / 0.005)));
    for (int k = 0; k < n || (k == 0 && i + 1 == path.size()); ++k) {
      const double t = static_cast<double>(k) / n;
      scene.setBasePose(Pose2D{a.x + t * (b.x - a.x), a.y + t * (b.y - a.y), 0.0});
      for (auto& id : scene.robotCollisions(collision::Filter::movableOnly())) ids.push_back(id);
      if (i + 1 == path.size()) break;
    }
  }
  std::sort(ids.begin(), ids.end());
  ids.erase(std::unique(ids.begin(), ids.end()), ids.end());
  Crossing c;
  for (const auto& id : ids) {
    c.mass += w.object(id).mass;
    c.effort_s += motion_planner::defaultObjectEffort(w.object(id), g_cost);
  }
  c.ids = std::move(ids);
  return c;
}

/// Fills a run's length, crossings, mass and J from its poses.
void measure(Run& run, const WorldCase& wc, const std::vector<Pose2D>& poses);

double xyLength(const std::vector<Pose2D>& p) {
  double l = 0;
  for (std::size_t i = 1; i < p.size(); ++i) l += std::hypot(p[i].x - p[i - 1].x, p[i].y - p[i - 1].y);
  return l;
}

/// KPIECE projection: x, y with 0.25 m cells (REFERENCE.md).
class XY : public ob::ProjectionEvaluator {
 public:
  using ob::ProjectionEvaluator::ProjectionEvaluator;
  unsigned int getDimension() const override { return 2; }
  void defaultCellSizes() override { cellSizes_ = {0.25, 0.25}; }
  void project(const ob::State* s, Eigen::Ref<Eigen::VectorXd> p) const override {
    const auto* b = s->as<ob::SE2StateSpace::StateType>();
    p(0) = b->getX();
    p(1) = b->getY();
  }
};

class XYGoal : public ob::GoalSampleableRegion {
 public:
  XYGoal(const ob::SpaceInformationPtr& si, double x, double y) : ob::GoalSampleableRegion(si), x_(x), y_(y) {
    setThreshold(0.01);
  }
  double distanceGoal(const ob::State* s) const override {
    const auto* b = s->as<ob::SE2StateSpace::StateType>();
    return std::hypot(b->getX() - x_, b->getY() - y_);
  }
  void sampleGoal(ob::State* s) const override {
    auto* b = s->as<ob::SE2StateSpace::StateType>();
    b->setXY(x_, y_);
    b->setYaw(rng_.uniformReal(-M_PI, M_PI));
  }
  unsigned int maxSampleCount() const override { return 1000000u; }

 private:
  double x_, y_;
  mutable ompl::RNG rng_;
};

/// An OMPL baseline run: raw lazy path against static obstacles.
struct Baseline {
  const WorldCase& wc;
  collision::Scene scene;
  ob::SpaceInformationPtr si;
  explicit Baseline(const WorldCase& c) : wc(c), scene(c.nw.world) {
    scene.setRobot(collision::RobotGeometry::disc(c.nw.robot_radius, 1.0));
    auto space = std::make_shared<ob::SE2StateSpace>();
    Aabb b = c.nw.world.bounds();
    b.extend(Eigen::Vector3d(c.nw.start.x, c.nw.start.y, 0));
    ob::RealVectorBounds rb(2);
    rb.setLow(0, b.min.x() - 0.5);
    rb.setLow(1, b.min.y() - 0.5);
    rb.setHigh(0, b.max.x() + 0.5);
    rb.setHigh(1, b.max.y() + 0.5);
    space->setBounds(rb);
    space->registerDefaultProjection(std::make_shared<XY>(space));
    si = std::make_shared<ob::SpaceInformation>(space);
    si->setStateValidityChecker([this](const ob::State* s) {
      if (!si->satisfiesBounds(s)) return false;
      const auto* st = s->as<ob::SE2StateSpace::StateType>();
      scene.setBasePose(Pose2D{st->getX(), st->getY(), st->getYaw()});
      return !scene.robotInCollision(collision::Filter::staticOnly());
    });
    si->setStateValidityCheckingResolution(0.02 / space->getMaximumExtent());
    si->setup();
  }

  std::pair<Run, Run> run(const std::string& planner, double limit, bool simplify) {
    ob::PlannerPtr p;
    if (planner == "rrtconnect") p = std::make_shared<og::RRTConnect>(si);
    if (planner == "kpiece") p = std::make_shared<og::KPIECE1>(si);
    if (planner == "lbkpiece") p = std::make_shared<og::LBKPIECE1>(si);
    auto pdef = std::make_shared<ob::ProblemDefinition>(si);
    ob::ScopedState<ob::SE2StateSpace> start(si->getStateSpace());
    start->setXY(wc.nw.start.x, wc.nw.start.y);
    start->setYaw(wrapAngle(wc.nw.start.theta));
    pdef->addStartState(start);
    pdef->setGoal(std::make_shared<XYGoal>(si, wc.nw.goals[0].pose.x, wc.nw.goals[0].pose.y));
    p->setProblemDefinition(pdef);
    p->setup();
    const auto t0 = std::chrono::steady_clock::now();
    p->solve(ob::timedPlannerTerminationCondition(limit));
    const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    Run raw, simp;
    raw.time_ms = ms;
    raw.success = pdef->hasExactSolution();
    if (!raw.success) return {raw, simp};
    og::PathGeometric path = *pdef->getSolutionPath()->as<og::PathGeometric>();
    auto poses = [](const og::PathGeometric& pg) {
      std::vector<Pose2D> out;
      for (std::size_t i = 0; i < pg.getStateCount(); ++i) {
        const auto* s = pg.getState(i)->as<ob::SE2StateSpace::StateType>();
        out.push_back(Pose2D{s->getX(), s->getY(), s->getYaw()});
      }
      return out;
    };
    measure(raw, wc, poses(path));
    if (simplify) {
      const auto t1 = std::chrono::steady_clock::now();
      og::PathSimplifier s(si);
      s.simplifyMax(path);
      simp.time_ms = ms + std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t1).count();
      simp.success = true;
      measure(simp, wc, poses(path));
    }
    return {raw, simp};
  }
};

void measure(Run& run, const WorldCase& wc, const std::vector<Pose2D>& poses) {
  run.length = xyLength(poses);
  Crossing c = crossed(wc.nw.world, wc.nw.robot_radius, poses);
  run.crossed = static_cast<int>(c.ids.size());
  run.objects = std::move(c.ids);
  run.mass = c.mass;
  run.effort_s = run.length / g_cost.base_speed + c.effort_s;
}

struct Summary {
  int runs{0}, ok{0};
  double med_ms{NAN}, p95_ms{NAN}, med_len{NAN}, med_cross{NAN}, mean_cross{NAN}, med_mass{NAN}, med_effort{NAN};
};

Summary summarize(const std::vector<Run>& runs);

/// The per-world check against the aims (x = miss), computed from the runs.
void writeAims(std::ostream& md, const std::vector<WorldCase>& worlds,
               std::map<std::string, std::map<std::string, std::vector<Run>>>& results) {
  auto has = [&](const std::string& w, const std::string& m) { return !results[w][m].empty(); };
  if (worlds.empty() || !has(worlds.front().name, "rrtc+simp")) return;  // needs the baselines
  auto fmt = [](double v, int digits) {
    char b[32];
    std::snprintf(b, sizeof(b), "%.*f", digits, v);
    return std::string(b);
  };
  const std::vector<std::string> ours = {"ours", "ours-prep", "ours-warm"};
  md << "\nAgainst the aims, per world (x = miss). Crossed: median / mean, a miss when above the best OMPL raw path "
        "(lowest of RRTConnect, KPIECE1, LBKPIECE1, medians and means separately). Length and J: median of ours-warm "
        "(and ours-len, objects free) over the median of RRTConnect + simplify; a length miss above 1.10. p95 in ms, a "
        "miss at 50 or more.\n\n| world | cold crossed | prep crossed | warm crossed | best raw crossed | warm length "
        "ratio | len length ratio | warm J ratio | cold p95 | prep p95 | warm p95 |\n|---|---|---|---|---|---|---|---|---|---|---|\n";
  std::map<std::string, int> misses;
  int fewer = 0;
  for (const auto& wc : worlds) {
    const std::string& w = wc.name;
    double best_med = INFINITY, best_mean = INFINITY;
    for (const std::string m : {"rrtconnect", "kpiece", "lbkpiece"}) {
      const Summary b = summarize(results[w][m]);
      best_med = std::min(best_med, b.med_cross);
      best_mean = std::min(best_mean, b.mean_cross);
    }
    const Summary ref = summarize(results[w]["rrtc+simp"]);
    md << "| " << w << " |";
    for (const auto& m : ours) {
      if (!has(w, m)) {
        md << " - |";
        continue;
      }
      const Summary o = summarize(results[w][m]);
      const bool miss = o.med_cross > best_med + 1e-9 || o.mean_cross > best_mean + 1e-9;
      if (miss) ++misses[m + " crossed"];
      if (m == "ours-warm" && (o.med_cross < best_med - 1e-9 || o.mean_cross < best_mean - 1e-9)) ++fewer;
      md << " " << fmt(o.med_cross, 0) << " / " << fmt(o.mean_cross, 2) << (miss ? " **x**" : "") << " |";
    }
    md << " " << fmt(best_med, 1) << " / " << fmt(best_mean, 2) << " |";
    for (const std::string m : {"ours-warm", "ours-len"}) {
      if (!has(w, m)) {
        md << " - |";
        continue;
      }
      const double r = summarize(results[w][m]).med_len / ref.med_len;
      if (r > 1.10) ++misses[m + " length"];
      md << " " << fmt(r, 2) << (r > 1.10 ? " **x**" : "") << " |";
    }
    if (has(w, "ours-warm")) {
      const double r = summarize(results[w]["ours-warm"]).med_effort / ref.med_effort;
      if (r > 1.0 + 1e-9) ++misses["ours-warm J above rrtc+simp"];
      md << " " << fmt(r, 2) << " |";
    } else {
      md << " - |";
    }
    for (const auto& m : ours) {
      if (!has(w, m)) {
        md << " - |";
        continue;
      }
      const double p = summarize(results[w][m]).p95_ms;
      if (p >= 50) ++misses[m + " p95"];
      md << " " << fmt(p, 1) << (p >= 50 ? " **x**" : "") << " |";
    }
    md << "\n";
  }
  md << "\nWorlds (of " << worlds.size() << ") where ours-warm crosses fewer objects than the best raw path (median or "
     << "mean): " << fewer << ". Misses:";
  if (misses.empty()) md << " none";
  for (const auto& [k, v] : misses) md << " " << k << " " << v << ";";
  md << "\n";
}

Summary summarize(const std::vector<Run>& runs) {
  Summary s;
  s.runs = static_cast<int>(runs.size());
  std::vector<double> t, l, c, m, e;
  for (const auto& r : runs) {
    t.push_back(r.time_ms);
    if (!r.success) continue;
    ++s.ok;
    l.push_back(r.length);
    c.push_back(r.crossed);
    m.push_back(r.mass);
    e.push_back(r.effort_s);
  }
  s.med_ms = interpolatedPercentile(t, 0.5);
  s.p95_ms = interpolatedPercentile(t, 0.95);
  s.med_len = interpolatedPercentile(l, 0.5);
  s.med_cross = interpolatedPercentile(c, 0.5);
  s.med_mass = interpolatedPercentile(m, 0.5);
  s.med_effort = interpolatedPercentile(e, 0.5);
  s.mean_cross = c.empty() ? NAN : std::accumulate(c.begin(), c.end(), 0.0) / static_cast<double>(c.size());
  return s;
}

using WorldFiles = std::vector<std::pair<std::string, fs::path>>;  // (short name, file)

/// The default set: the 19 bare Moghaddam SVGs and the JSON worlds with movables (omniscient
/// variants: full knowledge; the planning problem is the same as the partial-knowledge variant's).
WorldFiles defaultWorldFiles() {
  const fs::path root = benchmarksDir() / "namo";
  WorldFiles files;
  for (int n : {2, 4, 5, 7, 8, 10, 11, 13, 14, 16, 17, 19, 20, 22, 23, 25, 26, 28, 29}) {
    char name[64];
    std::snprintf(name, sizeof(name), "moghaddam_planning_2016_benchmark_%02d.svg", n);
    char shortname[16];
    std::snprintf(shortname, sizeof(shortname), "%02d", n);
    files.emplace_back(shortname, root / "moghaddam_planning_2016_benchmark" / name);
  }
  files.emplace_back("m01", root / "moghaddam_planning_2016_benchmark/01/01_omniscient.json");
  files.emplace_back("two_rooms", root / "first_level/01_two_rooms_corridor/01_two_rooms_corridor_omniscient.json");
  files.emplace_back("big_crossing", root / "first_level/03_big_crossing/03_big_crossing_omniscient.json");
  files.emplace_back("basic", root / "s-namo_cases/01_basic/01_basic_omniscient.json");
  files.emplace_back("opening", root / "s-namo_cases/02_basic_with_opening/02_basic_with_opening_omniscient.json");
  files.emplace_back("feast", root / "s-namo_cases/04_after_the_feast/04_after_the_feast_omniscient.json");
  files.emplace_back("feast_cplx", root / "s-namo_cases/04_after_the_feast/04_after_the_feast_omniscient_complexified.json");
  files.emplace_back("citi", root / "s-namo_cases/05_citi_second_floor/05_citi_second_floor_omniscient.json");
  files.emplace_back("chen", root / "stilman_2005_thesis/04_chen_difficult_problem/04_chen_difficult_problem_omniscient.json");
  return files;
}

std::string lowerExtension(const fs::path& p) {
  std::string e = p.extension().string();
  std::transform(e.begin(), e.end(), e.begin(), [](unsigned char c) { return std::tolower(c); });
  return e;
}

/// SVGs that a world JSON in `dir` names as its `files.geometry_file` (geometry, not worlds).
std::vector<fs::path> geometryFilesNamedIn(const fs::path& dir) {
  std::vector<fs::path> named;
  for (const auto& entry : fs::directory_iterator(dir)) {
    if (!entry.is_regular_file() || lowerExtension(entry.path()) != ".json") continue;
    std::ifstream in(entry.path());
    const auto j = nlohmann::json::parse(in, nullptr, /*allow_exceptions=*/false);
    if (!j.is_object() || !j.contains("files") || !j["files"].is_object()) continue;
    const auto& g = j["files"].value("geometry_file", nlohmann::json());
    if (g.is_string()) named.push_back(fs::weakly_canonical(dir / g.get<std::string>()));
  }
  return named;
}

/// The NAMO worlds under `dir`, recursively and sorted: every .json, and every .svg that no .json
/// beside it names as its geometry (the bare colour-convention SVGs).
std::vector<fs::path> worldFilesIn(const fs::path& dir) {
  std::vector<fs::path> candidates;
  for (const auto& entry : fs::recursive_directory_iterator(dir)) {
    const std::string ext = lowerExtension(entry.path());
    if (entry.is_regular_file() && (ext == ".json" || ext == ".svg")) candidates.push_back(entry.path());
  }
  std::sort(candidates.begin(), candidates.end());
  std::vector<fs::path> worlds;
  std::map<fs::path, std::vector<fs::path>> geometry;  // folder -> SVGs named by its JSONs
  for (const auto& p : candidates) {
    if (lowerExtension(p) == ".svg") {
      if (!geometry.count(p.parent_path())) geometry[p.parent_path()] = geometryFilesNamedIn(p.parent_path());
      const auto& named = geometry[p.parent_path()];
      if (std::find(named.begin(), named.end(), fs::weakly_canonical(p)) != named.end()) continue;
    }
    worlds.push_back(p);
  }
  return worlds;
}

/// The worlds named on the command line: files (.json or .svg) and folders (searched with
/// worldFilesIn). A missing path or a file of another kind is an input error naming it.
Result<WorldFiles> worldFilesFromArgs(const std::vector<std::string>& args) {
  WorldFiles files;
  for (const auto& a : args) {
    const fs::path p(a);
    std::error_code ec;
    if (fs::is_directory(p, ec)) {
      for (const auto& f : worldFilesIn(p)) files.emplace_back(f.stem().string(), f);
    } else if (!fs::exists(p, ec)) {
      return Error(ErrorCode::kNotFound, "no such world file or folder", SourceLocation(a));
    } else if (const std::string ext = lowerExtension(p); ext == ".json" || ext == ".svg") {
      files.emplace_back(p.stem().string(), p);
    } else {
      return Error(ErrorCode::kInvalidArgument, "not a NAMO world (.json or bare .svg)", SourceLocation(a));
    }
  }
  return files;
}

/// Loads the worlds whose short name contains `filter`. A world that does not load or has no
/// goal is skipped with its reason on stderr.
std::vector<WorldCase> loadWorlds(const WorldFiles& files, const std::string& filter) {
  std::vector<WorldCase> out;
  for (const auto& [name, file] : files) {
    if (!filter.empty() && name.find(filter) == std::string::npos) continue;
    auto w = world::loadNamo(file);
    if (!w) {
      std::cerr << "skip " << name << ": " << w.error().toString() << "\n";
      continue;
    }
    if (w->goals.empty()) {
      std::cerr << "skip " << name << " (" << file.string() << "): no goal\n";
      continue;
    }
    out.push_back(WorldCase{name, file, std::move(*w)});
  }
  return out;
}

}  // namespace

int main(int argc, char** argv) {
  int runs = 20, full_runs = 3, warmup = 5;
  double limit = 5.0;
  std::string filter, json_out, md_out;
  std::vector<std::string> world_args;  // world files and folders; none: the default set
  bool use_prepare = true;
  bool baselines = true;
  motion_planner::MotionPlannerParams params;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    auto next = [&]() -> std::string {
      if (i + 1 >= argc) {
        std::cerr << a << " needs a value\n";
        std::exit(2);
      }
      return argv[++i];
    };
    if (a == "--runs") runs = std::stoi(next());
    else if (a == "--full-runs") full_runs = std::stoi(next());
    else if (a == "--warmup") warmup = std::stoi(next());
    else if (a == "--time-limit") limit = std::stod(next());
    else if (a == "--filter") filter = next();
    else if (a == "--json") json_out = next();
    else if (a == "--markdown") md_out = next();
    else if (a == "--no-baselines") baselines = false;
    else if (a == "--no-prepare") use_prepare = false;
    else if (!a.empty() && a[0] != '-') world_args.push_back(a);
    else if (a == "--config") {
      auto p = motion_planner::loadMotionPlannerParams(next(), {"node"});
      if (!p) {
        std::cerr << p.error().toString() << "\n";
        return 2;
      }
      params = *p;
    }
    else {
      std::cerr << "usage: " << argv[0]
                << " [--runs N] [--full-runs N] [--warmup N] [--time-limit s] [--filter s] [--json f] [--markdown f] [--no-baselines] [--no-prepare] [--config f] [WORLD.json|WORLD.svg|FOLDER ...]\n";
      return 2;
    }
  }
  g_cost = params.cost;
  motion_planner::seedRandomness(42);
  ompl::msg::setLogLevel(ompl::msg::LOG_NONE);
  const auto files = world_args.empty() ? Result<WorldFiles>(defaultWorldFiles()) : worldFilesFromArgs(world_args);
  if (!files) {
    std::cerr << files.error().toString() << "\n";
    return 2;
  }
  const auto worlds = loadWorlds(*files, filter);
  if (worlds.empty()) {
    std::cerr << "namo_bench: ran nothing: no loadable world with a goal"
              << (filter.empty() ? "" : " matching --filter " + filter) << " among " << files->size()
              << " world files\n";
    return 2;
  }
  const std::vector<std::string> methods = {"ours",       "ours-prep", "ours-warm", "ours-any", "ours-len",
                                            "rrtconnect", "kpiece",    "lbkpiece",  "rrtc+simp"};
  std::map<std::string, std::map<std::string, std::vector<Run>>> results;  // world -> method -> runs
  std::map<std::string, std::vector<Run>> full;                           // world -> full runs
  std::map<std::string, std::vector<double>> prep_ms;                     // world -> prepare() times
  std::map<std::string, motion_planner::PrepareStats> prep_last;
  nlohmann::json js;
  js["time_limit_s"] = limit;
  js["runs"] = runs;
  for (const auto& wc : worlds) {
    std::cerr << "world " << wc.name << " (" << wc.nw.world.objectCount() << " objects, r = " << wc.nw.robot_radius
              << " m)\n";
    motion_planner::MotionPlanner mp(collision::RobotGeometry::disc(wc.nw.robot_radius, 1.0), params);
    mp.setWorld(wc.nw.world);
    motion_planner::MotionRequest req;
    req.start.base = wc.nw.start;
    req.goal = motion_planner::MotionGoal::basePoseGoal(wc.nw.goals[0].pose, !wc.nw.goals[0].has_orientation);
    int reported_mismatch = 0;
    auto record = [&](const std::string& method, int r, const motion_planner::MotionResult& res) {
      Run run;
      run.success = res.ok();
      run.time_ms = res.planning_time_s * 1e3;
      if (run.success) {
        std::vector<Pose2D> poses;
        for (const auto& w : res.path.waypoints) poses.push_back(Pose2D{w[0], w[1], w[2]});
        if (method == "ours-any") {
          run.length = xyLength(poses);
          run.crossed = static_cast<int>(res.blocking.size());
          run.effort_s = run.length / g_cost.base_speed;
          for (const auto& b : res.blocking) {
            run.mass += b.mass;
            run.effort_s += b.effort_s;
          }
        } else {
          measure(run, wc, poses);
          if (run.crossed != static_cast<int>(res.blocking.size())) ++reported_mismatch;
        }
        nlohmann::json jr{{"method", method}, {"world", wc.name}, {"run", r}, {"time_ms", run.time_ms},
                          {"length", run.length}, {"crossed", run.crossed}, {"mass", run.mass},
                          {"effort_s", run.effort_s}, {"objects", run.objects},
                          {"raw_crossed", res.stats.raw_blocking.size()}, {"cost_s", res.cost_s},
                          {"raw_cost_s", res.stats.raw_cost_s}, {"sampling_ms", res.stats.sampling_ms},
                          {"optimize_ms", res.stats.optimize_ms}, {"shortcut_ms", res.stats.shortcut_ms},
                          {"analysis_ms", res.stats.analysis_ms}, {"roadmap_nodes", res.stats.roadmap_nodes},
                          {"search_iterations", res.stats.search_iterations},
                          {"edges_evaluated", res.stats.edges_evaluated},
                          {"optimize_completed", res.stats.optimize_completed},
                          {"roadmap_reused", res.stats.roadmap_reused},
                          {"lazy_planner_used", res.stats.lazy_planner_used}};
        js["runs_detail"].push_back(jr);
      }
      results[wc.name][method].push_back(run);
    };
    // Cold cache.
    for (int r = 0; r < runs; ++r) {
      mp.clearRoadmapCache();
      record("ours", r, mp.plan(req, Termination::after(limit)));
    }
    // First query after prepare() (the node prepares after a static-world change).
    auto prepare = [&]() {
      auto ps = mp.prepare(motion_planner::PlanningGroup::kBase, req.start, {}, Termination::after(limit));
      if (!ps) {
        std::cerr << "  prepare: " << ps.error().toString() << "\n";
        return;
      }
      prep_ms[wc.name].push_back(ps->time_ms);
      prep_last[wc.name] = *ps;
    };
    if (use_prepare) {
      for (int r = 0; r < runs; ++r) {
        mp.clearRoadmapCache();
        prepare();
        record("ours-prep", r, mp.plan(req, Termination::after(limit)));
      }
    }
    // Warm cache: random queries with one movable displaced between benchmark queries.
    {
      mp.clearRoadmapCache();
      if (use_prepare) prepare();
      std::mt19937 rng(1234);
      const Aabb b = wc.nw.world.bounds();
      std::uniform_real_distribution<double> ux(b.min.x(), b.max.x()), uy(b.min.y(), b.max.y()),
          uth(-M_PI, M_PI), shift(-0.3, 0.3);
      std::vector<std::string> movable_ids;
      for (const auto& o : wc.nw.world.objects()) {
        if (o.kind == world::ObjectKind::kMovable) movable_ids.push_back(o.id);
      }
      int any_run = 0;
      auto randomQuery = [&]() {
        world::World moved = wc.nw.world;
        if (!movable_ids.empty()) {
          const auto& id = movable_ids[rng() % movable_ids.size()];
          Eigen::Isometry3d pose = moved.findObject(id)->pose;
          pose.translation().x() += shift(rng);
          pose.translation().y() += shift(rng);
          (void)moved.setObjectPose(id, pose);
        }
        mp.setWorld(moved);
        for (int attempt = 0; attempt < 200; ++attempt) {
          motion_planner::MotionRequest q;
          q.start.base = Pose2D{ux(rng), uy(rng), uth(rng)};
          q.goal = motion_planner::MotionGoal::basePoseGoal(Pose2D{ux(rng), uy(rng), uth(rng)}, true);
          const auto res = mp.plan(q, Termination::after(limit));
          if (res.status == motion_planner::MotionStatus::kStartInCollision ||
              res.status == motion_planner::MotionStatus::kGoalInCollision ||
              (res.status == motion_planner::MotionStatus::kNoPath && res.reason.find("proven") != std::string::npos)) {
            continue;  // not a query the graph manager would ask
          }
          record("ours-any", any_run++, res);
          break;
        }
        mp.setWorld(wc.nw.world);
      };
      for (int k = 0; k < warmup; ++k) randomQuery();
      for (int r = 0; r < runs; ++r) {
        randomQuery();
        record("ours-warm", r, mp.plan(req, Termination::after(limit)));
      }
      // The same query with objects free (object_cost_scale 0): the shortest static-free path
      // our roadmap search and shortcutting find, to compare lengths with RRTConnect +
      // simplification on equal terms (both ignore the movables).
      motion_planner::MotionRequest len_req = req;
      len_req.object_cost_scale = 0.0;
      for (int r = 0; r < runs; ++r) record("ours-len", r, mp.plan(len_req, Termination::after(limit)));
    }
    if (reported_mismatch > 0) std::cerr << "  WARNING: " << reported_mismatch << " runs where the report differs\n";
    if (baselines) {
      Baseline base(wc);
      for (const std::string p : {"rrtconnect", "kpiece", "lbkpiece"}) {
        for (int r = 0; r < runs; ++r) {
          auto [raw, simp] = base.run(p, limit, p == "rrtconnect");
          results[wc.name][p].push_back(raw);
          if (p == "rrtconnect") results[wc.name]["rrtc+simp"].push_back(simp);
          for (const auto& [m, run] : {std::pair<std::string, const Run&>{p, raw}, {"rrtc+simp", simp}}) {
            if (!run.success || (m == "rrtc+simp" && p != "rrtconnect")) continue;
            js["runs_detail"].push_back({{"method", m}, {"world", wc.name}, {"run", r}, {"time_ms", run.time_ms},
                                         {"length", run.length}, {"crossed", run.crossed}, {"mass", run.mass},
                                         {"effort_s", run.effort_s}, {"objects", run.objects}});
          }
        }
      }
    }
    req.mode = motion_planner::MotionMode::kFull;
    for (int r = 0; r < full_runs; ++r) {
      const auto res = mp.plan(req, Termination::after(limit));
      Run run;
      run.time_ms = res.planning_time_s * 1e3;
      run.success = res.ok();
      run.status = std::string(motion_planner::toString(res.status)) +
                   (res.status == motion_planner::MotionStatus::kNoPath && res.reason.find("proven") != std::string::npos
                        ? " (proven)"
                        : "");
      full[wc.name].push_back(run);
    }
  }

  // ---- report ----
  std::ostringstream md;
  auto f1 = [](double v) {
    char b[32];
    std::snprintf(b, sizeof(b), std::isnan(v) ? "-" : "%.1f", v);
    return std::string(b);
  };
  auto f2 = [](double v) {
    char b[32];
    std::snprintf(b, sizeof(b), std::isnan(v) ? "-" : (v < 10 ? "%.2f" : "%.1f"), v);
    return std::string(b);
  };
  md << "Per world, median over " << runs << " runs: movables crossed / path length (m) / planning time median, p95 (ms); "
     << "success if < 100 %\n\n";
  md << "| world | objects (movable) |";
  for (const auto& m : methods) md << " " << m << " |";
  md << " full mode |\n|---|---|";
  for (std::size_t i = 0; i < methods.size(); ++i) md << "---|";
  md << "---|\n";
  std::map<std::string, std::vector<Run>> agg;
  for (const auto& wc : worlds) {
    int movable = 0;
    for (const auto& o : wc.nw.world.objects()) movable += o.kind == world::ObjectKind::kMovable;
    md << "| " << wc.name << " | " << wc.nw.world.objectCount() << " (" << movable << ") |";
    for (const auto& m : methods) {
      const auto& rs = results[wc.name][m];
      if (rs.empty()) {
        md << " - |";
        continue;
      }
      agg[m].insert(agg[m].end(), rs.begin(), rs.end());
      const Summary s = summarize(rs);
      md << " " << f1(s.med_cross) << " / " << f1(s.med_len) << " / " << f2(s.med_ms) << ", " << f2(s.p95_ms);
      if (s.ok < s.runs) md << " (" << (100 * s.ok / s.runs) << " %)";
      md << " |";
      js["summary"][wc.name][m] = {{"success", s.ok}, {"runs", s.runs}, {"median_ms", s.med_ms}, {"p95_ms", s.p95_ms},
                                   {"median_length", s.med_len}, {"median_crossed", s.med_cross},
                                   {"mean_crossed", s.mean_cross}, {"median_mass", s.med_mass}};
    }
    std::map<std::string, int> statuses;
    std::vector<double> ft;
    for (const auto& r : full[wc.name]) {
      ++statuses[r.status];
      ft.push_back(r.time_ms);
    }
    std::string st;
    for (const auto& [k, v] : statuses) st += (st.empty() ? "" : ", ") + k + (v > 1 ? " x" + std::to_string(v) : "");
    md << " " << st << ", " << f2(interpolatedPercentile(ft, 0.5)) << " ms |\n";
    js["full"][wc.name] = {{"statuses", statuses}, {"median_ms", interpolatedPercentile(ft, 0.5)}, {"max_ms", interpolatedPercentile(ft, 1.0)}};
  }
  md << "\nAggregate over " << worlds.size() << " worlds:\n\n| method | success | median ms | p95 ms | median crossed | mean crossed | "
        "total crossed | median length (m) | mean mass crossed (kg) | median J (s) |\n|---|---|---|---|---|---|---|---|---|---|\n";
  for (const auto& m : methods) {
    if (agg[m].empty()) continue;
    const Summary s = summarize(agg[m]);
    double total = 0, mass = 0;
    for (const auto& r : agg[m]) {
      total += r.crossed;
      mass += r.mass;
    }
    md << "| " << m << " | " << s.ok << "/" << s.runs << " | " << f2(s.med_ms) << " | " << f2(s.p95_ms) << " | "
       << f1(s.med_cross) << " | " << f2(s.mean_cross) << " | " << total << " | " << f1(s.med_len) << " | "
       << f1(mass / std::max(1, s.ok)) << " | " << f1(s.med_effort) << " |\n";
    js["aggregate"][m] = {{"success", s.ok}, {"runs", s.runs}, {"median_ms", s.med_ms}, {"p95_ms", s.p95_ms},
                          {"median_crossed", s.med_cross}, {"mean_crossed", s.mean_cross}, {"total_crossed", total},
                          {"median_length", s.med_len}, {"median_effort_s", s.med_effort}};
  }
  writeAims(md, worlds, results);
  if (!prep_ms.empty()) {
    md << "\nprepare() (base group, cache cleared before each; not inside any request above except `ours`'s "
          "cold runs, which pay their own build):\n\n| world | median ms | p95 ms | max ms | nodes | edges | invalid "
          "edges |\n|---|---|---|---|---|---|---|\n";
    std::vector<double> all;
    for (const auto& wc : worlds) {
      const auto& v = prep_ms[wc.name];
      if (v.empty()) continue;
      all.insert(all.end(), v.begin(), v.end());
      const auto& ps = prep_last[wc.name];
      md << "| " << wc.name << " | " << f2(interpolatedPercentile(v, 0.5)) << " | " << f2(interpolatedPercentile(v, 0.95)) << " | "
         << f2(interpolatedPercentile(v, 1.0)) << " | " << ps.roadmap_nodes << " | " << ps.roadmap_edges << " | "
         << ps.edges_invalid << " |\n";
      js["prepare"][wc.name] = {{"median_ms", interpolatedPercentile(v, 0.5)}, {"p95_ms", interpolatedPercentile(v, 0.95)},
                                {"max_ms", interpolatedPercentile(v, 1.0)}, {"nodes", ps.roadmap_nodes},
                                {"edges", ps.roadmap_edges}, {"invalid_edges", ps.edges_invalid}};
    }
    md << "| all | " << f2(interpolatedPercentile(all, 0.5)) << " | " << f2(interpolatedPercentile(all, 0.95)) << " | "
       << f2(interpolatedPercentile(all, 1.0)) << " | | | |\n";
  }
  std::cout << md.str();
  if (!md_out.empty()) std::ofstream(md_out) << md.str();
  if (!json_out.empty()) std::ofstream(json_out) << js.dump(1) << "\n";
  return 0;
}
