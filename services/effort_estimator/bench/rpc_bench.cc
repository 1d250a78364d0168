// Estimate latency through the DDS service: this client and a tamp_effort_estimator_service it
// starts (in-memory store, prior models), one process each. For each participant profile and
// batch size (1 and 100 queries of mixed kinds) it measures N calls after a warm-up and prints
// p50/p99/mean round-trip times in microseconds as a Markdown table (docs/benchmarks.md), with the
// server's own handler time (ReplyHeader::service_time_s) to separate the estimates from the
// transport.
//
//   tamp_effort_estimator_rpc_bench [--n 2000] [--domain D]
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <numeric>
#include <random>
#include <string>
#include <thread>

#include "effort_estimator_node.h"
#include "synthetic.h"
#include "tamp/core/stats.h"
#include "tamp/process/supervisor.h"

using namespace tamp;  // NOLINT(google-build-using-namespace): a small benchmark tool

namespace {

struct Row {
  std::string profile;
  size_t batch;
  int n;
  double p50, p99, mean, server_mean;
};


}  // namespace

int main(int argc, char** argv) {
  int n = 2000, domain = 100 + static_cast<int>(::getpid() % 50);
  for (int i = 1; i + 1 < argc; i += 2) {
    if (!std::strcmp(argv[i], "--n"))
      n = std::atoi(argv[i + 1]);
    else if (!std::strcmp(argv[i], "--domain"))
      domain = std::atoi(argv[i + 1]);
  }
  tamp::log::setLevel("warn");
  const auto config = std::filesystem::temp_directory_path() /
                      ("effort_rpc_bench_" + std::to_string(::getpid()) + ".yaml");
  std::ofstream(config) << "store_directory: \"\"\n";

  std::mt19937_64 rng(1);
  std::vector<msg::EffortQuery> mixed;
  for (int i = 0; i < 100; ++i) {
    const ActionKind k = kAllActionKinds[static_cast<size_t>(i) % kAllActionKinds.size()];
    mixed.push_back(effort_estimator::toMsg(effort_estimator::synthetic::randomAction(k, rng)));
  }

  std::vector<Row> rows;
  for (const std::string profile : {"tamp_shm", "tamp_default"}) {
    process::Supervisor sup;
    process::ProcessSpec spec;
    spec.name = "bench_effort";
    spec.executable = std::string(TAMP_BIN_DIR) + "/tamp_effort_estimator_service";
    spec.args = {"--name", "bench_effort", "--domain",      std::to_string(domain), "--profile",
                 profile,  "--config",     config.string(), "--log-level",          "warn"};
    spec.restart = false;
    sup.add(spec);
    if (auto s = sup.startAll(); !s.ok()) {
      std::fprintf(stderr, "%s\n", s.error().toString().c_str());
      return 1;
    }
    auto p = dds::Participant::create(dds::ParticipantOptions{domain, profile, "bench", {}});
    if (!p) {
      std::fprintf(stderr, "%s\n", p.error().toString().c_str());
      return 1;
    }
    dds::RpcClient<msg::EffortRequest, msg::EffortReply> client(*p, dds::services::kEffort,
                                                                dds::RpcClientOptions{5.0, 3, 0});
    if (!client.waitForServer(Termination::after(20.0))) {
      std::fprintf(stderr, "effort estimator service did not appear\n");
      return 1;
    }
    for (size_t batch : {size_t{1}, size_t{100}}) {
      msg::EffortRequest req;
      req.queries(
          std::vector<msg::EffortQuery>(mixed.begin(), mixed.begin() + static_cast<long>(batch)));
      std::vector<double> us, server_us;
      const int warmup = n / 10 + 10;
      for (int i = 0; i < n + warmup; ++i) {
        Stopwatch sw;
        auto rep = client.call(req, dds::CallOptions{10.0, {}});
        const double t = sw.seconds() * 1e6;
        if (!rep || rep->estimates().size() != batch ||
            rep->estimates()[0].code() != msg::STATUS_OK) {
          std::fprintf(stderr, "%s batch %zu: call failed: %s\n", profile.c_str(), batch,
                       rep ? "bad reply" : rep.error().toString().c_str());
          return 1;
        }
        if (i >= warmup) {
          us.push_back(t);
          server_us.push_back(rep->header().service_time_s() * 1e6);
        }
      }
      auto mean = [](const std::vector<double>& v) {
        return std::accumulate(v.begin(), v.end(), 0.0) / static_cast<double>(v.size());
      };
      rows.push_back(Row{profile, batch, n, nearestRankPercentile(us, 0.5), nearestRankPercentile(us, 0.99), mean(us),
                         mean(server_us)});
      std::fprintf(stderr, "%-12s batch %3zu  n=%d  p50 %.0f us  p99 %.0f us  server %.1f us\n",
                   profile.c_str(), batch, n, rows.back().p50, rows.back().p99,
                   rows.back().server_mean);
    }
    sup.stopAll(3.0);
  }
  std::filesystem::remove(config);
  std::printf("Build: %s, %u cores.\n\n",
#ifdef NDEBUG
              "Release",
#else
              "Debug",
#endif
              std::thread::hardware_concurrency());
  std::printf(
      "| profile | queries per request | calls | p50 (us) | p99 (us) | mean (us) | server handler "
      "mean (us) |\n");
  std::printf("|---|---|---|---|---|---|---|\n");
  for (const auto& r : rows) {
    std::printf("| %s | %zu | %d | %.0f | %.0f | %.0f | %.1f |\n", r.profile.c_str(), r.batch, r.n,
                r.p50, r.p99, r.mean, r.server_mean);
  }
  return 0;
}
