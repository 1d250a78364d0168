// The only translation unit that includes PCL (slow to compile; see notes/dependencies.md §6).
#include "tamp/perception/segmentation.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <unordered_map>

#include <pcl/console/print.h>
#include <pcl/filters/voxel_grid.h>
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>
#include <pcl/sample_consensus/method_types.h>
#include <pcl/sample_consensus/model_types.h>
#include <pcl/search/kdtree.h>
#include <pcl/segmentation/extract_clusters.h>
#include <pcl/segmentation/sac_segmentation.h>

#include "tamp/perception/shape_fit.h"
#include "tamp/world/polygon.h"

namespace tamp::perception {
namespace {

using Cloud = pcl::PointCloud<pcl::PointXYZ>;

Status stopped(const Termination& term, const char* stage) {
  const bool cancelled = term.reason() == StopReason::kStopRequested;
  return Error(cancelled ? ErrorCode::kCancelled : ErrorCode::kTimeout,
               std::string(cancelled ? "cancelled" : "deadline passed") + " before " + stage);
}

/// Static objects of the prior in a 2-D grid of their grown bounding boxes.
class StaticIndex {
 public:
  StaticIndex() = default;
  StaticIndex(const world::World& prior, double margin) : margin_(margin), prior_(prior) {
    // prior_ shares the objects with `prior` and keeps them alive for the pointers below.
    for (const auto& o : prior_.objects()) {
      if (o.kind != world::ObjectKind::kStatic || o.hidden) continue;
      const Aabb b = o.aabb();
      if (b.empty()) continue;
      const int idx = static_cast<int>(objects_.size());
      objects_.push_back(&o);
      boxes_.push_back(b);
      for (long ix = cell(b.min.x() - margin); ix <= cell(b.max.x() + margin); ++ix) {
        for (long iy = cell(b.min.y() - margin); iy <= cell(b.max.y() + margin); ++iy) {
          grid_[key(ix, iy)].push_back(idx);
        }
      }
    }
  }
  /// True when `p` lies within `margin` (at most the construction's margin) of a static object.
  bool explains(const Eigen::Vector3d& p, double margin) const {
    margin = std::min(margin, margin_);
    auto it = grid_.find(key(cell(p.x()), cell(p.y())));
    if (it == grid_.end()) return false;
    for (int i : it->second) {
      const Aabb& b = boxes_[static_cast<std::size_t>(i)];
      if ((p.array() < b.min.array() - margin).any() || (p.array() > b.max.array() + margin).any()) continue;
      const world::Object& o = *objects_[static_cast<std::size_t>(i)];
      if (pointInShape(o.shape, o.pose, p, margin)) return true;
    }
    return false;
  }
  bool empty() const { return objects_.empty(); }

 private:
  static constexpr double kCell = 1.0;
  static long cell(double v) { return static_cast<long>(std::floor(v / kCell)); }
  static std::int64_t key(long ix, long iy) { return (static_cast<std::int64_t>(ix) << 32) ^ (iy & 0xffffffff); }
  double margin_{0.0};
  world::World prior_;
  std::vector<const world::Object*> objects_;
  std::vector<Aabb> boxes_;
  std::unordered_map<std::int64_t, std::vector<int>> grid_;
};

double ms(const Stopwatch& w) { return w.millis(); }

/// A support plane matching no prior region must cover at least this fraction of its inliers'
/// convex hull (distinct voxel cells; see the plane stage of Segmenter::run).
constexpr double kMinSupportFill = 0.25;

/// Points this close to a prior static object, at `range` from the sensor, are its returns.
double staticMargin(const PerceptionParams& P, double range) {
  return std::max(P.clusters.static_margin, P.planes.noise_sigmas * P.sensor.stddev(range));
}

}  // namespace

struct Segmenter::Impl {
  PerceptionParams params;
  Aabb workspace;
  StaticIndex statics;
  std::vector<world::Region> regions;
};

Segmenter::Segmenter(const PerceptionParams& params, const world::World& prior) : impl_(std::make_unique<Impl>()) {
  if (Status s = params.validate(); !s.ok()) throw std::invalid_argument(s.error().toString());
  // PCL reports "no plane found" on stderr; that is an expected outcome here (the loop stops).
  pcl::console::setVerbosityLevel(pcl::console::L_ALWAYS);
  impl_->params = params;
  if (params.crop.workspace) {
    impl_->workspace = *params.crop.workspace;
  } else {
    const Aabb b = prior.bounds();
    const double big = 1e4;
    if (b.empty()) {
      impl_->workspace.min = Eigen::Vector3d::Constant(-big);
      impl_->workspace.max = Eigen::Vector3d::Constant(big);
    } else {
      const double m = params.crop.workspace_margin;
      impl_->workspace.min = Eigen::Vector3d(b.min.x() - m, b.min.y() - m, -big);
      impl_->workspace.max = Eigen::Vector3d(b.max.x() + m, b.max.y() + m, big);
    }
  }
  impl_->workspace.min.z() = std::max(impl_->workspace.min.z(), params.crop.min_z);
  impl_->workspace.max.z() = std::min(impl_->workspace.max.z(), params.crop.max_z);
  // The static map's margin grows with the range noise (as the support planes' band does): a far
  // wall's returns scatter by several centimetres, and those would otherwise cluster into thin
  // false objects in front of it. The index is built for the largest margin (at max_range).
  impl_->statics = StaticIndex(prior, staticMargin(params, params.crop.max_range));
  for (const auto& r : prior.regions()) impl_->regions.push_back(r);
}

Segmenter::~Segmenter() = default;
Segmenter::Segmenter(Segmenter&&) noexcept = default;
Segmenter& Segmenter::operator=(Segmenter&&) noexcept = default;

const Aabb& Segmenter::workspace() const { return impl_->workspace; }

Result<Segmentation> Segmenter::run(const PointCloudFrame& frame, const Termination& term) const {
  const PerceptionParams& P = impl_->params;
  Segmentation out;
  Stopwatch watch;

  // ---- transform + crop ------------------------------------------------------------------------
  auto cropped = std::make_shared<Cloud>();
  {
    const Eigen::Matrix3f R = frame.world_T_sensor.linear().cast<float>();
    const Eigen::Vector3f t = frame.world_T_sensor.translation().cast<float>();
    const Eigen::Array3f lo = impl_->workspace.min.cast<float>().array();
    const Eigen::Array3f hi = impl_->workspace.max.cast<float>().array();
    const float r2min = static_cast<float>(P.crop.min_range * P.crop.min_range);
    const float r2max = static_cast<float>(P.crop.max_range * P.crop.max_range);
    const std::size_t n = frame.size();
    cropped->points.reserve(n);
    for (std::size_t i = 0; i < n; ++i) {
      const Eigen::Vector3f q(frame.xyz[3 * i], frame.xyz[3 * i + 1], frame.xyz[3 * i + 2]);
      if (!std::isfinite(q.x())) continue;  // validated: a triplet is all finite or a no-return
      ++out.valid_points;
      const float r2 = q.squaredNorm();
      if (r2 < r2min || r2 > r2max) continue;
      const Eigen::Vector3f w = R * q + t;
      if ((w.array() < lo).any() || (w.array() > hi).any()) continue;
      cropped->points.emplace_back(w.x(), w.y(), w.z());
    }
    cropped->width = static_cast<std::uint32_t>(cropped->points.size());
    cropped->height = 1;
    cropped->is_dense = true;
  }
  out.cropped_points = cropped->size();
  out.times.transform_crop = ms(watch);
  if (term()) return stopped(term, "the voxel filter").error();

  // ---- voxel grid ------------------------------------------------------------------------------
  watch.reset();
  auto cloud = std::make_shared<Cloud>();
  if (!cropped->empty()) {
    pcl::VoxelGrid<pcl::PointXYZ> grid;
    const float leaf = static_cast<float>(P.planes.voxel_size);
    grid.setLeafSize(leaf, leaf, leaf);
    grid.setInputCloud(cropped);
    grid.filter(*cloud);
  }
  out.scan.reserve(cloud->size());
  for (const auto& p : cloud->points) out.scan.emplace_back(p.x, p.y, p.z);
  out.times.voxel = ms(watch);
  if (term()) return stopped(term, "plane segmentation").error();

  // ---- support planes --------------------------------------------------------------------------
  watch.reset();
  std::vector<char> removed(cloud->size(), 0);
  {
    const Eigen::Vector3f origin = frame.world_T_sensor.translation().cast<float>();
    std::vector<pcl::index_t> search(cloud->size());
    for (std::size_t i = 0; i < cloud->size(); ++i) search[i] = static_cast<pcl::index_t>(i);
    // PCL's RANSAC is seeded with a constant (SACSegmentation(random = false)): frames are
    // reproducible.
    pcl::SACSegmentation<pcl::PointXYZ> seg;
    seg.setOptimizeCoefficients(true);
    seg.setModelType(pcl::SACMODEL_PERPENDICULAR_PLANE);
    seg.setMethodType(pcl::SAC_RANSAC);
    seg.setAxis(Eigen::Vector3f::UnitZ());
    seg.setEpsAngle(P.planes.max_tilt);
    seg.setDistanceThreshold(P.planes.distance_threshold);
    seg.setMaxIterations(P.planes.ransac_iterations);
    seg.setInputCloud(cloud);
    const double voxel_area = P.planes.voxel_size * P.planes.voxel_size;
    std::vector<std::vector<Eigen::Vector2d>> plane_xy;  // inliers' xy per accepted plane (hulls)
    for (int attempt = 0; attempt < P.planes.max_attempts; ++attempt) {
      if (static_cast<int>(search.size()) < P.planes.min_points) break;
      if (term()) return stopped(term, "the next support plane").error();
      // The model from an even subsample; inliers over every candidate point.
      const std::size_t stride =
          (search.size() + static_cast<std::size_t>(P.planes.ransac_max_points) - 1) / static_cast<std::size_t>(P.planes.ransac_max_points);
      auto sub = std::make_shared<pcl::Indices>();
      sub->reserve(search.size() / stride + 1);
      for (std::size_t k = 0; k < search.size(); k += stride) sub->push_back(search[k]);
      pcl::PointIndices sub_inliers;
      pcl::ModelCoefficients coeffs;
      seg.setIndices(sub);
      seg.segment(sub_inliers, coeffs);
      if (coeffs.values.size() != 4 || static_cast<int>(sub_inliers.indices.size() * stride) < P.planes.min_points) break;
      Eigen::Vector4f c(coeffs.values[0], coeffs.values[1], coeffs.values[2], coeffs.values[3]);
      c /= c.head<3>().norm();
      if (c.z() < 0) c = -c;
      const Eigen::Vector3f n = c.head<3>();
      // Noise-aware band: the along-ray range noise projected on the plane normal.
      std::vector<pcl::index_t> inliers;
      std::vector<pcl::index_t> rest;
      inliers.reserve(search.size());
      rest.reserve(search.size());
      const float base = static_cast<float>(P.planes.distance_threshold);
      for (auto i : search) {
        const Eigen::Vector3f q = cloud->points[static_cast<std::size_t>(i)].getVector3fMap();
        const float dist = std::abs(n.dot(q) + c.w());
        const Eigen::Vector3f ray = q - origin;
        const float range = ray.norm();
        const float cosine = range > 1e-6f ? std::abs(n.dot(ray)) / range : 1.0f;
        const float band = std::max(base, static_cast<float>(P.planes.noise_sigmas * P.sensor.stddev(range)) * cosine);
        (dist <= band ? inliers : rest).push_back(i);
      }
      search = std::move(rest);  // every inlier leaves the plane search, accepted or not
      if (static_cast<int>(inliers.size()) < P.planes.min_points) continue;
      Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
      for (auto i : inliers) centroid += cloud->points[static_cast<std::size_t>(i)].getVector3fMap().cast<double>();
      centroid /= static_cast<double>(inliers.size());
      SupportPlane plane;
      plane.coefficients = c.cast<double>();
      plane.measured_height = -(plane.coefficients.x() * centroid.x() + plane.coefficients.y() * centroid.y() +
                                plane.coefficients.w()) / plane.coefficients.z();
      plane.height = plane.measured_height;
      plane.inliers = static_cast<int>(inliers.size());
      {
        // Area from the distinct xy cells the inliers cover (range noise smears a surface over
        // several voxel layers, so inliers x voxel^2 would overestimate it).
        std::vector<std::int64_t> cells;
        cells.reserve(inliers.size());
        const float inv = 1.0f / static_cast<float>(P.planes.voxel_size);
        for (auto i : inliers) {
          const auto& q = cloud->points[static_cast<std::size_t>(i)];
          const auto ix = static_cast<std::int64_t>(std::floor(q.x * inv)), iy = static_cast<std::int64_t>(std::floor(q.y * inv));
          cells.push_back((ix << 32) ^ (iy & 0xffffffff));
        }
        std::sort(cells.begin(), cells.end());
        plane.area = static_cast<double>(std::unique(cells.begin(), cells.end()) - cells.begin()) * voxel_area;
      }
      // Match a prior region: same height and most inliers over its polygon (tables first).
      const world::Region* region = nullptr;
      for (const auto& r : impl_->regions) {
        if (std::abs(r.height - plane.measured_height) > P.planes.region_height_tolerance) continue;
        std::size_t over = 0;
        for (auto i : inliers) {
          const auto& q = cloud->points[static_cast<std::size_t>(i)];
          if (r.contains(Eigen::Vector2d(q.x, q.y))) ++over;
        }
        if (2 * over >= inliers.size() && (region == nullptr || r.kind == world::RegionKind::kTable)) region = &r;
      }
      // A rejected plane is an object's top: its points stay object points.
      if (region == nullptr && plane.area < P.planes.min_support_area) continue;
      // A large plane that matches no region must be a surface: its inliers must fill a good
      // part of their hull. A horizontal slice through walls and objects (the band of a plane
      // at some height cuts every vertical surface) can add up to the support area but fills
      // little of the room it spans; taking it as a support cut every object there in two.
      if (region == nullptr) {
        std::vector<Eigen::Vector2d> xy;
        xy.reserve(inliers.size());
        for (auto i : inliers) {
          const auto& q = cloud->points[static_cast<std::size_t>(i)];
          xy.emplace_back(q.x, q.y);
        }
        const double hull_area = std::abs(world::signedArea(convexHull(std::move(xy))));
        if (plane.area < kMinSupportFill * hull_area) continue;
      }
      if (region != nullptr) {
        plane.region = region->id;
        plane.height = region->height;
      }
      // A table region's polygon bounds what its plane removes (a box top at table height
      // elsewhere stays an object); a floor or an unmatched large plane removes all inliers.
      const bool bounded = region != nullptr && region->kind == world::RegionKind::kTable;
      world::Polygon2 grown;
      if (bounded) {
        const Eigen::Vector2d mid = world::areaCentroid(region->polygon);
        for (const auto& v : region->polygon) {
          const Eigen::Vector2d d = v - mid;
          grown.push_back(d.norm() > 1e-9 ? Eigen::Vector2d(v + d.normalized() * P.planes.region_margin * 1.42) : v);
        }
      }
      std::vector<Eigen::Vector2d> xy;
      xy.reserve(inliers.size());
      for (auto i : inliers) {
        const auto& q = cloud->points[static_cast<std::size_t>(i)];
        if (bounded && !world::containsPoint(grown, Eigen::Vector2d(q.x, q.y))) continue;
        removed[static_cast<std::size_t>(i)] = 1;
        xy.emplace_back(q.x, q.y);
      }
      out.plane_points += xy.size();
      // The same surface found twice (e.g. the far floor, noisier) merges into the first.
      auto same = std::find_if(out.planes.begin(), out.planes.end(), [&](const SupportPlane& o) {
        return o.region == plane.region && std::abs(o.height - plane.height) <= P.planes.region_height_tolerance;
      });
      if (same != out.planes.end()) {
        auto& pts = plane_xy[static_cast<std::size_t>(same - out.planes.begin())];
        pts.insert(pts.end(), xy.begin(), xy.end());
        same->inliers += plane.inliers;
        same->area += plane.area;
        continue;
      }
      if (static_cast<int>(out.planes.size()) >= P.planes.max_planes) break;
      out.planes.push_back(std::move(plane));
      plane_xy.push_back(std::move(xy));
    }
    for (std::size_t k = 0; k < out.planes.size(); ++k) out.planes[k].hull = convexHull(std::move(plane_xy[k]));
  }
  out.times.planes = ms(watch);
  if (term()) return stopped(term, "static-object removal").error();

  // ---- points of prior static objects ------------------------------------------------------------
  watch.reset();
  auto rest = std::make_shared<Cloud>();
  rest->points.reserve(cloud->size());
  for (std::size_t i = 0; i < cloud->size(); ++i) {
    if (removed[i]) continue;
    const auto& q = cloud->points[i];
    const Eigen::Vector3d p(q.x, q.y, q.z);
    if (!impl_->statics.empty() && impl_->statics.explains(p, staticMargin(P, (p - frame.world_T_sensor.translation()).norm()))) {
      ++out.static_points;
      continue;
    }
    rest->points.push_back(q);
  }
  rest->width = static_cast<std::uint32_t>(rest->points.size());
  rest->height = 1;
  rest->is_dense = true;
  out.times.static_objects = ms(watch);
  if (term()) return stopped(term, "clustering").error();

  // ---- Euclidean clustering ----------------------------------------------------------------------
  watch.reset();
  if (!rest->empty()) {
    auto tree = std::make_shared<pcl::search::KdTree<pcl::PointXYZ>>();
    tree->setInputCloud(rest);
    pcl::EuclideanClusterExtraction<pcl::PointXYZ> ec;
    ec.setClusterTolerance(P.clusters.tolerance);
    ec.setMinClusterSize(std::max(1, std::min(P.occupancy.min_cluster_points, P.clusters.min_points)));
    ec.setMaxClusterSize(std::numeric_limits<int>::max());
    ec.setSearchMethod(tree);
    ec.setInputCloud(rest);
    std::vector<pcl::PointIndices> found;
    ec.extract(found);
    for (const auto& c : found) {
      const int size = static_cast<int>(c.indices.size());
      if (size >= P.clusters.min_points && size <= P.clusters.max_points) {
        std::vector<Eigen::Vector3f> pts;
        pts.reserve(c.indices.size());
        for (auto i : c.indices) pts.push_back(rest->points[static_cast<std::size_t>(i)].getVector3fMap());
        out.clusters.push_back(std::move(pts));
      } else if (size >= P.occupancy.min_cluster_points) {
        std::vector<Eigen::Vector3f> pts;
        pts.reserve(c.indices.size());
        for (auto i : c.indices) pts.push_back(rest->points[static_cast<std::size_t>(i)].getVector3fMap());
        out.small_clusters.push_back(std::move(pts));
      }
    }
  }
  out.times.clustering = ms(watch);
  return out;
}

}  // namespace tamp::perception
