#pragma once
/// @file
/// `msg::PointCloudFrame` <-> `tamp::PointCloudFrame`, and perception's outputs as messages.
/// Incoming frames are validated: errors name the message field (`points`, `sensor_pose`, ...).

#include <cstdint>
#include <string>

#include "tamp/core/error.h"
#include "tamp/core/point_cloud.h"
#include "tamp/msg/robot.h"
#include "tamp/msg/world.h"
#include "tamp/perception/perception.h"

namespace tamp::perception {

/// dds::fromMsg (frames are published with dds::toMsg) and perception's checks: kInvalidArgument
/// naming the field: `points` (not a multiple of 3, empty, or more than `max_points`),
/// `width`/`height` (do not match the points), `sensor_pose` (non-finite or zero quaternion), and
/// whatever `validateFrame` finds.
Result<PointCloudFrame> fromMsg(const msg::PointCloudFrame& m, std::size_t max_points);

msg::WorldEvent toMsg(const WorldEvent& event, uint64_t seq);
msg::OccupancyMap occupancyToMsg(const std::string& octomap_binary, double resolution, int64_t stamp_ns,
                                 uint64_t seq, const std::string& map_id = "unknown_space");

}  // namespace tamp::perception
