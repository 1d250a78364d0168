#include "tamp/dds/rpc.h"

#include <unistd.h>

#include <atomic>

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

}  // namespace tamp::dds::detail
