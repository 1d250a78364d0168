// The only translation unit that includes OctoMap.
#define OCTOMAP_NODEBUGOUT  // OctoMap's debug prints ("Writing N nodes...") stay quiet
#include "tamp/perception/occupancy.h"

#include <cmath>
#include <sstream>
#include <stdexcept>
#include <unordered_set>

#include <octomap/OcTree.h>

#include "tamp/perception/shape_fit.h"

namespace tamp::perception {

struct OccupancyMap::Impl {
  OccupancyParams params;
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
  const double inv = 1.0 / std::max(p.free_space_voxel, p.resolution);
  std::unordered_set<std::uint64_t> seen;
  seen.reserve(scan.size() / 4 + 16);
  octomap::Pointcloud rays;
  rays.reserve(scan.size() / 4 + 16);
  for (const auto& q : scan) {
    const auto ix = static_cast<std::int64_t>(std::floor(q.x() * inv)) & 0x1FFFFF;
    const auto iy = static_cast<std::int64_t>(std::floor(q.y() * inv)) & 0x1FFFFF;
    const auto iz = static_cast<std::int64_t>(std::floor(q.z() * inv)) & 0x1FFFFF;
    const std::uint64_t key = (std::uint64_t(ix) << 42) | (std::uint64_t(iy) << 21) | std::uint64_t(iz);
    if (seen.insert(key).second) rays.push_back(q.x(), q.y(), q.z());
  }
  const octomap::point3d o(static_cast<float>(origin.x()), static_cast<float>(origin.y()),
                           static_cast<float>(origin.z()));
  octomap::KeySet free_cells, endpoint_cells;
  tree.computeUpdate(rays, o, free_cells, endpoint_cells, p.max_ray_range);

  octomap::KeySet hit_cells;
  for (const auto& q : occupied) {
    octomap::OcTreeKey k;
    if (tree.coordToKeyChecked(octomap::point3d(q.x(), q.y(), q.z()), k)) hit_cells.insert(k);
  }
  for (const auto& k : free_cells) {
    if (hit_cells.count(k) == 0) tree.updateNode(k, false, true);
  }
  for (const auto& k : hit_cells) {
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
