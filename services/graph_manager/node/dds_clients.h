#pragma once
/// @file
/// The graph manager's reach into the other services over DDS: `ServiceClients` over the
/// planner, motion-planner and effort-estimator request/reply services, `Executor` over the
/// execution monitor's command and status topics, `WorldSource` over the world model and the
/// robot state. Every call has a deadline; failures are values.

#include <condition_variable>
#include <map>
#include <memory>
#include <mutex>
#include <optional>

#include "tamp/dds/heartbeat.h"
#include "tamp/dds/participant.h"
#include "tamp/dds/rpc.h"
#include "tamp/dds/topics.h"
#include "tamp/dds/world_sync.h"
#include "tamp/graph_manager/graph_manager.h"

namespace tamp::graph_manager {

/// An adapter whose calls and waits tell the heartbeat that the mission's worker moves on
/// (dds::WorkWatch): a worker stuck elsewhere stops the beats, and the supervisor restarts it.
class Watched {
 public:
  void watchedBy(dds::WorkWatch* watch) { watch_ = watch; }

 protected:
  void alive() const {
    if (watch_) watch_->kick();
  }

 private:
  dds::WorkWatch* watch_{nullptr};
};

class DdsServiceClients : public ServiceClients, public Watched {
 public:
  DdsServiceClients(std::shared_ptr<dds::Participant> p, robot::RobotModel robot);
  /// The mission's robot (joint names of motion requests). Not concurrent with the calls below.
  void setRobot(robot::RobotModel robot) { robot_ = std::move(robot); }
  TaskPlan plan(const TaskQuery& q) override;
  MotionAnswer motion(const MotionQuery& q) override;
  /// Every query sent before any answer is awaited (one thread each; the RPC client is
  /// thread-safe): the motion node's planner pool works on them side by side.
  std::vector<MotionAnswer> motions(const std::vector<MotionQuery>& qs) override;
  Result<std::vector<PlacementOption>> placements(const PlacementQuery& q) override;
  Result<std::vector<GraspOption>> grasps(const GraspQuery& q) override;
  std::vector<EffortAnswer> effort(const std::vector<EffortQuery>& q) override;
  std::optional<std::uint64_t> effortModelVersion() override;
  /// The services none of whose servers is matched yet ("" once every one is). Thread-safe.
  std::string missingServers() const;

 private:
  /// `rep` screened (checked), the worker kicked: a call came back.
  template <typename Rep>
  Result<Rep> answered(Result<Rep> rep, const char* service) const;
  robot::RobotModel robot_;
  dds::RpcClient<msg::PlanRequest, msg::PlanReply> plan_;
  dds::RpcClient<msg::MotionRequest, msg::MotionReply> motion_;
  dds::RpcClient<msg::PlacementRequest, msg::PlacementReply> placement_;
  dds::RpcClient<msg::GraspRequest, msg::GraspReply> grasp_;
  dds::RpcClient<msg::EffortRequest, msg::EffortReply> effort_;
};

/// Commands go out as "<mission id>/<command id>": the monitor and the robot are idempotent on
/// command ids, and a deployment runs many missions whose steps are numbered alike.
class DdsExecutor : public Executor, public Watched {
 public:
  DdsExecutor(std::shared_ptr<dds::Participant> p, std::string mission_id);
  ExecutionReport execute(const EdgeCommand& command, double budget_s) override;
  /// The monitor's final status of a command sent before this node (re)started: the status topic
  /// keeps the last ones (transient-local), so an outcome that came while the node was down is
  /// read here.
  ExecutionReport await(const std::string& command_id, double budget_s) override;
  void setMission(const std::string& id) { mission_id_ = id; }
  /// The id a command of the current mission has on the wire.
  std::string wireId(const std::string& command_id) const { return mission_id_ + "/" + command_id; }
  /// True once an execution monitor's command reader and status writer are matched.
  bool monitorPresent() const { return writer_.matchedReaders() > 0 && reader_.matchedWriters() > 0; }
  /// Thread-safe: asks the execution monitor to stop the command execute() is waiting for, if
  /// any (a mission aborted mid-action: the robot stops instead of finishing the action). The
  /// monitor's final status (cancelled, or what it was already) ends the wait as usual.
  void cancelInFlight();

 private:
  void onStatus(const msg::ExecuteStatus& s);
  /// Waits (lock held) up to `budget_s` for the final status of `wire`; the report from it, or
  /// kTimeout. With `resend`, every quarter of a second: a reader matched since `matches`
  /// (a restarted execution monitor, which never saw the command) gets it again.
  ExecutionReport finalOf(std::unique_lock<std::mutex>& lock, const std::string& wire, double budget_s,
                          const msg::ExecuteCommand* resend = nullptr, int matches = 0);
  std::string mission_id_;
  dds::Writer<msg::ExecuteCommand> writer_;
  std::mutex mutex_;
  std::condition_variable cv_;
  std::map<std::string, msg::ExecuteStatus> final_;
  std::optional<msg::ExecuteCommand> in_flight_;  ///< the command execute() waits for (mutex_)
  dds::Reader<msg::ExecuteStatus> reader_;
};

class DdsWorldSource : public WorldSource, public Watched {
 public:
  DdsWorldSource(std::shared_ptr<dds::Participant> p, robot::RobotModel robot);
  /// The mission's robot (joint values of robot states). Not concurrent with `robot()`.
  void setRobot(robot::RobotModel robot) { robot_ = std::move(robot); }
  world::World world() override { return mirror_.snapshot(); }
  std::uint64_t version() override { return mirror_.publishedVersion(); }
  Observation robot() override;
  /// Waits until a robot state and a world model have arrived. On a timeout, says which did not.
  Status waitReady(const Termination& until);
  /// Which of the two has not arrived yet ("" once both have). Thread-safe.
  std::string missingInputs() const;

 private:
  robot::RobotModel robot_;
  dds::WorldMirror mirror_;
  mutable std::mutex mutex_;
  std::optional<msg::RobotState> last_;
  dds::Reader<msg::RobotState> state_;
};

}  // namespace tamp::graph_manager
