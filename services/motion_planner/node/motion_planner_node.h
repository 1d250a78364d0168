#pragma once
/// @file
/// The motion planning service over DDS: a thin adapter around tamp::motion_planner::MotionPlanner.
///
/// - Serves `services::kMotion`, `kPlacement` and `kGrasp` (idl/motion.idl) with one RpcServer
///   each; requests run one at a time on the planner (one scene and its lazy-mode roadmap
///   cache, guarded by a mutex; the DDS dispatch may call handlers concurrently).
/// - Mirrors the world model (`tamp::dds::WorldMirror`, topics tamp/world/objects + meta); before
///   each request the planner's scene is brought to the mirror's latest world (a diff: cheap when
///   little changed). A request naming a `world_version` waits (at most `world_wait_s`) for it.
/// - Motion outcomes are typed in the reply (`MotionReply::status` + `reason`), including
///   MOTION_INVALID_REQUEST for malformed requests (the reason names the IDL field); the reply
///   header says STATUS_OK then. Placement and grasp errors use the header's status code
///   (NOT_FOUND, INVALID_ARGUMENT, UNSUPPORTED, TIMEOUT, UNAVAILABLE) and message.
/// - Budget: the client's remaining budget (RequestContext) and its cancellation; a request
///   without budget gets `default_budget_s`.
/// - Roadmap preparation: after a world update (mirror change) the node's own run() thread
///   (spinOnce) brings the planner to the new world and calls MotionPlanner::prepare() for the
///   base group, under the planner's mutex, so the first lazy request after a static-world change
///   finds a complete roadmap. Cheap when only movables changed (the cached roadmap is reused).
///   A request arriving meanwhile stops the preparation (kept, resumed at the next spin) rather
///   than wait for it; `prepare_budget_s` caps one preparation.
#include <atomic>
#include <optional>
#include <stop_token>

#include <filesystem>
#include <memory>
#include <mutex>
#include <string>

#include "tamp/dds/service_node.h"
#include "tamp/dds/world_sync.h"
#include "tamp/motion_planner/motion_planner.h"

namespace tamp::motion_planner {

/// The service's configuration file: the planner parameters (params.h) plus a `node` section.
struct NodeConfig {
  std::string robot{"mobile_manipulator"};  ///< "mobile_manipulator" or "disc"
  std::filesystem::path urdf;               ///< mobile_manipulator: URDF; empty: RobotModel::loadDefault()
  double disc_radius{0.354};                ///< disc: m, > 0
  double disc_height{1.0};                  ///< disc: m, > 0
  std::string world_id{"world"};
  double default_budget_s{5.0};             ///< > 0
  double world_wait_s{2.0};                 ///< >= 0
  bool prepare{true};                       ///< prepare the base group's roadmap after world updates
  double prepare_budget_s{2.0};             ///< > 0: cap of one preparation
  MotionPlannerParams params;
};

/// Reads a configuration file (`config/services/motion_planner.yaml` layout); errors name
/// file:line:column and the field.
Result<NodeConfig> loadNodeConfig(const std::filesystem::path& file);
Result<NodeConfig> parseNodeConfig(const std::string& yaml_text, const std::string& name);

class MotionPlannerNode : public dds::ServiceNode {
 public:
  /// For serviceMain: reads `args.config_file` (default: configDir()/services/motion_planner.yaml).
  static Result<std::unique_ptr<dds::ServiceNode>> create(const dds::ServiceArgs& args);
  /// With a configuration in hand (tests, embedded use). Throws std::runtime_error when DDS fails.
  static Result<std::unique_ptr<MotionPlannerNode>> create(const dds::ServiceArgs& args, NodeConfig config);
  ~MotionPlannerNode() override;

  msg::MotionReply handleMotion(const msg::MotionRequest& req, const dds::RequestContext& ctx);
  msg::PlacementReply handlePlacement(const msg::PlacementRequest& req, const dds::RequestContext& ctx);
  msg::GraspReply handleGrasp(const msg::GraspRequest& req, const dds::RequestContext& ctx);

  /// What spinOnce() does: when the world changed since the last preparation (or the last one
  /// was interrupted), brings the planner to the mirror's world and prepares the base group's
  /// roadmap (fixed joints of the last base request, else the robot's default state). Returns
  /// whether a preparation ran; nothing when `prepare` is off, nothing changed or a request waits.
  std::optional<PrepareStats> prepareIfWorldChanged();

 protected:
  std::pair<uint64_t, uint64_t> requestCounters() const override;
  void spinOnce() override;

 private:
  MotionPlannerNode(const dds::ServiceArgs& args, NodeConfig config, MotionPlanner planner);
  /// The request's termination (default budget when none), and the world brought up to date.
  /// Returns an error when the requested world version does not arrive in time.
  Result<Termination> prepare(uint64_t world_version, const dds::RequestContext& ctx);

  /// A handler about to take `mutex_`: stops a running preparation.
  void interruptPreparation();

  NodeConfig config_;
  std::mutex mutex_;  // guards planner_ and last_base_start_
  MotionPlanner planner_;
  std::optional<robot::RobotState> last_base_start_;
  std::atomic<bool> world_dirty_{true};
  std::atomic<int> waiting_{0};    // handlers waiting for mutex_
  std::mutex stop_mutex_;          // guards prepare_stop_
  std::stop_source prepare_stop_;
  std::unique_ptr<dds::WorldMirror> mirror_;
  std::unique_ptr<dds::RpcServer<msg::MotionRequest, msg::MotionReply>> motion_;
  std::unique_ptr<dds::RpcServer<msg::PlacementRequest, msg::PlacementReply>> placement_;
  std::unique_ptr<dds::RpcServer<msg::GraspRequest, msg::GraspReply>> grasp_;
};

}  // namespace tamp::motion_planner
