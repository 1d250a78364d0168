#include "tamp/perception/params.h"

#include <algorithm>
#include <cmath>
#include <set>

#include "tamp/config/schema.h"
#include "tamp/core/format.h"
#include "tamp/core/paths.h"

namespace tamp::perception {
namespace {

using config::atLeast;
using config::Ends;
using config::inRange;
using config::nonNegative;
using config::positive;

/// "must be greater than <name> (<bound>), got <v>" unless v is finite, above `bound` and `also`.
std::optional<std::string> above(double v, double bound, const std::string& name,
                                 bool also = true) {
  if (also && std::isfinite(v) && v > bound) return std::nullopt;
  return "must be greater than " + name + " (" + formatNumber(bound) + "), got " + formatNumber(v);
}

/// "must be >= <name> (<bound>), got <v>" unless v >= bound.
std::optional<std::string> atLeastField(int v, int bound, const std::string& name) {
  if (v >= bound) return std::nullopt;
  return "must be >= " + name + " (" + std::to_string(bound) + "), got " + std::to_string(v);
}

/// crop.workspace: [xmin, ymin, zmin, xmax, ymax, zmax].
std::optional<std::string> workspaceBox(const std::vector<double>& v, std::optional<Aabb>& out) {
  if (v.size() != 6) {
    return "expected [xmin, ymin, zmin, xmax, ymax, zmax], got " + std::to_string(v.size()) +
           " numbers";
  }
  Aabb b;
  b.min = Eigen::Vector3d(v[0], v[1], v[2]);
  b.max = Eigen::Vector3d(v[3], v[4], v[5]);
  out = b;
  return std::nullopt;
}

const config::Schema<PerceptionParams>& schema() {
  using P = PerceptionParams;
  static const config::Schema<P> kSchema = [] {
    config::Schema<P> s;
    s.section("sensor", &P::sensor)
        .field("noise_stddev", &SensorNoise::noise_stddev, nonNegative())
        .field("noise_quadratic", &SensorNoise::noise_quadratic, nonNegative());
    using C = CropParams;
    s.section("crop", &P::crop)
        .convert<std::vector<double>>(
            "workspace", &C::workspace, workspaceBox,
            [](const std::optional<Aabb>& w) -> std::optional<std::string> {
              if (!w || (!w->empty() && w->min.allFinite() && w->max.allFinite())) {
                return std::nullopt;
              }
              return "must be a non-empty finite box (min <= max)";
            })
        .field("workspace_margin", &C::workspace_margin, nonNegative())
        .field("min_range", &C::min_range, nonNegative())
        .field("max_range", &C::max_range)
        .rule("max_range", [](const C& c) { return above(c.max_range, c.min_range, "min_range"); })
        .field("min_z", &C::min_z,
               config::that<double>([](double v) { return std::isfinite(v); }, "must be finite"))
        .field("max_z", &C::max_z)
        .rule("max_z", [](const C& c) { return above(c.max_z, c.min_z, "min_z"); });
    using PL = PlaneParams;
    s.section("planes", &P::planes)
        .field("voxel_size", &PL::voxel_size, inRange(0, 0.5, Ends::kOpenClosed, "m"))
        .field("max_planes", &PL::max_planes, atLeast(0))
        .field("max_attempts", &PL::max_attempts)
        .rule("max_attempts",
              [](const PL& p) { return atLeastField(p.max_attempts, p.max_planes, "max_planes"); })
        .field("ransac_iterations", &PL::ransac_iterations, atLeast(1))
        .field("distance_threshold", &PL::distance_threshold, positive())
        .field("noise_sigmas", &PL::noise_sigmas, nonNegative())
        .field("ransac_max_points", &PL::ransac_max_points, atLeast(100))
        .field("max_tilt", &PL::max_tilt, inRange(0, 1.5, Ends::kOpen, "rad"))
        .field("min_points", &PL::min_points, atLeast(3))
        .field("min_support_area", &PL::min_support_area, positive())
        .field("region_height_tolerance", &PL::region_height_tolerance, positive())
        .field("region_margin", &PL::region_margin, nonNegative());
    using CL = ClusterParams;
    s.section("clusters", &P::clusters)
        .field("tolerance", &CL::tolerance)
        .field("min_points", &CL::min_points, atLeast(1))
        .field("max_points", &CL::max_points)
        .rule("max_points",
              [](const CL& c) { return atLeastField(c.max_points, c.min_points, "min_points"); })
        .field("min_height", &CL::min_height, nonNegative())
        .field("min_size", &CL::min_size, nonNegative())
        .field("max_size", &CL::max_size)
        .rule("max_size", [](const CL& c) { return above(c.max_size, c.min_size, "min_size"); })
        .field("static_margin", &CL::static_margin, nonNegative())
        .field("cylinder_residual_ratio", &CL::cylinder_residual_ratio,
               inRange(0, 1, Ends::kOpenClosed));
    s.rule("clusters", "tolerance", [](const P& p) {
      const double t = p.clusters.tolerance;
      return above(t, p.planes.voxel_size, "planes.voxel_size", t > 0);
    });
    using T = TrackingParams;
    s.section("tracking", &P::tracking)
        .field("gate_distance", &T::gate_distance, positive())
        .field("size_tolerance", &T::size_tolerance, nonNegative())
        .field("height_tolerance", &T::height_tolerance, nonNegative())
        .field("confirm_hits", &T::confirm_hits, atLeast(1))
        .field("tentative_timeout_s", &T::tentative_timeout_s, positive())
        .field("gone_frames", &T::gone_frames, atLeast(1))
        .field("smoothing", &T::smoothing, inRange(0, 1, Ends::kOpenClosed))
        .field("snap_distance", &T::snap_distance, positive())
        .field("explained_margin", &T::explained_margin, positive())
        .field("explained_fraction", &T::explained_fraction, inRange(0, 1, Ends::kOpenClosed))
        .field("settle_frames", &T::settle_frames, atLeast(0))
        .field("update_distance", &T::update_distance, nonNegative())
        .field("update_angle", &T::update_angle, nonNegative())
        .field("move_event_distance", &T::move_event_distance, positive())
        .field("move_event_angle", &T::move_event_angle, positive())
        .field("visibility_bin", &T::visibility_bin,
               inRange(0, 0.2, Ends::kOpenClosed, "(tangent units)"))
        .field("visibility_margin", &T::visibility_margin, positive())
        .field("gone_fraction", &T::gone_fraction, inRange(0, 1, Ends::kOpenClosed))
        .field("present_fraction", &T::present_fraction, inRange(0, 1, Ends::kOpenClosed))
        .field("gone_min_samples", &T::gone_min_samples, atLeast(1))
        .field("reacquire", &T::reacquire);
    using K = ClassifyParams;
    s.section("classify", &P::classify)
        .field("movable_max_extent", &K::movable_max_extent, positive())
        .field("movable_max_height", &K::movable_max_height, positive())
        .field("density", &K::density, positive())
        .field("min_mass", &K::min_mass, positive())
        .field("graspable_max_width", &K::graspable_max_width, nonNegative())
        .field("graspable_max_mass", &K::graspable_max_mass, nonNegative());
    using SF = SelfFilterParams;
    s.section("self_filter", &P::self_filter)
        .field("enabled", &SF::enabled)
        .field("padding", &SF::padding, inRange(0, 0.5, Ends::kClosed, "m"))
        .field("held_adopt_radius", &SF::held_adopt_radius, inRange(0, 1.0, Ends::kOpenClosed, "m"));
    using O = OccupancyParams;
    s.section("occupancy", &P::occupancy)
        .field("enabled", &O::enabled)
        .field("resolution", &O::resolution, inRange(0, 1, Ends::kOpenClosed, "m"))
        .field("free_space_voxel", &O::free_space_voxel, positive())
        .field("max_ray_range", &O::max_ray_range, positive())
        .field("explained_margin", &O::explained_margin, nonNegative())
        .field("prob_hit", &O::prob_hit, inRange(0.5, 1, Ends::kOpen))
        .field("prob_miss", &O::prob_miss, inRange(0, 0.5, Ends::kOpen))
        .field("occupancy_threshold", &O::occupancy_threshold, inRange(0.5, 1, Ends::kClosedOpen))
        .field("min_cluster_points", &O::min_cluster_points, atLeast(1));
    s.root().convert<int>(
        "max_points", &P::max_points,
        [](int v, std::size_t& out) -> std::optional<std::string> {
          if (v < 1) return "must be >= 1, got " + std::to_string(v);
          out = static_cast<std::size_t>(v);
          return std::nullopt;
        },
        atLeast<std::size_t>(1));
    return s;
  }();
  return kSchema;
}

}  // namespace

std::optional<std::string> ObjectClass::invalidReason() const {
  if (label.empty()) return std::string("label must not be empty");
  if (auto why = shape.invalidReason()) return "shape: " + *why;
  if (kind == world::ObjectKind::kMovable && !(mass > 0 && std::isfinite(mass))) {
    return "mass of a movable class must be positive, got " + formatNumber(mass);
  }
  if (!(mass >= 0) || !std::isfinite(mass)) return "mass must be >= 0, got " + formatNumber(mass);
  return std::nullopt;
}

Status PerceptionParams::validate() const {
  std::vector<Error> errors = schema().errors(*this);
  std::set<std::string> labels;
  for (std::size_t i = 0; i < classes.size(); ++i) {
    const std::string f = "classes[" + std::to_string(i) + "]";
    if (auto why = classes[i].invalidReason()) errors.emplace_back(ErrorCode::kInvalidArgument, *why, SourceLocation{"", 0, 0, f});
    if (!labels.insert(classes[i].label).second) {
      errors.emplace_back(ErrorCode::kInvalidArgument, "duplicate class label '" + classes[i].label + "'",
                          SourceLocation{"", 0, 0, f + ".label"});
    }
  }
  if (errors.empty()) return Status::Ok();
  return Error(ErrorCode::kInvalidArgument, "invalid perception parameters:\n" + joinErrors(errors));
}

Result<PerceptionParams> parsePerceptionParams(const std::string& yaml_text, const std::string& name) {
  auto doc = config::parseYaml(yaml_text, name);
  if (!doc) return doc.error();
  PerceptionParams p;
  config::FieldReader r(*doc);
  if (!doc->root.IsNull() && !r.isMap()) {
    return Error(ErrorCode::kParseError, "expected a mapping of parameters", SourceLocation{name, 1, 1, ""});
  }
  schema().read(r, p);
  for (auto& cr : r.sequence("classes", false)) {
    ObjectClass c;
    cr.required("label", c.label);
    std::string shape = "box", kind = "movable";
    cr.optional("shape", shape);
    if (shape == "box") {
      Eigen::Vector3d size = Eigen::Vector3d::Zero();
      if (cr.required("size", size)) c.shape = world::Shape::box(size.x(), size.y(), size.z());
    } else if (shape == "cylinder") {
      double radius = 0, height = 0;
      cr.required("radius", radius);
      cr.required("height", height);
      c.shape = world::Shape::cylinder(radius, height);
    } else {
      cr.fail("shape", "unknown class shape '" + shape + "' (expected one of: box, cylinder)");
    }
    if (cr.optional("kind", kind)) {
      if (auto k = world::objectKindFromString(kind)) {
        c.kind = *k;
      } else {
        cr.fail("kind", "unknown kind '" + kind + "' (expected one of: static, movable)");
      }
    }
    cr.optional("mass", c.mass);
    cr.optional("graspable", c.graspable);
    if (cr.ok()) {
      if (auto why = c.invalidReason()) cr.fail("", *why);
    }
    cr.refuseUnknownKeys();
    p.classes.push_back(std::move(c));
  }

  r.ignore("node");  // the DDS node's own section (services/perception/node)
  r.refuseUnknownKeys();
  if (!r.ok()) return r.status().error();
  if (Status s = p.validate(); !s.ok()) return s.error();  // e.g. duplicate class labels
  return p;
}

Result<PerceptionParams> loadPerceptionParams(const std::filesystem::path& file) {
  auto text = readTextFile(file);
  if (!text) return text.error();
  return parsePerceptionParams(*text, file.string());
}

std::vector<ObjectClass> classesFromWorld(const world::World& prior) {
  std::vector<ObjectClass> out;
  for (const auto& o : prior.objects()) {
    if (o.kind != world::ObjectKind::kMovable || o.hidden) continue;
    const std::string label = o.label.empty() ? std::string("object") : o.label;
    bool seen = false;
    for (const auto& c : out) seen = seen || (c.label == label && c.shape == o.shape);
    if (seen) continue;
    // Two shapes under one label get distinct class labels.
    std::string unique = label;
    for (int n = 2; std::any_of(out.begin(), out.end(), [&](const ObjectClass& c) { return c.label == unique; }); ++n) {
      unique = label + "_" + std::to_string(n);
    }
    ObjectClass c;
    c.label = unique;
    c.shape = o.shape;
    c.kind = o.kind;
    c.mass = o.mass;
    c.graspable = o.graspable;
    out.push_back(std::move(c));
  }
  return out;
}

}  // namespace tamp::perception
