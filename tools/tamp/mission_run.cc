#include "mission_run.h"

#include <chrono>
#include <cmath>
#include <condition_variable>
#include <cstdio>
#include <fstream>
#include <mutex>
#include <optional>
#include <thread>

#include <nlohmann/json.hpp>

#include "cli_common.h"
#include "tamp/core/paths.h"
#include "tamp/dds/convert.h"
#include "tamp/dds/endpoint.h"
#include "tamp/dds/topics.h"
#include "tamp/render/render.h"
#include "tamp/world/scenario.h"

namespace fs = std::filesystem;

namespace tamp::runner {
namespace {

bool isFinal(msg::MissionState s) {
  return s == msg::MissionState::MISSION_SUCCEEDED || s == msg::MissionState::MISSION_FAILED ||
         s == msg::MissionState::MISSION_ABORTED;
}

std::string bar(double fraction, int width = 30) {
  fraction = std::clamp(std::isfinite(fraction) ? fraction : 0.0, 0.0, 1.0);
  const int n = static_cast<int>(std::lround(fraction * width));
  return "[" + std::string(static_cast<std::size_t>(n), '#') + std::string(static_cast<std::size_t>(width - n), '.') + "]";
}

/// Executed base paths, moved objects and what perception found over the scenario's world.
void writeWorldPictures(const world::Scenario& sc, const nlohmann::json& report, const fs::path& dir) {
  render::Drawing d;
  d.world = sc.world;
  d.title = sc.name + " -- " + report.value("policy", "") + ": " + report.value("status", "");
  const auto robot = robot::RobotModel::loadDescription(sc.robot.description);
  const world::Polygon2 footprint = robot ? robot->baseFootprint() : world::Polygon2{};
  int i = 0;
  for (const auto& a : report.value("actions", nlohmann::json::array())) {
    const auto& path = a["base_path"];
    if (!path.is_array() || path.size() < 2) continue;
    render::PathOverlay p;
    for (const auto& xy : path) p.poses.push_back(Pose2D{xy[0].get<double>(), xy[1].get<double>(), 0.0});
    p.label = a.value("variant", "") == "around" ? "detour" : std::to_string(++i);
    if (a.value("outcome", "") != "succeeded") {
      p.colour = render::Rgba{0.85, 0.15, 0.15, 1.0};
      p.dashed = true;
    }
    d.paths.push_back(std::move(p));
  }
  for (const auto& m : report.value("moves", nlohmann::json::array())) {
    const std::string id = m.value("object", "");
    const world::Object* o = d.world.findObject(id);
    if (!o || !m.contains("to")) continue;
    if (m.contains("from")) {
      render::Footprint old;
      old.polygon = o->shape.footprint();
      old.pose = Pose2D{m["from"]["x"].get<double>(), m["from"]["y"].get<double>(), m["from"]["yaw"].get<double>()};
      old.colour = render::Rgba{0.9, 0.5, 0.1, 1.0};
      old.dashed = true;
      old.label = id + " before";
      d.robots.push_back(old);
    }
    Eigen::Isometry3d to = Eigen::Isometry3d::Identity();
    to.translation() = Eigen::Vector3d(m["to"]["x"].get<double>(), m["to"]["y"].get<double>(), m["to"]["z"].get<double>());
    to.linear() = Eigen::AngleAxisd(m["to"]["yaw"].get<double>(), Eigen::Vector3d::UnitZ()).toRotationMatrix();
    (void)d.world.setObjectPose(id, to);
  }
  // What perception found that the scenario did not list, where it estimated it (dashed).
  for (const auto& o : report.value("perceived", nlohmann::json::array())) {
    if (!o.contains("pose")) continue;
    render::Footprint seen;
    seen.pose = Pose2D{o["pose"]["x"].get<double>(), o["pose"]["y"].get<double>(), o["pose"]["yaw"].get<double>()};
    // The outline's world corners into the object's frame (a footprint is drawn at its pose).
    const Eigen::Rotation2Dd to_object(-seen.pose.theta);
    for (const auto& xy : o.value("footprint", nlohmann::json::array()))
      seen.polygon.push_back(to_object * (Eigen::Vector2d(xy[0].get<double>(), xy[1].get<double>()) -
                                          Eigen::Vector2d(seen.pose.x, seen.pose.y)));
    if (seen.polygon.size() < 3) continue;
    seen.colour = render::Rgba{0.55, 0.15, 0.65, 1.0};
    seen.dashed = true;
    seen.label = o.value("id", "") + " (perceived)";
    d.robots.push_back(std::move(seen));
  }
  render::Footprint start;
  start.polygon = footprint;
  start.pose = sc.robot.start;
  start.label = "start";
  d.robots.push_back(start);
  for (const char* ext : {"world.png", "world.svg"}) {
    if (Status s = render::render(d, dir / ext); !s) std::fprintf(stderr, "tamp run: %s: %s\n", ext, s.error().message.c_str());
  }
}

/// Writes `text` to `file` through a temporary in the same folder and a rename, so a reader never
/// sees half a report. The error, or nothing.
std::optional<std::string> writeAtomically(const fs::path& file, const std::string& text) {
  if (Status s = writeFileAtomically(file, text, "the report"); !s) return s.error().toString();
  return std::nullopt;
}

/// `latest_dir/latest` -> the run folder (relative when inside latest_dir), replaced atomically.
std::optional<std::string> pointLatestAt(const fs::path& latest_dir, const fs::path& run_dir) {
  const fs::path link = latest_dir / "latest";
  const fs::path tmp = latest_dir / ".latest.tmp";
  std::error_code ec;
  fs::remove(tmp, ec);
  const fs::path rel = run_dir.lexically_relative(latest_dir);
  fs::create_directory_symlink(rel.empty() || *rel.begin() == ".." ? run_dir : rel, tmp, ec);
  if (!ec) fs::rename(tmp, link, ec);
  if (ec) return "cannot link " + link.string() + " to " + run_dir.string() + ": " + ec.message();
  return std::nullopt;
}

/// The run's artefacts; the error of a report that could not be written, or nothing. The graph
/// and the pictures are best effort (a missing graphviz is said, not fatal).
std::optional<std::string> writeArtefacts(const msg::MissionStatus& st, const MissionOptions& o) {
  const fs::path dir = o.out_dir;
  const std::string report_text = st.report_json() + "\n";
  if (auto bad = writeAtomically(dir / "report.json", report_text)) return bad;
  if (!o.latest_dir.empty()) {
    if (auto bad = writeAtomically(o.latest_dir / "report.json", report_text)) return bad;
    if (auto bad = pointLatestAt(o.latest_dir, dir)) return bad;
  }
  if (!st.graph_dot().empty()) {
    std::ofstream(dir / "graph.dot") << st.graph_dot();
    const std::string cmd = "dot -Tsvg '" + (dir / "graph.dot").string() + "' -o '" + (dir / "graph.svg").string() +
                            "' 2>/dev/null";
    if (std::system(cmd.c_str()) != 0) std::fprintf(stderr, "tamp run: graph.svg not written (is graphviz installed?)\n");
  }
  auto report = nlohmann::json::parse(st.report_json(), nullptr, false);
  auto sc = world::loadScenario(o.scenario);
  if (!report.is_discarded() && sc) writeWorldPictures(*sc, report, dir);
  return std::nullopt;
}

int exitCodeOf(const nlohmann::json& report, msg::MissionState state) {
  if (state == msg::MissionState::MISSION_SUCCEEDED) return cli::kExitOk;
  const std::string outcome = report.is_discarded() ? "" : report.value("outcome", "");
  if (outcome == "timeout") return cli::kExitTimeout;
  if (outcome == "input_error") return cli::kExitInputError;
  if (outcome == "unavailable") return cli::kExitServiceError;
  return cli::kExitNoSolution;
}

void printSummary(const nlohmann::json& r) {
  if (r.is_discarded()) return;
  std::printf("\n%-10s %s\n", "status", r.value("status", "?").c_str());
  if (!r.value("reason", "").empty()) std::printf("%-10s %s\n", "reason", r.value("reason", "").c_str());
  std::printf("executed %.1f s, predicted %.1f s, planning %.2f s (%.2f s to the first action), %d replans\n",
              r.value("executed_effort_s", 0.0), r["predicted_effort_s"].is_number() ? r["predicted_effort_s"].get<double>() : 0.0,
              r.value("planning_time_s", 0.0), r.value("planning_time_to_first_action_s", 0.0), r.value("replans", 0));
  std::printf("calls: planner %d, motion %d, placement %d, grasp %d, effort %d; objects moved:", r.value("planner_calls", 0),
              r.value("motion_calls", 0), r.value("placement_calls", 0), r.value("grasp_calls", 0),
              r.value("effort_calls", 0));
  for (const auto& o : r.value("objects_moved", nlohmann::json::array())) std::printf(" %s", o.get<std::string>().c_str());
  std::printf("\n");
  for (const auto& rp : r.value("replanning", nlohmann::json::array())) {
    std::string joined;
    for (const auto& n : rp.value("rejoined", nlohmann::json::array())) joined += " " + n.get<std::string>();
    std::printf("replanned after %s (%s): %s%s at %s, planner %d, motion %d calls, latency %s\n",
                rp.value("event", "").c_str(), rp.value("detail", "").c_str(), rp.value("how", "").c_str(),
                joined.empty() ? "" : (" to" + joined).c_str(), rp.value("at_node", "").c_str(),
                rp.value("planner_calls", 0), rp.value("motion_calls", 0),
                rp["latency_s"].is_number() ? (std::to_string(rp["latency_s"].get<double>()).substr(0, 5) + " s").c_str() : "-");
  }
  for (const auto& c : r.value("conditionals", nlohmann::json::array())) {
    const auto calls = [&](const char* k) { return c[k].is_number() ? std::to_string(c[k].get<int>()) : std::string("-"); };
    std::printf("conditional at %s: %s: %s, planner %s, motion %s calls\n", c.value("at_node", "").c_str(),
                c.value("observation", "").c_str(),
                c.value("prebuilt", false) ? ("prebuilt branch " + c.value("branch_node", std::string())).c_str()
                                           : "no prebuilt branch, replanned",
                calls("planner_calls").c_str(), calls("motion_calls").c_str());
  }
  for (const auto& d : r.value("decisions", nlohmann::json::array())) {
    std::printf("decision at %s:\n", d.value("node", "").c_str());
    const bool observed = d.value("what", "").rfind("observation:", 0) == 0;  // a conditional branch
    if (observed) std::printf("  %s\n", d.value("what", "").c_str());
    for (const auto& a : d["alternatives"]) {
      if (observed)
        std::printf("  %s %s\n", a.value("chosen", false) ? "*" : " ", a.value("alternative", "").c_str());
      else if (a["effort_s"].is_number())
        std::printf("  %s %6.1f s  %s\n", a.value("chosen", false) ? "*" : " ", a["effort_s"].get<double>(),
                    a.value("alternative", "").c_str());
      else if (a.value("cut", false))
        std::printf("  %s >=%5.1f s  %s (cut)\n", " ", a["bound_s"].get<double>(), a.value("alternative", "").c_str());
      else
        std::printf("  %s    -     %s (no complete branch)\n", " ", a.value("alternative", "").c_str());
    }
  }
}

}  // namespace

std::optional<std::string> checkScenario(const std::string& file) {
  if (!fs::exists(file)) return "scenario file does not exist: " + file;
  auto sc = world::loadScenario(file);
  if (!sc) return sc.error().toString();
  auto robot = robot::RobotModel::loadDescription(sc->robot.description);
  if (!robot) return robot.error().toString();
  auto problem = world::toPddlProblem(*sc, *robot);
  if (!problem) return sc->file.string() + ": " + problem.error().toString();
  return std::nullopt;
}

int runMission(const std::shared_ptr<dds::Participant>& p, const MissionOptions& o, const std::function<bool()>& poll) {
  std::mutex m;
  std::condition_variable cv;
  std::optional<msg::MissionStatus> last;
  std::string last_line;
  const std::string id = "mission-" + std::to_string(dds::nowNs());
  dds::Reader<msg::MissionStatus> reader(p, dds::topics::kMissionStatus, [&](const msg::MissionStatus& s, const dds::SampleMeta&) {
    if (s.mission_id() != id) return;
    std::lock_guard g(m);
    if (!s.last_action().empty()) {
      const std::string line = s.last_action() + "|" + std::to_string(s.actions_done()) + s.last_outcome();
      if (line != last_line) {
        last_line = line;
        const double frac = s.predicted_total_s() > 0 ? s.done_predicted_s() / s.predicted_total_s() : 0.0;
        std::printf("  %-44s predicted %6.1f s  measured %6.1f s  %-9s %s %3.0f%%\n", s.last_action().c_str(),
                    s.last_predicted_s(), s.last_measured_s(), s.last_outcome().c_str(), bar(frac, 20).c_str(), 100 * frac);
        std::fflush(stdout);
      }
    } else if (s.state() == msg::MissionState::MISSION_PLANNING || s.state() == msg::MissionState::MISSION_REPLANNING) {
      std::printf("  ... %s\n", s.message().c_str());
      std::fflush(stdout);
    }
    last = s;
    cv.notify_all();
  });
  dds::Writer<msg::MissionCommand> writer(p, dds::topics::kMissionCommand);
  if (!writer.waitForReaders(Termination::after(20.0))) {
    std::fprintf(stderr, "tamp run: no graph manager on this domain\n");
    return cli::kExitServiceError;
  }
  msg::MissionCommand c;
  c.mission_id(id);
  c.scenario_path(o.scenario);
  c.policy(o.policy == "infeasible" ? msg::EffortPolicy::POLICY_INFEASIBILITY_ONLY
           : o.policy == "oracle"   ? msg::EffortPolicy::POLICY_ORACLE
                                    : msg::EffortPolicy::POLICY_EFFORT_BASED);
  c.seed(o.seed);
  std::printf("\ntamp run: mission %s, scenario %s, policy %s\n", id.c_str(), o.scenario.c_str(), o.policy.c_str());
  std::fflush(stdout);
  if (Status s = writer.write(c); !s) {
    std::fprintf(stderr, "tamp run: %s\n", s.error().message.c_str());
    return cli::kExitServiceError;
  }
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(o.timeout_s);
  // Out of time or stopped: the mission is aborted, and its report (what was done, what was
  // planned) is still written when the graph manager answers within kAbortWait.
  constexpr auto kAbortWait = std::chrono::seconds(30);
  bool timed_out = false;
  std::unique_lock lock(m);
  auto abortAndWait = [&] {
    lock.unlock();
    msg::MissionCommand abort = c;
    abort.abort(true);
    (void)writer.write(abort);
    lock.lock();
    return cv.wait_for(lock, kAbortWait, [&] { return last && isFinal(last->state()); });
  };
  while (!(last && isFinal(last->state()))) {
    if (std::chrono::steady_clock::now() > deadline) {
      std::fprintf(stderr, "tamp run: the mission did not end within %.0f s: aborting it (its report follows)\n",
                   o.timeout_s);
      timed_out = true;
      if (!abortAndWait()) {
        std::fprintf(stderr, "tamp run: no report: the graph manager did not answer the abort\n");
        return cli::kExitTimeout;
      }
      break;
    }
    cv.wait_for(lock, std::chrono::milliseconds(100));
    lock.unlock();
    const bool stop = poll();
    lock.lock();
    if (stop && !abortAndWait()) return cli::kExitServiceError;
  }
  const msg::MissionStatus final_status = *last;
  lock.unlock();
  const auto written = writeArtefacts(final_status, o);
  const auto report = nlohmann::json::parse(final_status.report_json(), nullptr, false);
  printSummary(report);
  if (written) {
    std::fprintf(stderr, "tamp run: the report was not written: %s\n", written->c_str());
    return cli::kExitOutputError;
  }
  std::printf("tamp run: report, graph and pictures in %s\n", o.out_dir.c_str());
  if (!o.latest_dir.empty())
    std::printf("tamp run: report also at %s (%s -> this run)\n", (o.latest_dir / "report.json").c_str(),
                (o.latest_dir / "latest").c_str());
  return timed_out ? cli::kExitTimeout : exitCodeOf(report, final_status.state());
}

}  // namespace tamp::runner
