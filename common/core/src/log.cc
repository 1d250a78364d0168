#include "tamp/core/log.h"

#include <cstdlib>
#include <mutex>
#include <stdexcept>

#include <spdlog/sinks/stdout_color_sinks.h>

namespace tamp::log {
namespace {

std::mutex& mutex() {
  static std::mutex m;
  return m;
}

spdlog::level::level_enum& currentLevel() {
  static spdlog::level::level_enum level = [] {
    const char* env = std::getenv("TAMP_LOG_LEVEL");
    if (env == nullptr) return spdlog::level::info;
    auto l = spdlog::level::from_str(env);
    // from_str maps unknown names to "off"; only accept "off" when it was asked for.
    if (l == spdlog::level::off && std::string(env) != "off") return spdlog::level::info;
    return l;
  }();
  return level;
}

}  // namespace

std::shared_ptr<spdlog::logger> get(const std::string& component) {
  std::lock_guard lock(mutex());
  if (auto existing = spdlog::get(component)) return existing;
  auto logger = spdlog::stderr_color_mt(component);
  logger->set_pattern("[%H:%M:%S.%e] [%n] [%^%l%$] %v");
  logger->set_level(currentLevel());
  return logger;
}

void setLevel(const std::string& level) {
  auto l = spdlog::level::from_str(level);
  if (l == spdlog::level::off && level != "off") {
    throw std::invalid_argument("unknown log level '" + level +
                                "' (expected trace, debug, info, warn, error, critical or off)");
  }
  std::lock_guard lock(mutex());
  currentLevel() = l;
  spdlog::set_level(l);
}

}  // namespace tamp::log
