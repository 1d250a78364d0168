// `tamp render SCENARIO -o out.png`: a top-down picture of a scenario (YAML) or of a NAMO
// benchmark world (.json / bare .svg): objects (hidden ones dashed red), regions, locations, the
// robot at its start and at its goal, and optional paths from a JSON file.
#include <fstream>
#include <iostream>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include "cli_common.h"
#include "tamp/core/paths.h"
#include "tamp/render/render.h"
#include "tamp/robot/robot_model.h"
#include "tamp/world/scenario.h"

namespace {

// [{"label": "plan", "colour": "#1f77b4", "dashed": false, "poses": [[x, y, theta], ...]}, ...]
tamp::Result<std::vector<tamp::render::PathOverlay>> readPaths(const std::string& file) {
  using tamp::Error;
  using tamp::ErrorCode;
  auto text = tamp::readTextFile(file);
  if (!text) return text.error();
  std::vector<tamp::render::PathOverlay> out;
  try {
    const auto j = nlohmann::json::parse(*text);
    if (!j.is_array())
      return Error(ErrorCode::kParseError, "expected a list of paths", tamp::SourceLocation{file});
    for (size_t i = 0; i < j.size(); ++i) {
      const auto& p = j[i];
      const std::string field = "[" + std::to_string(i) + "]";
      tamp::render::PathOverlay o;
      if (!p.is_object() || !p.contains("poses") || !p["poses"].is_array()) {
        return Error(ErrorCode::kParseError, "expected {\"poses\": [[x, y, theta], ...]}",
                     tamp::SourceLocation{file, 0, 0, field});
      }
      for (const auto& q : p["poses"]) {
        if (!q.is_array() || q.size() < 2 || q.size() > 3 || !q[0].is_number() ||
            !q[1].is_number() || (q.size() == 3 && !q[2].is_number())) {
          return Error(ErrorCode::kParseError, "a pose is [x, y] or [x, y, theta]",
                       tamp::SourceLocation{file, 0, 0, field + ".poses"});
        }
        o.poses.push_back(
            {q[0].get<double>(), q[1].get<double>(), q.size() == 3 ? q[2].get<double>() : 0.0});
      }
      if (p.contains("label") && p["label"].is_string()) o.label = p["label"].get<std::string>();
      if (p.contains("dashed") && p["dashed"].is_boolean()) o.dashed = p["dashed"].get<bool>();
      if (p.contains("colour") && p["colour"].is_string()) {
        auto c = tamp::render::Rgba::fromHex(p["colour"].get<std::string>());
        if (!c)
          return Error(ErrorCode::kParseError, "colour must be #rrggbb",
                       tamp::SourceLocation{file, 0, 0, field + ".colour"});
        o.colour = *c;
      }
      out.push_back(std::move(o));
    }
  } catch (const nlohmann::json::exception& e) {
    return Error(ErrorCode::kParseError, std::string("invalid JSON: ") + e.what(),
                 tamp::SourceLocation{file});
  }
  return out;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Draw a scenario or a NAMO world top-down (PNG or SVG)."};
  std::string scenario_file, output, paths_file;
  tamp::render::RenderOptions opt;
  bool no_hidden = false, no_labels = false, no_grid = false;
  app.add_option("scenario", scenario_file, "scenario YAML, or a NAMO world (.json / bare .svg)")
      ->required();
  app.add_option("-o,--output", output, "output picture (.png or .svg)")->required();
  app.add_option("--paths", paths_file,
                 "JSON list of paths to draw: [{label, colour, poses: [[x, y, theta]...]}]");
  app.add_option("--ppm", opt.pixels_per_metre, "pixels per metre (reduced to fit --max-pixels)");
  app.add_option("--max-pixels", opt.max_pixels, "longest side of the picture");
  app.add_flag("--no-hidden", no_hidden, "leave out objects only the simulator knows");
  app.add_flag("--no-labels", no_labels, "no text labels");
  app.add_flag("--no-grid", no_grid, "no 1 m grid");
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return e.get_exit_code() == 0 ? app.exit(e) : (app.exit(e), tamp::cli::kExitInputError);
  }
  opt.show_hidden = !no_hidden;
  opt.show_labels = !no_labels;
  opt.show_grid = !no_grid;

  auto sc = tamp::world::loadScenario(scenario_file);
  if (!sc) {
    std::cerr << sc.error().toString() << "\n";
    return tamp::cli::kExitInputError;
  }
  for (const auto& w : sc->warnings) std::cerr << "warning: " << w << "\n";
  auto robot = tamp::robot::RobotModel::loadDescription(sc->robot.description);
  if (!robot) {
    std::cerr << robot.error().toString() << "\n";
    return tamp::cli::kExitInputError;
  }
  tamp::render::Drawing d;
  d.world = sc->world;
  d.title = sc->name + (sc->description.empty() ? "" : ": " + sc->description);
  tamp::render::Footprint start;
  start.polygon = robot->baseFootprint();
  start.pose = sc->robot.start;
  start.label = "robot";
  d.robots.push_back(start);
  if (sc->goal.base) {
    tamp::render::Footprint goal = start;
    goal.pose = *sc->goal.base;
    goal.label = "goal";
    goal.dashed = true;
    goal.colour = {0.10, 0.60, 0.20, 1.0};
    d.robots.push_back(goal);
  }
  if (!paths_file.empty()) {
    auto paths = readPaths(paths_file);
    if (!paths) {
      std::cerr << paths.error().toString() << "\n";
      return tamp::cli::kExitInputError;
    }
    for (auto& p : *paths) {
      p.footprint = robot->baseFootprint();
      d.paths.push_back(std::move(p));
    }
  }
  const tamp::Status s = tamp::render::render(d, output, opt);
  tamp::render::releaseFontCaches();
  if (!s) {
    std::cerr << s.error().toString() << "\n";
    return tamp::cli::kExitInputError;
  }
  std::cout << output << "\n";
  return tamp::cli::kExitOk;
}
