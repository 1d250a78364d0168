#pragma once
/// @file
/// Optimal one-to-one assignment (the Hungarian method, Kuhn-Munkres with potentials, O(n^3)),
/// used to associate detections with tracked objects.

#include <vector>

namespace tamp::perception {

/// Minimum-cost assignment of rows to columns. `cost[r][c]` is the cost of pairing row r with
/// column c; +infinity (or any non-finite value) forbids the pair. Rows and columns may differ
/// in number; some rows stay unassigned when forbidden pairs leave no choice. Returns, for each
/// row, its column or -1. Precondition: every row has the same length (throws
/// std::invalid_argument naming the row).
std::vector<int> solveAssignment(const std::vector<std::vector<double>>& cost);

}  // namespace tamp::perception
