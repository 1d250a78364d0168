// The only translation unit that includes PCL (slow to compile; see notes/dependencies.md §6).
#include "tamp/perception/segmentation.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <optional>
#include <stdexcept>
#include <unordered_map>

#include <pcl/console/print.h>
#include <pcl/ModelCoefficients.h>
#include <pcl/PointIndices.h>
#include <pcl/filters/voxel_grid.h>
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>
#include <pcl/sample_consensus/ransac.h>
#include <pcl/sample_consensus/sac_model_perpendicular_plane.h>
#include <pcl/search/kdtree.h>
#include <pcl/segmentation/extract_clusters.h>

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

// ---- fast exact replacements of pcl::VoxelGrid, pcl::EuclideanClusterExtraction and the plane
// model's inlier count (the three took ~45 % of a 300k frame; see docs/benchmarks.md) ------------

/// Empty slot of an open-addressing set of xy cell keys (ix << 32) ^ (iy & 0xffffffff); cell
/// (-1, -1) has this key and is counted apart.
constexpr std::uint64_t kNoCell = ~std::uint64_t{0};

/// A key and a payload, sorted by key.
struct KeyVal {
  std::uint64_t key;
  std::uint32_t val;
};

/// Stable LSD radix sort of records by their `key` member (keys < 2^bits), at most 8 bits per
/// pass (256 buckets: the scatter's write streams stay in L1).
template <typename T>
void radixSort(std::vector<T>& a, int bits) {
  const std::size_t n = a.size();
  if (n < 2 || bits <= 0) return;
  const int passes = (bits + 7) / 8;
  const int digit = (bits + passes - 1) / passes;
  const std::size_t buckets = std::size_t{1} << digit;
  std::unique_ptr<T[]> tmp(new T[n]);  // uninitialised: every element is written
  T* src = a.data();
  T* dst = tmp.get();
  std::vector<std::size_t> count(buckets);
  for (int shift = 0; shift < bits; shift += digit) {
    std::fill(count.begin(), count.end(), 0);
    for (std::size_t i = 0; i < n; ++i) ++count[(src[i].key >> shift) & (buckets - 1)];
    if (count[(src[0].key >> shift) & (buckets - 1)] == n) continue;  // one bucket: no-op pass
    std::size_t sum = 0;
    for (auto& c : count) {
      const std::size_t k = c;
      c = sum;
      sum += k;
    }
    for (std::size_t i = 0; i < n; ++i) dst[count[(src[i].key >> shift) & (buckets - 1)]++] = src[i];
    std::swap(src, dst);
  }
  if (src != a.data()) std::copy(src, src + n, a.data());
}

int bitWidth(std::uint64_t v) {
  int b = 0;
  while (v != 0) {
    ++b;
    v >>= 1;
  }
  return b;
}

/// What pcl::VoxelGrid<PointXYZ> (leaf size `leaf`, defaults otherwise) outputs: the centroid of
/// every occupied leaf, leaves in its order (ascending (z, y, x) leaf coordinates), the same leaf
/// arithmetic (floor(coordinate * (1 / leaf)) in float). Instead of sorting every point by its
/// leaf, points are summed per leaf as they come (a direct-mapped cache of recent leaves: the
/// rows above in the organised frame hit the same leaves) and only those sums are radix-sorted.
/// The grid covers leaf coordinates [first, first + count) per axis, fixed in advance.
class LeafGrid {
 public:
  LeafGrid(const Eigen::Array3i& first, const Eigen::Array3i& count, float leaf, std::size_t expected)
      : inv_(1.0f / leaf), first_(first.cast<float>()), div_(count.cast<std::int64_t>()),
        mul1_(static_cast<std::uint64_t>(count[0])), mul2_(mul1_ * static_cast<std::uint64_t>(count[1])),
        recent_(std::size_t{1} << kCacheBits, kNone) {
    runs_.reserve(expected / 3 + 1);
  }
  /// Adds a point; false (nothing added) when its leaf is outside the grid.
  bool add(const Eigen::Vector3f& p) {
    const auto i0 = static_cast<std::int64_t>(static_cast<int>(std::floor(p.x() * inv_) - first_[0]));
    const auto i1 = static_cast<std::int64_t>(static_cast<int>(std::floor(p.y() * inv_) - first_[1]));
    const auto i2 = static_cast<std::int64_t>(static_cast<int>(std::floor(p.z() * inv_) - first_[2]));
    if (i0 < 0 || i1 < 0 || i2 < 0 || i0 >= div_[0] || i1 >= div_[1] || i2 >= div_[2]) return false;
    const std::uint64_t idx = static_cast<std::uint64_t>(i0) + static_cast<std::uint64_t>(i1) * mul1_ + static_cast<std::uint64_t>(i2) * mul2_;
    std::uint32_t& slot = recent_[(idx * 0x9E3779B97F4A7C15ull) >> (64 - kCacheBits)];
    std::uint32_t r = last_ != kNone && runs_[last_].key == idx ? last_ : slot;
    if (r == kNone || runs_[r].key != idx) {
      r = static_cast<std::uint32_t>(runs_.size());
      runs_.push_back({idx, 0.0f, 0.0f, 0.0f, 0});
    }
    slot = last_ = r;
    Run& run = runs_[r];
    run.x += p.x();
    run.y += p.y();
    run.z += p.z();
    ++run.n;
    return true;
  }
  /// The leaves' centroids in PCL's order.
  void centroids(Cloud& out) {
    radixSort(runs_, bitWidth(mul2_ * static_cast<std::uint64_t>(div_[2])));
    out.clear();
    out.points.reserve(runs_.size() / 2 + 1);
    for (std::size_t a = 0; a < runs_.size();) {
      std::size_t b = a;
      Eigen::Vector3f sum = Eigen::Vector3f::Zero();
      std::uint32_t n = 0;
      for (; b < runs_.size() && runs_[b].key == runs_[a].key; ++b) {
        sum += Eigen::Vector3f(runs_[b].x, runs_[b].y, runs_[b].z);
        n += runs_[b].n;
      }
      const Eigen::Vector3f c = sum / static_cast<float>(n);
      out.points.emplace_back(c.x(), c.y(), c.z());
      a = b;
    }
    out.width = static_cast<std::uint32_t>(out.points.size());
    out.height = 1;
    out.is_dense = true;
  }

 private:
  static constexpr int kCacheBits = 12;
  static constexpr std::uint32_t kNone = std::numeric_limits<std::uint32_t>::max();
  struct Run {  // points of one leaf met in a row; sorted with their sums (no gather afterwards)
    std::uint64_t key;
    float x, y, z;
    std::uint32_t n;
  };
  float inv_;
  Eigen::Array3f first_;
  Eigen::Array<std::int64_t, 3, 1> div_;
  std::uint64_t mul1_, mul2_;
  std::vector<Run> runs_;
  std::vector<std::uint32_t> recent_;
  std::uint32_t last_{kNone};
};

/// Would pcl::VoxelGrid refuse points within [lo, hi] (its int32 leaf index overflows; it then
/// passes the cloud through)?
bool pclVoxelOverflow(const Eigen::Array3f& lo, const Eigen::Array3f& hi, float leaf) {
  const Eigen::Array3f span = (hi - lo) * Eigen::Array3f::Constant(1.0f / leaf);
  const auto dx = static_cast<std::int64_t>(span.x()) + 1, dy = static_cast<std::int64_t>(span.y()) + 1,
             dz = static_cast<std::int64_t>(span.z()) + 1;
  return dx * dy * dz > static_cast<std::int64_t>(std::numeric_limits<std::int32_t>::max());
}

/// pcl::VoxelGrid<PointXYZ> on `pts` (bounds `lo`, `hi`) with a LeafGrid over those bounds.
void voxelFilter(const std::vector<Eigen::Vector3f>& pts, const Eigen::Array3f& lo, const Eigen::Array3f& hi, float leaf,
                 Cloud& out) {
  if (pts.empty() || pclVoxelOverflow(lo, hi, leaf)) {  // PCL's pass-through
    out.clear();
    for (const auto& p : pts) out.points.emplace_back(p.x(), p.y(), p.z());
    out.width = static_cast<std::uint32_t>(out.points.size());
    out.height = 1;
    out.is_dense = true;
    return;
  }
  const float inv = 1.0f / leaf;
  Eigen::Array3i min_b, max_b;
  for (int k = 0; k < 3; ++k) {
    min_b[k] = static_cast<int>(std::floor(lo[k] * inv));
    max_b[k] = static_cast<int>(std::floor(hi[k] * inv));
  }
  LeafGrid grid(min_b, max_b - min_b + 1, leaf, pts.size());
  for (const auto& p : pts) grid.add(p);  // always inside
  grid.centroids(out);
}

/// The clusters pcl::EuclideanClusterExtraction finds in `pts` (connected components of the
/// graph joining points closer than `tolerance`, same float distance test as its FLANN radius
/// search) with min_size..max_size points; indices ascending within a cluster, clusters by size,
/// largest first, ties in order of their smallest index (PCL's order). Instead of a kd-tree
/// radius search per point: a grid of cells of `tolerance` (neighbours are in the 26 adjacent
/// cells, contiguous runs of the key-sorted points) and a union-find over point pairs.
/// Returns nullopt where the grid's keys would overflow: the caller uses PCL.
std::optional<std::vector<std::vector<int>>> euclideanClusters(const std::vector<Eigen::Vector3f>& pts, double tolerance,
                                                               std::size_t min_size, std::size_t max_size) {
  std::vector<std::vector<int>> clusters;
  const std::size_t n = pts.size();
  if (n == 0) return clusters;
  const double inv = 1.0 / (tolerance * (1.0 + 1e-4));  // a pair within tolerance: cells differ by <= 1
  Eigen::Array3d lo = pts.front().cast<double>().array(), hi = lo;
  for (const auto& p : pts) {
    lo = lo.min(p.cast<double>().array());
    hi = hi.max(p.cast<double>().array());
  }
  const Eigen::Array3d cmin = (lo * inv).floor();
  const Eigen::Array3d extent = (hi * inv).floor() - cmin + 3.0;  // one empty cell of padding each side
  if (!(extent.prod() < 4e18)) return std::nullopt;
  const auto DX = static_cast<std::uint64_t>(extent.x()), DXY = DX * static_cast<std::uint64_t>(extent.y());
  std::vector<KeyVal> keys(n);
  for (std::size_t i = 0; i < n; ++i) {
    const Eigen::Array3d c = (pts[i].cast<double>().array() * inv).floor() - cmin + 1.0;
    keys[i] = {static_cast<std::uint64_t>(c.x()) + static_cast<std::uint64_t>(c.y()) * DX + static_cast<std::uint64_t>(c.z()) * DXY,
               static_cast<std::uint32_t>(i)};
  }
  radixSort(keys, bitWidth(DXY * static_cast<std::uint64_t>(extent.z())));
  // Points in key order (structure of arrays) and the cells' ranges.
  std::vector<float> xs(n), ys(n), zs(n);
  std::vector<std::uint64_t> cell_key;
  std::vector<std::uint32_t> cell_begin;
  for (std::size_t s = 0; s < n; ++s) {
    const Eigen::Vector3f& p = pts[keys[s].val];
    xs[s] = p.x();
    ys[s] = p.y();
    zs[s] = p.z();
    if (s == 0 || keys[s].key != keys[s - 1].key) {
      cell_key.push_back(keys[s].key);
      cell_begin.push_back(static_cast<std::uint32_t>(s));
    }
  }
  const std::size_t cells = cell_key.size();
  cell_begin.push_back(static_cast<std::uint32_t>(n));
  std::vector<std::uint32_t> parent(n);
  for (std::size_t s = 0; s < n; ++s) parent[s] = static_cast<std::uint32_t>(s);
  auto find = [&](std::uint32_t x) {
    while (parent[x] != x) {
      parent[x] = parent[parent[x]];
      x = parent[x];
    }
    return x;
  };
  const auto r2 = static_cast<float>(tolerance * tolerance);  // PCL: float(radius * radius), d2 < r2
  // Forward half of the 3x3x3 neighbourhood as key ranges [first, last] of 1 to 3 cells: every
  // pair of neighbouring cells is visited once (from the one with the smaller key).
  const std::uint64_t rows[5][2] = {{0, 1},
                                    {DX - 1, DX + 1},
                                    {DXY - DX - 1, DXY - DX + 1},
                                    {DXY - 1, DXY + 1},
                                    {DXY + DX - 1, DXY + DX + 1}};
  for (std::size_t ci = 0; ci < cells; ++ci) {
    const std::uint64_t k = cell_key[ci];
    const std::uint32_t b0 = cell_begin[ci], e0 = cell_begin[ci + 1];
    for (const auto& row : rows) {
      const std::uint64_t first = k + row[0], last = k + row[1];
      std::size_t cj = static_cast<std::size_t>(std::lower_bound(cell_key.begin() + static_cast<std::ptrdiff_t>(ci), cell_key.end(), first) -
                                                cell_key.begin());
      for (; cj < cells && cell_key[cj] <= last; ++cj) {
        const std::uint32_t e1 = cell_begin[cj + 1];
        for (std::uint32_t a = b0; a < e0; ++a) {
          const float ax = xs[a], ay = ys[a], az = zs[a];
          for (std::uint32_t b = cj == ci ? a + 1 : cell_begin[cj]; b < e1; ++b) {
            const float ddx = ax - xs[b], ddy = ay - ys[b], ddz = az - zs[b];
            if (ddx * ddx + ddy * ddy + ddz * ddz < r2) {
              const std::uint32_t ra = find(a), rb = find(b);
              if (ra != rb) parent[std::max(ra, rb)] = std::min(ra, rb);
            }
          }
        }
      }
    }
  }
  // Components in order of their smallest original index (PCL's seed order).
  std::vector<std::uint32_t> root_of(n);
  for (std::size_t s = 0; s < n; ++s) root_of[keys[s].val] = find(static_cast<std::uint32_t>(s));
  std::vector<int> comp(n, -1);  // by root (a sorted position)
  std::vector<std::vector<int>> all;
  for (std::size_t i = 0; i < n; ++i) {
    int& c = comp[root_of[i]];
    if (c < 0) {
      c = static_cast<int>(all.size());
      all.emplace_back();
    }
    all[static_cast<std::size_t>(c)].push_back(static_cast<int>(i));
  }
  for (auto& c : all) {
    if (c.size() >= min_size && c.size() <= max_size) clusters.push_back(std::move(c));
  }
  std::stable_sort(clusters.begin(), clusters.end(), [](const auto& a, const auto& b) { return a.size() > b.size(); });
  return clusters;
}

/// SampleConsensusModelPerpendicularPlane with the inlier count of RANSAC's hypotheses (PCL's
/// generic build: an indexed scalar loop, ~10 % of a frame) over a contiguous copy of the points.
class PerpendicularPlaneModel : public pcl::SampleConsensusModelPerpendicularPlane<pcl::PointXYZ> {
 public:
  PerpendicularPlaneModel(const Cloud::ConstPtr& cloud, const pcl::Indices& indices)
      : pcl::SampleConsensusModelPerpendicularPlane<pcl::PointXYZ>(cloud, indices, false) {
    xs_.reserve(indices.size());
    ys_.reserve(indices.size());
    zs_.reserve(indices.size());
    for (auto i : indices) {
      const auto& p = (*cloud)[static_cast<std::size_t>(i)];
      xs_.push_back(p.x);
      ys_.push_back(p.y);
      zs_.push_back(p.z);
    }
  }
  std::size_t countWithinDistance(const Eigen::VectorXf& c, const double threshold) const override {
    if (!isModelValid(c)) return 0;
    const float a = c[0], b = c[1], cc = c[2], d = c[3];
    // PCL: float |coefficients . (p, 1)| < threshold (a double): the same as <= the largest
    // float below the threshold; the dot product summed as Eigen's SSE reduction does.
    float t = static_cast<float>(threshold);
    if (static_cast<double>(t) >= threshold) t = std::nextafter(t, 0.0f);
    std::size_t count = 0;
    const std::size_t n = xs_.size();
    for (std::size_t i = 0; i < n; ++i) count += std::abs((a * xs_[i] + cc * zs_[i]) + (b * ys_[i] + d)) <= t ? 1 : 0;
    return count;
  }

 private:
  std::vector<float> xs_, ys_, zs_;
};

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

namespace {

/// The frame's finite returns within the crop ranges, in the world frame and inside `workspace`;
/// `lo` and `hi` their bounds. Counts out.valid_points.
std::vector<Eigen::Vector3f> cropToWorkspace(const PointCloudFrame& frame, const Aabb& workspace,
                                             const PerceptionParams& P, Segmentation& out, Eigen::Array3f& lo_out,
                                             Eigen::Array3f& hi_out) {
  std::vector<Eigen::Vector3f> cropped;
  Eigen::Array3f cropped_lo = Eigen::Array3f::Constant(std::numeric_limits<float>::infinity());
  Eigen::Array3f cropped_hi = -cropped_lo;
  const Eigen::Matrix3f R = frame.world_T_sensor.linear().cast<float>();
  const Eigen::Vector3f t = frame.world_T_sensor.translation().cast<float>();
  const Eigen::Array3f lo = workspace.min.cast<float>().array();
  const Eigen::Array3f hi = workspace.max.cast<float>().array();
  const float r2min = static_cast<float>(P.crop.min_range * P.crop.min_range);
  const float r2max = static_cast<float>(P.crop.max_range * P.crop.max_range);
  const std::size_t n = frame.size();
  cropped.reserve(n);
  for (std::size_t i = 0; i < n; ++i) {
    const Eigen::Vector3f q(frame.xyz[3 * i], frame.xyz[3 * i + 1], frame.xyz[3 * i + 2]);
    if (!std::isfinite(q.x())) continue;  // validated: a triplet is all finite or a no-return
    ++out.valid_points;
    const float r2 = q.squaredNorm();
    if (r2 < r2min || r2 > r2max) continue;
    const Eigen::Vector3f w = R * q + t;
    if ((w.array() < lo).any() || (w.array() > hi).any()) continue;
    cropped.push_back(w);
    cropped_lo = cropped_lo.min(w.array());
    cropped_hi = cropped_hi.max(w.array());
  }
  lo_out = cropped_lo;
  hi_out = cropped_hi;
  return cropped;
}

/// What pcl::SACSegmentation (RANSAC, perpendicular plane, optimised coefficients) does, with
/// the model's faster inlier count. Its RANSAC is seeded with a constant (random = false):
/// frames are reproducible.
void segmentPlane(const std::shared_ptr<Cloud>& cloud, const pcl::Indices& indices, const PerceptionParams& P,
                  pcl::PointIndices& inliers, pcl::ModelCoefficients& coeffs) {
  inliers.indices.clear();
  coeffs.values.clear();
  auto model = std::make_shared<PerpendicularPlaneModel>(cloud, indices);
  model->setAxis(Eigen::Vector3f::UnitZ());
  model->setEpsAngle(P.planes.max_tilt);
  pcl::RandomSampleConsensus<pcl::PointXYZ> sac(model, P.planes.distance_threshold);
  sac.setProbability(0.99);
  sac.setMaxIterations(P.planes.ransac_iterations);
  if (!sac.computeModel(0)) return;
  sac.getInliers(inliers.indices);
  Eigen::VectorXf coeff(model->getModelSize()), refined(model->getModelSize());
  sac.getModelCoefficients(coeff);
  model->optimizeModelCoefficients(inliers.indices, coeff, refined);
  coeffs.values.assign(refined.data(), refined.data() + refined.size());
  model->selectWithinDistance(refined, P.planes.distance_threshold, inliers.indices);
}

/// Whether `q` lies in plane `c`'s noise-aware band: within the plane threshold, or within the
/// along-ray range noise (seen from `origin`) projected on the plane normal, whichever is wider.
bool inBand(const Eigen::Vector3f& q, const Eigen::Vector4f& c, const Eigen::Vector3f& origin,
            const PerceptionParams& P) {
  const Eigen::Vector3f n = c.head<3>();
  const Eigen::Vector3f ray = q - origin;
  const float range = ray.norm();
  const float cosine = range > 1e-6f ? std::abs(n.dot(ray)) / range : 1.0f;
  const float band = std::max(static_cast<float>(P.planes.distance_threshold),
                              static_cast<float>(P.planes.noise_sigmas * P.sensor.stddev(range)) * cosine);
  return std::abs(n.dot(q) + c.w()) <= band;
}

/// The points of `search` in the plane `c`'s band (inBand); `search` keeps the others.
std::vector<pcl::index_t> takeBandInliers(const Cloud& cloud, std::vector<pcl::index_t>& search,
                                          const Eigen::Vector4f& c, const Eigen::Vector3f& origin,
                                          const PerceptionParams& P) {
  std::vector<pcl::index_t> inliers;
  std::vector<pcl::index_t> rest;
  inliers.reserve(search.size());
  rest.reserve(search.size());
  for (auto i : search)
    (inBand(cloud.points[static_cast<std::size_t>(i)].getVector3fMap(), c, origin, P) ? inliers : rest).push_back(i);
  search = std::move(rest);
  return inliers;
}

/// How many of the points `indices` lie in plane `c`'s band (inBand).
std::size_t bandCount(const Cloud& cloud, const pcl::Indices& indices, const Eigen::Vector4f& c,
                      const Eigen::Vector3f& origin, const PerceptionParams& P) {
  std::size_t count = 0;
  for (auto i : indices) count += inBand(cloud.points[static_cast<std::size_t>(i)].getVector3fMap(), c, origin, P) ? 1 : 0;
  return count;
}

/// The level plane at the most common height of the points `indices` (a histogram of z in bins
/// of the plane threshold; the mean height of the points within a threshold of the fullest bin,
/// the lowest of equally full ones).
Eigen::Vector4f commonLevel(const Cloud& cloud, const pcl::Indices& indices, const PerceptionParams& P) {
  const double bin = P.planes.distance_threshold;
  float lo = std::numeric_limits<float>::infinity(), hi = -lo;
  for (auto i : indices) {
    lo = std::min(lo, cloud.points[static_cast<std::size_t>(i)].z);
    hi = std::max(hi, cloud.points[static_cast<std::size_t>(i)].z);
  }
  if (!(lo <= hi)) return {0.0f, 0.0f, 1.0f, 0.0f};
  std::vector<std::size_t> counts(static_cast<std::size_t>((hi - lo) / bin) + 1, 0);
  for (auto i : indices) ++counts[static_cast<std::size_t>((cloud.points[static_cast<std::size_t>(i)].z - lo) / bin)];
  const auto fullest = static_cast<double>(std::max_element(counts.begin(), counts.end()) - counts.begin());
  const double centre = lo + (fullest + 0.5) * bin;
  double sum = 0.0;
  std::size_t n = 0;
  for (auto i : indices) {
    const double z = cloud.points[static_cast<std::size_t>(i)].z;
    if (std::abs(z - centre) > bin) continue;
    sum += z;
    ++n;
  }
  return {0.0f, 0.0f, 1.0f, static_cast<float>(-sum / static_cast<double>(std::max<std::size_t>(n, 1)))};
}

/// The plane of the two that holds more of RANSAC's subsample `sub` in its band: RANSAC's `c`,
/// or the level plane at the subsample's most common height (commonLevel). RANSAC draws a few
/// hundred samples: where walls fill most of the image and the floor is a fifth of the points,
/// it can miss the floor and settle on a plane tilted by a few degrees through a strip of it and
/// the boxes on it. That plane, rejected, took its strip out of the search, and the rest of the
/// floor stayed as object points joining the boxes into one "new object" (namo_moghaddam_07, one
/// frame in 50). Support surfaces are level in this world model (regions have a height, objects
/// stand upright), so the level plane is always a candidate, and the consensus decides.
Eigen::Vector4f betterOfLevel(const Cloud& cloud, const pcl::Indices& sub, const Eigen::Vector4f& c,
                              const Eigen::Vector3f& origin, const PerceptionParams& P) {
  const Eigen::Vector4f level = commonLevel(cloud, sub, P);
  return bandCount(cloud, sub, level, origin, P) > bandCount(cloud, sub, c, origin, P) ? level : c;
}

/// Area from the distinct xy cells the inliers cover (range noise smears a surface over several
/// voxel layers, so inliers x voxel^2 would overestimate it). Distinct cells counted in an
/// open-addressing set (sorting them was ~2 % of a frame).
double distinctCellArea(const Cloud& cloud, const std::vector<pcl::index_t>& inliers, double voxel_size) {
  const double voxel_area = voxel_size * voxel_size;
  std::size_t size = 1024;
  while (size < 2 * inliers.size()) size *= 2;
  std::vector<std::uint64_t> table(size, kNoCell);
  std::size_t distinct = 0;
  bool minus_one = false;  // cell (-1, -1), whose key is kNoCell
  const float inv = 1.0f / static_cast<float>(voxel_size);
  for (auto i : inliers) {
    const auto& q = cloud.points[static_cast<std::size_t>(i)];
    const auto ix = static_cast<std::int64_t>(std::floor(q.x * inv)), iy = static_cast<std::int64_t>(std::floor(q.y * inv));
    const auto cell = static_cast<std::uint64_t>((ix << 32) ^ (iy & 0xffffffff));
    if (cell == kNoCell) {
      distinct += minus_one ? 0 : 1;
      minus_one = true;
      continue;
    }
    for (std::size_t h = (cell * 0x9E3779B97F4A7C15ull) >> 32 & (size - 1);; h = (h + 1) & (size - 1)) {
      if (table[h] == cell) break;
      if (table[h] == kNoCell) {
        table[h] = cell;
        ++distinct;
        break;
      }
    }
  }
  return static_cast<double>(distinct) * voxel_area;
}

/// The prior region a plane at `height` matches: same height and most inliers over its polygon
/// (tables first); null for none.
const world::Region* matchRegion(const std::vector<world::Region>& regions, double height, const Cloud& cloud,
                                 const std::vector<pcl::index_t>& inliers, const PerceptionParams& P) {
  const world::Region* region = nullptr;
  for (const auto& r : regions) {
    if (std::abs(r.height - height) > P.planes.region_height_tolerance) continue;
    std::size_t over = 0;
    for (auto i : inliers) {
      const auto& q = cloud.points[static_cast<std::size_t>(i)];
      if (r.contains(Eigen::Vector2d(q.x, q.y))) ++over;
    }
    if (2 * over >= inliers.size() && (region == nullptr || r.kind == world::RegionKind::kTable)) region = &r;
  }
  return region;
}

/// The area of the inliers' xy convex hull.
double inlierHullArea(const Cloud& cloud, const std::vector<pcl::index_t>& inliers) {
  std::vector<Eigen::Vector2d> xy;
  xy.reserve(inliers.size());
  for (auto i : inliers) {
    const auto& q = cloud.points[static_cast<std::size_t>(i)];
    xy.emplace_back(q.x, q.y);
  }
  return std::abs(world::signedArea(convexHull(std::move(xy))));
}

/// Marks in `removed` the inliers a support plane removes and returns their xy: a table region's
/// polygon bounds what its plane removes (a box top at table height elsewhere stays an object); a
/// floor or an unmatched large plane removes all inliers.
std::vector<Eigen::Vector2d> removeSupported(const Cloud& cloud, const std::vector<pcl::index_t>& inliers,
                                             const world::Region* region, const PerceptionParams& P,
                                             std::vector<char>& removed) {
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
    const auto& q = cloud.points[static_cast<std::size_t>(i)];
    if (bounded && !world::containsPoint(grown, Eigen::Vector2d(q.x, q.y))) continue;
    removed[static_cast<std::size_t>(i)] = 1;
    xy.emplace_back(q.x, q.y);
  }
  return xy;
}

/// The support planes (out.planes, out.plane_points): RANSAC on an even subsample, inliers over
/// every candidate point, matched to the prior `regions`; the points they remove marked in
/// `removed`. A stop request or timeout between planes is an error.
Status findSupportPlanes(const std::shared_ptr<Cloud>& cloud, const Eigen::Vector3f& origin, const PerceptionParams& P,
                         const std::vector<world::Region>& regions, const Termination& term, Segmentation& out,
                         std::vector<char>& removed) {
  std::vector<pcl::index_t> search(cloud->size());
  for (std::size_t i = 0; i < cloud->size(); ++i) search[i] = static_cast<pcl::index_t>(i);
  std::vector<std::vector<Eigen::Vector2d>> plane_xy;  // inliers' xy per accepted plane (hulls)
  for (int attempt = 0; attempt < P.planes.max_attempts; ++attempt) {
    if (static_cast<int>(search.size()) < P.planes.min_points) break;
    if (term()) return stopped(term, "the next support plane");
    // The model from an even subsample; inliers over every candidate point.
    const std::size_t stride =
        (search.size() + static_cast<std::size_t>(P.planes.ransac_max_points) - 1) / static_cast<std::size_t>(P.planes.ransac_max_points);
    pcl::Indices sub;
    sub.reserve(search.size() / stride + 1);
    for (std::size_t k = 0; k < search.size(); k += stride) sub.push_back(search[k]);
    pcl::PointIndices sub_inliers;
    pcl::ModelCoefficients coeffs;
    segmentPlane(cloud, sub, P, sub_inliers, coeffs);
    if (coeffs.values.size() != 4 || static_cast<int>(sub_inliers.indices.size() * stride) < P.planes.min_points) break;
    Eigen::Vector4f c(coeffs.values[0], coeffs.values[1], coeffs.values[2], coeffs.values[3]);
    c /= c.head<3>().norm();
    if (c.z() < 0) c = -c;
    c = betterOfLevel(*cloud, sub, c, origin, P);
    // Every inlier leaves the plane search, accepted or not.
    const std::vector<pcl::index_t> inliers = takeBandInliers(*cloud, search, c, origin, P);
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
    plane.area = distinctCellArea(*cloud, inliers, P.planes.voxel_size);
    const world::Region* region = matchRegion(regions, plane.measured_height, *cloud, inliers, P);
    // A rejected plane is an object's top: its points stay object points.
    if (region == nullptr && plane.area < P.planes.min_support_area) continue;
    // A large plane that matches no region must be a surface: its inliers must fill a good
    // part of their hull. A horizontal slice through walls and objects (the band of a plane
    // at some height cuts every vertical surface) can add up to the support area but fills
    // little of the room it spans; taking it as a support cut every object there in two.
    if (region == nullptr && plane.area < kMinSupportFill * inlierHullArea(*cloud, inliers)) continue;
    if (region != nullptr) {
      plane.region = region->id;
      plane.height = region->height;
    }
    std::vector<Eigen::Vector2d> xy = removeSupported(*cloud, inliers, region, P, removed);
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
  return Status::Ok();
}

}  // namespace

Result<Segmentation> Segmenter::run(const PointCloudFrame& frame, const Termination& term) const {
  const PerceptionParams& P = impl_->params;
  Segmentation out;
  Stopwatch watch;

  // ---- transform + crop ------------------------------------------------------------------------
  Eigen::Array3f cropped_lo, cropped_hi;
  std::vector<Eigen::Vector3f> cropped = cropToWorkspace(frame, impl_->workspace, P, out, cropped_lo, cropped_hi);
  out.cropped_points = cropped.size();
  out.times.transform_crop = ms(watch);
  if (term()) return stopped(term, "the voxel filter").error();

  // ---- voxel grid ------------------------------------------------------------------------------
  watch.reset();
  auto cloud = std::make_shared<Cloud>();
  voxelFilter(cropped, cropped_lo, cropped_hi, static_cast<float>(P.planes.voxel_size), *cloud);
  std::vector<Eigen::Vector3f>().swap(cropped);
  out.scan.reserve(cloud->size());
  for (const auto& p : cloud->points) out.scan.emplace_back(p.x, p.y, p.z);
  out.times.voxel = ms(watch);
  if (term()) return stopped(term, "plane segmentation").error();

  // ---- support planes --------------------------------------------------------------------------
  watch.reset();
  std::vector<char> removed(cloud->size(), 0);
  const Eigen::Vector3f origin = frame.world_T_sensor.translation().cast<float>();
  if (Status s = findSupportPlanes(cloud, origin, P, impl_->regions, term, out, removed); !s.ok()) return s.error();
  out.times.planes = ms(watch);
  if (term()) return stopped(term, "static-object removal").error();

  // ---- points of prior static objects ------------------------------------------------------------
  watch.reset();
  std::vector<Eigen::Vector3f> rest;
  rest.reserve(cloud->size());
  for (std::size_t i = 0; i < cloud->size(); ++i) {
    if (removed[i]) continue;
    const auto& q = cloud->points[i];
    const Eigen::Vector3d p(q.x, q.y, q.z);
    if (!impl_->statics.empty() && impl_->statics.explains(p, staticMargin(P, (p - frame.world_T_sensor.translation()).norm()))) {
      ++out.static_points;
      continue;
    }
    rest.emplace_back(q.x, q.y, q.z);
  }
  out.times.static_objects = ms(watch);
  if (term()) return stopped(term, "clustering").error();

  // ---- Euclidean clustering ----------------------------------------------------------------------
  watch.reset();
  if (!rest.empty()) {
    const int min_size = std::max(1, std::min(P.occupancy.min_cluster_points, P.clusters.min_points));
    auto found = euclideanClusters(rest, P.clusters.tolerance, static_cast<std::size_t>(min_size),
                                   std::numeric_limits<std::size_t>::max());
    if (!found) found = detail::euclideanClustersPcl(rest, P.clusters.tolerance, min_size);  // extreme extents
    for (const auto& c : *found) {
      const int size = static_cast<int>(c.size());
      const bool object = size >= P.clusters.min_points && size <= P.clusters.max_points;
      if (!object && size < P.occupancy.min_cluster_points) continue;
      std::vector<Eigen::Vector3f> pts;
      pts.reserve(c.size());
      for (auto i : c) pts.push_back(rest[static_cast<std::size_t>(i)]);
      (object ? out.clusters : out.small_clusters).push_back(std::move(pts));
    }
  }
  out.times.clustering = ms(watch);
  return out;
}

namespace detail {

namespace {
Cloud::Ptr toCloud(const std::vector<Eigen::Vector3f>& points) {
  auto cloud = std::make_shared<Cloud>();
  cloud->points.reserve(points.size());
  for (const auto& p : points) cloud->points.emplace_back(p.x(), p.y(), p.z());
  cloud->width = static_cast<std::uint32_t>(cloud->points.size());
  cloud->height = 1;
  cloud->is_dense = true;
  return cloud;
}
}  // namespace

std::vector<Eigen::Vector3f> voxelGrid(const std::vector<Eigen::Vector3f>& points, float leaf) {
  Eigen::Array3f lo = Eigen::Array3f::Constant(std::numeric_limits<float>::infinity()), hi = -lo;
  for (const auto& p : points) {
    lo = lo.min(p.array());
    hi = hi.max(p.array());
  }
  Cloud out;
  voxelFilter(points, lo, hi, leaf, out);
  std::vector<Eigen::Vector3f> v;
  for (const auto& p : out.points) v.emplace_back(p.x, p.y, p.z);
  return v;
}

std::vector<Eigen::Vector3f> voxelGridPcl(const std::vector<Eigen::Vector3f>& points, float leaf) {
  Cloud out;
  if (!points.empty()) {
    pcl::VoxelGrid<pcl::PointXYZ> grid;
    grid.setLeafSize(leaf, leaf, leaf);
    grid.setInputCloud(toCloud(points));
    grid.filter(out);
  }
  std::vector<Eigen::Vector3f> v;
  for (const auto& p : out.points) v.emplace_back(p.x, p.y, p.z);
  return v;
}

std::vector<std::vector<int>> euclideanClusters(const std::vector<Eigen::Vector3f>& points, double tolerance,
                                                int min_size) {
  auto found = tamp::perception::euclideanClusters(points, tolerance, static_cast<std::size_t>(std::max(1, min_size)),
                                                   std::numeric_limits<std::size_t>::max());
  return found ? std::move(*found) : euclideanClustersPcl(points, tolerance, min_size);
}

std::vector<std::vector<int>> euclideanClustersPcl(const std::vector<Eigen::Vector3f>& points, double tolerance,
                                                   int min_size) {
  std::vector<std::vector<int>> clusters;
  if (points.empty()) return clusters;
  const auto input = toCloud(points);
  auto tree = std::make_shared<pcl::search::KdTree<pcl::PointXYZ>>();
  tree->setInputCloud(input);
  pcl::EuclideanClusterExtraction<pcl::PointXYZ> ec;
  ec.setClusterTolerance(tolerance);
  ec.setMinClusterSize(std::max(1, min_size));
  ec.setMaxClusterSize(std::numeric_limits<int>::max());
  ec.setSearchMethod(tree);
  ec.setInputCloud(input);
  std::vector<pcl::PointIndices> found;
  ec.extract(found);
  for (auto& c : found) clusters.emplace_back(c.indices.begin(), c.indices.end());
  return clusters;
}

}  // namespace detail

}  // namespace tamp::perception
