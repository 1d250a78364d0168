#pragma once
/// @file
/// Typed request/reply over a pair of topics ("<service>/request", "<service>/reply").
///
/// Client: `call()` stamps a correlation id (`<client_id>#<seq>`), waits for a server to match,
/// sends, and waits for the reply with that id until the call's deadline. A request without reply
/// after `attempt_timeout_s` is re-sent with the same id (the server answers a repeated id from its
/// reply cache, so retries are idempotent). A stop request sends a cancel to the server and
/// returns kCancelled. Failures are values:
///   kUnavailable  no server matched before the deadline ("no server for 'x' on domain 7 ...")
///   kTimeout      a server matched but no reply came in time
///   kCancelled    the stop token fired
///   kInvalidArgument  the request exceeds the service's payload limit (checked before sending)
///   other codes   the server's reply header said so (its message is kept)
///
/// Server: each request is validated on the listener thread (ids present, payload limit, cancel,
/// duplicate) and queued; worker threads run the handler with a Termination built from the
/// request's budget and a per-request stop token. A handler that throws produces a kInternal reply;
/// nothing escapes. Requests whose budget ran out in the queue get a kTimeout reply unrun.

#include <unistd.h>

#include <condition_variable>
#include <deque>
#include <list>
#include <thread>
#include <unordered_map>

#include "tamp/core/log.h"
#include "tamp/dds/convert.h"
#include "tamp/dds/topics.h"

namespace tamp::dds {

struct RpcClientOptions {
  double attempt_timeout_s{1.0};  ///< re-send when no reply came within this time
  int max_attempts{10};           ///< sends per call, the first included
  uint32_t max_request_bytes{0};  ///< 0: the ServiceSpec's limit
  /// The server's budget is the call's remaining time less this margin (at most a fifth of that
  /// time), so that a handler that works to the end of its budget (an anytime planner) still has
  /// its reply reach the client before the client gives up.
  double reply_margin_s{0.05};
};

struct CallOptions {
  double timeout_s{5.0};  ///< the whole call, server discovery included
  std::stop_token stop;   ///< request cancellation
};

struct RequestContext {
  std::string request_id;
  std::string client_id;
  unsigned attempt{1};
  Termination termination;  ///< the client's remaining budget + cancellation
};

struct RpcServerOptions {
  int threads{1};
  size_t reply_cache_size{256};
  uint32_t max_request_bytes{0};  ///< 0: the ServiceSpec's limit
  /// A reply is written only once the reply writer is matched with a reader of the requesting
  /// participant, waiting for it at most this long (and never past the request's budget); 0: no
  /// wait. A client matches the server (and sends) when *its* endpoints have matched; the
  /// server's reply writer may match the client's reply reader later (under DDS Security, when
  /// that reader's crypto tokens arrive), and a VOLATILE reply written before then is lost.
  /// $TAMP_RPC_REPLY_MATCH_WAIT_S overrides it (measurements).
  double reply_match_wait_s{5.0};
};

namespace detail {
/// A process-unique client id: "<host>:<pid>:<n>".
std::string newClientId();
std::string hostName();
std::shared_ptr<spdlog::logger> rpcLog();
/// `configured`, or $TAMP_RPC_REPLY_MATCH_WAIT_S when set (seconds, >= 0; a bad value is logged
/// and ignored).
double replyMatchWait(double configured);
}  // namespace detail

template <typename Req, typename Rep>
class RpcClient {
 public:
  RpcClient(std::shared_ptr<Participant> p, const std::string& service, const RpcClientOptions& options = {},
            uint32_t spec_limit = 16u << 20)
      : participant_(p),
        service_(service),
        options_(options),
        max_bytes_(options.max_request_bytes ? options.max_request_bytes : spec_limit),
        client_id_(detail::newClientId()),
        writer_(p, TopicSpec<Req>{request_topic_.assign(service + "/request").c_str(), QosClass::kRpc}),
        reader_(p, TopicSpec<Rep>{reply_topic_.assign(service + "/reply").c_str(), QosClass::kRpc},
                [this](const Rep& rep, const SampleMeta& meta) { onReply(rep, meta); },
                ReaderOptions{"", "", {}, /*inline_callbacks=*/true}) {}
  RpcClient(std::shared_ptr<Participant> p, const ServiceSpec<Req, Rep>& spec, const RpcClientOptions& options = {})
      : RpcClient(std::move(p), spec.name, options, spec.max_request_bytes) {}

  const std::string& clientId() const { return client_id_; }
  const std::string& service() const { return service_; }
  /// True once a server's request reader and reply writer are both matched.
  bool serverPresent() const { return writer_.matchedReaders() > 0 && reader_.matchedWriters() > 0; }
  bool waitForServer(const Termination& until) const {
    while (!serverPresent()) {
      if (until()) return false;
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
    }
    return true;
  }

  /// Sends `request` (its header is filled in) and returns the reply or why there is none.
  Result<Rep> call(Req request, const CallOptions& opts = {}) {
    const Deadline deadline = Deadline::in(opts.timeout_s);
    const Termination term(deadline, opts.stop);
    const std::string id = client_id_ + "#" + std::to_string(++seq_);
    request.header().request_id(id);
    request.header().client_id(client_id_);
    request.header().cancel(false);
    request.header().attempt(1);
    request.header().budget_s(serverBudget(opts.timeout_s));
    const uint32_t size = writer_.serializedSize(request);
    if (size > max_bytes_) {
      return Error(ErrorCode::kInvalidArgument, "request of " + std::to_string(size) + " bytes exceeds the limit of " +
                                                    std::to_string(max_bytes_) + " bytes of service '" + service_ + "'");
    }
    auto pending = std::make_shared<Pending>();
    {
      std::lock_guard lock(mutex_);
      pending_[id] = pending;
    }
    struct Erase {
      RpcClient* c;
      std::string id;
      ~Erase() {
        std::lock_guard lock(c->mutex_);
        c->pending_.erase(id);
      }
    } erase{this, id};

    bool ever_matched = false;
    int attempts = 0;
    while (!term()) {
      if (!serverPresent()) {
        if (!waitForServer(term)) break;
      }
      ever_matched = true;
      if (attempts < options_.max_attempts) {
        ++attempts;
        request.header().attempt(attempts);
        request.header().budget_s(serverBudget(deadline.secondsLeft()));
        if (Status s = writer_.write(request); !s.ok()) return s.error();
      }
      const Deadline attempt_end = deadline.min(Deadline::in(options_.attempt_timeout_s));
      std::unique_lock lock(pending->m);
      while (!pending->reply && !term.token().stop_requested() && !attempt_end.expired()) {
        pending->cv.wait_until(lock, std::min(attempt_end.time(), Clock::now() + std::chrono::milliseconds(20)));
      }
      if (pending->reply) {
        Rep rep = std::move(*pending->reply);
        const auto& h = rep.header();
        if (h.code() != msg::STATUS_OK) {
          return Error(fromMsg(h.code()), "service '" + service_ + "' (" + h.server_id() + "): " + h.message());
        }
        return rep;
      }
    }
    if (term.token().stop_requested()) {
      request.header().cancel(true);
      (void)writer_.write(request);
      return Error(ErrorCode::kCancelled, "call to '" + service_ + "' cancelled");
    }
    if (!ever_matched) {
      return Error(ErrorCode::kUnavailable, "no server for '" + service_ + "' on DDS domain " +
                                                std::to_string(participant_->domainId()) + " within " +
                                                std::to_string(opts.timeout_s) + " s");
    }
    return Error(ErrorCode::kTimeout, "no reply from '" + service_ + "' within " + std::to_string(opts.timeout_s) +
                                          " s after " + std::to_string(attempts) + " attempt(s)");
  }

 private:
  /// What the server may spend of `left` seconds: the reply margin kept back, never 0 (which the
  /// header reads as "no budget").
  double serverBudget(double left) const {
    const double margin = std::min(std::max(0.0, options_.reply_margin_s), 0.2 * left);
    return std::max(left - margin, 1e-6);
  }

  struct Pending {
    std::mutex m;
    std::condition_variable cv;
    std::optional<Rep> reply;
  };

  void onReply(const Rep& rep, const SampleMeta& meta) {
    // Every client of a service sees every reply; keep ours. (A DDS content filter would do this on
    // the writer side, but Fast DDS 2.9 evaluates it through DynamicData at ~16 us per payload byte.)
    if (!meta.alive || rep.header().client_id() != client_id_) return;
    std::shared_ptr<Pending> p;
    {
      std::lock_guard lock(mutex_);
      auto it = pending_.find(rep.header().request_id());
      if (it == pending_.end()) return;  // late duplicate of an answered request
      p = it->second;
    }
    {
      std::lock_guard lock(p->m);
      if (!p->reply) p->reply = rep;
    }
    p->cv.notify_all();
  }

  std::shared_ptr<Participant> participant_;
  std::string service_;
  RpcClientOptions options_;
  uint32_t max_bytes_;
  std::string client_id_;
  std::string request_topic_, reply_topic_;
  std::mutex mutex_;
  std::unordered_map<std::string, std::shared_ptr<Pending>> pending_;
  std::atomic<uint64_t> seq_{0};
  Writer<Req> writer_;
  Reader<Rep> reader_;  // last: its callback uses the members above
};

template <typename Req, typename Rep>
class RpcServer {
 public:
  using Handler = std::function<Rep(const Req&, const RequestContext&)>;

  RpcServer(std::shared_ptr<Participant> p, const std::string& service, Handler handler,
            const RpcServerOptions& options = {}, uint32_t spec_limit = 16u << 20)
      : service_(service),
        handler_(std::move(handler)),
        options_(options),
        max_bytes_(options.max_request_bytes ? options.max_request_bytes : spec_limit),
        server_id_(detail::hostName() + ":" + std::to_string(::getpid())),
        reply_match_wait_s_(detail::replyMatchWait(options.reply_match_wait_s)),
        writer_(p, TopicSpec<Rep>{reply_topic_.assign(service + "/reply").c_str(), QosClass::kRpc}) {
    require(static_cast<bool>(handler_), "RpcServer for '" + service + "' needs a handler");
    require(options.threads >= 1, "RpcServer threads must be >= 1, got " + std::to_string(options.threads));
    for (int i = 0; i < options.threads; ++i) workers_.emplace_back([this](std::stop_token st) { work(st); });
    reader_ = std::make_unique<Reader<Req>>(
        p, TopicSpec<Req>{request_topic_.assign(service + "/request").c_str(), QosClass::kRpc},
        [this](const Req& req, const SampleMeta& meta) { onRequest(req, meta); },
        ReaderOptions{"", "", {}, /*inline_callbacks=*/true});
  }
  RpcServer(std::shared_ptr<Participant> p, const ServiceSpec<Req, Rep>& spec, Handler handler,
            const RpcServerOptions& options = {})
      : RpcServer(std::move(p), spec.name, std::move(handler), options, spec.max_request_bytes) {}

  ~RpcServer() {
    reader_.reset();  // no new requests
    {
      std::lock_guard lock(mutex_);
      for (auto& [id, st] : states_) st.stop.request_stop();
    }
    for (auto& w : workers_) w.request_stop();
    cv_.notify_all();
    workers_.clear();  // joins
  }

  const std::string& service() const { return service_; }
  uint64_t served() const { return served_.load(); }
  uint64_t failed() const { return failed_.load(); }
  uint64_t rejected() const { return rejected_.load(); }
  int matchedClients() const { return reader_ ? reader_->matchedWriters() : 0; }

 private:
  struct State {
    bool done{false};
    std::stop_source stop;
    std::optional<Rep> reply;
  };
  struct Job {
    Req request;
    Deadline deadline;
    std::stop_token stop;
    std::string client_writer;  ///< GUID of the request's writer: names the client's participant
  };

  void onRequest(const Req& req, const SampleMeta& meta) {
    if (!meta.alive) return;
    const auto& h = req.header();
    if (h.request_id().empty() || h.client_id().empty()) {
      ++rejected_;
      detail::rpcLog()->warn("{}: dropped a request without request_id/client_id (from writer {})", service_,
                             meta.writer_guid);
      return;
    }
    std::unique_lock lock(mutex_);
    auto it = states_.find(h.request_id());
    if (h.cancel()) {
      if (it != states_.end() && !it->second.done) it->second.stop.request_stop();
      return;
    }
    if (it != states_.end()) {
      if (it->second.done && it->second.reply) {
        Rep cached = *it->second.reply;
        lock.unlock();
        (void)writer_.write(cached);  // the client missed our reply: send it again
      }
      return;  // queued or running: the reply will come
    }
    const uint32_t size = typename TypeSupport<Req>::type().getSerializedSizeProvider(const_cast<Req*>(&req))();
    if (size > max_bytes_) {
      ++rejected_;
      lock.unlock();
      Rep rep;
      fillHeader(rep, req, msg::STATUS_INVALID_ARGUMENT,
                 "request of " + std::to_string(size) + " bytes exceeds the limit of " + std::to_string(max_bytes_) +
                     " bytes",
                 0.0);
      (void)writer_.write(rep);
      return;
    }
    State& st = states_[h.request_id()];
    order_.push_back(h.request_id());
    trimCache();
    const Deadline deadline = h.budget_s() > 0 ? Deadline::in(h.budget_s()) : Deadline::never();
    queue_.push_back(Job{req, deadline, st.stop.get_token(), meta.writer_guid});
    lock.unlock();
    cv_.notify_one();
  }

  void work(std::stop_token st) {
    while (!st.stop_requested()) {
      std::unique_lock lock(mutex_);
      cv_.wait(lock, st, [&] { return !queue_.empty(); });
      if (st.stop_requested()) return;
      Job job = std::move(queue_.front());
      queue_.pop_front();
      lock.unlock();

      const auto& h = job.request.header();
      Stopwatch sw;
      Rep rep;
      if (job.deadline.expired()) {
        fillHeader(rep, job.request, msg::STATUS_TIMEOUT, "the request's budget ran out before it was started", 0.0);
      } else if (job.stop.stop_requested()) {
        fillHeader(rep, job.request, msg::STATUS_CANCELLED, "cancelled by the client", 0.0);
      } else {
        RequestContext ctx{h.request_id(), h.client_id(), h.attempt(), Termination(job.deadline, job.stop)};
        try {
          rep = handler_(job.request, ctx);
          fillHeader(rep, job.request, rep.header().code(), rep.header().message(), sw.seconds());
        } catch (const std::exception& e) {
          rep = Rep();
          fillHeader(rep, job.request, msg::STATUS_INTERNAL, std::string("handler failed: ") + e.what(), sw.seconds());
        } catch (...) {
          rep = Rep();
          fillHeader(rep, job.request, msg::STATUS_INTERNAL, "handler failed with an unknown exception", sw.seconds());
        }
      }
      if (rep.header().code() == msg::STATUS_OK) {
        ++served_;
      } else {
        ++failed_;
      }
      {
        std::lock_guard g(mutex_);
        auto it = states_.find(h.request_id());
        if (it != states_.end()) {
          it->second.done = true;
          it->second.reply = rep;
        }
      }
      awaitClient(job, st);
      if (Status s = writer_.write(rep); !s.ok()) {
        detail::rpcLog()->error("{}: cannot send reply {}: {}", service_, h.request_id(), s.error().toString());
      }
    }
  }

  /// Before a reply: waits (bounded) until the reply writer is matched with the client's
  /// participant, so that the reply is not written to no one (RpcServerOptions::reply_match_wait_s).
  void awaitClient(const Job& job, const std::stop_token& st) {
    if (job.client_writer.empty() || writer_.matchesParticipantOf(job.client_writer)) return;
    if (reply_match_wait_s_ <= 0.0) {
      detail::rpcLog()->warn("{}: reply {} written while the client's reply reader is not matched (no wait)", service_,
                             job.request.header().request_id());
      return;
    }
    Stopwatch waited;
    const bool matched = writer_.waitForParticipantOf(
        job.client_writer, Termination(job.deadline.min(Deadline::in(reply_match_wait_s_)), st));
    const auto& h = job.request.header();
    if (matched) {
      detail::rpcLog()->info("{}: reply {} waited {:.3f} s for the client's reply reader to match", service_,
                             h.request_id(), waited.seconds());
    } else {
      detail::rpcLog()->warn("{}: reply {}: the client's reply reader not matched within {:.3f} s; sent anyway (a "
                             "retry of the request is answered from the reply cache)",
                             service_, h.request_id(), waited.seconds());
    }
  }

  void fillHeader(Rep& rep, const Req& req, msg::StatusCode code, const std::string& message, double seconds) {
    auto& out = rep.header();
    out.request_id(req.header().request_id());
    out.client_id(req.header().client_id());
    out.server_id(server_id_);
    out.code(code);
    out.message(message);
    out.service_time_s(seconds);
  }

  void trimCache() {  // caller holds mutex_
    while (order_.size() > options_.reply_cache_size) {
      auto it = states_.find(order_.front());
      if (it != states_.end() && !it->second.done) break;  // never forget work in flight
      if (it != states_.end()) states_.erase(it);
      order_.pop_front();
    }
  }

  std::string service_;
  Handler handler_;
  RpcServerOptions options_;
  uint32_t max_bytes_;
  std::string server_id_;
  double reply_match_wait_s_;
  std::string request_topic_, reply_topic_;
  std::mutex mutex_;
  std::condition_variable_any cv_;
  std::deque<Job> queue_;
  std::unordered_map<std::string, State> states_;
  std::deque<std::string> order_;
  std::atomic<uint64_t> served_{0}, failed_{0}, rejected_{0};
  Writer<Rep> writer_;
  std::vector<std::jthread> workers_;
  std::unique_ptr<Reader<Req>> reader_;  // last: its callback uses the members above
};

}  // namespace tamp::dds
