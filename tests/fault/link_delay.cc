// tamp_link_delay: a one-way delay on a link without tc netem (issue 13, part 4). The CI VM's
// kernel has no sch_netem, but it has nfnetlink_queue: an nftables rule (`queue num N`, set up by
// tests/fault/two_hosts.sh) hands every packet a network namespace sends on the link to queue N;
// this program holds each one and gives it the NF_ACCEPT verdict DELAY ms (plus a uniform jitter in
// [-JITTER, +JITTER] ms) after it arrived. The kernel keeps a queued packet until its verdict, so a
// late verdict is a delay; the packets leave in the order they came (a jittered release never
// overtakes the one before it, as netem with a rate). Run one per namespace and direction.
//
//   tamp_link_delay --queue N --delay-ms D [--jitter-ms J] [--seed S] [--max-held P]
//
// Prints "ready" once bound (add the nftables rule after that: a queue nobody listens to drops),
// and on SIGTERM/SIGINT releases what it holds and prints one line of counters:
//   tamp_link_delay: queue N delay D ms jitter J ms: delayed P packets, max held H, late L,
//   socket overruns O
// (late: released more than 5 ms after its due time; overruns: the netlink socket's buffer was
// full, so some queued packets' messages were lost: those are dropped when the queue is unbound).
// The queue is not fail-open: a packet the kernel cannot queue is dropped and counted by the kernel
// in /proc/net/netfilter/nfnetlink_queue (queue_dropped, user_dropped), which two_hosts.sh reports
// beside these counters.
//
// Exit codes: 0 stopped by a signal, 30 bad arguments, 31 no nfnetlink_queue or no permission
// (CAP_NET_ADMIN), 32 the netlink socket failed while running.
// <arpa/inet.h> (glibc's netinet/in.h) before <linux/netfilter.h>, which otherwise pulls in
// linux/in.h and the two redefine struct in_addr.
#include <arpa/inet.h>  // ntohl
#include <libnetfilter_queue/libnetfilter_queue.h>
#include <linux/netfilter.h>  // NF_ACCEPT
#include <poll.h>
#include <time.h>
#include <sys/socket.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <csignal>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <deque>
#include <filesystem>
#include <optional>
#include <random>
#include <stdexcept>
#include <string>
#include <string_view>

namespace {

using Clock = std::chrono::steady_clock;
using Ms = std::chrono::duration<double, std::milli>;

constexpr int kExitArgs = 30;
constexpr int kExitUnsupported = 31;
constexpr int kExitSocket = 32;
constexpr double kLateMs = 5.0;  // a release this much after its due time counts as late

struct Options {
  int queue{0};           // nfqueue number, 0..65535
  double delay_ms{0.0};   // must be >= 0
  double jitter_ms{0.0};  // must be >= 0 and <= delay_ms
  unsigned seed{1};
  std::uint32_t queue_maxlen{65536};  // kernel queue length; beyond it the kernel drops
};

struct Held {
  std::uint32_t id;
  Clock::time_point due;
};

struct Delayer {
  Options opt;
  std::mt19937 rng;
  std::deque<Held> held;  // due times never decrease
  std::uint64_t delayed{0};
  std::uint64_t late{0};
  std::size_t peak_held{0};
  std::uint64_t overruns{0};  // ENOBUFS: queued packets whose message was lost (held until exit)
  nfq_q_handle* queue{nullptr};
};

volatile std::sig_atomic_t g_stop = 0;

void onSignal(int) { g_stop = 1; }

[[noreturn]] void fail(int code, const std::string& message) {
  std::fprintf(stderr, "tamp_link_delay: %s\n", message.c_str());
  std::exit(code);
}

double parseNumber(std::string_view flag, const char* text) {
  try {
    std::size_t used = 0;
    const double v = std::stod(text, &used);
    if (used == std::strlen(text)) return v;
  } catch (const std::exception&) {
  }
  fail(kExitArgs, std::string(flag) + " takes a number, got '" + text + "'");
}

Options parseOptions(int argc, char** argv) {
  Options o;
  bool have_delay = false;
  for (int i = 1; i < argc; ++i) {
    const std::string_view flag = argv[i];
    if (i + 1 >= argc) fail(kExitArgs, "missing value after " + std::string(flag));
    const double v = parseNumber(flag, argv[++i]);
    if (flag == "--queue") {
      o.queue = static_cast<int>(v);
    } else if (flag == "--delay-ms") {
      o.delay_ms = v;
      have_delay = true;
    } else if (flag == "--jitter-ms") {
      o.jitter_ms = v;
    } else if (flag == "--seed") {
      o.seed = static_cast<unsigned>(v);
    } else if (flag == "--max-held") {
      o.queue_maxlen = static_cast<std::uint32_t>(v);
    } else {
      fail(kExitArgs, "unknown option " + std::string(flag) +
                          " (usage: --queue N --delay-ms D [--jitter-ms J] [--seed S] "
                          "[--max-held P])");
    }
  }
  if (!have_delay) fail(kExitArgs, "--delay-ms is required");
  if (o.queue < 0 || o.queue > 65535) fail(kExitArgs, "--queue must be 0..65535");
  if (o.delay_ms < 0.0) fail(kExitArgs, "--delay-ms must be >= 0");
  if (o.jitter_ms < 0.0 || o.jitter_ms > o.delay_ms)
    fail(kExitArgs, "--jitter-ms must be between 0 and --delay-ms");
  if (o.queue_maxlen == 0) fail(kExitArgs, "--max-held must be positive");
  return o;
}

/// When a packet that arrived now leaves: DELAY +- JITTER, never before the one queued before it.
Clock::time_point dueTime(Delayer& d) {
  std::uniform_real_distribution<double> jitter(-d.opt.jitter_ms, d.opt.jitter_ms);
  const double ms = d.opt.delay_ms + (d.opt.jitter_ms > 0.0 ? jitter(d.rng) : 0.0);
  auto due = Clock::now() + std::chrono::duration_cast<Clock::duration>(Ms(ms));
  if (!d.held.empty()) due = std::max(due, d.held.back().due);
  return due;
}

/// libnetfilter_queue's callback: hold the packet, no verdict yet.
int onPacket(nfq_q_handle*, nfgenmsg*, nfq_data* packet, void* data) {
  auto& d = *static_cast<Delayer*>(data);
  const nfqnl_msg_packet_hdr* header = nfq_get_msg_packet_hdr(packet);
  if (header == nullptr) return 0;
  d.held.push_back({ntohl(header->packet_id), dueTime(d)});
  d.peak_held = std::max(d.peak_held, d.held.size());
  return 0;
}

void accept(Delayer& d, const Held& h) {
  if (nfq_set_verdict(d.queue, h.id, NF_ACCEPT, 0, nullptr) < 0)
    fail(kExitSocket, "verdict for packet " + std::to_string(h.id) + " failed: " + strerror(errno));
  ++d.delayed;
}

/// Accepts every held packet that is due (all of them when `all`).
void releaseDue(Delayer& d, bool all) {
  const auto now = Clock::now();
  while (!d.held.empty() && (all || d.held.front().due <= now)) {
    if (!all && Ms(now - d.held.front().due).count() > kLateMs) ++d.late;
    accept(d, d.held.front());
    d.held.pop_front();
  }
}

/// ppoll() timeout until the next packet is due, to the nanosecond (poll()'s whole milliseconds,
/// rounded up, released packets up to 1 ms late); none while nothing is held.
std::optional<timespec> untilNextDue(const Delayer& d) {
  if (d.held.empty()) return std::nullopt;
  const auto ns = std::chrono::duration_cast<std::chrono::nanoseconds>(d.held.front().due - Clock::now()).count();
  if (ns <= 0) return timespec{0, 0};
  return timespec{static_cast<time_t>(ns / 1000000000), static_cast<long>(ns % 1000000000)};
}

nfq_handle* openNetlink() {
  if (!std::filesystem::exists("/proc/net/netfilter/nfnetlink_queue"))
    fail(kExitUnsupported,
         "this kernel has no nfnetlink_queue (/proc/net/netfilter/nfnetlink_queue is missing; "
         "modprobe nfnetlink_queue or CONFIG_NETFILTER_NETLINK_QUEUE)");
  nfq_handle* h = nfq_open();
  if (h == nullptr)
    fail(kExitUnsupported, std::string("cannot open an nfnetlink socket: ") + strerror(errno));
  if (nfq_bind_pf(h, AF_INET) < 0) {
    const int e = errno;
    fail(kExitUnsupported, std::string("cannot bind to IPv4 queues: ") + strerror(e) +
                               (e == EPERM ? " (needs root or CAP_NET_ADMIN)" : ""));
  }
  // Bursts of DDS datagrams: a large socket buffer, so no queued packet's message is lost (a lost
  // message leaves its packet held in the kernel without an id to release it by).
  nfnl_rcvbufsiz(nfq_nfnlh(h), 16 << 20);
  return h;
}

void bindQueue(nfq_handle* h, Delayer& d) {
  d.queue = nfq_create_queue(h, static_cast<std::uint16_t>(d.opt.queue), &onPacket, &d);
  if (d.queue == nullptr)
    fail(kExitUnsupported, "cannot bind queue " + std::to_string(d.opt.queue) + ": " +
                               strerror(errno) + " (another program on it, or no permission)");
  if (nfq_set_mode(d.queue, NFQNL_COPY_META, 0) < 0)
    fail(kExitUnsupported, std::string("cannot set the copy mode: ") + strerror(errno));
  if (nfq_set_queue_maxlen(d.queue, d.opt.queue_maxlen) < 0)
    fail(kExitUnsupported, std::string("cannot set the queue length: ") + strerror(errno));
  // Not fail-open: a full queue drops (counted by the kernel), it never lets a packet skip the
  // delay unseen.
  if (nfq_set_queue_flags(d.queue, NFQA_CFG_F_FAIL_OPEN, 0) < 0)
    fail(kExitUnsupported, std::string("cannot clear fail-open: ") + strerror(errno));
}

/// Reads what the socket has and hands it to libnetfilter_queue (which calls onPacket).
void readPackets(nfq_handle* h, Delayer& d) {
  alignas(8) static char buf[1 << 16];
  for (;;) {
    const ssize_t n = recv(nfq_fd(h), buf, sizeof buf, MSG_DONTWAIT);
    if (n > 0) {
      nfq_handle_packet(h, buf, static_cast<int>(n));
      continue;
    }
    if (n < 0 && (errno == EAGAIN || errno == EINTR)) return;
    if (n < 0 && errno == ENOBUFS) {
      ++d.overruns;
      continue;
    }
    fail(kExitSocket, std::string("netlink socket: ") + (n == 0 ? "closed" : strerror(errno)));
  }
}

void run(nfq_handle* h, Delayer& d) {
  pollfd p{nfq_fd(h), POLLIN, 0};
  while (!g_stop) {
    const std::optional<timespec> timeout = untilNextDue(d);
    const int r = ppoll(&p, 1, timeout ? &*timeout : nullptr, nullptr);
    if (r < 0 && errno != EINTR) fail(kExitSocket, std::string("ppoll: ") + strerror(errno));
    if (r > 0) readPackets(h, d);
    releaseDue(d, false);
  }
  releaseDue(d, true);
}

}  // namespace

int main(int argc, char** argv) {
  Delayer d;
  d.opt = parseOptions(argc, argv);
  d.rng.seed(d.opt.seed);
  std::signal(SIGTERM, onSignal);
  std::signal(SIGINT, onSignal);
  nfq_handle* h = openNetlink();
  bindQueue(h, d);
  std::printf("ready\n");
  std::fflush(stdout);
  run(h, d);
  nfq_destroy_queue(d.queue);
  nfq_close(h);
  std::printf(
      "tamp_link_delay: queue %d delay %g ms jitter %g ms: delayed %llu packets, max held "
      "%zu, late %llu, socket overruns %llu\n",
      d.opt.queue, d.opt.delay_ms, d.opt.jitter_ms, static_cast<unsigned long long>(d.delayed),
      d.peak_held, static_cast<unsigned long long>(d.late),
      static_cast<unsigned long long>(d.overruns));
  return 0;
}
