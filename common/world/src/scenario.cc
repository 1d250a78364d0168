#include "tamp/world/scenario.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <set>
#include <sstream>

#include "tamp/collision/scene.h"
#include "tamp/config/yaml_reader.h"
#include "tamp/core/paths.h"
#include "tamp/core/trajectory.h"

namespace tamp::world {

using config::FieldReader;

std::string_view toString(FaultKind kind) {
  switch (kind) {
    case FaultKind::kDropHeld:
      return "drop_held";
    case FaultKind::kObjectAppears:
      return "object_appears";
    case FaultKind::kActionFails:
      return "action_fails";
  }
  return "unknown";
}

namespace {

std::string num(double v) {
  std::ostringstream os;
  os << v;
  return os.str();
}

bool positive(double v) { return std::isfinite(v) && v > 0; }

/// Expands ${TAMP_BENCHMARKS_DIR}/${TAMP_CONFIG_DIR} and resolves against the scenario file.
std::optional<std::filesystem::path> expandPath(const std::string& text,
                                                const std::string& scenario_file,
                                                std::string& why) {
  const std::string& s = text;
  for (const auto& [var, dir] :
       {std::pair<std::string, std::filesystem::path>{"${TAMP_BENCHMARKS_DIR}", benchmarksDir()},
        std::pair<std::string, std::filesystem::path>{"${TAMP_CONFIG_DIR}", configDir()}}) {
    if (s.rfind(var, 0) == 0 && (s.size() == var.size() || s[var.size()] == '/')) {
      std::string rest = s.substr(var.size());
      while (!rest.empty() && rest[0] == '/') rest.erase(0, 1);
      return (dir / rest).lexically_normal();
    }
  }
  if (s.find("${") != std::string::npos) {
    why = "unknown variable in path '" + text +
          "' (known: ${TAMP_BENCHMARKS_DIR}, ${TAMP_CONFIG_DIR})";
    return std::nullopt;
  }
  if (s.empty()) {
    why = "path is empty";
    return std::nullopt;
  }
  return resolveRelativeTo(scenario_file, s);
}

/// A path field; records an error and returns nullopt on failure. `must_exist` checks the file.
std::optional<std::filesystem::path> readPath(FieldReader& r, const std::string& key, bool required,
                                              bool must_exist) {
  std::string text;
  if (!(required ? r.required(key, text) : r.optional(key, text))) return std::nullopt;
  std::string why;
  auto p = expandPath(text, r.file(), why);
  if (!p) {
    r.fail(key, why);
    return std::nullopt;
  }
  std::error_code ec;
  if (must_exist && !std::filesystem::is_regular_file(*p, ec)) {
    r.fail(key, "file '" + p->string() + "' does not exist");
    return std::nullopt;
  }
  return p;
}

/// [[x, y], ...] into a polygon; records errors.
bool readPolygon(FieldReader& r, const std::string& key, Polygon2& out) {
  r.ignore(key);
  const YAML::Node n = r.isMap() ? r.node()[key] : YAML::Node();
  if (!n.IsDefined() || !n.IsSequence()) {
    r.fail(key, "expected a list of [x, y] points");
    return false;
  }
  out.clear();
  for (size_t i = 0; i < n.size(); ++i) {
    std::vector<double> v;
    std::string why;
    if (!config::convert(n[i], v, why) || v.size() != 2) {
      r.fail(key, "point " + std::to_string(i) + ": expected [x, y]" +
                      (why.empty() ? "" : " (" + why + ")"));
      return false;
    }
    out.emplace_back(v[0], v[1]);
  }
  if (out.size() < 3) {
    r.fail(key, "needs at least 3 points, got " + std::to_string(out.size()));
    return false;
  }
  return true;
}

/// {xyz: [x, y, z], rpy: [r, p, y]} (rpy optional).
bool readPose3(FieldReader& r, const std::string& key, Eigen::Isometry3d& out) {
  FieldReader p = r.child(key);
  if (!p.isMap()) return false;
  Eigen::Vector3d xyz = Eigen::Vector3d::Zero(), rpy = Eigen::Vector3d::Zero();
  bool ok = p.required("xyz", xyz);
  p.optional("rpy", rpy);
  p.refuseUnknownKeys();
  if (!ok) return false;
  out = Eigen::Isometry3d::Identity();
  out.translation() = xyz;
  out.linear() = (Eigen::AngleAxisd(rpy.z(), Eigen::Vector3d::UnitZ()) *
                  Eigen::AngleAxisd(rpy.y(), Eigen::Vector3d::UnitY()) *
                  Eigen::AngleAxisd(rpy.x(), Eigen::Vector3d::UnitX()))
                     .toRotationMatrix();
  return true;
}

std::optional<Shape> readShape(FieldReader& r) {
  FieldReader s = r.child("shape");
  if (!s.isMap()) return std::nullopt;
  std::string type;
  if (!s.required("type", type)) return std::nullopt;
  Shape shape;
  bool ok = true;
  if (type == "box") {
    Eigen::Vector3d size;
    ok = s.required("size", size);
    shape = Shape::box(size.x(), size.y(), size.z());
  } else if (type == "cylinder") {
    double radius = 0, height = 0;
    ok = s.required("radius", radius) & s.required("height", height);
    shape = Shape::cylinder(radius, height);
  } else if (type == "sphere") {
    double radius = 0;
    ok = s.required("radius", radius);
    shape = Shape::sphere(radius);
  } else if (type == "prism") {
    Polygon2 poly;
    double height = 0;
    ok = readPolygon(s, "polygon", poly) & s.required("height", height);
    shape = Shape::prism(poly, height);
  } else {
    s.fail("type", "unknown shape type '" + type + "' (expected box, cylinder, sphere or prism)");
    return std::nullopt;
  }
  s.refuseUnknownKeys();
  if (!ok) return std::nullopt;
  if (auto why = shape.invalidReason()) {
    s.fail("", *why);
    return std::nullopt;
  }
  return shape;
}

/// m: the narrowest horizontal width of a shape, across which the fingers close (boxes: the
/// smaller footprint side; cylinders and spheres: the diameter; prisms: the polygon's minimum
/// width, found perpendicular to an edge of its convex hull).
double narrowestWidth(const Shape& s) {
  switch (s.kind) {
    case ShapeKind::kBox:
      return std::min(s.size.x(), s.size.y());
    case ShapeKind::kCylinder:
    case ShapeKind::kSphere:
      return 2 * s.radius;
    case ShapeKind::kPrism: {
      const Polygon2& p = s.polygon;
      double best = std::numeric_limits<double>::infinity();
      for (size_t i = 0; i < p.size(); ++i) {
        for (size_t j = i + 1; j < p.size(); ++j) {
          const Eigen::Vector2d d = p[j] - p[i];
          if (d.norm() < 1e-12) continue;
          const Eigen::Vector2d n = Eigen::Vector2d(-d.y(), d.x()).normalized();
          double lo = 0, hi = 0;
          for (const auto& q : p) {
            const double h = n.dot(q - p[i]);
            lo = std::min(lo, h);
            hi = std::max(hi, h);
          }
          if (lo > -1e-9 || hi < 1e-9) best = std::min(best, hi - lo);  // a hull edge
        }
      }
      return std::isfinite(best) ? best : 0.0;
    }
  }
  return 0.0;
}

/// The robot's limits on grasping (from its description), for the graspability rules.
struct GraspLimits {
  double payload{0.0};     ///< kg
  double max_width{0.0};   ///< m
  double push_limit{0.0};  ///< kg, the heaviest object the base pushes
  std::string source;     ///< the robot description file, for messages
};

/// One object entry (world.objects, world.hidden_objects, faults[i].object). Graspability
/// (docs/scenarios.md): `graspable: false` forbids a grasp; `graspable: true` on an object
/// heavier than the payload is an error; without the flag an object is graspable when it is
/// movable, within the payload and no wider than the open gripper. `limits` is null when the
/// robot description failed to load (that error is reported; the flag is then taken as given).
std::optional<Object> readObject(FieldReader& r, const World& w, bool hidden,
                                 const GraspLimits* limits, bool may_omit_pose = false) {
  Object o;
  o.hidden = hidden;
  bool ok = r.required("id", o.id);
  if (ok && !isValidId(o.id)) {
    r.fail("id", "'" + o.id +
                     "' is not a valid id (a lower-case letter, then lower-case letters, digits, "
                     "'_' or '-')");
    ok = false;
  }
  r.optional("label", o.label);
  std::string kind;
  if (r.required("kind", kind)) {
    if (auto k = objectKindFromString(kind))
      o.kind = *k;
    else {
      r.fail("kind", "expected static or movable, got '" + kind + "'");
      ok = false;
    }
  } else {
    ok = false;
  }
  auto shape = readShape(r);
  if (!shape)
    ok = false;
  else
    o.shape = *shape;
  r.optional("mass", o.mass);
  const bool has_graspable = r.optional("graspable", o.graspable);
  const Region* on = nullptr;
  if (r.optional("on", o.region)) {
    on = w.findRegion(o.region);
    if (on == nullptr) {
      r.fail("on", "unknown region '" + o.region + "'");
      ok = false;
    }
  }
  const bool has_pose = r.has("pose"), has_at = r.has("at");
  r.ignore("pose");  // listed among the expected keys even when absent
  r.ignore("at");
  if (has_pose && has_at) {
    r.fail(
        "",
        "give only one of 'pose' ({xyz, rpy}) or 'at' ([x, y, yaw] resting on 'on' or the floor)");
    ok = false;
  } else if (!has_pose && !has_at && !may_omit_pose) {
    r.fail("",
           "give exactly one of 'pose' ({xyz, rpy}) or 'at' ([x, y, yaw] resting on 'on' or the "
           "floor)");
    ok = false;
  } else if (has_pose) {
    ok &= readPose3(r, "pose", o.pose);
  } else if (has_at) {
    Pose2D at;
    if (r.required("at", at) && shape) {
      const double z = (on ? on->height : 0.0) + shape->halfHeight();
      o.pose = at.toIsometry(z);
      if (on != nullptr && !on->contains({at.x, at.y})) {
        r.fail("at", "[" + num(at.x) + ", " + num(at.y) + "] is outside region '" + on->id + "'");
        ok = false;
      }
    } else {
      ok = false;
    }
  }
  r.refuseUnknownKeys();
  if (!ok) return std::nullopt;
  if (o.kind == ObjectKind::kMovable && !(o.mass > 0)) {
    r.fail("mass", "a movable object needs a positive mass (kg), got " + num(o.mass));
    return std::nullopt;
  }
  if (o.kind == ObjectKind::kStatic && o.graspable) {
    r.fail("graspable", "a static object cannot be graspable");
    return std::nullopt;
  }
  if (limits != nullptr && o.kind == ObjectKind::kMovable) {
    if (has_graspable && o.graspable && o.mass > limits->payload) {
      r.fail("graspable", "'" + o.id + "' weighs " + num(o.mass) +
                              " kg, more than the robot's payload of " + num(limits->payload) +
                              " kg (" + limits->source + "); a scenario may forbid a grasp, "
                              "never allow one above the payload");
      return std::nullopt;
    }
    if (!has_graspable) {
      o.graspable = o.mass <= limits->payload && narrowestWidth(o.shape) <= limits->max_width;
    }
  }
  return o;
}

/// r.node()[key] when r is a mapping, else an undefined node (indexing a scalar throws).
YAML::Node valueOf(const FieldReader& r, const std::string& key) {
  return r.isMap() ? YAML::Node(r.node()[key]) : YAML::Node(YAML::NodeType::Undefined);
}

/// "(pred a b)" -> {"pred", "a", "b"}; empty on a syntax error.
std::vector<std::string> atomTokens(const std::string& atom) {
  std::string s = atom;
  const auto a = s.find_first_not_of(" \t"), b = s.find_last_not_of(" \t");
  if (a == std::string::npos || s[a] != '(' || s[b] != ')') return {};
  s = s.substr(a + 1, b - a - 1);
  if (s.find_first_of("()") != std::string::npos) return {};
  std::istringstream in(s);
  std::vector<std::string> out;
  for (std::string t; in >> t;) {
    for (char& c : t) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    out.push_back(t);
  }
  return out;
}

enum class PType { kLocation, kRegion, kItem, kArmconf };

const std::map<std::string, std::vector<PType>>& predicates() {
  static const std::map<std::string, std::vector<PType>> p{
      {"robot-at", {PType::kLocation}},
      {"arm-at", {PType::kArmconf}},
      {"hand-empty", {}},
      {"holding", {PType::kItem}},
      {"on", {PType::kItem, PType::kRegion}},
      {"reaches", {PType::kLocation, PType::kArmconf}},
      {"conf-over", {PType::kArmconf, PType::kRegion}},
      {"graspable", {PType::kItem}},
      {"occludes", {PType::kItem, PType::kItem}},
  };
  return p;
}

/// Empty when `atom` is a well-typed atom of the domain over the planner's world; else why not.
std::optional<std::string> checkAtom(const std::string& atom, const World& planner) {
  const auto t = atomTokens(atom);
  if (t.empty()) return "'" + atom + "' is not an atom '(predicate arg ...)'";
  const auto it = predicates().find(t[0]);
  if (it == predicates().end()) return "unknown predicate '" + t[0] + "' in '" + atom + "'";
  if (t.size() - 1 != it->second.size()) {
    return "'" + t[0] + "' takes " + std::to_string(it->second.size()) + " arguments, got " +
           std::to_string(t.size() - 1);
  }
  for (size_t i = 1; i < t.size(); ++i) {
    const std::string& a = t[i];
    bool ok = false;
    const char* what = "";
    switch (it->second[i - 1]) {
      case PType::kLocation:
        ok = planner.findLocation(a) != nullptr;
        what = "location";
        break;
      case PType::kRegion:
        ok = planner.findRegion(a) != nullptr;
        what = "region";
        break;
      case PType::kItem: {
        const Object* o = planner.findObject(a);
        ok = o != nullptr && o->kind == ObjectKind::kMovable;
        what = "movable object (hidden objects are unknown to the planner)";
        break;
      }
      case PType::kArmconf:
        ok =
            a == "stow" || (a.rfind("over_", 0) == 0 && planner.findRegion(a.substr(5)) != nullptr);
        what = "arm configuration (stow or over_<region>)";
        break;
    }
    if (!ok) return "'" + a + "' in '" + atom + "' is not a " + what;
  }
  return std::nullopt;
}

}  // namespace

std::optional<std::string> SimParameters::invalidReason() const {
  const std::pair<const char*, double> pos[] = {{"base_max_linear_speed", base_max_linear_speed},
                                                {"base_linear_accel", base_linear_accel},
                                                {"base_max_angular_speed", base_max_angular_speed},
                                                {"base_angular_accel", base_angular_accel},
                                                {"arm_max_joint_speed", arm_max_joint_speed},
                                                {"arm_joint_accel", arm_joint_accel}};
  for (const auto& [name, v] : pos) {
    if (!positive(v)) return std::string(name) + " must be positive, got " + num(v);
  }
  const std::pair<const char*, double> nonneg[] = {
      {"grasp_duration", grasp_duration},
      {"release_duration", release_duration},
      {"segment_stop_time", segment_stop_time},
      {"duration_noise_stddev", duration_noise_stddev}};
  for (const auto& [name, v] : nonneg) {
    if (!(std::isfinite(v) && v >= 0)) return std::string(name) + " must be >= 0, got " + num(v);
  }
  return std::nullopt;
}

std::optional<std::string> PerceptionPriors::invalidReason() const {
  if (!positive(max_range)) return "max_range must be positive, got " + num(max_range);
  if (!(position_stddev >= 0 && std::isfinite(position_stddev)))
    return "position_stddev must be >= 0";
  if (!(detection_probability >= 0 && detection_probability <= 1)) {
    return "detection_probability must be in [0, 1], got " + num(detection_probability);
  }
  return std::nullopt;
}

robot::RobotState Scenario::startState() const {
  robot::RobotState s;
  s.base = robot.start;
  s.arm = robot.arm;
  s.gripper = robot.gripper;
  return s;
}

// ---- loading ------------------------------------------------------------------------------------

namespace {

void readSim(FieldReader& r, SimParameters& p) {
  if (!r.has("sim")) {
    r.ignore("sim");
    return;
  }
  FieldReader s = r.child("sim");
  s.optional("base_max_linear_speed", p.base_max_linear_speed);
  s.optional("base_linear_accel", p.base_linear_accel);
  s.optional("base_max_angular_speed", p.base_max_angular_speed);
  s.optional("base_angular_accel", p.base_angular_accel);
  s.optional("arm_max_joint_speed", p.arm_max_joint_speed);
  s.optional("arm_joint_accel", p.arm_joint_accel);
  s.optional("grasp_duration", p.grasp_duration);
  s.optional("release_duration", p.release_duration);
  s.optional("segment_stop_time", p.segment_stop_time);
  s.optional("duration_noise_stddev", p.duration_noise_stddev);
  unsigned seed = p.seed;
  if (s.optional("seed", seed)) p.seed = seed;
  s.refuseUnknownKeys();
  if (auto why = p.invalidReason()) {
    const std::string field = why->substr(0, why->find(' '));
    s.fail(field, why->substr(field.size() + 1));
  }
}

void readPerception(FieldReader& r, PerceptionPriors& p) {
  if (!r.has("perception")) {
    r.ignore("perception");
    return;
  }
  FieldReader s = r.child("perception");
  s.optional("max_range", p.max_range);
  s.optional("position_stddev", p.position_stddev);
  s.optional("detection_probability", p.detection_probability);
  s.refuseUnknownKeys();
  if (auto why = p.invalidReason()) {
    const std::string field = why->substr(0, why->find(' '));
    s.fail(field, why->substr(field.size() + 1));
  }
}

NamoOptions readNamoOptions(FieldReader& w, const GraspLimits* limits) {
  NamoOptions o;
  if (limits != nullptr) {
    o.max_graspable_mass = limits->payload;
    o.max_mass = std::max({1.0, limits->payload, limits->push_limit});
  }
  if (!w.has("namo_options")) {
    w.ignore("namo_options");
    return o;
  }
  FieldReader n = w.child("namo_options");
  double v = 0;
  if (n.optional("scale", v)) o.scale = v;
  if (n.optional("robot_radius", v)) o.robot_radius = v;
  n.optional("wall_height", o.wall_height);
  n.optional("movable_height", o.movable_height);
  n.optional("density", o.density);
  n.optional("max_mass", o.max_mass);
  if (n.optional("max_graspable_mass", o.max_graspable_mass) && limits != nullptr &&
      o.max_graspable_mass > limits->payload) {
    n.fail("max_graspable_mass", "must not exceed the robot's payload of " +
                                     num(limits->payload) + " kg (" + limits->source + "), got " +
                                     num(o.max_graspable_mass));
    o.max_graspable_mass = limits->payload;
  }
  n.optional("bare_robot_side", o.bare_robot_side);
  n.optional("robot", o.robot);
  n.optional("curve_segments", o.curve_segments);
  n.refuseUnknownKeys();
  if (auto why = o.invalidReason()) n.fail("", *why);
  return o;
}

}  // namespace

namespace {
Result<Scenario> parseScenarioImpl(const std::string& yaml_text, const std::string& file_name,
                                   bool name_is_file_stem);

/// Where (x, y) lies outside the workspace's xy extent: a message, else nothing.
/// `reach` > 0: (x, y) may lie up to that far outside (a static object's circumradius).
std::optional<std::string> outsideWorkspace(const std::optional<Aabb>& ws, double x, double y,
                                            double reach = 0.0) {
  if (!ws || ws->empty()) return std::nullopt;
  const double dx = std::max({ws->min.x() - x, 0.0, x - ws->max.x()});
  const double dy = std::max({ws->min.y() - y, 0.0, y - ws->max.y()});
  if (std::isfinite(dx) && std::isfinite(dy) && std::hypot(dx, dy) <= reach) return std::nullopt;
  return "[" + num(x) + ", " + num(y) + "] is outside the workspace [" + num(ws->min.x()) + ", " +
         num(ws->min.y()) + ", " + num(ws->max.x()) + ", " + num(ws->max.y()) + "]" +
         (reach > 0 ? " by more than the object's size" : "");
}

/// Locations, regions and objects are PDDL objects of one problem: an id names one thing only.
/// Empty when `id` is free among the kinds other than `self`.
std::optional<std::string> sharedId(const World& w, const std::string& id, const char* self) {
  const std::string me = self;
  if (me != "region" && w.findRegion(id) != nullptr) return "id '" + id + "' is already a region";
  if (me != "location" && w.findLocation(id) != nullptr) return "id '" + id + "' is already a location";
  if (me != "object" && w.findObject(id) != nullptr) return "id '" + id + "' is already an object";
  return std::nullopt;
}
}  // namespace

Result<Scenario> parseScenario(const std::string& yaml_text, const std::string& file_name) {
  // Last line of defence: a yaml-cpp exception from an unexpected node shape (e.g. a complex
  // key) becomes a parse error at its mark instead of escaping.
  try {
    return parseScenarioImpl(yaml_text, file_name, false);
  } catch (const YAML::Exception& e) {
    return Error(ErrorCode::kParseError, "unexpected YAML structure: " + e.msg,
                 SourceLocation{file_name, e.mark.line + 1, e.mark.column + 1, ""});
  }
}

namespace {
Result<Scenario> parseScenarioFile(const std::string& yaml_text, const std::string& file_name) {
  try {
    return parseScenarioImpl(yaml_text, file_name, true);
  } catch (const YAML::Exception& e) {
    return Error(ErrorCode::kParseError, "unexpected YAML structure: " + e.msg,
                 SourceLocation{file_name, e.mark.line + 1, e.mark.column + 1, ""});
  }
}

/// `pddl:` (domain, problem, init); without it, the default domain.
void readPddl(FieldReader& r, Scenario& sc) {
  FieldReader p = r.child("pddl", false);
  if (r.has("pddl")) {
    if (auto d = readPath(p, "domain", true, true)) sc.domain = *d;
    if (auto pr = readPath(p, "problem", false, true)) sc.problem = *pr;
    p.optional("init", sc.pddl_init);
    p.refuseUnknownKeys();
  } else {
    sc.domain = configDir() / "pddl" / "mobile_manipulation.pddl";
  }
}

/// The robot's description (`robot.description`, else the default robot), loaded: first, as
/// graspability follows its payload and gripper. Nullopt when it cannot be (the error recorded).
std::optional<robot::RobotModel> readRobotModel(FieldReader& rb, Scenario& sc) {
  std::optional<robot::RobotModel> model;
  auto desc = rb.has("description") ? readPath(rb, "description", true, true)
                                    : std::optional<std::filesystem::path>(
                                          configDir() / "robots" / "mobile_manipulator.yaml");
  rb.ignore("description");
  if (desc) {
    sc.robot.description = *desc;
    auto m = robot::RobotModel::loadDescription(*desc);
    if (!m)
      rb.fail("description", m.error().toString());
    else
      model = std::move(m).value();
  }
  return model;
}

/// `world.namo`: the world loaded from a NAMO file, with its `namo_options`.
void readNamoWorld(FieldReader& w, Scenario& sc, const GraspLimits* limits) {
  if (w.has("namo")) {
    const NamoOptions nopt = readNamoOptions(w, limits);
    if (auto path = readPath(w, "namo", true, true); path && w.ok()) {
      auto nw = loadNamo(*path, nopt);
      if (!nw) {
        w.fail("namo", nw.error().toString());
      } else {
        sc.world = std::move(nw->world);
        sc.namo = NamoSource{*path, nw->scale, nw->robot_radius, nw->goals};
        for (auto& msg : nw->warnings) sc.warnings.push_back(std::move(msg));
      }
    }
  } else {
    w.ignore("namo_options");
    if (w.has("namo_options")) w.fail("namo_options", "only valid together with 'namo'");
  }
}

/// `world.workspace`: [xmin, ymin, xmax, ymax].
void readWorkspace(FieldReader& w, Scenario& sc) {
  if (w.has("workspace")) {
    std::vector<double> b;
    if (w.required("workspace", b)) {
      if (b.size() != 4 || !(b[0] < b[2]) || !(b[1] < b[3])) {
        w.fail("workspace", "expected [xmin, ymin, xmax, ymax] with min < max");
      } else {
        Aabb ws;
        ws.extend(Eigen::Vector3d(b[0], b[1], 0.0));
        ws.extend(Eigen::Vector3d(b[2], b[3], 2.0));
        sc.world.setWorkspace(ws);
      }
    }
  } else {
    w.ignore("workspace");
  }
}

/// One element of `world.regions`, added to the world.
void readRegion(FieldReader& e, Scenario& sc) {
  Region g;
  bool ok = e.required("id", g.id);
  e.optional("label", g.label);
  std::string kind = "floor";
  e.optional("kind", kind);
  if (auto k = regionKindFromString(kind))
    g.kind = *k;
  else {
    e.fail("kind", "expected floor or table, got '" + kind + "'");
    ok = false;
  }
  if (e.has("rect") == e.has("polygon")) {
    e.fail("", "give exactly one of 'rect' ([xmin, ymin, xmax, ymax]) or 'polygon'");
    ok = false;
    e.ignore("rect");
    e.ignore("polygon");
  } else if (e.has("rect")) {
    std::vector<double> b;
    if (e.required("rect", b) && b.size() == 4 && b[0] < b[2] && b[1] < b[3]) {
      g.polygon = {{b[0], b[1]}, {b[2], b[1]}, {b[2], b[3]}, {b[0], b[3]}};
    } else {
      e.fail("rect", "expected [xmin, ymin, xmax, ymax] with min < max");
      ok = false;
    }
  } else {
    ok &= readPolygon(e, "polygon", g.polygon);
    g.polygon = cleanPolygon(g.polygon);
  }
  e.optional("height", g.height);
  e.refuseUnknownKeys();
  if (!ok) return;
  for (const auto& v : g.polygon) {
    if (auto why = outsideWorkspace(sc.world.workspace(), v.x(), v.y())) {
      e.fail(e.has("rect") ? "rect" : "polygon", "corner " + *why);
      break;
    }
  }
  if (auto why = sharedId(sc.world, g.id, "region")) {
    e.fail("id", *why + " (regions, locations and objects are PDDL objects: one id each)");
    return;
  }
  if (Status s = sc.world.addRegion(g); !s) e.fail("id", s.error().message);
}

/// One element of `world.locations`, added to the world.
void readLocation(FieldReader& e, Scenario& sc) {
  Location l;
  const bool ok = e.required("id", l.id) & e.required("pose", l.pose);
  e.optional("label", l.label);
  e.refuseUnknownKeys();
  if (!ok) return;
  if (auto why = outsideWorkspace(sc.world.workspace(), l.pose.x, l.pose.y)) e.fail("pose", *why);
  if (auto why = sharedId(sc.world, l.id, "location")) {
    e.fail("id", *why + " (regions, locations and objects are PDDL objects: one id each)");
    return;
  }
  if (Status s = sc.world.addLocation(l); !s) e.fail("id", s.error().message);
}

/// The id of the object held at the start (`robot.holding.object`), read before the objects:
/// that one may omit its pose (it follows the gripper). Empty when none.
std::string heldObjectId(const FieldReader& r) {
  std::string held_id;
  // (Indexing a missing key gives an invalid node: test IsDefined() before anything else.)
  if (const YAML::Node rn = valueOf(r, "robot"); rn.IsDefined() && rn.IsMap()) {
    if (const YAML::Node hn = rn["holding"]; hn.IsDefined() && hn.IsMap()) {
      if (const YAML::Node on = hn["object"]; on.IsDefined() && on.IsScalar())
        held_id = on.Scalar();
    }
  }
  return held_id;
}

/// `world.objects` and `world.hidden_objects`, added to the world.
void readObjects(FieldReader& w, Scenario& sc, const GraspLimits* limits,
                 const std::string& held_id) {
  for (const char* list : {"objects", "hidden_objects"}) {
    const bool hidden = std::string_view(list) == "hidden_objects";
    for (FieldReader& e : w.sequence(list, false)) {
      // The held object may omit its pose: it is computed from the grasp below.
      const bool is_held = !held_id.empty() && e.has("id") && e.node()["id"].IsScalar() &&
                           e.node()["id"].Scalar() == held_id;
      auto o = readObject(e, sc.world, hidden, limits, is_held);
      if (!o) continue;
      if (!is_held || e.has("pose") || e.has("at")) {
        // Movable and hidden objects stand inside; a static one (a wall bounding the room) may
        // straddle the edge but must reach into the workspace.
        const auto t = o->pose.translation();
        const double reach = o->kind == ObjectKind::kStatic
                                 ? circumradius(o->shape.footprint(), Eigen::Vector2d::Zero())
                                 : 0.0;
        if (auto why = outsideWorkspace(sc.world.workspace(), t.x(), t.y(), reach))
          e.fail(e.has("pose") ? "pose" : "at", *why);
      }
      if (auto why = sharedId(sc.world, o->id, "object")) {
        e.fail("id", *why + " (regions, locations and objects are PDDL objects: one id each)");
        continue;
      }
      if (Status s = sc.world.addObject(*o); !s) e.fail("id", s.error().message);
    }
  }
}

/// `robot.start`: a location id or a pose (then location "start" is added).
void readStart(FieldReader& rb, Scenario& sc) {
  rb.ignore("start");
  const YAML::Node st = valueOf(rb, "start");
  if (!st.IsDefined()) {
    if (sc.world.findLocation("start") != nullptr) {
      sc.robot.start_location = "start";
      sc.robot.start = sc.world.findLocation("start")->pose;
    } else {
      rb.fail("start", "missing required field (a location id or [x, y, theta])");
    }
  } else if (st.IsScalar()) {
    const Location* l = sc.world.findLocation(st.Scalar());
    if (l == nullptr)
      rb.fail("start", "unknown location '" + st.Scalar() + "'");
    else {
      sc.robot.start_location = l->id;
      sc.robot.start = l->pose;
    }
  } else if (rb.required("start", sc.robot.start)) {
    if (auto why = outsideWorkspace(sc.world.workspace(), sc.robot.start.x, sc.robot.start.y))
      rb.fail("start", *why);
    sc.robot.start_location = "start";
    const Location* l = sc.world.findLocation("start");
    if (l == nullptr)
      (void)sc.world.addLocation(Location{"start", "robot start", sc.robot.start});
    else if (!(l->pose == sc.robot.start))
      rb.fail("start", "differs from location 'start'; name the location instead");
  }
}

/// `robot.arm`: a named configuration or joint values.
void readArm(FieldReader& rb, Scenario& sc, const std::optional<robot::RobotModel>& model) {
  rb.ignore("arm");
  const YAML::Node arm = valueOf(rb, "arm");
  if (model) {
    if (!arm.IsDefined() || arm.IsScalar()) {
      const std::string name = arm.IsDefined() ? arm.Scalar() : "stow";
      if (auto q = model->namedConfiguration(name)) {
        sc.robot.arm = *q;
        sc.robot.arm_configuration = name;
      } else {
        std::string names;
        for (const auto& n : model->namedConfigurationNames())
          names += (names.empty() ? "" : ", ") + n;
        rb.fail("arm", "unknown arm configuration '" + name + "' (robot has: " + names + ")");
      }
    } else if (rb.required("arm", sc.robot.arm)) {
      if (sc.robot.arm.size() != model->armDof()) {
        rb.fail("arm", "expected " + std::to_string(model->armDof()) + " joint values, got " +
                           std::to_string(sc.robot.arm.size()));
      } else if (!model->withinLimits(sc.robot.arm)) {
        for (size_t k = 0; k < sc.robot.arm.size(); ++k) {
          const auto& lim = model->armLimits()[k];
          if (sc.robot.arm[k] < lim.lower || sc.robot.arm[k] > lim.upper) {
            rb.fail("arm", model->armJointNames()[k] + " = " + num(sc.robot.arm[k]) +
                               " is outside its limits [" + num(lim.lower) + ", " + num(lim.upper) +
                               "]");
          }
        }
      }
    }
  }
}

/// `robot.gripper`: open | closed | metres.
void readGripper(FieldReader& rb, Scenario& sc, const std::optional<robot::RobotModel>& model) {
  rb.ignore("gripper");
  const YAML::Node g = valueOf(rb, "gripper");
  if (model) {
    sc.robot.gripper = model->options().gripper_closed;
    if (g.IsDefined()) {
      double v = 0;
      std::string why;
      if (g.IsScalar() && g.Scalar() == "open")
        sc.robot.gripper = model->options().gripper_open;
      else if (g.IsScalar() && g.Scalar() == "closed")
        sc.robot.gripper = model->options().gripper_closed;
      else if (config::convert(g, v, why) && v >= model->gripperLimits().lower &&
               v <= model->gripperLimits().upper) {
        sc.robot.gripper = v;
      } else {
        rb.fail("gripper", "expected open, closed or a value in [" +
                               num(model->gripperLimits().lower) + ", " +
                               num(model->gripperLimits().upper) + "] m");
      }
    }
  }
}

/// `robot.holding`: the object in the gripper at the start (placed by placeHeldObject).
void readHolding(FieldReader& rb) {
  if (rb.has("holding")) {
    FieldReader h = rb.child("holding");
    std::string id;
    Eigen::Isometry3d grasp = Eigen::Isometry3d::Identity();
    h.required("object", id);
    if (h.has("grasp"))
      readPose3(h, "grasp", grasp);
    else
      h.ignore("grasp");
    h.refuseUnknownKeys();
  } else {
    rb.ignore("holding");
  }
}

/// `goal.base`: a location id or a pose (then location "goal" is added).
void readGoalBase(FieldReader& g, Scenario& sc) {
  g.ignore("base");
  const YAML::Node b = valueOf(g, "base");
  if (b.IsDefined()) {
    if (b.IsScalar()) {
      const Location* l = sc.world.findLocation(b.Scalar());
      if (l == nullptr)
        g.fail("base", "unknown location '" + b.Scalar() + "'");
      else {
        sc.goal.base = l->pose;
        sc.goal.base_location = l->id;
      }
    } else {
      Pose2D p;
      if (g.required("base", p)) {
        if (auto why = outsideWorkspace(sc.world.workspace(), p.x, p.y)) g.fail("base", *why);
        sc.goal.base = p;
        const Location* l = sc.world.findLocation("goal");
        if (l == nullptr) {
          (void)sc.world.addLocation(Location{"goal", "goal base pose", p});
          sc.goal.base_location = "goal";
        } else if (l->pose == p) {
          sc.goal.base_location = "goal";
        } else {
          g.fail("base", "differs from location 'goal'; name the location instead");
        }
      }
    }
  }
}

/// `goal:` (pddl atoms, base, tolerances, objects in regions).
void readGoal(FieldReader& r, Scenario& sc) {
  FieldReader g = r.child("goal");
  g.optional("pddl", sc.goal.pddl);
  readGoalBase(g, sc);
  g.optional("position_tolerance", sc.goal.position_tolerance);
  g.optional("angle_tolerance", sc.goal.angle_tolerance);
  if (!positive(sc.goal.position_tolerance)) g.fail("position_tolerance", "must be positive");
  if (!positive(sc.goal.angle_tolerance)) g.fail("angle_tolerance", "must be positive");
  for (FieldReader& e : g.sequence("objects_in_regions", false)) {
    std::string o, rg;
    if (e.required("object", o) & e.required("region", rg)) {
      const Object* obj = sc.world.findObject(o);
      if (obj == nullptr || obj->hidden || obj->kind != ObjectKind::kMovable) {
        e.fail("object", "'" + o + "' is not a movable object known to the planner");
      }
      if (sc.world.findRegion(rg) == nullptr) e.fail("region", "unknown region '" + rg + "'");
      sc.goal.object_in_region.emplace_back(o, rg);
    }
    e.refuseUnknownKeys();
  }
  g.refuseUnknownKeys();
}

/// One element of `faults`.
Fault readFault(FieldReader& f, const Scenario& sc, const GraspLimits* limits) {
  Fault fault;
  std::string type;
  if (f.required("type", type)) {
    if (type == "drop_held")
      fault.kind = FaultKind::kDropHeld;
    else if (type == "object_appears")
      fault.kind = FaultKind::kObjectAppears;
    else if (type == "action_fails")
      fault.kind = FaultKind::kActionFails;
    else
      f.fail("type",
             "unknown fault '" + type + "' (expected drop_held, object_appears or action_fails)");
  }
  double t = 0;
  int step = 0;
  if (f.optional("at_time", t)) {
    fault.at_time = t;
    if (!(t >= 0)) f.fail("at_time", "must be >= 0 s, got " + num(t));
  }
  if (f.optional("at_step", step)) {
    fault.at_step = step;
    if (step < 0) f.fail("at_step", "must be >= 0, got " + std::to_string(step));
  }
  if (fault.at_time.has_value() == fault.at_step.has_value())
    f.fail("", "give exactly one of 'at_time' (s) or 'at_step'");
  f.optional("reason", fault.reason);
  if (fault.kind == FaultKind::kObjectAppears) {
    FieldReader o = f.child("object");
    if (o.isMap()) {
      fault.object = readObject(o, sc.world, false, limits);
      if (fault.object && sc.world.findObject(fault.object->id) != nullptr) {
        o.fail("id", "'" + fault.object->id + "' already exists in the world");
      } else if (fault.object) {
        if (auto why = sharedId(sc.world, fault.object->id, "object"))
          o.fail("id", *why + " (regions, locations and objects are PDDL objects: one id each)");
        const auto xy = fault.object->pose.translation();
        if (auto why = outsideWorkspace(sc.world.workspace(), xy.x(), xy.y()))
          o.fail(o.has("pose") ? "pose" : "at", *why);
      }
    }
  } else {
    f.ignore("object");
    if (f.has("object")) f.fail("object", "only for object_appears");
  }
  const bool filtered = fault.kind == FaultKind::kActionFails || fault.kind == FaultKind::kDropHeld;
  if (f.optional("action", fault.action) && filtered) {
    if (!actionKindFromString(fault.action)) {
      f.fail("action",
             "unknown action '" + fault.action + "' (expected move_base, move_arm, pick or place)");
    } else if (fault.kind == FaultKind::kDropHeld && !fault.at_step) {
      f.fail("action", "a drop waits for an action of a kind only with at_step");
    }
  } else if (!fault.action.empty()) {
    f.fail("action", "only for action_fails and drop_held");
  }
  f.refuseUnknownKeys();
  return fault;
}

/// The held object (`robot.holding`): its pose from the grasp at the start state.
void placeHeldObject(FieldReader& rb, Scenario& sc, const std::optional<robot::RobotModel>& model) {
  FieldReader h = rb.child("holding");
  std::string id;
  h.required("object", id);
  Eigen::Isometry3d grasp = Eigen::Isometry3d::Identity();
  if (h.has("grasp")) readPose3(h, "grasp", grasp);
  const Object* o = sc.world.findObject(id);
  if (o == nullptr) {
    h.fail("object", "unknown object '" + id + "'");
  } else if (o->kind != ObjectKind::kMovable || !o->graspable) {
    h.fail("object", "object '" + id + "' must be movable and graspable");
  } else {
    Object held = *o;
    held.pose = model->toolPoseInWorld(sc.startState()) * grasp;
    held.region.clear();
    (void)sc.world.updateObject(held);
    if (Status s = sc.world.setHeld(HeldObject{id, model->options().tool_link, grasp}); !s) {
      h.fail("object", s.error().message);
    }
  }
}

/// The goal's and the initial state's atoms, over the planner's world.
void checkAtoms(FieldReader& r, Scenario& sc) {
  const World planner = sc.world.plannerView();
  FieldReader g = r.child("goal");
  for (size_t i = 0; i < sc.goal.pddl.size(); ++i) {
    if (auto why = checkAtom(sc.goal.pddl[i], planner)) g.failAt("pddl", i, *why);
  }
  FieldReader p = r.child("pddl", false);
  for (size_t i = 0; i < sc.pddl_init.size(); ++i) {
    if (auto why = checkAtom(sc.pddl_init[i], planner)) p.failAt("init", i, *why);
  }
  if (sc.goal.empty()) g.fail("", "needs at least one of pddl, base, objects_in_regions");
}

/// The robot's start should be free: a warning otherwise (NAMO worlds at native scale may be
/// tight).
void warnStartInContact(Scenario& sc, const std::optional<robot::RobotModel>& model,
                        const std::string& file_name) {
  collision::Scene scene(sc.world);
  scene.setRobot(model->collisionGeometry());
  std::vector<Eigen::Isometry3d> poses;
  model->linkPoses(sc.startState(), poses);
  scene.setLinkPoses(poses);
  (void)scene.attachHeld();
  const auto hits = scene.robotCollisions();
  if (!hits.empty()) {
    std::string list;
    for (const auto& h : hits) list += (list.empty() ? "" : ", ") + h;
    sc.warnings.push_back(file_name + ": field 'robot.start': the robot starts in contact with " +
                          list);
  }
}

Result<Scenario> parseScenarioImpl(const std::string& yaml_text, const std::string& file_name,
                                   bool name_is_file_stem) {
  auto doc = config::parseYaml(yaml_text, file_name);
  if (!doc) return doc.error();
  FieldReader r(*doc);
  if (!r.isMap()) {
    if (!r.ok()) return r.errors().front();
    return Error(ErrorCode::kInvalidArgument,
                 "a scenario is a mapping (name:, robot:, world:, goal:, ...)",
                 SourceLocation{file_name, 1, 1, ""});
  }
  Scenario sc;
  sc.file = file_name;
  if (r.required("name", sc.name)) {
    if (!isValidId(sc.name)) {
      r.fail("name", "'" + sc.name + "' is not a valid id");
    } else if (const std::string stem = std::filesystem::path(file_name).stem().string();
               name_is_file_stem && sc.name != stem) {
      // Runs, reports and config/pddl/problems/<name>.pddl are named by `name`, files by their
      // stem: two names for one scenario would make both ambiguous.
      r.fail("name", "'" + sc.name + "' differs from the file name '" + stem +
                         "' (a scenario file is named <name>.yaml)");
    }
  }
  r.optional("description", sc.description);
  readPddl(r, sc);

  // ---- robot description (first: graspability follows its payload and gripper) ----
  FieldReader rb = r.child("robot");
  const std::optional<robot::RobotModel> model = readRobotModel(rb, sc);
  std::optional<GraspLimits> grasp_limits;
  if (model) {
    grasp_limits =
        GraspLimits{model->payload(), model->maxGraspWidth(), model->pushLimit(), sc.robot.description.string()};
  }
  const GraspLimits* limits = grasp_limits ? &*grasp_limits : nullptr;

  // ---- world ----
  FieldReader w = r.child("world");
  readNamoWorld(w, sc, limits);
  sc.world.setName(sc.name);
  readWorkspace(w, sc);
  for (FieldReader& e : w.sequence("regions", false)) readRegion(e, sc);
  for (FieldReader& e : w.sequence("locations", false)) readLocation(e, sc);
  readObjects(w, sc, limits, heldObjectId(r));
  w.refuseUnknownKeys();

  // ---- robot ----
  readStart(rb, sc);
  readArm(rb, sc, model);
  readGripper(rb, sc, model);
  readHolding(rb);
  rb.refuseUnknownKeys();

  readGoal(r, sc);
  for (FieldReader& f : r.sequence("faults", false)) sc.faults.push_back(readFault(f, sc, limits));

  readSim(r, sc.sim);
  readPerception(r, sc.perception);
  r.refuseUnknownKeys();

  // ---- cross-checks that need the whole file ----
  if (r.ok() && model) {
    if (rb.has("holding")) placeHeldObject(rb, sc, model);
    checkAtoms(r, sc);
    warnStartInContact(sc, model, file_name);
  }
  if (!r.ok()) return r.errors().size() == 1 ? r.errors().front() : r.status().error();
  return sc;
}
}  // namespace

Result<Scenario> loadScenario(const std::filesystem::path& file) {
  const std::string ext = file.extension().string();
  if (ext == ".json" || ext == ".svg") {
    // A NAMO world on its own: the default robot scaled in.
    auto model = robot::RobotModel::loadDefault();
    if (!model) return model.error();
    NamoOptions o;
    o.robot_radius = model->baseRadius();
    o.max_graspable_mass = model->payload();
    o.max_mass = std::max({1.0, model->payload(), model->pushLimit()});
    auto nw = loadNamo(file, o);
    if (!nw) return nw.error();
    Scenario sc;
    std::string stem = file.stem().string();
    for (char& c : stem) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    std::string name = "namo_";
    for (char c : stem) name += ((c >= 'a' && c <= 'z') || (c >= '0' && c <= '9')) ? c : '_';
    sc.name = name.substr(0, 64);
    sc.description = "NAMO benchmark world " + file.string();
    sc.file = file;
    sc.domain = configDir() / "pddl" / "mobile_manipulation.pddl";
    sc.world = std::move(nw->world);
    sc.world.setName(sc.name);
    sc.namo = NamoSource{file, nw->scale, nw->robot_radius, nw->goals};
    sc.warnings = std::move(nw->warnings);
    sc.robot.description = configDir() / "robots" / "mobile_manipulator.yaml";
    sc.robot.start = nw->start;
    sc.robot.start_location = "start";
    sc.robot.arm = model->defaultState().arm;
    sc.robot.arm_configuration = "stow";
    sc.robot.gripper = model->options().gripper_closed;
    if (!nw->goals.empty()) {
      sc.goal.base = nw->goals.front().pose;
      sc.goal.base_location = nw->goals.front().id;
      if (!nw->goals.front().has_orientation) sc.goal.angle_tolerance = 2 * M_PI;
    }
    return sc;
  }
  auto text = readTextFile(file);
  if (!text) return text.error();
  return parseScenarioFile(*text, file.string());
}

// ---- PDDL
// -------------------------------------------------------------------------------------------

bool occludes(const Object& x, const Object& o, const Eigen::Vector2d& approach, double margin) {
  const Eigen::Vector2d po = o.pose.translation().head<2>();
  const Eigen::Vector2d px = x.pose.translation().head<2>();
  const Eigen::Vector2d d = po - approach;
  const double len = d.norm();
  if (len <= 0) return false;
  const double t = (px - approach).dot(d) / len;  // along the approach
  const double lateral = std::abs(d.x() * (px - approach).y() - d.y() * (px - approach).x()) / len;
  const double ro = circumradius(o.shape.footprint(), Eigen::Vector2d::Zero());
  const double rx = circumradius(x.shape.footprint(), Eigen::Vector2d::Zero());
  const bool in_corridor = t > 0 && t < len && lateral < rx + ro + margin;
  const bool crowding = margin > 0 && (px - po).norm() < rx + ro + margin;  // in the grasp's room
  return in_corridor || crowding;
}

bool reachesRegion(const robot::RobotModel& robot, const Pose2D& base, const Region& region) {
  const Eigen::Vector2d b(base.x, base.y);
  const Eigen::Vector2d ahead =
      b + 0.55 * Eigen::Vector2d(std::cos(base.theta), std::sin(base.theta));
  Eigen::Vector2d target = ahead;
  if (!region.contains(ahead)) {
    // Nearest boundary point, then 5 cm towards the region's centroid.
    double best = std::numeric_limits<double>::infinity();
    const auto& P = region.polygon;
    for (size_t i = 0; i < P.size(); ++i) {
      const Eigen::Vector2d s0 = P[i], s1 = P[(i + 1) % P.size()];
      const double len2 = (s1 - s0).squaredNorm();
      const double t = len2 > 0 ? std::clamp((ahead - s0).dot(s1 - s0) / len2, 0.0, 1.0) : 0.0;
      const Eigen::Vector2d q = s0 + t * (s1 - s0);
      if ((q - ahead).norm() < best) {
        best = (q - ahead).norm();
        target = q;
      }
    }
    const Eigen::Vector2d c = areaCentroid(P);
    if ((c - target).norm() > 1e-9) target += 0.05 * (c - target).normalized();
  }
  const Eigen::Isometry3d world_T_base = base.toIsometry(0.0);
  const Eigen::Vector3d p =
      world_T_base.inverse() * Eigen::Vector3d(target.x(), target.y(), region.height + 0.10);
  const double yaw = std::atan2(p.y(), p.x());
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.translation() = p;
  T.linear() = (Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()) *
                Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitY()))
                   .toRotationMatrix();
  robot::IkOptions opt;
  opt.max_attempts = 24;
  opt.position_tolerance = 1e-3;
  opt.orientation_tolerance = 1e-2;
  return robot.inverseKinematics(T, robot.defaultState().arm, opt).ok();
}

std::string PddlProblem::text() const {
  std::ostringstream os;
  os << "(define (problem " << name << ")\n  (:domain " << domain << ")\n  (:objects";
  std::string type;
  for (size_t i = 0; i < objects.size(); ++i) {
    if (objects[i].second != type) {
      if (!type.empty()) os << " - " << type;
      type = objects[i].second;
      os << "\n   ";
    }
    os << " " << objects[i].first;
  }
  if (!type.empty()) os << " - " << type;
  os << ")\n  (:init";
  for (const auto& a : init) os << "\n    " << a;
  os << "\n    (= (total-cost) 0))\n  (:goal (and";
  for (const auto& a : goal) os << " " << a;
  os << "))\n  (:metric minimize (total-cost)))\n";
  return os.str();
}

Result<PddlProblem> toPddlProblem(const Scenario& sc, const robot::RobotModel& robot) {
  const World w = sc.plannerWorld();
  PddlProblem p;
  p.name = sc.name;
  std::vector<std::string> items;
  for (const auto& o : w.objects()) {
    if (o.kind == ObjectKind::kMovable) items.push_back(o.id);
  }
  for (const auto& l : w.locations()) p.objects.emplace_back(l.id, "location");
  for (const auto& r : w.regions()) p.objects.emplace_back(r.id, "region");
  for (const auto& r : w.regions()) p.objects.emplace_back("over_" + r.id, "armconf");
  for (const auto& i : items) p.objects.emplace_back(i, "item");

  std::set<std::string> init;
  if (sc.robot.start_location.empty() || w.findLocation(sc.robot.start_location) == nullptr) {
    return Error(ErrorCode::kInvalidArgument, "the robot's start is not a named location");
  }
  init.insert("(robot-at " + sc.robot.start_location + ")");
  init.insert("(arm-at stow)");
  const auto& held = w.held();
  if (held)
    init.insert("(holding " + held->object_id + ")");
  else
    init.insert("(hand-empty)");
  for (const auto& o : w.objects()) {
    if (o.kind != ObjectKind::kMovable) continue;
    if (o.graspable) init.insert("(graspable " + o.id + ")");
    if (!o.region.empty() && !(held && held->object_id == o.id))
      init.insert("(on " + o.id + " " + o.region + ")");
  }
  // reaches / conf-over, and for occlusion the nearest location reaching each region.
  std::map<std::string, const Location*> approach;
  for (const auto& r : w.regions()) {
    init.insert("(conf-over over_" + r.id + " " + r.id + ")");
    double best = std::numeric_limits<double>::infinity();
    for (const auto& l : w.locations()) {
      if (!reachesRegion(robot, l.pose, r)) continue;
      init.insert("(reaches " + l.id + " over_" + r.id + ")");
      const double d = (areaCentroid(r.polygon) - Eigen::Vector2d(l.pose.x, l.pose.y)).norm();
      if (d < best) {
        best = d;
        approach[r.id] = &l;
      }
    }
  }
  for (const auto& l : w.locations()) init.insert("(reaches " + l.id + " stow)");
  // occludes: x stands in the approach corridor from the region's location to o.
  for (const auto& o : w.objects()) {
    if (o.kind != ObjectKind::kMovable || o.region.empty() || (held && held->object_id == o.id))
      continue;
    auto ap = approach.find(o.region);
    if (ap == approach.end()) continue;
    const Eigen::Vector2d l(ap->second->pose.x, ap->second->pose.y);
    for (const auto& x : w.objects()) {
      if (&x == &o || x.kind != ObjectKind::kMovable || x.region != o.region ||
          (held && held->object_id == x.id))
        continue;
      if (occludes(x, o, l)) init.insert("(occludes " + x.id + " " + o.id + ")");
    }
  }
  for (const auto& a : sc.pddl_init) {
    if (auto why = checkAtom(a, w)) return Error(ErrorCode::kInvalidArgument, "pddl.init: " + *why);
    const auto t = atomTokens(a);
    std::string norm = "(";
    for (size_t i = 0; i < t.size(); ++i) norm += (i ? " " : "") + t[i];
    init.insert(norm + ")");
  }
  p.init.assign(init.begin(), init.end());
  for (const auto& a : sc.goal.pddl) {
    if (auto why = checkAtom(a, w)) return Error(ErrorCode::kInvalidArgument, "goal.pddl: " + *why);
    const auto t = atomTokens(a);
    std::string norm = "(";
    for (size_t i = 0; i < t.size(); ++i) norm += (i ? " " : "") + t[i];
    p.goal.push_back(norm + ")");
  }
  if (sc.goal.base && !sc.goal.base_location.empty())
    p.goal.push_back("(robot-at " + sc.goal.base_location + ")");
  for (const auto& [o, r] : sc.goal.object_in_region) p.goal.push_back("(on " + o + " " + r + ")");
  std::sort(p.goal.begin(), p.goal.end());
  p.goal.erase(std::unique(p.goal.begin(), p.goal.end()), p.goal.end());
  return p;
}

}  // namespace tamp::world
