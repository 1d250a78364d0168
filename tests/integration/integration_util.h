#pragma once
// Helpers for multi-process tests: isolated domains, service processes, waiting.
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <iostream>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>

#include "../../common/dds/tests/test_util.h"
#include "tamp/core/termination.h"
#include "tamp/process/supervisor.h"

namespace tamp::integration {

inline std::filesystem::path binDir() { return TAMP_BIN_DIR; }
using dds::testing::isolatedDomain;

/// The scratch files and folders of the running test: removed when it passes, kept (and named
/// on stderr) when it fails, so that repeated runs do not fill the temp directory.
class Scratch : public ::testing::EmptyTestEventListener {
 public:
  static void add(const std::filesystem::path& p) {
    static Scratch* const self = [] {
      auto* s = new Scratch;  // owned by gtest's listener list
      ::testing::UnitTest::GetInstance()->listeners().Append(s);
      return s;
    }();
    self->paths_.push_back(p);
  }

  void OnTestEnd(const ::testing::TestInfo& info) override {
    const bool passed = info.result() != nullptr && info.result()->Passed();
    for (const auto& p : paths_) {
      std::error_code ec;
      if (!std::filesystem::exists(p, ec)) continue;
      if (passed) {
        std::filesystem::remove_all(p, ec);
      } else {
        std::cerr << "kept for diagnosis: " << p.string() << "\n";
      }
    }
    paths_.clear();
  }

 private:
  std::vector<std::filesystem::path> paths_;
};

/// A path in the temp directory for this process (`stem`_pid`suffix`), scratch of the running test.
inline std::filesystem::path tempFile(const std::string& stem, const std::string& suffix = "") {
  auto p = std::filesystem::temp_directory_path() / (stem + "_" + std::to_string(::getpid()) + suffix);
  Scratch::add(p);
  return p;
}

/// A service process on `domain` (stdout/stderr into a temp log, shown when a test fails).
inline process::ProcessSpec serviceSpec(const std::string& exe, const std::string& name, int domain,
                                        std::vector<std::string> extra = {}) {
  process::ProcessSpec s;
  s.name = name;
  s.executable = binDir() / exe;
  s.args = {"--name", name, "--domain", std::to_string(domain), "--heartbeat-period", "0.2"};
  s.args.insert(s.args.end(), extra.begin(), extra.end());
  s.log_file = tempFile("tamp_it_" + name + ".log");
  s.restart = false;
  return s;
}

inline std::string readFile(const std::filesystem::path& p) {
  std::ifstream in(p);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

/// Runs a command to completion, returns (exit code, stdout+stderr).
inline std::pair<int, std::string> runCommand(const std::filesystem::path& exe, const std::vector<std::string>& args,
                                              double timeout_s = 30.0) {
  process::ProcessSpec s;
  s.name = exe.filename().string();
  s.executable = exe;
  s.args = args;
  s.log_file = tempFile("tamp_it_cmd_" + s.name + ".out");
  std::filesystem::remove(s.log_file);
  s.restart = false;
  process::Supervisor sup;
  sup.add(s);
  if (!sup.startAll().ok()) return {-1, "cannot start " + exe.string()};
  const Deadline d = Deadline::in(timeout_s);
  while (!d.expired()) {
    sup.poll();
    if (sup.status(s.name)->phase == process::ProcessPhase::kExited) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  sup.stopAll(1.0);
  return {sup.status(s.name)->last_exit_code, readFile(s.log_file)};
}

}  // namespace tamp::integration
