#include "tamp/perception/assignment.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <random>

#include <gtest/gtest.h>

namespace tamp::perception {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

/// Brute force: the most pairs, then the least cost (the contract of solveAssignment).
std::pair<int, double> bruteForce(const std::vector<std::vector<double>>& c) {
  const int rows = static_cast<int>(c.size()), cols = static_cast<int>(c[0].size());
  std::vector<int> perm(std::max(rows, cols));
  std::iota(perm.begin(), perm.end(), 0);
  int best_n = -1;
  double best = kInf;
  do {
    int n = 0;
    double s = 0;
    for (int r = 0; r < rows; ++r) {
      const int col = perm[r];
      if (col < cols && std::isfinite(c[r][col])) {
        ++n;
        s += c[r][col];
      }
    }
    if (n > best_n || (n == best_n && s < best - 1e-12)) {
      best_n = n;
      best = s;
    }
  } while (std::next_permutation(perm.begin(), perm.end()));
  return {best_n, best};
}

TEST(AssignmentTest, MatchesBruteForceOnRandomGatedMatrices) {
  std::mt19937 rng(42);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (int trial = 0; trial < 300; ++trial) {
    const int rows = 1 + static_cast<int>(rng() % 6), cols = 1 + static_cast<int>(rng() % 6);
    std::vector<std::vector<double>> c(rows, std::vector<double>(cols));
    for (auto& row : c) {
      for (auto& v : row) v = u(rng) < 0.3 ? kInf : u(rng);
    }
    const auto a = solveAssignment(c);
    ASSERT_EQ(static_cast<int>(a.size()), rows);
    int n = 0;
    double s = 0;
    std::vector<int> used(cols, 0);
    for (int r = 0; r < rows; ++r) {
      if (a[r] < 0) continue;
      ASSERT_LT(a[r], cols);
      ASSERT_TRUE(std::isfinite(c[r][a[r]])) << "a forbidden pair was assigned";
      ASSERT_EQ(used[a[r]]++, 0) << "column assigned twice";
      ++n;
      s += c[r][a[r]];
    }
    const auto [bn, bs] = bruteForce(c);
    EXPECT_EQ(n, bn) << "trial " << trial;
    EXPECT_NEAR(s, bs, 1e-9) << "trial " << trial;
  }
}

TEST(AssignmentTest, EmptyAndRaggedInputs) {
  EXPECT_TRUE(solveAssignment({}).empty());
  EXPECT_EQ(solveAssignment({{}, {}}), (std::vector<int>{-1, -1}));
  EXPECT_THROW(solveAssignment({{1.0, 2.0}, {1.0}}), std::invalid_argument);
}

}  // namespace
}  // namespace tamp::perception
