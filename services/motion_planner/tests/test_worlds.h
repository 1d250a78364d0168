#pragma once
// Hand-built worlds for the motion planner tests, and an independent geometric checker (plain
// 2-D geometry, no FCL) for planar disc robots among axis-aligned boxes.
#include <string>
#include <vector>

#include "tamp/core/trajectory.h"
#include "tamp/world/world.h"

namespace tamp::motion_planner::testing {

/// A static or movable axis-aligned box standing on the floor.
world::Object box(const std::string& id, double cx, double cy, double sx, double sy, bool movable,
                  double height = 1.0, double mass = 5.0);

/// A 10 x 4 m room (walls 0.2 m thick, inner faces at x = 0/10, y = 0/4) split at x = 5 by a wall
/// with a 1 m door at y in [1.5, 2.5]. `crate` (movable, 0.4 x 1.0) fills the door when
/// `door_blocked`; `far_box` (movable) stands in a corner away from any path.
world::World corridorWorld(bool door_blocked);

/// The same room with two doors: door A at y in [0.4, 1.4] blocked by two heavy, non-graspable
/// movables in a row (`heavy_a`, `heavy_b`), door B at y in [2.6, 3.6] blocked by one light box
/// (`light`).
world::World twoDoorWorld();

/// An open 10 x 6 m room with one light movable box (`obstacle`, 0.6 x 0.6) at (5, 3).
world::World openRoomWorld();

/// Independent check: the smallest clearance (m) of a disc of `radius` moving along the base
/// path (base_x, base_y; interpolated every `step` m) from the boxes and box prisms of `w`
/// (objects whose id is in `skip` are ignored). Negative: penetration.
double discClearance(const world::World& w, const JointPath& path, double radius, double step,
                     const std::vector<std::string>& skip = {}, bool movables = true);

/// Ids of objects of `w` that a disc of `radius` touches along the base path (step `step`).
std::vector<std::string> discTouches(const world::World& w, const JointPath& path, double radius, double step,
                                     bool movables_only = true);

}  // namespace tamp::motion_planner::testing
