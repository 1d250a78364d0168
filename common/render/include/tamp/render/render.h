#pragma once
/// @file
/// Top-down pictures of a world (PNG or SVG, through Cairo): static, movable and hidden objects in
/// distinct styles, support regions, named locations, robot footprints and paths with labels.
/// Used by `tamp render` and later by the mission reports.
///
/// Styles (see docs/world.md for a legend): static objects dark grey; movable objects orange
/// (label with the mass); hidden objects (simulator only) red dashed outline without fill;
/// the held object in the robot's colour; table regions light brown, floor regions light green
/// (dashed outline); locations as small arrows; robot footprints as outlines with a heading
/// tick; paths as polylines in their colour with the label at the end. A 1 m grid and a scale
/// bar give the metric scale. World frame: x to the right, y up.
///
/// Objects are drawn by their footprint (shape outline projected on the floor at their pose;
/// non-upright shapes by their bounding box), lowest top first, so items on a table appear on it.

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "tamp/core/error.h"
#include "tamp/core/geometry.h"
#include "tamp/world/polygon.h"
#include "tamp/world/world.h"

namespace tamp::render {

struct Rgba {
  double r{0.0}, g{0.0}, b{0.0}, a{1.0};  ///< each in [0, 1]
  /// "#rrggbb" or "#rrggbbaa"; nullopt when malformed.
  static std::optional<Rgba> fromHex(const std::string& hex);
};

/// A robot outline at a pose (e.g. the start, the goal, or states along a path).
struct Footprint {
  world::Polygon2 polygon;  ///< in the robot's base frame, m
  Pose2D pose;
  Rgba colour{0.10, 0.35, 0.85, 1.0};
  std::string label;
  bool dashed{false};
};

/// A planar path (base poses) drawn as a polyline.
struct PathOverlay {
  std::vector<Pose2D> poses;
  Rgba colour{0.10, 0.35, 0.85, 1.0};
  std::string label;
  double width_px{2.5};
  bool dashed{false};
  /// When > 0 and a footprint polygon is given, the footprint is drawn every this many metres.
  double footprint_every_m{0.0};
  world::Polygon2 footprint;
};

/// What to draw. The world is held by value (cheap to copy).
struct Drawing {
  world::World world;
  std::vector<Footprint> robots;
  std::vector<PathOverlay> paths;
  std::string title;
};

struct RenderOptions {
  double pixels_per_metre{120.0};  ///< reduced when the picture would exceed `max_pixels`
  int max_pixels{2400};            ///< longest side of the picture, px
  double margin_m{0.4};            ///< around the view
  bool show_hidden{true};
  bool show_labels{true};
  bool show_regions{true};
  bool show_locations{true};
  bool show_grid{true};
  std::optional<Aabb> view;  ///< area to draw (xy); default: the world's bounds, robots, paths
  /// Empty when usable; else why not.
  std::optional<std::string> invalidReason() const;
};

/// Writes a PNG. kIo when the file cannot be written; kInvalidArgument for bad options or an
/// empty view.
Status renderPng(const Drawing& drawing, const std::filesystem::path& file,
                 const RenderOptions& options = {});
/// Writes an SVG (vector; same content as the PNG).
Status renderSvg(const Drawing& drawing, const std::filesystem::path& file,
                 const RenderOptions& options = {});
/// PNG or SVG by the file's extension (.png / .svg); kInvalidArgument otherwise.
Status render(const Drawing& drawing, const std::filesystem::path& file,
              const RenderOptions& options = {});

/// Releases Cairo's and fontconfig's process-wide font caches. Call once at the end of a process
/// that rendered (so leak checkers report only real leaks); no rendering may follow.
void releaseFontCaches();

/// The outline an object is drawn with (world xy): its upright footprint, or its bounding box.
world::Polygon2 objectOutline(const world::Object& object);

}  // namespace tamp::render
