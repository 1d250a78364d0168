#pragma once
// Hand-built worlds for the motion planner tests, and an independent geometric checker (plain
// 2-D geometry, no FCL) for planar disc robots among axis-aligned boxes.
#include <string>
#include <vector>

#include "tamp/core/trajectory.h"
#include "tamp/motion_planner/motion_planner.h"
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

/// A 30 x 30 m room with a closed 2 x 2 m pocket (static walls, inner faces at x = 24.1/25.9,
/// y = 24.1/25.9) whose 1 m door in its south wall is filled by `crate` (movable).
world::World pocketWorld();

/// An open 10 x 6 m room with one light movable box (`obstacle`, 0.6 x 0.6) at (5, 3).
world::World openRoomWorld();

/// The disc radius of the planar robot in these tests (m).
inline constexpr double kDiscRadius = 0.3;

/// A planner for the planar disc robot (kDiscRadius) with `w` set.
MotionPlanner discPlanner(const world::World& w, const MotionPlannerParams& p = {});
/// Parameters under which the effort-aware roadmap search finishes (LazySP's optimum over the
/// roadmap): it is otherwise cut by a count of edge evaluations (1000 by default; then the best
/// path over the edges known valid is kept) and a wall-clock safety cap. The outcome then depends
/// on the seeds only; the NAMO benchmark measures the defaults.
MotionPlannerParams untimedParams();
/// A base-group request between two poses.
MotionRequest baseRequest(Pose2D from, Pose2D to, MotionMode mode = MotionMode::kLazy);
/// The ids of the blocking objects, sorted.
std::vector<std::string> blockingIds(const std::vector<BlockingObject>& blocking);

/// Independent check: the smallest clearance (m) of a disc of `radius` moving along the base
/// path (base_x, base_y; interpolated every `step` m) from the boxes and box prisms of `w`
/// (objects whose id is in `skip` are ignored). Negative: penetration.
double discClearance(const world::World& w, const JointPath& path, double radius, double step,
                     const std::vector<std::string>& skip = {}, bool movables = true);

/// Ids of objects of `w` that a disc of `radius` touches along the base path (step `step`).
std::vector<std::string> discTouches(const world::World& w, const JointPath& path, double radius, double step,
                                     bool movables_only = true);

}  // namespace tamp::motion_planner::testing
