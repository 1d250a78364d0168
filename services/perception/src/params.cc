#include "tamp/core/format.h"
#include "tamp/perception/params.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <cstdio>
#include <functional>
#include <set>

#include "tamp/config/yaml_reader.h"
#include "tamp/core/paths.h"

namespace tamp::perception {
namespace {

/// One rule per field: (dotted field, ok?, message). Shared by validate() and the loader, which
/// attaches the YAML location of the field.
struct Rule {
  std::string section;
  std::string field;
  bool ok;
  std::string message;
};

bool positive(double v) { return std::isfinite(v) && v > 0; }
bool nonNegative(double v) { return std::isfinite(v) && v >= 0; }
std::string mustBePositive(double v) { return "must be positive, got " + formatNumber(v); }
std::string mustBeNonNegative(double v) { return "must be >= 0, got " + formatNumber(v); }
bool inHalfOpen01(double v) { return std::isfinite(v) && v > 0 && v <= 1; }

std::vector<Rule> rules(const PerceptionParams& p) {
  const CropParams& c = p.crop;
  const PlaneParams& pl = p.planes;
  const ClusterParams& cl = p.clusters;
  const TrackingParams& t = p.tracking;
  const ClassifyParams& k = p.classify;
  const OccupancyParams& o = p.occupancy;
  std::vector<Rule> r = {
      {"sensor", "noise_stddev", nonNegative(p.sensor.noise_stddev), mustBeNonNegative(p.sensor.noise_stddev)},
      {"sensor", "noise_quadratic", nonNegative(p.sensor.noise_quadratic), mustBeNonNegative(p.sensor.noise_quadratic)},
      {"planes", "noise_sigmas", nonNegative(pl.noise_sigmas), mustBeNonNegative(pl.noise_sigmas)},
      {"planes", "ransac_max_points", pl.ransac_max_points >= 100,
       "must be >= 100, got " + std::to_string(pl.ransac_max_points)},
      {"crop", "workspace_margin", nonNegative(c.workspace_margin), mustBeNonNegative(c.workspace_margin)},
      {"crop", "min_range", nonNegative(c.min_range), mustBeNonNegative(c.min_range)},
      {"crop", "max_range", std::isfinite(c.max_range) && c.max_range > c.min_range,
       "must be greater than min_range (" + formatNumber(c.min_range) + "), got " + formatNumber(c.max_range)},
      {"crop", "min_z", std::isfinite(c.min_z), "must be finite, got " + formatNumber(c.min_z)},
      {"crop", "max_z", std::isfinite(c.max_z) && c.max_z > c.min_z,
       "must be greater than min_z (" + formatNumber(c.min_z) + "), got " + formatNumber(c.max_z)},
      {"planes", "voxel_size", positive(pl.voxel_size) && pl.voxel_size <= 0.5,
       "must be in (0, 0.5] m, got " + formatNumber(pl.voxel_size)},
      {"planes", "max_planes", pl.max_planes >= 0, "must be >= 0, got " + std::to_string(pl.max_planes)},
      {"planes", "max_attempts", pl.max_attempts >= pl.max_planes,
       "must be >= max_planes (" + std::to_string(pl.max_planes) + "), got " + std::to_string(pl.max_attempts)},
      {"planes", "ransac_iterations", pl.ransac_iterations >= 1,
       "must be >= 1, got " + std::to_string(pl.ransac_iterations)},
      {"planes", "distance_threshold", positive(pl.distance_threshold), mustBePositive(pl.distance_threshold)},
      {"planes", "max_tilt", std::isfinite(pl.max_tilt) && pl.max_tilt > 0 && pl.max_tilt < 1.5,
       "must be in (0, 1.5) rad, got " + formatNumber(pl.max_tilt)},
      {"planes", "min_points", pl.min_points >= 3, "must be >= 3, got " + std::to_string(pl.min_points)},
      {"planes", "min_support_area", positive(pl.min_support_area), mustBePositive(pl.min_support_area)},
      {"planes", "region_height_tolerance", positive(pl.region_height_tolerance),
       mustBePositive(pl.region_height_tolerance)},
      {"planes", "region_margin", nonNegative(pl.region_margin), mustBeNonNegative(pl.region_margin)},
      {"clusters", "tolerance", positive(cl.tolerance) && cl.tolerance > pl.voxel_size,
       "must be greater than planes.voxel_size (" + formatNumber(pl.voxel_size) + "), got " + formatNumber(cl.tolerance)},
      {"clusters", "min_points", cl.min_points >= 1, "must be >= 1, got " + std::to_string(cl.min_points)},
      {"clusters", "max_points", cl.max_points >= cl.min_points,
       "must be >= min_points (" + std::to_string(cl.min_points) + "), got " + std::to_string(cl.max_points)},
      {"clusters", "min_height", nonNegative(cl.min_height), mustBeNonNegative(cl.min_height)},
      {"clusters", "min_size", nonNegative(cl.min_size), mustBeNonNegative(cl.min_size)},
      {"clusters", "max_size", std::isfinite(cl.max_size) && cl.max_size > cl.min_size,
       "must be greater than min_size (" + formatNumber(cl.min_size) + "), got " + formatNumber(cl.max_size)},
      {"clusters", "static_margin", nonNegative(cl.static_margin), mustBeNonNegative(cl.static_margin)},
      {"clusters", "cylinder_residual_ratio", inHalfOpen01(cl.cylinder_residual_ratio),
       "must be in (0, 1], got " + formatNumber(cl.cylinder_residual_ratio)},
      {"tracking", "gate_distance", positive(t.gate_distance), mustBePositive(t.gate_distance)},
      {"tracking", "size_tolerance", nonNegative(t.size_tolerance), mustBeNonNegative(t.size_tolerance)},
      {"tracking", "height_tolerance", nonNegative(t.height_tolerance), mustBeNonNegative(t.height_tolerance)},
      {"tracking", "confirm_hits", t.confirm_hits >= 1, "must be >= 1, got " + std::to_string(t.confirm_hits)},
      {"tracking", "tentative_timeout_s", positive(t.tentative_timeout_s), mustBePositive(t.tentative_timeout_s)},
      {"tracking", "gone_frames", t.gone_frames >= 1, "must be >= 1, got " + std::to_string(t.gone_frames)},
      {"tracking", "smoothing", inHalfOpen01(t.smoothing), "must be in (0, 1], got " + formatNumber(t.smoothing)},
      {"tracking", "snap_distance", positive(t.snap_distance), mustBePositive(t.snap_distance)},
      {"tracking", "update_distance", nonNegative(t.update_distance), mustBeNonNegative(t.update_distance)},
      {"tracking", "update_angle", nonNegative(t.update_angle), mustBeNonNegative(t.update_angle)},
      {"tracking", "move_event_distance", positive(t.move_event_distance), mustBePositive(t.move_event_distance)},
      {"tracking", "move_event_angle", positive(t.move_event_angle), mustBePositive(t.move_event_angle)},
      {"tracking", "visibility_bin", positive(t.visibility_bin) && t.visibility_bin <= 0.2,
       "must be in (0, 0.2] (tangent units), got " + formatNumber(t.visibility_bin)},
      {"tracking", "visibility_margin", positive(t.visibility_margin), mustBePositive(t.visibility_margin)},
      {"tracking", "gone_fraction", inHalfOpen01(t.gone_fraction), "must be in (0, 1], got " + formatNumber(t.gone_fraction)},
      {"tracking", "present_fraction", inHalfOpen01(t.present_fraction),
       "must be in (0, 1], got " + formatNumber(t.present_fraction)},
      {"tracking", "gone_min_samples", t.gone_min_samples >= 1,
       "must be >= 1, got " + std::to_string(t.gone_min_samples)},
      {"classify", "movable_max_extent", positive(k.movable_max_extent), mustBePositive(k.movable_max_extent)},
      {"classify", "movable_max_height", positive(k.movable_max_height), mustBePositive(k.movable_max_height)},
      {"classify", "density", positive(k.density), mustBePositive(k.density)},
      {"classify", "min_mass", positive(k.min_mass), mustBePositive(k.min_mass)},
      {"classify", "graspable_max_width", nonNegative(k.graspable_max_width), mustBeNonNegative(k.graspable_max_width)},
      {"classify", "graspable_max_mass", nonNegative(k.graspable_max_mass), mustBeNonNegative(k.graspable_max_mass)},
      {"occupancy", "resolution", positive(o.resolution) && o.resolution <= 1.0,
       "must be in (0, 1] m, got " + formatNumber(o.resolution)},
      {"occupancy", "free_space_voxel", positive(o.free_space_voxel), mustBePositive(o.free_space_voxel)},
      {"occupancy", "max_ray_range", positive(o.max_ray_range), mustBePositive(o.max_ray_range)},
      {"occupancy", "explained_margin", nonNegative(o.explained_margin), mustBeNonNegative(o.explained_margin)},
      {"occupancy", "prob_hit", std::isfinite(o.prob_hit) && o.prob_hit > 0.5 && o.prob_hit < 1,
       "must be in (0.5, 1), got " + formatNumber(o.prob_hit)},
      {"occupancy", "prob_miss", std::isfinite(o.prob_miss) && o.prob_miss > 0 && o.prob_miss < 0.5,
       "must be in (0, 0.5), got " + formatNumber(o.prob_miss)},
      {"occupancy", "occupancy_threshold",
       std::isfinite(o.occupancy_threshold) && o.occupancy_threshold >= 0.5 && o.occupancy_threshold < 1,
       "must be in [0.5, 1), got " + formatNumber(o.occupancy_threshold)},
      {"occupancy", "min_cluster_points", o.min_cluster_points >= 1,
       "must be >= 1, got " + std::to_string(o.min_cluster_points)},
      {"", "max_points", p.max_points >= 1, "must be >= 1"},
  };
  if (c.workspace) {
    r.push_back({"crop", "workspace", !c.workspace->empty() && c.workspace->min.allFinite() && c.workspace->max.allFinite(),
                 "must be a non-empty finite box (min <= max)"});
  }
  return r;
}

std::string join(const std::string& section, const std::string& field) {
  return section.empty() ? field : section + "." + field;
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
  std::vector<Error> errors;
  for (const Rule& r : rules(*this)) {
    if (!r.ok) errors.emplace_back(ErrorCode::kInvalidArgument, r.message, SourceLocation{"", 0, 0, join(r.section, r.field)});
  }
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
  std::map<std::string, config::FieldReader> sections;
  auto section = [&](const std::string& key) -> config::FieldReader& {
    auto it = sections.find(key);
    if (it == sections.end()) it = sections.emplace(key, r.child(key, false)).first;
    return it->second;
  };
  {
    auto& s = section("sensor");
    s.optional("noise_stddev", p.sensor.noise_stddev);
    s.optional("noise_quadratic", p.sensor.noise_quadratic);
  }
  {
    auto& s = section("crop");
    std::vector<double> ws;
    if (s.optional("workspace", ws)) {
      if (s.check(ws.size() == 6, "workspace", "expected [xmin, ymin, zmin, xmax, ymax, zmax], got " +
                                                   std::to_string(ws.size()) + " numbers")) {
        Aabb b;
        b.min = Eigen::Vector3d(ws[0], ws[1], ws[2]);
        b.max = Eigen::Vector3d(ws[3], ws[4], ws[5]);
        p.crop.workspace = b;
      }
    }
    s.optional("workspace_margin", p.crop.workspace_margin);
    s.optional("min_range", p.crop.min_range);
    s.optional("max_range", p.crop.max_range);
    s.optional("min_z", p.crop.min_z);
    s.optional("max_z", p.crop.max_z);
  }
  {
    auto& s = section("planes");
    s.optional("voxel_size", p.planes.voxel_size);
    s.optional("max_planes", p.planes.max_planes);
    s.optional("max_attempts", p.planes.max_attempts);
    s.optional("ransac_iterations", p.planes.ransac_iterations);
    s.optional("distance_threshold", p.planes.distance_threshold);
    s.optional("noise_sigmas", p.planes.noise_sigmas);
    s.optional("ransac_max_points", p.planes.ransac_max_points);
    s.optional("max_tilt", p.planes.max_tilt);
    s.optional("min_points", p.planes.min_points);
    s.optional("min_support_area", p.planes.min_support_area);
    s.optional("region_height_tolerance", p.planes.region_height_tolerance);
    s.optional("region_margin", p.planes.region_margin);
  }
  {
    auto& s = section("clusters");
    s.optional("tolerance", p.clusters.tolerance);
    s.optional("min_points", p.clusters.min_points);
    s.optional("max_points", p.clusters.max_points);
    s.optional("min_height", p.clusters.min_height);
    s.optional("min_size", p.clusters.min_size);
    s.optional("max_size", p.clusters.max_size);
    s.optional("static_margin", p.clusters.static_margin);
    s.optional("cylinder_residual_ratio", p.clusters.cylinder_residual_ratio);
  }
  {
    auto& s = section("tracking");
    TrackingParams& t = p.tracking;
    s.optional("gate_distance", t.gate_distance);
    s.optional("size_tolerance", t.size_tolerance);
    s.optional("height_tolerance", t.height_tolerance);
    s.optional("confirm_hits", t.confirm_hits);
    s.optional("tentative_timeout_s", t.tentative_timeout_s);
    s.optional("gone_frames", t.gone_frames);
    s.optional("smoothing", t.smoothing);
    s.optional("snap_distance", t.snap_distance);
    s.optional("update_distance", t.update_distance);
    s.optional("update_angle", t.update_angle);
    s.optional("move_event_distance", t.move_event_distance);
    s.optional("move_event_angle", t.move_event_angle);
    s.optional("visibility_bin", t.visibility_bin);
    s.optional("visibility_margin", t.visibility_margin);
    s.optional("gone_fraction", t.gone_fraction);
    s.optional("present_fraction", t.present_fraction);
    s.optional("gone_min_samples", t.gone_min_samples);
    s.optional("reacquire", t.reacquire);
  }
  {
    auto& s = section("classify");
    s.optional("movable_max_extent", p.classify.movable_max_extent);
    s.optional("movable_max_height", p.classify.movable_max_height);
    s.optional("density", p.classify.density);
    s.optional("min_mass", p.classify.min_mass);
    s.optional("graspable_max_width", p.classify.graspable_max_width);
    s.optional("graspable_max_mass", p.classify.graspable_max_mass);
  }
  {
    auto& s = section("occupancy");
    OccupancyParams& o = p.occupancy;
    s.optional("enabled", o.enabled);
    s.optional("resolution", o.resolution);
    s.optional("free_space_voxel", o.free_space_voxel);
    s.optional("max_ray_range", o.max_ray_range);
    s.optional("explained_margin", o.explained_margin);
    s.optional("prob_hit", o.prob_hit);
    s.optional("prob_miss", o.prob_miss);
    s.optional("occupancy_threshold", o.occupancy_threshold);
    s.optional("min_cluster_points", o.min_cluster_points);
  }
  int max_points = static_cast<int>(p.max_points);
  if (r.optional("max_points", max_points)) {
    if (r.check(max_points >= 1, "max_points", "must be >= 1, got " + std::to_string(max_points))) {
      p.max_points = static_cast<std::size_t>(max_points);
    }
  }

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

  // Per-field rules with the YAML location of the field (or of its section).
  for (const Rule& rule : rules(p)) {
    if (rule.section.empty()) continue;
    section(rule.section).check(rule.ok, rule.field, rule.message);
  }
  for (auto& [key, s] : sections) s.refuseUnknownKeys();
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
