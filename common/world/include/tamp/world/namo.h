#pragma once
/// @file
/// Loader for the NAMO benchmark worlds of `tests/data/benchmarks/namo/` (see its README.md and
/// REFERENCE.md) into the world model, extruded to 3-D, with the robot's start and goals.
///
/// Two formats:
/// - **JSON + SVG** (namosim's older format): the JSON names entities (robot, walls, movable
///   types) whose geometry is an SVG `<path>` by id. Metric scale s = geometry_scale / 3.5433
///   m per SVG user unit (= geometry_scale with `no_scaling_workaround`). An entity is movable
///   iff its type is in the robot's `movable_whitelist` (the README's authoritative rule).
/// - **Bare SVG** (the 19 Moghaddam figures): fill #e6e6e6 static, #00ff00 robot start, #ff0000
///   goal, any other fill movable. Scaled so that the green robot square's side (square root of
///   its area) is `bare_robot_side` (0.5 m by default, REFERENCE.md's convention); the robot is
///   then a disc of radius side/sqrt(2) (0.354 m).
///
/// Frame: x = s*u, y = -s*v for SVG user coordinates (u, v) after all transforms, without
/// namosim's centring (the README's reference-pose frame). Cubic/quadratic Bezier segments are
/// flattened into `curve_segments` lines. Poses: the start is the robot polygon's area
/// centroid, its heading the direction of the 2-point `orientation_id` path (0 without one);
/// goals likewise. Angles are radians in [-pi, pi) (the README gives degrees).
///
/// Extrusion rule (documented in docs/scenarios.md): every obstacle is a prism whose polygon is
/// relative to its area centroid, standing on the floor (pose z = height/2). Heights: walls,
/// pillars and bare static obstacles `wall_height` (1.0 m); by type: box 0.5, chair 0.9,
/// stool 0.45, table 0.75, sofa 0.8, cabinet 1.2, bed 0.5, other/bare movables
/// `movable_height` (0.5 m). Mass of a movable = `density` (60 kg/m^3) x footprint area x
/// height, clamped to [1, `max_mass`] kg. A NAMO world's movables are, by the benchmark's own
/// rule, movable by its robot; the masses are this loader's assumption, so a scenario caps them
/// at the most its robot can move (the larger of its payload and push limit). Graspable iff mass <= `max_graspable_mass` -- the robot's
/// payload when a scenario loads the world (tamp::robot::RobotModel::payload(), 25 kg for the
/// shipped robot) -- the PDDL domain moves objects by pick and place only, so "graspable" means
/// "can be moved".
/// Ids: entity names lower-cased (bare SVGs: `wall_NN`, `movable_NN` in document order, the SVG
/// id in the label). The world also gets a `floor` region over the drawing's extent and
/// locations `start` and one per goal (the goal's id, or `goal` for bare SVGs).

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "tamp/core/error.h"
#include "tamp/core/geometry.h"
#include "tamp/world/world.h"

namespace tamp::world {

struct NamoOptions {
  double wall_height{1.0};             ///< m, walls, pillars and bare static obstacles
  double movable_height{0.5};          ///< m, movables of unknown type and bare movables
  double density{60.0};                ///< kg/m^3, mass rule for movables
  /// kg: the heaviest a movable is made. The scenario loader sets it to the most the robot can
  /// move (max of payload and push limit: the benchmark's movables are movable); a scenario may
  /// set it higher, and heavier movables are then ones this robot cannot move. 150 kg for direct
  /// callers.
  double max_mass{150.0};
  /// kg: heavier movables are not graspable. The scenario loader sets it to the robot's payload
  /// and refuses a larger value; 25 kg (the shipped robot's payload) for direct callers.
  double max_graspable_mass{25.0};
  double bare_robot_side{0.5};         ///< m, bare SVGs: side of the robot square
  std::optional<double> scale;         ///< m per SVG user unit; overrides every other rule
  std::optional<double> robot_radius;  ///< m: scale so the benchmark robot's circumradius
                                       ///< (bare SVGs: side/sqrt(2)) equals this
  std::string robot;                   ///< JSON: the robot entity to use; empty = the first one
  int curve_segments{8};               ///< lines per Bezier curve
  /// Empty when usable; else why not (names the option).
  std::optional<std::string> invalidReason() const;
};

struct NamoGoal {
  std::string id;  ///< location id in the world
  Pose2D pose;     ///< centroid + heading (0 when the goal has no orientation)
  bool has_orientation{false};
};

struct NamoWorld {
  World world;           ///< walls static, obstacles movable, floor region, locations
  std::string robot_id;  ///< e.g. "robot_01"
  Pose2D start;          ///< robot start (base pose)
  bool start_has_orientation{false};
  std::vector<NamoGoal> goals;        ///< in the order they are to be visited
  Polygon2 robot_footprint;           ///< robot polygon relative to its centroid (world axes), m
  double robot_radius{0.0};           ///< m, circumradius (bare SVGs: side/sqrt(2))
  double scale{0.0};                  ///< m per SVG user unit
  std::string source;                 ///< the file loaded
  std::vector<std::string> warnings;  ///< skipped entities, broken goals, ... (file:line: ...)
};

/// Loads a `.json` world (with its SVG) or a bare `.svg` world. Errors name the file, line and
/// field or element: kNotFound/kIo, kParseError (JSON/XML/path syntax), kInvalidArgument
/// (missing robot, missing geometry file, bad options).
Result<NamoWorld> loadNamo(const std::filesystem::path& file, const NamoOptions& options = {});
/// A bare (colour-convention) SVG world from text; `name` is used as the file name in messages.
Result<NamoWorld> parseNamoBareSvg(const std::string& svg_text, const std::string& name,
                                   const NamoOptions& options = {});
/// A JSON + SVG world from texts; `json_name`/`svg_name` are used in messages.
Result<NamoWorld> parseNamoJson(const std::string& json_text, const std::string& json_name,
                                const std::string& svg_text, const std::string& svg_name,
                                const NamoOptions& options = {});

}  // namespace tamp::world
