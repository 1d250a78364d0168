// The segmenter's replacements of PCL stages (voxel grid, Euclidean clustering) against PCL
// itself on random clouds: same leaves in the same order, same clusters.
#include <algorithm>
#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include "tamp/perception/segmentation.h"

namespace tamp::perception {
namespace {

/// Surfaces and blobs: planes with gaps, dense blobs, scattered points, some far off the origin.
std::vector<Eigen::Vector3f> randomCloud(std::uint32_t seed, std::size_t n) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  std::normal_distribution<float> g(0.0f, 1.0f);
  std::vector<Eigen::Vector3f> pts;
  const Eigen::Vector3f offset(3.0f * u(rng), -5.0f + 2.0f * u(rng), 0.5f * u(rng));
  for (std::size_t i = 0; i < n; ++i) {
    switch (i % 4) {
      case 0:  // a noisy floor with a gap
        pts.emplace_back(2.0f * u(rng), 2.0f * u(rng), 0.003f * g(rng));
        if (std::abs(pts.back().x()) < 0.1f) pts.back().x() += 0.3f;
        break;
      case 1:  // blobs of a few cm
        pts.emplace_back(0.5f * std::round(2.0f * u(rng)) + 0.03f * g(rng), 0.5f * std::round(2.0f * u(rng)) + 0.03f * g(rng),
                         0.2f + 0.03f * g(rng));
        break;
      case 2:  // sparse points: pairs near the tolerance
        pts.emplace_back(3.0f * u(rng), 3.0f * u(rng), 1.0f + 0.5f * u(rng));
        break;
      default:  // a wall
        pts.emplace_back(1.5f, 2.0f * u(rng), 1.0f + u(rng));
        break;
    }
    pts.back() += offset;
  }
  return pts;
}

TEST(SegmentationTest, VoxelGridMatchesPcl) {
  for (std::uint32_t seed = 1; seed <= 6; ++seed) {
    const auto pts = randomCloud(seed, 20000 + 5000 * seed);
    for (const float leaf : {0.02f, 0.05f}) {
      const auto fast = detail::voxelGrid(pts, leaf);
      const auto ref = detail::voxelGridPcl(pts, leaf);
      ASSERT_EQ(fast.size(), ref.size()) << "seed " << seed << " leaf " << leaf;
      for (std::size_t i = 0; i < fast.size(); ++i) {
        ASSERT_LT((fast[i] - ref[i]).norm(), 1e-5f) << "seed " << seed << " leaf " << leaf << " voxel " << i;
      }
    }
  }
  EXPECT_TRUE(detail::voxelGrid({}, 0.02f).empty());
}

TEST(SegmentationTest, EuclideanClustersMatchPcl) {
  for (std::uint32_t seed = 1; seed <= 6; ++seed) {
    // Voxelised like the segmenter's input (neighbours at about the voxel size).
    const auto pts = detail::voxelGrid(randomCloud(seed, 8000 + 3000 * seed), 0.02f);
    for (const double tolerance : {0.03, 0.05}) {
      for (const int min_size : {1, 3, 25}) {
        auto fast = detail::euclideanClusters(pts, tolerance, min_size);
        auto ref = detail::euclideanClustersPcl(pts, tolerance, min_size);
        ASSERT_EQ(fast.size(), ref.size()) << "seed " << seed << " tolerance " << tolerance;
        ASSERT_GT(fast.size(), 1u);
        for (std::size_t i = 1; i < fast.size(); ++i) EXPECT_GE(fast[i - 1].size(), fast[i].size());
        for (const auto& c : fast) EXPECT_TRUE(std::is_sorted(c.begin(), c.end()));
        // PCL orders clusters of equal size arbitrarily: compare as sets.
        std::sort(fast.begin(), fast.end());
        std::sort(ref.begin(), ref.end());
        EXPECT_EQ(fast, ref) << "seed " << seed << " tolerance " << tolerance << " min_size " << min_size;
      }
    }
  }
  EXPECT_TRUE(detail::euclideanClusters({}, 0.05, 1).empty());
}

}  // namespace
}  // namespace tamp::perception
