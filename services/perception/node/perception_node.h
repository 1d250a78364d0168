#pragma once
/// @file
/// The perception service on DDS: subscribes depth frames (`topics::kPointCloud`), runs
/// `Perception` on the newest one (older frames waiting behind it are skipped: perception must
/// not fall behind the sensor), and publishes
/// - the world model with `dds::WorldPublisher` (keyed objects + meta, transient-local; only
///   changed objects are written, removed ones disposed);
/// - the world events (`topics::kWorldEvents`);
/// - the OctoMap of unexplained space (`topics::kOccupancy`, the OctoMap binary stream) at most
///   every `occupancy_period_s`.
/// With a robot model it also subscribes the robot state (`topics::kRobotState`: base pose,
/// joint positions, held object id) and gives each frame the robot's body at the frame's stamp,
/// interpolated between the states around it (`robotStateAt`), so the robot's links and held
/// object are not reported as obstacles (`self_filter.h`). A frame whose state has not arrived
/// yet waits for it up to `robot_state_wait_s`; then the nearest state within
/// `robot_state_max_age_s` is used. A frame with no state that close is processed unfiltered and
/// counted (`framesWithoutState`).
/// A malformed frame is rejected with a warning naming the field and counted; nothing escapes
/// the DDS callback or the worker thread.

#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <filesystem>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>

#include "tamp/dds/service_node.h"
#include "tamp/msg_validation/validate.h"
#include "tamp/dds/world_sync.h"
#include "tamp/perception/perception.h"

namespace tamp::perception {

struct PerceptionNodeOptions {
  PerceptionParams params;
  world::World prior;                ///< static map + declared objects (planner view)
  std::string world_id{"world"};     ///< WorldMeta key
  double occupancy_period_s{1.0};    ///< >= 0; 0 publishes after every frame
  double frame_budget_s{0.5};        ///< deadline of one frame's processing, > 0
  /// The robot whose body and held object are filtered out; nullptr: no filtering, the robot
  /// state is not subscribed. `create()` loads the scenario's robot description (else the
  /// default robot).
  std::shared_ptr<const robot::RobotModel> robot;
  double robot_state_max_age_s{0.5};  ///< s, >= 0: largest |frame stamp - state stamp| used
  /// s, in [0, 5]: how long a frame waits for a robot state at or after its stamp (states and
  /// frames travel on different topics; under load the frame may arrive first).
  double robot_state_wait_s{0.25};
  /// Where the node keeps its checkpoint (checkpoint.h); empty: none. `create()` sets it to
  /// `$TAMP_RUN_DIR/perception.checkpoint` and, when that file exists, starts from it: `prior`
  /// restored and `resume_grasp` set.
  std::filesystem::path checkpoint_file;
  std::optional<Perception::HeldGrasp> resume_grasp;
  std::uint64_t resume_world_version{0};  ///< the checkpoint's: versions are published above it
};

/// Node options from the service's YAML (`config/services/perception.yaml`): the perception
/// parameters plus a `node:` section (`world_id`, `occupancy_period_s`, `frame_budget_s`,
/// `robot_state_max_age_s`).
/// The prior world is not part of this file (it comes from the scenario).
Result<PerceptionNodeOptions> loadNodeOptions(const std::filesystem::path& file);
Result<PerceptionNodeOptions> parseNodeOptions(const std::string& yaml_text, const std::string& name);

class PerceptionNode : public dds::ServiceNode {
 public:
  /// Throws std::runtime_error when DDS fails, std::invalid_argument for invalid options.
  PerceptionNode(const dds::ServiceArgs& args, PerceptionNodeOptions options);
  ~PerceptionNode() override;

  static Result<std::unique_ptr<dds::ServiceNode>> create(const dds::ServiceArgs& args);

  std::uint64_t framesProcessed() const { return processed_.load(); }
  std::uint64_t framesRejected() const { return rejected_.load(); }
  std::uint64_t framesSkipped() const { return skipped_.load(); }
  /// Frames processed without a robot state close enough to filter the robot's body.
  std::uint64_t framesWithoutState() const { return without_state_.load(); }
  /// Robot states received and accepted (malformed ones are counted as rejected requests).
  std::uint64_t robotStates() const { return states_.load(); }
  /// A copy of the current world model (thread-safe).
  world::World worldSnapshot() const;

 protected:
  std::pair<uint64_t, uint64_t> requestCounters() const override;
  /// Not ready until a robot state arrived (frames cannot be placed without the robot's body).
  std::string notReadyBecause() const override;

 private:
  msgv::RejectLog rejects_{"perception"};  // malformed input: logged once per kind, rate-limited
  void onCloud(const msg::PointCloudFrame& m);
  void onState(const msg::RobotState& m);
  /// The robot's body at `stamp_ns` (waiting up to `robot_state_wait_s` for a state at or after
  /// it), or nullopt when no state is within the age limit.
  std::optional<RobotBody> bodyAt(std::int64_t stamp_ns, std::stop_token stop) const;
  void work(std::stop_token stop);
  void process(const PointCloudFrame& frame, std::stop_token stop);
  /// Writes the checkpoint when the world model or the grasp changed since the last one.
  void checkpoint(bool world_changed);

  PerceptionNodeOptions options_;
  std::unique_ptr<Perception> perception_;  // worker thread only (world copies under mutex_)
  dds::WorldPublisher world_pub_;
  dds::Writer<msg::WorldEvent> events_;
  dds::Writer<msg::OccupancyMap> occupancy_;
  mutable std::mutex mutex_;
  std::condition_variable_any cv_;
  std::optional<PointCloudFrame> pending_;
  world::World snapshot_;
  std::atomic<std::uint64_t> processed_{0}, rejected_{0}, skipped_{0}, without_state_{0};
  std::atomic<std::uint64_t> states_{0}, bad_states_{0};
  mutable std::mutex state_mutex_;
  mutable std::condition_variable_any state_cv_;  // a state arrived
  std::deque<StampedRobotState> states_seen_;     // stamp order, newest last, bounded
  std::uint64_t event_seq_{0}, map_seq_{0};
  std::optional<Clock::time_point> last_map_;
  std::optional<Perception::HeldGrasp> checkpointed_grasp_;  // worker thread only
  bool checkpoint_failed_{false};                            // logged once
  std::shared_ptr<dds::WorkWatch> frame_watch_;  // the worker, watched while it processes a frame
  std::jthread worker_;
  std::unique_ptr<dds::Reader<msg::RobotState>> robot_states_;
  std::unique_ptr<dds::Reader<msg::PointCloudFrame>> clouds_;  // last: callbacks need the rest
};

}  // namespace tamp::perception
