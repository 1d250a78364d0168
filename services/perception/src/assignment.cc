#include "tamp/perception/assignment.h"

#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace tamp::perception {
namespace {

/// e-maxx formulation: n rows <= m columns, 1-based, a[i][j] finite. Returns column per row.
std::vector<int> hungarian(const std::vector<std::vector<double>>& a, int n, int m) {
  const double inf = std::numeric_limits<double>::infinity();
  std::vector<double> u(n + 1, 0.0), v(m + 1, 0.0);
  std::vector<int> p(m + 1, 0), way(m + 1, 0);
  for (int i = 1; i <= n; ++i) {
    p[0] = i;
    int j0 = 0;
    std::vector<double> minv(m + 1, inf);
    std::vector<char> used(m + 1, 0);
    do {
      used[j0] = 1;
      const int i0 = p[j0];
      double delta = inf;
      int j1 = 0;
      for (int j = 1; j <= m; ++j) {
        if (used[j]) continue;
        const double cur = a[i0 - 1][j - 1] - u[i0] - v[j];
        if (cur < minv[j]) {
          minv[j] = cur;
          way[j] = j0;
        }
        if (minv[j] < delta) {
          delta = minv[j];
          j1 = j;
        }
      }
      for (int j = 0; j <= m; ++j) {
        if (used[j]) {
          u[p[j]] += delta;
          v[j] -= delta;
        } else {
          minv[j] -= delta;
        }
      }
      j0 = j1;
    } while (p[j0] != 0);
    do {
      const int j1 = way[j0];
      p[j0] = p[j1];
      j0 = j1;
    } while (j0 != 0);
  }
  std::vector<int> row_to_col(n, -1);
  for (int j = 1; j <= m; ++j) {
    if (p[j] != 0) row_to_col[p[j] - 1] = j - 1;
  }
  return row_to_col;
}

}  // namespace

std::vector<int> solveAssignment(const std::vector<std::vector<double>>& cost) {
  const int rows = static_cast<int>(cost.size());
  if (rows == 0) return {};
  const int cols = static_cast<int>(cost[0].size());
  double finite_sum = 0.0;
  for (int r = 0; r < rows; ++r) {
    if (static_cast<int>(cost[r].size()) != cols) {
      throw std::invalid_argument("solveAssignment: row " + std::to_string(r) + " has " +
                                  std::to_string(cost[r].size()) + " columns, row 0 has " + std::to_string(cols));
    }
    for (double c : cost[r]) {
      if (std::isfinite(c)) finite_sum += std::abs(c);
    }
  }
  if (cols == 0) return std::vector<int>(rows, -1);
  // A forbidden pair costs more than every finite assignment together, so the optimum uses as
  // few of them as possible; they are dropped afterwards.
  const double forbidden = 2.0 * finite_sum + 1.0;
  const bool transpose = rows > cols;
  const int n = transpose ? cols : rows, m = transpose ? rows : cols;
  std::vector<std::vector<double>> a(n, std::vector<double>(m));
  for (int r = 0; r < rows; ++r) {
    for (int c = 0; c < cols; ++c) {
      const double v = std::isfinite(cost[r][c]) ? cost[r][c] : forbidden;
      if (transpose) {
        a[c][r] = v;
      } else {
        a[r][c] = v;
      }
    }
  }
  const std::vector<int> assigned = hungarian(a, n, m);
  std::vector<int> result(rows, -1);
  for (int i = 0; i < n; ++i) {
    const int j = assigned[i];
    if (j < 0) continue;
    const int r = transpose ? j : i, c = transpose ? i : j;
    if (std::isfinite(cost[r][c])) result[r] = c;
  }
  return result;
}

}  // namespace tamp::perception
