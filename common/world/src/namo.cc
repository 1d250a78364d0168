#include "tamp/world/namo.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <map>
#include <set>
#include <sstream>

#include <nlohmann/json.hpp>

#include "svg.h"
#include "tamp/core/paths.h"

namespace tamp::world {

namespace {

constexpr double kNamosimScaling = 3.5433;  // 90-dpi px per mm (namosim World.SCALING_CONSTANT)

std::string num(double v) {
  std::ostringstream os;
  os << v;
  return os.str();
}

/// A valid world id from a benchmark name: lower case, invalid characters to '_'.
std::string sanitiseId(const std::string& name, const std::string& fallback) {
  std::string id;
  for (char c : name) {
    const char l = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    id += ((l >= 'a' && l <= 'z') || (l >= '0' && l <= '9') || l == '_' || l == '-') ? l : '_';
  }
  if (id.empty()) id = fallback;
  if (id[0] < 'a' || id[0] > 'z') id = "o_" + id;
  if (id.size() > 64) id.resize(64);
  return id;
}

double heightForType(const std::string& type, const NamoOptions& o) {
  static const std::map<std::string, double> kHeights{
      {"box", 0.5},  {"chair", 0.9},   {"stool", 0.45}, {"table", 0.75},
      {"sofa", 0.8}, {"cabinet", 1.2}, {"bed", 0.5}};
  if (type == "wall" || type == "pillar") return o.wall_height;
  auto it = kHeights.find(type);
  return it != kHeights.end() ? it->second : o.movable_height;
}

Eigen::Vector2d toWorld(const Eigen::Vector2d& uv, double s) {
  return Eigen::Vector2d(s * uv.x(), -s * uv.y());
}

Polygon2 toWorld(const Polygon2& uv, double s) {
  Polygon2 out;
  out.reserve(uv.size());
  for (const auto& p : uv) out.push_back(toWorld(p, s));
  return out;
}

/// Heading of a 2-point direction path (first -> last point, world frame).
std::optional<double> headingOf(const svg::Element& e, double s) {
  if (e.points.size() < 2) return std::nullopt;
  const Eigen::Vector2d d = toWorld(e.points.back(), s) - toWorld(e.points.front(), s);
  if (d.norm() <= 0) return std::nullopt;
  return wrapAngle(std::atan2(d.y(), d.x()));
}

struct Builder {
  const NamoOptions& opt;
  NamoWorld out;
  Aabb extent;
  std::map<std::string, int> used_ids;

  std::string uniqueId(std::string id) {
    const int n = used_ids[id]++;
    if (n == 0) return id;
    return id + "_" + std::to_string(n + 1);
  }

  /// Adds an extruded obstacle; degenerate outlines become warnings.
  void addObstacle(const std::string& id_in, const std::string& label, ObjectKind kind,
                   const Polygon2& world_pts, double height, const std::string& where) {
    const Polygon2 clean = cleanPolygon(world_pts);
    for (const auto& p : world_pts) extent.extend(Eigen::Vector3d(p.x(), p.y(), 0.0));
    if (clean.size() < 3 || std::abs(signedArea(clean)) < 1e-10) {
      out.warnings.push_back(where + ": '" + id_in + "' has no area (" +
                             std::to_string(world_pts.size()) + " points); skipped");
      return;
    }
    const Eigen::Vector2d c = areaCentroid(clean);
    Polygon2 local;
    local.reserve(clean.size());
    for (const auto& p : clean) local.push_back(p - c);
    Object o;
    o.id = uniqueId(id_in);
    o.label = label;
    o.kind = kind;
    o.shape = Shape::prism(std::move(local), height);
    o.pose.translation() = Eigen::Vector3d(c.x(), c.y(), 0.5 * height);
    if (kind == ObjectKind::kMovable) {
      o.mass = std::clamp(opt.density * std::abs(signedArea(clean)) * height, 1.0, std::max(1.0, opt.max_mass));
      o.graspable = o.mass <= opt.max_graspable_mass;
      o.region = "floor";
    }
    extent.extend(Eigen::Vector3d(c.x(), c.y(), height));
    if (Status s = out.world.addObject(std::move(o)); !s) {
      out.warnings.push_back(where + ": " + s.error().message + "; skipped");
    }
  }

  void setRobot(const Polygon2& world_pts, std::optional<double> heading) {
    const Polygon2 clean = cleanPolygon(world_pts);
    const Eigen::Vector2d c = areaCentroid(clean.size() >= 3 ? clean : world_pts);
    out.start = Pose2D{c.x(), c.y(), heading.value_or(0.0)};
    out.start_has_orientation = heading.has_value();
    out.robot_footprint.clear();
    for (const auto& p : clean) out.robot_footprint.push_back(p - c);
    out.robot_radius = circumradius(out.robot_footprint, Eigen::Vector2d::Zero());
    for (const auto& p : world_pts) extent.extend(Eigen::Vector3d(p.x(), p.y(), 0.0));
  }

  void addGoal(const std::string& id, const Polygon2& world_pts, std::optional<double> heading) {
    const Polygon2 clean = cleanPolygon(world_pts);
    const Eigen::Vector2d c = areaCentroid(clean.size() >= 3 ? clean : world_pts);
    out.goals.push_back(
        NamoGoal{id, Pose2D{c.x(), c.y(), heading.value_or(0.0)}, heading.has_value()});
    for (const auto& p : world_pts) extent.extend(Eigen::Vector3d(p.x(), p.y(), 0.0));
  }

  /// Floor region, workspace and locations.
  Status finish() {
    if (extent.empty()) return Error(ErrorCode::kInvalidArgument, "the world has no geometry");
    Region floor;
    floor.id = "floor";
    floor.label = "floor";
    floor.kind = RegionKind::kFloor;
    floor.polygon = {{extent.min.x(), extent.min.y()},
                     {extent.max.x(), extent.min.y()},
                     {extent.max.x(), extent.max.y()},
                     {extent.min.x(), extent.max.y()}};
    floor.height = 0.0;
    if (Status s = out.world.addRegion(floor); !s) return s;
    Aabb ws = extent;
    ws.min.z() = 0.0;
    ws.max.z() = std::max(ws.max.z(), opt.wall_height);
    out.world.setWorkspace(ws);
    if (Status s = out.world.addLocation(Location{"start", "robot start", out.start}); !s) return s;
    for (const auto& g : out.goals) {
      if (out.world.findLocation(g.id) != nullptr) continue;
      if (Status s = out.world.addLocation(Location{g.id, "goal", g.pose}); !s) return s;
    }
    return Status::Ok();
  }
};

Status validateOptions(const NamoOptions& o) {
  if (auto why = o.invalidReason()) return Error(ErrorCode::kInvalidArgument, *why);
  return Status::Ok();
}

// ---- JSON helpers (every error names the field path)
// ---------------------------------------------

struct JsonCtx {
  const std::string& file;
  std::vector<Error> errors;
  void fail(const std::string& field, const std::string& msg) {
    errors.emplace_back(ErrorCode::kInvalidArgument, msg, SourceLocation{file, 0, 0, field});
  }
  const nlohmann::json* get(const nlohmann::json& j, const std::string& key,
                            const std::string& path, bool required, nlohmann::json::value_t type) {
    const std::string field = path.empty() ? key : path + "." + key;
    if (!j.is_object() || !j.contains(key)) {
      if (required) fail(field, "missing required field");
      return nullptr;
    }
    const nlohmann::json& v = j.at(key);
    const bool ok =
        type == nlohmann::json::value_t::number_float ? v.is_number() : v.type() == type;
    if (!ok) {
      fail(field, std::string("expected ") +
                      (type == nlohmann::json::value_t::string    ? "a string"
                       : type == nlohmann::json::value_t::object  ? "an object"
                       : type == nlohmann::json::value_t::array   ? "a list"
                       : type == nlohmann::json::value_t::boolean ? "true or false"
                                                                  : "a number") +
                      ", got " + v.type_name());
      return nullptr;
    }
    return &v;
  }
};

}  // namespace

std::optional<std::string> NamoOptions::invalidReason() const {
  auto pos = [](double v) { return std::isfinite(v) && v > 0; };
  if (!pos(wall_height)) return "wall_height must be positive, got " + num(wall_height);
  if (!pos(movable_height)) return "movable_height must be positive, got " + num(movable_height);
  if (!pos(density)) return "density must be positive, got " + num(density);
  if (!(std::isfinite(max_mass) && max_mass >= 1.0)) return "max_mass must be >= 1 kg, got " + num(max_mass);
  if (!(max_graspable_mass >= 0))
    return "max_graspable_mass must be >= 0, got " + num(max_graspable_mass);
  if (!pos(bare_robot_side)) return "bare_robot_side must be positive, got " + num(bare_robot_side);
  if (scale && !pos(*scale)) return "scale must be positive, got " + num(*scale);
  if (robot_radius && !pos(*robot_radius))
    return "robot_radius must be positive, got " + num(*robot_radius);
  if (scale && robot_radius) return "give either scale or robot_radius, not both";
  if (curve_segments < 1 || curve_segments > 64)
    return "curve_segments must be in [1, 64], got " + std::to_string(curve_segments);
  return std::nullopt;
}

// ---- bare SVG
// ------------------------------------------------------------------------------------

Result<NamoWorld> parseNamoBareSvg(const std::string& svg_text, const std::string& name,
                                   const NamoOptions& options) {
  if (Status s = validateOptions(options); !s) return s.error();
  svg::Options so;
  so.curve_segments = options.curve_segments;
  auto doc = svg::parse(svg_text, name, so);
  if (!doc) return doc.error();
  const svg::Element* robot = nullptr;
  std::vector<const svg::Element*> goals, statics, movables;
  int robots = 0;
  std::vector<std::string> ignored;
  for (const auto& e : doc->elements) {
    if (e.fill == "#00ff00") {
      ++robots;
      if (robot == nullptr) robot = &e;
    } else if (e.fill == "#ff0000") {
      goals.push_back(&e);
    } else if (e.fill == "#e6e6e6") {
      statics.push_back(&e);
    } else if (e.fill == "none" || e.fill == "transparent") {
      ignored.push_back(name + ":" + std::to_string(e.line) + ": <" + e.tag + " id='" + e.id +
                        "'> has no fill; ignored");
    } else {
      movables.push_back(&e);
    }
  }
  if (robots != 1 || goals.empty()) {
    return Error(ErrorCode::kInvalidArgument,
                 "a bare NAMO SVG needs exactly one robot square (fill #00ff00) and at least one "
                 "goal (fill #ff0000), "
                 "found " +
                     std::to_string(robots) + " and " + std::to_string(goals.size()),
                 SourceLocation{name, 0, 0, ""});
  }
  const double side_units = std::sqrt(std::abs(signedArea(cleanPolygon(robot->points))));
  if (!(side_units > 0)) {
    return Error(ErrorCode::kInvalidArgument, "the robot square (fill #00ff00) has no area",
                 SourceLocation{name, robot->line, 0, ""});
  }
  double s = options.bare_robot_side / side_units;
  if (options.scale) s = *options.scale;
  if (options.robot_radius) s = *options.robot_radius / (side_units / std::sqrt(2.0));
  Builder b{options, {}, {}, {}};
  b.out.source = name;
  b.out.scale = s;
  b.out.world.setName(std::filesystem::path(name).stem().string());
  b.out.warnings = doc->warnings;
  b.out.warnings.insert(b.out.warnings.end(), ignored.begin(), ignored.end());
  b.out.robot_id = "robot";
  b.setRobot(toWorld(robot->points, s), std::nullopt);
  b.out.robot_radius = side_units * s / std::sqrt(2.0);  // the disc of REFERENCE.md
  for (size_t k = 0; k < goals.size(); ++k) {
    b.addGoal(goals.size() == 1 ? "goal" : "goal_" + std::to_string(k + 1),
              toWorld(goals[k]->points, s), std::nullopt);
  }
  auto label = [](const svg::Element* e, const char* what) {
    return std::string(what) + (e->id.empty() ? "" : " (svg " + e->id + ")");
  };
  char buf[32];
  for (size_t k = 0; k < statics.size(); ++k) {
    std::snprintf(buf, sizeof buf, "wall_%02zu", k + 1);
    b.addObstacle(buf, label(statics[k], "static obstacle"), ObjectKind::kStatic,
                  toWorld(statics[k]->points, s), options.wall_height,
                  name + ":" + std::to_string(statics[k]->line));
  }
  for (size_t k = 0; k < movables.size(); ++k) {
    std::snprintf(buf, sizeof buf, "movable_%02zu", k + 1);
    b.addObstacle(buf, label(movables[k], "movable obstacle"), ObjectKind::kMovable,
                  toWorld(movables[k]->points, s), options.movable_height,
                  name + ":" + std::to_string(movables[k]->line));
  }
  if (Status st = b.finish(); !st)
    return Error(st.error().code, st.error().message, SourceLocation{name, 0, 0, ""});
  return std::move(b.out);
}

// ---- JSON + SVG
// ----------------------------------------------------------------------------------

namespace {

/// nlohmann's parse error `e`, at its line and column of `json_text`.
Error jsonParseError(const nlohmann::json::parse_error& e, const std::string& json_text,
                     const std::string& json_name) {
  // Byte offset -> line and column.
  const size_t upto = std::min<size_t>(e.byte > 0 ? e.byte - 1 : 0, json_text.size());
  const int line = 1 + static_cast<int>(std::count(
                           json_text.begin(), json_text.begin() + static_cast<long>(upto), '\n'));
  const size_t nl = json_text.rfind('\n', upto == 0 ? 0 : upto - 1);
  const int col = static_cast<int>(upto - (nl == std::string::npos ? 0 : nl + 1)) + 1;
  std::string what = e.what();
  const auto p = what.find("parse error");
  if (p != std::string::npos) {
    const auto colon = what.find(": ", what.find(": ", p) + 2);
    if (colon != std::string::npos) what = what.substr(colon + 2);
  }
  return Error(ErrorCode::kParseError, "invalid JSON: " + what,
               SourceLocation{json_name, line, col, ""});
}

/// Several errors found in one pass as one: the first's code, every message.
Error joinedErrors(const std::vector<Error>& errors) {
  return errors.size() == 1 ? errors.front() : Error(errors.front().code, joinErrors(errors));
}

/// An element of `things.entities`.
struct Entity {
  std::string name, type, geom_id, orient_id, field;
  std::vector<std::string> whitelist;
};

/// `things.entities`; errors in `cx`.
std::vector<Entity> readEntities(JsonCtx& cx, const nlohmann::json* entities) {
  using VT = nlohmann::json::value_t;
  std::vector<Entity> ents;
  for (size_t i = 0; i < entities->size(); ++i) {
    const std::string path = "things.entities[" + std::to_string(i) + "]";
    const nlohmann::json& e = (*entities)[i];
    if (!e.is_object()) {
      cx.fail(path, std::string("expected an object, got ") + e.type_name());
      continue;
    }
    Entity en;
    en.field = path;
    if (auto* v = cx.get(e, "name", path, true, VT::string)) en.name = v->get<std::string>();
    if (auto* v = cx.get(e, "type", path, true, VT::string)) en.type = v->get<std::string>();
    if (auto* g = cx.get(e, "geometry", path, true, VT::object)) {
      if (auto* v = cx.get(*g, "id", path + ".geometry", true, VT::string))
        en.geom_id = v->get<std::string>();
      if (auto* v = cx.get(*g, "orientation_id", path + ".geometry", false, VT::string))
        en.orient_id = v->get<std::string>();
    }
    if (auto* wl = cx.get(e, "movable_whitelist", path, false, VT::array)) {
      for (size_t k = 0; k < wl->size(); ++k) {
        if ((*wl)[k].is_string())
          en.whitelist.push_back((*wl)[k].get<std::string>());
        else
          cx.fail(path + ".movable_whitelist[" + std::to_string(k) + "]", "expected a string");
      }
    }
    ents.push_back(std::move(en));
  }
  return ents;
}

/// Every entity but `robot` as an obstacle of `b` at scale `s`: another robot is static, the
/// types on the robot's whitelist are movable.
void addObstacles(Builder& b, const std::vector<Entity>& ents, const Entity* robot,
                  const std::map<std::string, const svg::Element*>& by_id, double s,
                  const std::string& json_name, const std::string& svg_name,
                  const NamoOptions& options) {
  const std::set<std::string> whitelist(robot->whitelist.begin(), robot->whitelist.end());
  for (const auto& e : ents) {
    if (&e == robot) continue;
    auto it = by_id.find(e.geom_id);
    if (it == by_id.end()) {
      b.out.warnings.push_back(json_name + ": " + e.field + ": could not find geometry '" +
                               e.geom_id + "' of '" + e.name + "' in " + svg_name + "; skipped");
      continue;
    }
    const std::string where = svg_name + ":" + std::to_string(it->second->line);
    if (e.type == "robot") {
      b.out.warnings.push_back(json_name + ": " + e.field + ": other robot '" + e.name +
                               "' becomes a static obstacle");
      b.addObstacle(sanitiseId(e.name, "robot"), "robot (other agent)", ObjectKind::kStatic,
                    toWorld(it->second->points, s), options.wall_height, where);
      continue;
    }
    const bool movable = whitelist.count(e.type) != 0;
    b.addObstacle(sanitiseId(e.name, "object"), e.type + " (svg " + e.geom_id + ")",
                  movable ? ObjectKind::kMovable : ObjectKind::kStatic,
                  toWorld(it->second->points, s), heightForType(e.type, options), where);
  }
}

/// `things.zones.goals` at scale `s`: every goal for a single robot, else goal_k for robot_k;
/// errors in `cx`.
void addGoals(Builder& b, JsonCtx& cx, const nlohmann::json* things, const Entity* robot,
              const std::vector<const Entity*>& robots,
              const std::map<std::string, const svg::Element*>& by_id, double s,
              const std::string& json_name) {
  using VT = nlohmann::json::value_t;
  std::string robot_suffix;
  {
    const auto us = robot->name.find_last_of('_');
    if (us != std::string::npos) robot_suffix = robot->name.substr(us + 1);
  }
  const nlohmann::json* zones = cx.get(*things, "zones", "things", false, VT::object);
  const nlohmann::json* goals =
      zones ? cx.get(*zones, "goals", "things.zones", false, VT::array) : nullptr;
  for (size_t i = 0; goals != nullptr && i < goals->size(); ++i) {
    const std::string path = "things.zones.goals[" + std::to_string(i) + "]";
    const nlohmann::json& g = (*goals)[i];
    std::string gname, gid, orient;
    if (!g.is_object()) {
      cx.fail(path, "expected an object");
      continue;
    }
    if (g.contains("name") && g["name"].is_string()) gname = g["name"].get<std::string>();
    if (const nlohmann::json* geo = cx.get(g, "geometry", path, false, VT::object)) {
      if (auto* v = cx.get(*geo, "id", path + ".geometry", true, VT::string))
        gid = v->get<std::string>();
      if (auto* v = cx.get(*geo, "orientation_id", path + ".geometry", false, VT::string))
        orient = v->get<std::string>();
    }
    if (gname.empty()) gname = gid;
    if (robots.size() > 1) {
      const auto us = gname.find_last_of('_');
      if (us == std::string::npos || gname.substr(us + 1) != robot_suffix) continue;
    }
    if (const nlohmann::json* pose = cx.get(g, "pose", path, false, VT::array)) {
      if (pose->size() == 3 && (*pose)[0].is_number() && (*pose)[1].is_number() &&
          (*pose)[2].is_number()) {
        const Pose2D p{(*pose)[0].get<double>(), (*pose)[1].get<double>(),
                       wrapAngle((*pose)[2].get<double>() * M_PI / 180.0)};
        b.out.goals.push_back(NamoGoal{sanitiseId(gname, "goal"), p, true});
        b.extent.extend(Eigen::Vector3d(p.x, p.y, 0));
      } else {
        cx.fail(path + ".pose", "expected [x, y, theta_degrees]");
      }
      continue;
    }
    auto git = by_id.find(gid);
    if (gid.empty() || git == by_id.end()) {
      b.out.warnings.push_back(json_name + ": " + path + ": goal '" + gname +
                               "': no SVG element '" + gid + "'; skipped");
      continue;
    }
    std::optional<double> gh;
    if (!orient.empty()) {
      auto oit = by_id.find(orient);
      if (oit != by_id.end()) gh = headingOf(*oit->second, s);
    }
    b.addGoal(sanitiseId(gname, "goal"), toWorld(git->second->points, s), gh);
  }
}

}  // namespace

Result<NamoWorld> parseNamoJson(const std::string& json_text, const std::string& json_name,
                                const std::string& svg_text, const std::string& svg_name,
                                const NamoOptions& options) {
  if (Status s = validateOptions(options); !s) return s.error();
  nlohmann::json j;
  try {
    j = nlohmann::json::parse(json_text);
  } catch (const nlohmann::json::parse_error& e) {
    return jsonParseError(e, json_text, json_name);
  }
  JsonCtx cx{json_name, {}};
  using VT = nlohmann::json::value_t;
  double geometry_scale = 0;
  if (auto* gs = cx.get(j, "geometry_scale", "", true, VT::number_float))
    geometry_scale = gs->get<double>();
  bool workaround = false;
  if (auto* nw = cx.get(j, "no_scaling_workaround", "", false, VT::boolean))
    workaround = nw->get<bool>();
  const nlohmann::json* things = cx.get(j, "things", "", true, VT::object);
  const nlohmann::json* entities =
      things ? cx.get(*things, "entities", "things", true, VT::array) : nullptr;
  if (!cx.errors.empty()) return joinedErrors(cx.errors);
  if (!(geometry_scale > 0) || !std::isfinite(geometry_scale)) {
    return Error(ErrorCode::kInvalidArgument, "must be positive, got " + num(geometry_scale),
                 SourceLocation{json_name, 0, 0, "geometry_scale"});
  }

  svg::Options so;
  so.curve_segments = options.curve_segments;
  auto doc = svg::parse(svg_text, svg_name, so);
  if (!doc) return doc.error();
  std::map<std::string, const svg::Element*> by_id;
  for (const auto& e : doc->elements) {
    if (!e.id.empty()) by_id.emplace(e.id, &e);
  }

  const std::vector<Entity> ents = readEntities(cx, entities);
  if (!cx.errors.empty()) return joinedErrors(cx.errors);

  // The robot.
  std::vector<const Entity*> robots;
  for (const auto& e : ents) {
    if (e.type == "robot") robots.push_back(&e);
  }
  const Entity* robot = nullptr;
  for (const Entity* r : robots) {
    if (options.robot.empty() || r->name == options.robot) {
      robot = r;
      break;
    }
  }
  if (robot == nullptr) {
    return Error(ErrorCode::kInvalidArgument,
                 options.robot.empty() ? "no entity of type 'robot'"
                                       : "no robot entity named '" + options.robot + "'",
                 SourceLocation{json_name, 0, 0, "things.entities"});
  }
  auto rit = by_id.find(robot->geom_id);
  if (rit == by_id.end()) {
    return Error(ErrorCode::kInvalidArgument,
                 "robot '" + robot->name + "': no SVG element with id '" + robot->geom_id +
                     "' in " + svg_name,
                 SourceLocation{json_name, 0, 0, robot->field + ".geometry.id"});
  }
  const Polygon2& robot_uv = rit->second->points;
  const double robot_r_units =
      circumradius(cleanPolygon(robot_uv), areaCentroid(cleanPolygon(robot_uv)));
  double s = workaround ? geometry_scale : geometry_scale / kNamosimScaling;
  if (options.scale) s = *options.scale;
  if (options.robot_radius) {
    if (!(robot_r_units > 0)) {
      return Error(ErrorCode::kInvalidArgument, "robot '" + robot->name + "' has no extent",
                   SourceLocation{svg_name, rit->second->line, 0, ""});
    }
    s = *options.robot_radius / robot_r_units;
  }

  Builder b{options, {}, {}, {}};
  b.out.source = json_name;
  b.out.scale = s;
  b.out.robot_id = robot->name;
  b.out.world.setName(std::filesystem::path(json_name).stem().string());
  b.out.warnings = doc->warnings;
  std::optional<double> heading;
  if (!robot->orient_id.empty()) {
    auto oit = by_id.find(robot->orient_id);
    if (oit != by_id.end())
      heading = headingOf(*oit->second, s);
    else
      b.out.warnings.push_back(json_name + ": robot '" + robot->name + "': orientation element '" +
                               robot->orient_id + "' not found; heading 0");
  }
  b.setRobot(toWorld(robot_uv, s), heading);
  addObstacles(b, ents, robot, by_id, s, json_name, svg_name, options);
  addGoals(b, cx, things, robot, robots, by_id, s, json_name);
  if (!cx.errors.empty()) return joinedErrors(cx.errors);
  if (b.out.goals.empty())
    b.out.warnings.push_back(json_name + ": no usable goal for robot '" + robot->name + "'");
  if (Status st = b.finish(); !st)
    return Error(st.error().code, st.error().message, SourceLocation{json_name, 0, 0, ""});
  return std::move(b.out);
}

Result<NamoWorld> loadNamo(const std::filesystem::path& file, const NamoOptions& options) {
  const std::string ext = file.extension().string();
  if (ext == ".svg") {
    auto text = readTextFile(file);
    if (!text) return text.error();
    return parseNamoBareSvg(*text, file.string(), options);
  }
  if (ext != ".json") {
    return Error(ErrorCode::kUnsupported, "expected a NAMO world .json or a bare .svg",
                 SourceLocation{file.string()});
  }
  auto text = readTextFile(file);
  if (!text) return text.error();
  // Find the geometry file first (a JSON error is reported by parseNamoJson).
  std::filesystem::path svg_path;
  try {
    const auto j = nlohmann::json::parse(*text);
    if (j.is_object() && j.contains("files") && j["files"].is_object() &&
        j["files"].contains("geometry_file") && j["files"]["geometry_file"].is_string()) {
      svg_path = resolveRelativeTo(file, j["files"]["geometry_file"].get<std::string>());
    } else {
      return Error(ErrorCode::kInvalidArgument,
                   "missing required field (a string, path relative to the JSON)",
                   SourceLocation{file.string(), 0, 0, "files.geometry_file"});
    }
  } catch (const nlohmann::json::exception&) {
    return parseNamoJson(*text, file.string(), "", "", options);
  }
  auto svg_text = readTextFile(svg_path);
  if (!svg_text) {
    return Error(svg_text.error().code,
                 "geometry file '" + svg_path.string() + "': " + svg_text.error().message,
                 SourceLocation{file.string(), 0, 0, "files.geometry_file"});
  }
  return parseNamoJson(*text, file.string(), *svg_text, svg_path.string(), options);
}

}  // namespace tamp::world
