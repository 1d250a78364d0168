#pragma once
/// @file
/// The skeleton every service process follows (the Fast DDS examples' app pattern):
///
///   services/<svc>/main.cc:
///     int main(int argc, char** argv) {
///       return tamp::dds::serviceMain(argc, argv, "symbolic_planner", "FF task planner service",
///           [](const tamp::dds::ServiceArgs& a) { return tamp::symbolic_planner::PlannerNode::create(a); });
///     }
///
/// `serviceMain` blocks SIGINT/SIGTERM before any thread exists, parses the standard arguments
/// (--domain, --profile, --config, --name, --log-level, --run-id, --security, ...), builds the node, runs it until a signal
/// or stop(), and returns an exit code (0 clean stop, 30 bad arguments/config, 40 DDS failure).
///
/// A `ServiceNode` owns the participant, publishes heartbeats and answers echo requests on
/// "tamp/<name>/echo" (`tamp ping <name>`). Subclasses create their servers, writers and readers
/// in `create()` and may do periodic work in `spinOnce()`.

#include <atomic>
#include <condition_variable>
#include <functional>
#include <memory>
#include <string>

#include "tamp/dds/heartbeat.h"
#include "tamp/dds/rpc.h"

namespace tamp::dds {

/// The command line every service accepts.
struct ServiceArgs {
  std::string name;         ///< service name (heartbeat, echo topic); default: the service's own
  int domain_id{-1};        ///< -1: $TAMP_DOMAIN_ID or 0
  std::string profile;      ///< DDS participant profile; empty: tamp_default
  std::string config_file;  ///< service parameters (YAML); empty: the service's defaults
  /// The run's scenario (YAML); empty: none. Overrides a scenario named in the service's own
  /// parameters (the simulator's ground truth, perception's priors, the planners' robot).
  std::string scenario_file;
  std::string log_level{"info"};
  double heartbeat_period_s{1.0};
  /// The run this service belongs to (its DDS partition, see runPartition()); empty: $TAMP_RUN_ID,
  /// else no run.
  std::string run_id;
  /// A file its supervisor (`tamp launch`) touches every heartbeat period; empty: none. When its
  /// modification time is older than `orphan_timeout_s` the service stops by itself (exit 0), so a
  /// service whose supervisor was killed and not restarted does not run forever.
  std::string supervisor_lease;
  double orphan_timeout_s{0.0};  ///< > 0 with supervisor_lease; seconds
  /// The main loop (run(): spinOnce() and its wait) may go this long without turning before the
  /// service stops beating and counts as dead (HeartbeatPublisher::setStallLimit); 0: never.
  double stall_timeout_s{20.0};
  /// DDS Security directory (deploy/security/make_certs.sh); empty: $TAMP_DDS_SECURITY, else none.
  std::string security_dir;
  /// The certificate/permissions to use from it; empty: the service name.
  std::string security_identity;
};

/// Parses the standard arguments. Returns an error for bad arguments; `--help` prints usage and
/// returns kCancelled (exit 0).
Result<ServiceArgs> parseServiceArgs(int argc, char** argv, const std::string& default_name,
                                     const std::string& description);

class ServiceNode {
 public:
  ServiceNode(const ServiceNode&) = delete;
  ServiceNode& operator=(const ServiceNode&) = delete;
  virtual ~ServiceNode();

  /// Marks the service ready and blocks until stop(); calls spinOnce() every spin period.
  /// Returns the exit code.
  int run();
  /// Thread-safe; run() returns soon after.
  void stop();

  const std::string& name() const { return name_; }
  const std::string& runId() const { return participant_->runId(); }
  const std::shared_ptr<Participant>& participant() const { return participant_; }
  HeartbeatPublisher& heartbeat() { return *heartbeat_; }

 protected:
  /// Creates the participant, heartbeat and echo server. Throws std::runtime_error when DDS fails
  /// (serviceMain turns that into exit code 40 with the message).
  explicit ServiceNode(const ServiceArgs& args);
  /// Periodic work on the run() thread (default: none).
  virtual void spinOnce() {}
  /// How often spinOnce() runs.
  virtual double spinPeriodSeconds() const { return 0.1; }
  /// Once, on the run() thread, after stop() and before run() returns (the participant still
  /// up): a last, bounded chance to hand over what the service holds (default: nothing).
  virtual void onStop() {}
  /// Sum of requests served/failed by the node's servers, for the heartbeat (default: echo only).
  virtual std::pair<uint64_t, uint64_t> requestCounters() const;
  /// What the service still waits for before it can do its work (e.g. "no robot state yet");
  /// empty: ready (the default). Until it is empty the heartbeat says SERVICE_STARTING with this
  /// as its detail, and `tamp run` / `tamp mission` do not start a mission. Polled by run() at
  /// every turn of the main loop; once ready, a service stays ready. Thread-safe.
  virtual std::string notReadyBecause() const { return {}; }

 private:
  std::string name_;
  std::shared_ptr<Participant> participant_;
  std::unique_ptr<HeartbeatPublisher> heartbeat_;
  std::unique_ptr<RpcServer<msg::EchoRequest, msg::EchoReply>> echo_;
  /// True when the supervisor's lease (ServiceArgs::supervisor_lease) expired.
  bool orphaned() const;
  /// One poll of notReadyBecause() while starting: the heartbeat's detail, READY once it is
  /// empty. Returns what it still waits for.
  std::string awaitInputs(const std::string& was);
  std::string supervisor_lease_;
  double orphan_timeout_s_{0.0};
  double stall_timeout_s_{0.0};
  std::mutex mutex_;
  std::condition_variable cv_;
  bool stop_{false};
};

/// Echo service name of a node: "tamp/<node>/echo".
std::string echoService(const std::string& node_name);
/// The echo handler (payload back, optional simulated work that honours the termination).
msg::EchoReply echoHandler(const msg::EchoRequest& req, const RequestContext& ctx);

using NodeFactory = std::function<Result<std::unique_ptr<ServiceNode>>(const ServiceArgs&)>;

/// Blocks termination signals, parses arguments, builds the node with `make`, runs it, and maps
/// every failure to an exit code with a one-line message on stderr.
int serviceMain(int argc, char** argv, const std::string& default_name, const std::string& description,
                const NodeFactory& make);

}  // namespace tamp::dds
