// Request/reply round trip between two processes: this client and a tamp_echo_node it starts.
// For each participant profile (shared memory only, UDPv4 only, default) and payload size (64 B,
// 1 MiB) it measures N calls after a warm-up and prints p50/p99/mean in microseconds as a
// Markdown table (for docs/benchmarks.md).
//
//   tamp_rpc_bench [--small-n 2000] [--large-n 200] [--domain D] [--security DIR]
//
// --security DIR (deploy/security/make_certs.sh): both processes secured (the echo node as
// "diagnostics", this client as "tamp"), for the cost of DDS Security.
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <numeric>
#include <string>
#include <thread>

#include <sys/utsname.h>

#include "tamp/core/stats.h"
#include "tamp/dds/service_node.h"
#include "tamp/process/supervisor.h"

namespace {

struct Row {
  std::string profile;
  size_t bytes;
  int n;
  double p50, p99, mean, max;
};


std::string cpuModel() {
  std::ifstream in("/proc/cpuinfo");
  std::string line;
  while (std::getline(in, line)) {
    if (line.rfind("model name", 0) == 0) return line.substr(line.find(':') + 2);
  }
  return "unknown";
}

}  // namespace

int main(int argc, char** argv) {
  int small_n = 2000, large_n = 200, domain = 150 + static_cast<int>(::getpid() % 50);
  std::string security = "none";
  for (int i = 1; i + 1 < argc; i += 2) {
    if (!std::strcmp(argv[i], "--small-n")) small_n = std::atoi(argv[i + 1]);
    else if (!std::strcmp(argv[i], "--large-n")) large_n = std::atoi(argv[i + 1]);
    else if (!std::strcmp(argv[i], "--domain")) domain = std::atoi(argv[i + 1]);
    else if (!std::strcmp(argv[i], "--security")) security = argv[i + 1];
  }
  tamp::log::setLevel("warn");
  std::vector<Row> rows;
  for (const std::string profile : {"tamp_shm", "tamp_udp", "tamp_default"}) {
    tamp::process::Supervisor sup;
    tamp::process::ProcessSpec spec;
    // Secured, the echo node needs a name the access table grants an identity to.
    const std::string echo_name = security == "none" ? "bench_echo" : "diagnostics";
    spec.name = echo_name;
    spec.executable = std::string(TAMP_BIN_DIR) + "/tamp_echo_node";
    spec.args = {"--name", echo_name, "--domain", std::to_string(domain), "--profile", profile, "--log-level",
                 "warn", "--security", security};
    spec.restart = false;
    sup.add(spec);
    if (auto s = sup.startAll(); !s.ok()) {
      std::fprintf(stderr, "%s\n", s.error().toString().c_str());
      return 1;
    }
    tamp::dds::ParticipantOptions po{domain, profile, "bench", {}};
    po.security_dir = security;
    auto p = tamp::dds::Participant::create(po);
    if (!p) {
      std::fprintf(stderr, "%s\n", p.error().toString().c_str());
      return 1;
    }
    tamp::dds::RpcClient<tamp::msg::EchoRequest, tamp::msg::EchoReply> client(
        *p, tamp::dds::echoService(echo_name), tamp::dds::RpcClientOptions{5.0, 3, 64u << 20});
    if (!client.waitForServer(tamp::Termination::after(20.0))) {
      std::fprintf(stderr, "echo node did not appear\n");
      return 1;
    }
    for (size_t bytes : {size_t{64}, size_t{1} << 20}) {
      const int n = bytes > 1000 ? large_n : small_n;
      tamp::msg::EchoRequest req;
      req.payload(std::vector<uint8_t>(bytes, 0xab));
      std::vector<double> us;
      for (int i = 0; i < n + n / 10 + 10; ++i) {
        tamp::Stopwatch sw;
        auto rep = client.call(req, tamp::dds::CallOptions{10.0, {}});
        const double t = sw.seconds() * 1e6;
        if (!rep || rep->payload().size() != bytes) {
          std::fprintf(stderr, "%s %zu B: call failed: %s\n", profile.c_str(), bytes,
                       rep ? "wrong payload" : rep.error().toString().c_str());
          return 1;
        }
        if (i >= n / 10 + 10) us.push_back(t);  // after warm-up
      }
      rows.push_back(Row{profile, bytes, n, tamp::nearestRankPercentile(us, 0.5), tamp::nearestRankPercentile(us, 0.99),
                         std::accumulate(us.begin(), us.end(), 0.0) / static_cast<double>(us.size()),
                         *std::max_element(us.begin(), us.end())});
      std::fprintf(stderr, "%-12s %8zu B  n=%d  p50 %.0f us  p99 %.0f us\n", profile.c_str(), bytes, n, rows.back().p50,
                   rows.back().p99);
    }
    sup.stopAll(3.0);
  }
  utsname u{};
  uname(&u);
  std::printf("DDS Security: %s.\n", security == "none" ? "off" : "on (PKI-DH, Access-Permissions, AES-GCM-GMAC)");
  std::printf("Machine: %s, %u cores (%s %s). Build: %s.\n\n", cpuModel().c_str(), std::thread::hardware_concurrency(),
              u.sysname, u.release,
#ifdef NDEBUG
              "Release"
#else
              "Debug"
#endif
  );
  std::printf("| profile | payload | calls | p50 (us) | p99 (us) | mean (us) | max (us) |\n");
  std::printf("|---|---|---|---|---|---|---|\n");
  for (const auto& r : rows) {
    std::printf("| %s | %s | %d | %.0f | %.0f | %.0f | %.0f |\n", r.profile.c_str(),
                r.bytes > 1000 ? "1 MiB" : "64 B", r.n, r.p50, r.p99, r.mean, r.max);
  }
  return 0;
}
