#include "cloud_convert.h"

#include "tamp/dds/convert.h"
#include "tamp/perception/validation.h"

namespace tamp::perception {

Result<PointCloudFrame> fromMsg(const msg::PointCloudFrame& m, std::size_t max_points) {
  auto bad = [](const std::string& field, const std::string& why) {
    return Error(ErrorCode::kInvalidArgument, "malformed point cloud: " + why, SourceLocation{"", 0, 0, field});
  };
  const std::size_t values = m.points().size();
  if (values == 0) return bad("points", "empty cloud (no points)");
  if (values % 3 != 0) return bad("points", "size " + std::to_string(values) + " is not a multiple of 3");
  if (values / 3 > max_points) {
    return bad("points", std::to_string(values / 3) + " points exceed the limit of " + std::to_string(max_points));
  }
  // The checks above are cheap and come before the points are copied.
  auto frame = dds::fromMsg(m);
  if (!frame) return frame.error();
  PointCloudFrame f = std::move(frame).value();
  if (Status s = validateFrame(f, max_points); !s.ok()) {
    Error e = s.error();
    if (e.where.field == "xyz" || e.where.field.rfind("xyz[", 0) == 0) e.where.field.replace(0, 3, "points");
    if (e.where.field == "world_T_sensor") e.where.field = "sensor_pose";
    return e;
  }
  return f;
}

msg::WorldEvent toMsg(const WorldEvent& e, uint64_t seq) {
  msg::WorldEvent m;
  m.header().stamp_ns(e.stamp_ns);
  m.header().frame_id("world");
  m.header().seq(seq);
  switch (e.type) {
    case EventType::kAdded:
      m.type(msg::WORLD_OBJECT_ADDED);
      break;
    case EventType::kMoved:
      m.type(msg::WORLD_OBJECT_MOVED);
      break;
    case EventType::kRemoved:
      m.type(msg::WORLD_OBJECT_REMOVED);
      break;
    case EventType::kGone:
      m.type(msg::WORLD_OBJECT_GONE);
      break;
  }
  m.object_id(e.object_id);
  m.kind(e.kind == world::ObjectKind::kMovable ? msg::OBJECT_MOVABLE : msg::OBJECT_STATIC);
  m.pose(dds::toMsg(e.pose));
  m.description(e.description);
  return m;
}

msg::OccupancyMap occupancyToMsg(const std::string& binary, double resolution, int64_t stamp_ns, uint64_t seq,
                                 const std::string& map_id) {
  msg::OccupancyMap m;
  m.header().stamp_ns(stamp_ns);
  m.header().frame_id("world");
  m.header().seq(seq);
  m.map_id(map_id);
  m.resolution(resolution);
  m.octree(std::vector<uint8_t>(binary.begin(), binary.end()));
  return m;
}

}  // namespace tamp::perception
