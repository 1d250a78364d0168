#pragma once
/// @file
/// The motion planning service over DDS: a thin adapter around tamp::motion_planner::MotionPlanner.
///
/// - Serves `services::kMotion`, `kPlacement` and `kGrasp` (idl/motion.idl) with one RpcServer
///   each, on a pool of `node.planners` planners (default 2): each has its own scene and lazy-mode
///   roadmap cache, all built alike (same parameters and seeds, each prepared after world
///   updates), and serves one request at a time, so that independent requests run concurrently.
///   A request takes the lowest-numbered idle planner whose roadmap is prepared (else it
///   interrupts a running preparation, else the lowest idle one), so sequential requests go to
///   planner 0 and are as deterministic as with one planner; concurrent ones depend on which
///   planner serves them (each planner's results depend on its seeds and its own request
///   history). The DDS dispatch calls handlers concurrently.
/// - Mirrors the world model (`tamp::dds::WorldMirror`, topics tamp/world/objects + meta); before
///   each request the planner's scene is brought to the mirror's latest world (a diff: cheap when
///   little changed). A request naming a `world_version` waits (at most `world_wait_s`) for it;
///   the reply's `world_version` is the mirror's complete version when the world was taken (the
///   world planned in is at least that version).
/// - Hypothetical worlds: `object_overrides` move or remove objects for one request (unknown ids
///   and non-finite poses are MOTION_INVALID_REQUEST naming `object_overrides[i]...`);
///   `held_grasp_given` attaches `held_object_id` at `held_link` / `held_link_T_object`.
///   `movable_cost_weight` is taken as it is: 0 = movables free (the static-only lazy path).
/// - Object prices: the node follows the effort estimator's fitted models
///   (`topics::kEffortModel`, transient-local): each snapshot's pick, place and move_base values
///   replace the planners' object effort (fittedObjectEffort); `BlockingObject.effort_s` and
///   `MotionReply.cost_s` use them. Until one arrives, the default models price objects.
#include <atomic>
#include <condition_variable>
#include <filesystem>
#include <memory>
#include <mutex>
#include <optional>
#include <stop_token>
#include <string>
#include <vector>

#include "tamp/dds/service_node.h"
#include "tamp/msg_validation/validate.h"
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
  int planners{2};                          ///< planners in the pool (concurrent requests), 1..16
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

  /// What spinOnce() does: for each idle planner whose world changed since its last preparation
  /// (or whose last one was interrupted), brings it to the mirror's world and prepares the base
  /// group's roadmap (fixed joints of its last base request, else the robot's default state).
  /// Returns, per planner, what its preparation did (nothing for a planner not prepared: `prepare`
  /// off, nothing changed, busy, or a request waits).
  std::vector<std::optional<PrepareStats>> prepareIfWorldChanged();
  /// Applies an effort model snapshot (what the kEffortModel reader does); errors name the field.
  Status applyEffortModel(const msg::EffortModelSnapshot& snapshot);
  /// Version of the last effort model snapshot applied (0: the default models).
  uint64_t effortModelVersion() const;
  std::size_t plannerCount() const { return slots_.size(); }

 protected:
  std::pair<uint64_t, uint64_t> requestCounters() const override;
  /// A world model (requests are planned in it; before it, they are answered NOT_READY).
  std::string notReadyBecause() const override;
  void spinOnce() override;

 private:
  msgv::RejectLog rejects_{"motion_planner"};  // malformed input: logged once per kind, rate-limited
  /// One planner of the pool and its bookkeeping (flags guarded by pool_mutex_).
  struct Slot {
    explicit Slot(MotionPlanner p) : planner(std::move(p)) {}
    MotionPlanner planner;
    std::optional<robot::RobotState> last_base_start;  // used only by whoever holds the slot
    bool busy{false};       // a request or a preparation holds it
    bool preparing{false};  // ... a preparation
    bool dirty{true};       // the world changed since its last complete preparation
    std::uint64_t effort_version{0};  // effort model applied to this planner
    std::stop_source prepare_stop;
  };
  /// A slot held by one request (released on destruction).
  class Lease {
   public:
    Lease(MotionPlannerNode* node, std::size_t index) : node_(node), index_(index) {}
    Lease(Lease&& o) noexcept : node_(o.node_), index_(o.index_) { o.node_ = nullptr; }
    Lease& operator=(Lease&&) = delete;
    Lease(const Lease&) = delete;
    Lease& operator=(const Lease&) = delete;
    ~Lease();
    Slot& slot() const { return *node_->slots_[index_]; }
    std::size_t index() const { return index_; }

   private:
    MotionPlannerNode* node_;
    std::size_t index_;
  };

  MotionPlannerNode(const dds::ServiceArgs& args, NodeConfig config, std::vector<MotionPlanner> planners);
  /// The request's termination (default budget when none), after waiting for the requested
  /// world version. Returns an error when that version does not arrive in time.
  Result<Termination> termination(uint64_t world_version, const dds::RequestContext& ctx);
  /// Waits for a planner (see the file comment) until `term` fires; nothing then.
  std::optional<Lease> acquire(const Termination& term);
  /// Brings the leased planner to the mirror's world and the current effort model; returns the
  /// mirror's complete world version taken.
  uint64_t syncPlanner(Slot& slot);

  NodeConfig config_;
  mutable std::mutex pool_mutex_;  // guards the slots' flags, waiting_, effort_
  std::condition_variable pool_cv_;
  std::vector<std::unique_ptr<Slot>> slots_;
  int waiting_{0};  // requests waiting for a planner
  std::shared_ptr<const ObjectEffortFn> effort_;  // null: the default models
  std::uint64_t effort_version_{0};               // bumps per applied snapshot
  std::uint64_t effort_model_version_{0};         // the snapshot's version
  std::unique_ptr<dds::WorldMirror> mirror_;
  std::unique_ptr<dds::Reader<msg::EffortModelSnapshot>> effort_reader_;
  /// The robot's reported state: a preparation before any request is for the robot as it stands
  /// (arm, gripper), which keys the roadmap the first request will look for.
  void onRobotState(const msg::RobotState& m);
  std::optional<robot::RobotState> robot_now_;  // guarded by pool_mutex_
  std::unique_ptr<dds::Reader<msg::RobotState>> robot_reader_;
  std::unique_ptr<dds::RpcServer<msg::MotionRequest, msg::MotionReply>> motion_;
  std::unique_ptr<dds::RpcServer<msg::PlacementRequest, msg::PlacementReply>> placement_;
  std::unique_ptr<dds::RpcServer<msg::GraspRequest, msg::GraspReply>> grasp_;
};

}  // namespace tamp::motion_planner
