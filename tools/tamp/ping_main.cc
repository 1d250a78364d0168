// `tamp ping SERVICE`: round trips to a service's echo endpoint (every node has one).
#include <algorithm>
#include <cstdio>
#include <iostream>

#include <CLI/CLI.hpp>

#include "cli_common.h"
#include "tamp/dds/service_node.h"

int main(int argc, char** argv) {
  CLI::App app{"Measure request/reply round trips to a TAMP service's echo endpoint", "tamp ping"};
  std::string service;
  int domain = -1, count = 10;
  std::string profile, security;
  size_t size = 64;
  double timeout = 5.0;
  app.add_option("service", service, "service name, e.g. symbolic_planner")->required();
  app.add_option("--domain", domain, "DDS domain id (default: $TAMP_DOMAIN_ID or 0)")->check(CLI::Range(0, 232));
  app.add_option("--profile", profile, "DDS participant profile");
  std::string run_id;
  app.add_option("--run-id", run_id, "run the service belongs to (default: $TAMP_RUN_ID or none)");
  app.add_option("-c,--count", count, "number of round trips")->check(CLI::Range(1, 1000000));
  app.add_option("-s,--size", size, "payload bytes")->check(CLI::Range(0, 16 << 20));
  app.add_option("--timeout", timeout, "seconds per call")->check(CLI::Range(0.01, 3600.0));
  app.add_option("--security", security, "DDS Security directory (deploy/security/make_certs.sh; default: $TAMP_DDS_SECURITY)");
  CLI11_PARSE(app, argc, argv);

  tamp::dds::ParticipantOptions po;
  po.domain_id = domain;
  po.name = "tamp/ping";
  if (!profile.empty()) po.profile = profile;
  po.security_dir = security;
  auto participant = tamp::dds::Participant::create(po, run_id);
  if (!participant) {
    std::cerr << "tamp ping: " << participant.error().toString() << "\n";
    return tamp::cli::kExitServiceError;
  }
  tamp::dds::RpcClient<tamp::msg::EchoRequest, tamp::msg::EchoReply> client(*participant,
                                                                             tamp::dds::echoService(service));
  std::vector<double> rtt_us;
  for (int i = 0; i < count; ++i) {
    tamp::msg::EchoRequest req;
    req.payload(std::vector<uint8_t>(size, static_cast<uint8_t>(i)));
    tamp::Stopwatch sw;
    auto rep = client.call(req, tamp::dds::CallOptions{timeout, {}});
    if (!rep) {
      std::cerr << "tamp ping: " << rep.error().toString() << "\n";
      return rep.error().code == tamp::ErrorCode::kTimeout ? tamp::cli::kExitTimeout : tamp::cli::kExitServiceError;
    }
    rtt_us.push_back(sw.seconds() * 1e6);
    std::printf("reply from %s (pid %u): seq=%d bytes=%zu time=%.0f us\n", rep->header().server_id().c_str(),
                rep->pid(), i + 1, rep->payload().size(), rtt_us.back());
  }
  std::sort(rtt_us.begin(), rtt_us.end());
  std::printf("--- %s: %d round trips, min %.0f us, median %.0f us, max %.0f us\n", service.c_str(), count,
              rtt_us.front(), rtt_us[rtt_us.size() / 2], rtt_us.back());
  return tamp::cli::kExitOk;
}
