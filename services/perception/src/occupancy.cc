// The only translation unit that includes OctoMap.
#define OCTOMAP_NODEBUGOUT  // OctoMap's debug prints ("Writing N nodes...") stay quiet
#include "tamp/perception/occupancy.h"

#include <cmath>
#include <sstream>
#include <stdexcept>
#include <algorithm>
#include <cstdint>
#include <utility>
#include <vector>

#include <octomap/OcTree.h>

#include "tamp/perception/shape_fit.h"

namespace tamp::perception {

namespace {

constexpr std::uint64_t kEmpty = ~std::uint64_t{0};
constexpr std::uint64_t kTombstone = kEmpty - 1;  // keys use 48 bits: neither is a key

/// Inserts `key` into an open-addressing table (size a power of 2, kEmpty = free slot); false if
/// it was there.
bool insertKey(std::vector<std::uint64_t>& table, std::uint64_t key) {
  const std::size_t mask = table.size() - 1;
  for (std::size_t i = (key * 0x9E3779B97F4A7C15ull) >> 40 & mask;; i = (i + 1) & mask) {
    if (table[i] == key) return false;
    if (table[i] == kEmpty) {
      table[i] = key;
      return true;
    }
  }
}

/// Replaces `key` by a tombstone (lookups go on past it; grow() drops it).
void eraseKey(std::vector<std::uint64_t>& table, std::uint64_t key) {
  const std::size_t mask = table.size() - 1;
  for (std::size_t i = (key * 0x9E3779B97F4A7C15ull) >> 40 & mask;; i = (i + 1) & mask) {
    if (table[i] == key) {
      table[i] = kTombstone;
      return;
    }
    if (table[i] == kEmpty) return;
  }
}

bool containsKey(const std::vector<std::uint64_t>& table, std::uint64_t key) {
  const std::size_t mask = table.size() - 1;
  for (std::size_t i = (key * 0x9E3779B97F4A7C15ull) >> 40 & mask;; i = (i + 1) & mask) {
    if (table[i] == key) return true;
    if (table[i] == kEmpty) return false;
  }
}

/// Doubles an open-addressing table.
void grow(std::vector<std::uint64_t>& table) {
  std::vector<std::uint64_t> bigger(2 * table.size(), kEmpty);
  for (auto k : table) {
    if (k != kEmpty && k != kTombstone) insertKey(bigger, k);
  }
  table.swap(bigger);
}

std::uint64_t packKey(const octomap::OcTreeKey& k) {
  return std::uint64_t{k[0]} | (std::uint64_t{k[1]} << 16) | (std::uint64_t{k[2]} << 32);
}

}  // namespace

struct OccupancyMap::Impl {
  OccupancyParams params;
  octomap::KeyRay ray;  // reused across rays and frames
  // Keys of leaves at the free clamping threshold (open-addressing set; entries and tombstones
  // counted in clamped_used). Only a hit raises such a leaf: integrate() erases its key first.
  std::vector<std::uint64_t> clamped_free = std::vector<std::uint64_t>(std::size_t{1} << 16, kEmpty);
  std::size_t clamped_used{0};
  octomap::OcTree tree;
  octomap::KeySet hits;  // voxels that received a hit and may be occupied
  // Inner nodes lag the leaves until updateInnerNodes(): refreshing them walks the whole tree, so
  // it is done once per frame, not after every integrate/clear call (which set this).
  bool inner_stale{false};
  explicit Impl(const OccupancyParams& p) : params(p), tree(p.resolution) {
    tree.setProbHit(p.prob_hit);
    tree.setProbMiss(p.prob_miss);
    tree.setOccupancyThres(p.occupancy_threshold);
  }
};

OccupancyMap::OccupancyMap(const OccupancyParams& params) {
  if (!(params.resolution > 0) || !std::isfinite(params.resolution)) {
    throw std::invalid_argument("OccupancyMap: resolution must be positive, got " + std::to_string(params.resolution));
  }
  if (!(params.prob_hit > 0.5 && params.prob_hit < 1.0) || !(params.prob_miss > 0.0 && params.prob_miss < 0.5) ||
      !(params.occupancy_threshold >= 0.5 && params.occupancy_threshold < 1.0)) {
    throw std::invalid_argument("OccupancyMap: need prob_hit in (0.5, 1), prob_miss in (0, 0.5), "
                                "occupancy_threshold in [0.5, 1)");
  }
  impl_ = std::make_unique<Impl>(params);
}

OccupancyMap::~OccupancyMap() = default;

void OccupancyMap::integrate(const Eigen::Vector3d& origin, const std::vector<Eigen::Vector3f>& scan,
                             const std::vector<Eigen::Vector3f>& occupied) {
  octomap::OcTree& tree = impl_->tree;
  const OccupancyParams& p = impl_->params;
  // One ray endpoint per free_space_voxel: the ray count, not the point count, sets the cost.
  // (The first scan point of each such cell; a small open-addressing set, ~1000 cells a frame.)
  const double inv = 1.0 / std::max(p.free_space_voxel, p.resolution);
  std::vector<octomap::point3d> rays;
  {
    std::vector<std::uint64_t> table(4096, kEmpty);
    std::size_t used = 0;
    for (const auto& q : scan) {
      const auto ix = static_cast<std::int64_t>(std::floor(q.x() * inv)) & 0x1FFFFF;
      const auto iy = static_cast<std::int64_t>(std::floor(q.y() * inv)) & 0x1FFFFF;
      const auto iz = static_cast<std::int64_t>(std::floor(q.z() * inv)) & 0x1FFFFF;
      const std::uint64_t key = (std::uint64_t(ix) << 42) | (std::uint64_t(iy) << 21) | std::uint64_t(iz);
      if (insertKey(table, key)) {
        rays.emplace_back(q.x(), q.y(), q.z());
        if (2 * ++used > table.size()) grow(table);  // keep the load under 1/2
      }
    }
  }
  const octomap::point3d o(static_cast<float>(origin.x()), static_cast<float>(origin.y()),
                           static_cast<float>(origin.z()));
  // OccupancyOcTreeBase::computeUpdate (no bounding box, serial) with open-addressing sets
  // instead of its hash sets (octomap::KeySet): the cells of every ray except any ray's end cell.
  // The free cells are updated in the order the rays first reach them: consecutive cells of a
  // ray share most of their path down the tree (cache), where KeySet's order is random.
  std::vector<octomap::OcTreeKey> free_cells;
  free_cells.reserve(rays.size() * 64);
  std::size_t free_size = std::size_t{1} << 12;  // load <= 1/2 for ~40 new cells a ray
  while (free_size < rays.size() * 80) free_size *= 2;
  std::vector<std::uint64_t> free_set(free_size, kEmpty), end_set(std::size_t{1} << 12, kEmpty);
  std::size_t end_used = 0;
  {
    octomap::KeyRay& ray = impl_->ray;
    const double maxrange = p.max_ray_range;
    const auto addRay = [&] {
      for (const auto& k : ray) {
        if (!insertKey(free_set, packKey(k))) continue;
        free_cells.push_back(k);
        if (2 * free_cells.size() > free_set.size()) grow(free_set);
      }
    };
    for (const auto& q : rays) {
      if (maxrange < 0.0 || (q - o).norm() <= maxrange) {
        if (tree.computeRayKeys(o, q, ray)) addRay();
        octomap::OcTreeKey key;
        if (tree.coordToKeyChecked(q, key) && insertKey(end_set, packKey(key)) && 2 * ++end_used > end_set.size()) grow(end_set);
      } else {
        const octomap::point3d direction = (q - o).normalized();
        const octomap::point3d new_end = o + direction * static_cast<float>(maxrange);
        if (tree.computeRayKeys(o, new_end, ray)) addRay();
      }
    }
  }

  octomap::KeySet hit_cells;
  for (const auto& q : occupied) {
    octomap::OcTreeKey k;
    if (tree.coordToKeyChecked(octomap::point3d(q.x(), q.y(), q.z()), k)) hit_cells.insert(k);
  }
  // A free update of a cell already clamped at free changes nothing (OcTree::updateNode returns
  // after a search from the root); those cells are remembered and skipped without the search.
  std::vector<std::uint64_t>& clamped = impl_->clamped_free;
  const float clamp_min = tree.getClampingThresMinLog();
  for (const auto& k : free_cells) {
    const std::uint64_t packed = packKey(k);
    if (containsKey(end_set, packed) || containsKey(clamped, packed) || hit_cells.count(k) != 0) continue;
    const octomap::OcTreeNode* n = tree.updateNode(k, false, true);
    if (n != nullptr && n->getLogOdds() <= clamp_min && insertKey(clamped, packed) && 2 * ++impl_->clamped_used > clamped.size()) {
      grow(clamped);
      impl_->clamped_used = 0;
      for (auto c : clamped) impl_->clamped_used += c != kEmpty ? 1 : 0;
    }
  }
  for (const auto& k : hit_cells) {
    eraseKey(impl_->clamped_free, packKey(k));
    tree.updateNode(k, true, true);
    impl_->hits.insert(k);
  }
  impl_->inner_stale = true;
}

std::size_t OccupancyMap::clearSeenThrough(const RangeImage& image, double margin) {
  octomap::OcTree& tree = impl_->tree;
  std::size_t updated = 0;
  for (auto it = impl_->hits.begin(); it != impl_->hits.end();) {
    const octomap::OcTreeNode* n = tree.search(*it);
    if (n == nullptr || !tree.isNodeOccupied(n)) {
      it = impl_->hits.erase(it);
      continue;
    }
    const octomap::point3d c = tree.keyToCoord(*it);
    const Eigen::Vector3d centre(c.x(), c.y(), c.z());
    const Eigen::Vector3d half = Eigen::Vector3d::Constant(0.5 * tree.getResolution());
    if (image.seenThrough(centre - half, centre + half, margin)) {
      tree.updateNode(*it, false, true);
      ++updated;
    }
    ++it;
  }
  if (updated > 0) impl_->inner_stale = true;
  return updated;
}

std::size_t OccupancyMap::clearObject(const world::Object& object) {
  octomap::OcTree& tree = impl_->tree;
  const double m = impl_->params.explained_margin;
  const Aabb b = object.aabb();
  if (b.empty()) return 0;
  const octomap::point3d lo(static_cast<float>(b.min.x() - m), static_cast<float>(b.min.y() - m),
                            static_cast<float>(b.min.z() - m));
  const octomap::point3d hi(static_cast<float>(b.max.x() + m), static_cast<float>(b.max.y() + m),
                            static_cast<float>(b.max.z() + m));
  std::vector<octomap::OcTreeKey> explained;
  for (auto it = tree.begin_leafs_bbx(lo, hi), end = tree.end_leafs_bbx(); it != end; ++it) {
    if (!tree.isNodeOccupied(*it)) continue;
    const octomap::point3d c = it.getCoordinate();
    const double grow = m + 0.5 * (it.getSize() - tree.getResolution());
    if (pointInShape(object.shape, object.pose, Eigen::Vector3d(c.x(), c.y(), c.z()), grow)) {
      explained.push_back(it.getKey());
    }
  }
  // Set to free rather than deleted: OctoMap 1.9's deleteNode() trips its own assertion
  // (children == NULL) when an inner node loses its last child.
  for (const auto& key : explained) {
    tree.setNodeValue(key, tree.getClampingThresMinLog(), true);
    impl_->hits.erase(key);
  }
  if (!explained.empty()) impl_->inner_stale = true;
  return explained.size();
}

void OccupancyMap::updateInnerNodes() {
  if (!impl_->inner_stale) return;
  impl_->tree.updateInnerOccupancy();
  impl_->inner_stale = false;
}

void OccupancyMap::clear() {
  impl_->tree.clear();
  impl_->hits.clear();
  std::fill(impl_->clamped_free.begin(), impl_->clamped_free.end(), kEmpty);
  impl_->clamped_used = 0;
}

CellState OccupancyMap::state(const Eigen::Vector3d& p) const {
  const octomap::OcTreeNode* n = impl_->tree.search(p.x(), p.y(), p.z());
  if (n == nullptr) return CellState::kUnknown;
  return impl_->tree.isNodeOccupied(n) ? CellState::kOccupied : CellState::kFree;
}

std::vector<Eigen::Vector3d> OccupancyMap::occupiedVoxels() const {
  const octomap::OcTree& tree = impl_->tree;
  const double res = tree.getResolution();
  std::vector<Eigen::Vector3d> out;
  for (auto it = tree.begin_leafs(), end = tree.end_leafs(); it != end; ++it) {
    if (!tree.isNodeOccupied(*it)) continue;
    const octomap::point3d c = it.getCoordinate();
    const double size = it.getSize();
    if (size <= res * 1.5) {
      out.emplace_back(c.x(), c.y(), c.z());
      continue;
    }
    const int n = static_cast<int>(std::lround(size / res));  // a pruned leaf: expand it
    for (int i = 0; i < n; ++i) {
      for (int j = 0; j < n; ++j) {
        for (int k = 0; k < n; ++k) {
          out.emplace_back(c.x() - size / 2 + (i + 0.5) * res, c.y() - size / 2 + (j + 0.5) * res,
                           c.z() - size / 2 + (k + 0.5) * res);
        }
      }
    }
  }
  return out;
}

std::size_t OccupancyMap::occupiedCount() const {
  std::size_t n = 0;
  const octomap::OcTree& tree = impl_->tree;
  for (auto it = tree.begin_leafs(), end = tree.end_leafs(); it != end; ++it) {
    if (tree.isNodeOccupied(*it)) ++n;
  }
  return n;
}

std::size_t OccupancyMap::hitVoxels() const { return impl_->hits.size(); }

double OccupancyMap::resolution() const { return impl_->tree.getResolution(); }

std::string OccupancyMap::toBinary() const {
  // The binary format stores the maximum-likelihood map; write a pruned copy so that the node
  // count in the header matches what a reader reconstructs.
  octomap::OcTree copy(impl_->tree);
  copy.toMaxLikelihood();
  copy.prune();
  std::ostringstream s(std::ios_base::out | std::ios_base::binary);
  s << "# Octomap OcTree binary file\n# (written by tamp perception)\n#\n";
  s << "id " << copy.getTreeType() << "\n";
  s << "size " << copy.size() << "\n";
  s << "res " << copy.getResolution() << "\n";
  s << "data\n";
  copy.writeBinaryData(s);
  return s.str();
}

}  // namespace tamp::perception
