#include "tamp/dds/rpc.h"

#include <unistd.h>

#include <atomic>
#include <cmath>
#include <cstdlib>

namespace tamp::dds::detail {

std::string hostName() {
  char buf[256] = {0};
  if (gethostname(buf, sizeof(buf) - 1) != 0) return "unknown";
  return buf;
}

std::string newClientId() {
  static std::atomic<uint64_t> n{0};
  return hostName() + ":" + std::to_string(::getpid()) + ":" + std::to_string(++n);
}

std::shared_ptr<spdlog::logger> rpcLog() { return log::get("rpc"); }

double replyMatchWait(double configured) {
  const char* env = std::getenv("TAMP_RPC_REPLY_MATCH_WAIT_S");
  if (env == nullptr || *env == '\0') return configured;
  char* end = nullptr;
  const double v = std::strtod(env, &end);
  if (*end != '\0' || !std::isfinite(v) || v < 0.0) {
    rpcLog()->warn("TAMP_RPC_REPLY_MATCH_WAIT_S must be a number of seconds >= 0, got '{}': using {} s", env,
                   configured);
    return configured;
  }
  return v;
}

}  // namespace tamp::dds::detail
