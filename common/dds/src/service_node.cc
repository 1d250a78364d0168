#include "tamp/dds/service_node.h"

#include <pthread.h>
#include <signal.h>
#include <unistd.h>

#include <filesystem>
#include <iostream>
#include <thread>

namespace tamp::dds {

std::string echoService(const std::string& node_name) { return "tamp/" + node_name + "/echo"; }

msg::EchoReply echoHandler(const msg::EchoRequest& req, const RequestContext& ctx) {
  msg::EchoReply rep;
  if (!(req.work_s() >= 0.0) || req.work_s() > 3600.0) {
    rep.header().code(msg::STATUS_INVALID_ARGUMENT);
    rep.header().message("field 'work_s': must be in [0, 3600], got " + std::to_string(req.work_s()));
    return rep;
  }
  if (req.work_s() > 0) {
    const Deadline done = Deadline::in(req.work_s());
    while (!done.expired()) {
      if (ctx.termination()) {
        rep.header().code(ctx.termination.reason() == StopReason::kDeadline ? msg::STATUS_TIMEOUT
                                                                              : msg::STATUS_CANCELLED);
        rep.header().message("echo work interrupted");
        return rep;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
    }
  }
  rep.payload(req.payload());
  rep.pid(static_cast<uint32_t>(::getpid()));
  return rep;
}

ServiceNode::ServiceNode(const ServiceArgs& args)
    : name_(args.name),
      supervisor_lease_(args.supervisor_lease),
      orphan_timeout_s_(args.orphan_timeout_s),
      stall_timeout_s_(args.stall_timeout_s) {
  ParticipantOptions po;
  po.domain_id = args.domain_id;
  if (!args.profile.empty()) po.profile = args.profile;
  po.name = "tamp/" + args.name;
  po.security_dir = args.security_dir;
  po.security_identity = args.security_identity.empty() ? args.name : args.security_identity;
  auto p = Participant::create(po, args.run_id);
  if (!p) throw std::runtime_error(p.error().toString());
  participant_ = *p;
  heartbeat_ = std::make_unique<HeartbeatPublisher>(participant_, name_, args.heartbeat_period_s);
  echo_ = std::make_unique<RpcServer<msg::EchoRequest, msg::EchoReply>>(participant_, echoService(name_),
                                                                       echoHandler);
  heartbeat_->setCounters([this] { return requestCounters(); });
}

ServiceNode::~ServiceNode() {
  if (heartbeat_) heartbeat_->setCounters({});
}

std::pair<uint64_t, uint64_t> ServiceNode::requestCounters() const {
  return {echo_ ? echo_->served() : 0, echo_ ? echo_->failed() + echo_->rejected() : 0};
}

bool ServiceNode::orphaned() const {
  if (supervisor_lease_.empty() || orphan_timeout_s_ <= 0) return false;
  std::error_code ec;
  const auto touched = std::filesystem::last_write_time(supervisor_lease_, ec);
  // A lease that vanished counts as expired: the run's folder was removed.
  if (ec) return true;
  const double age = std::chrono::duration<double>(std::filesystem::file_time_type::clock::now() - touched).count();
  return age > orphan_timeout_s_;
}

int ServiceNode::run() {
  std::string waiting = notReadyBecause();
  heartbeat_->setDetail(waiting);
  heartbeat_->setState(waiting.empty() ? msg::SERVICE_READY : msg::SERVICE_STARTING);
  log::get(name_)->info("{} ready on DDS domain {} (profile {}{})", name_, participant_->domainId(),
                        participant_->profile(),
                        (runId().empty() ? std::string() : ", run " + runId()) +
                            (participant_->securityIdentity().empty()
                                 ? std::string()
                                 : ", DDS Security as '" + participant_->securityIdentity() + "'"));
  heartbeat_->setStallLimit(stall_timeout_s_);
  std::unique_lock lock(mutex_);
  while (!stop_) {
    lock.unlock();
    heartbeat_->kick();
    if (!waiting.empty()) waiting = awaitInputs(waiting);
    if (orphaned()) {
      log::get(name_)->warn("{}: no supervisor renewed {} for {:.1f} s: stopping", name_, supervisor_lease_,
                            orphan_timeout_s_);
      lock.lock();
      break;
    }
    try {
      const auto t0 = Clock::now();
      spinOnce();
      const double took = std::chrono::duration<double>(Clock::now() - t0).count();
      if (stall_timeout_s_ > 0 && took > 0.5 * stall_timeout_s_)
        log::get(name_)->warn("{}: one turn of the main loop took {:.1f} s (stall limit {:.1f} s)", name_, took,
                              stall_timeout_s_);
    } catch (const std::exception& e) {
      log::get(name_)->error("spinOnce failed: {}", e.what());
      heartbeat_->setState(msg::SERVICE_DEGRADED);
      heartbeat_->setDetail(e.what());
    }
    lock.lock();
    cv_.wait_for(lock, std::chrono::duration<double>(spinPeriodSeconds()), [this] { return stop_; });
  }
  log::get(name_)->info("{} stopping", name_);
  heartbeat_->setStallLimit(0.0);  // the clean stop may take longer than a turn
  heartbeat_->setState(msg::SERVICE_STOPPING);
  lock.unlock();
  try {
    onStop();
  } catch (const std::exception& e) {
    log::get(name_)->error("onStop failed: {}", e.what());
  }
  return 0;
}

std::string ServiceNode::awaitInputs(const std::string& was) {
  std::string now = notReadyBecause();
  heartbeat_->setDetail(now);
  if (now.empty()) {
    heartbeat_->setState(msg::SERVICE_READY);
    log::get(name_)->info("{}: its inputs arrived (it waited for: {}): ready", name_, was);
  }
  return now;
}

void ServiceNode::stop() {
  {
    std::lock_guard lock(mutex_);
    stop_ = true;
  }
  cv_.notify_all();
}

int serviceMain(int argc, char** argv, const std::string& default_name, const std::string& description,
                const NodeFactory& make) {
  // Block the termination signals in this thread before any other thread exists (DDS creates
  // several); a dedicated thread waits for them and stops the node.
  sigset_t set;
  sigemptyset(&set);
  sigaddset(&set, SIGINT);
  sigaddset(&set, SIGTERM);
  pthread_sigmask(SIG_BLOCK, &set, nullptr);

  auto args = parseServiceArgs(argc, argv, default_name, description);
  if (!args) {
    if (args.error().code == ErrorCode::kCancelled) return 0;  // --help
    std::cerr << default_name << ": " << args.error().toString() << "\n";
    return 30;
  }
  try {
    log::setLevel(args->log_level);
  } catch (const std::exception& e) {
    std::cerr << default_name << ": " << e.what() << "\n";
    return 30;
  }
  std::unique_ptr<ServiceNode> node;
  try {
    auto made = make(*args);
    if (!made) {
      std::cerr << args->name << ": " << made.error().toString() << "\n";
      return made.error().code == ErrorCode::kUnavailable || made.error().code == ErrorCode::kInternal ? 40 : 30;
    }
    node = std::move(*made);
  } catch (const std::exception& e) {
    std::cerr << args->name << ": cannot start: " << e.what() << "\n";
    return 40;
  }
  std::jthread waiter([&node, set]() {
    int sig = 0;
    sigwait(&set, &sig);
    if (sig != 0) node->stop();
  });
  const int rc = node->run();
  // Wake the signal thread if we stopped for another reason.
  pthread_kill(waiter.native_handle(), SIGTERM);
  waiter.join();
  node.reset();
  return rc;
}

}  // namespace tamp::dds
