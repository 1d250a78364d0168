// tamp_echo_node: the bare service skeleton (heartbeat + echo endpoint, nothing else). Used by the
// multi-process tests, the round-trip benchmark, and to check a deployment's DDS connectivity.
//
// For the supervision tests, $TAMP_ECHO_HANG_FILE names a file while whose existence the node's
// main loop hangs (a service stuck in its work while its heartbeat thread runs on), and
// $TAMP_ECHO_NOT_READY_FILE one while whose existence it is alive but not ready (an input that
// never arrives).
#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <thread>

#include "tamp/dds/service_node.h"

namespace {
class EchoNode : public tamp::dds::ServiceNode {
 public:
  explicit EchoNode(const tamp::dds::ServiceArgs& args) : ServiceNode(args) {
    if (const char* f = std::getenv("TAMP_ECHO_HANG_FILE"); f != nullptr) hang_file_ = f;
    if (const char* f = std::getenv("TAMP_ECHO_NOT_READY_FILE"); f != nullptr) not_ready_file_ = f;
  }
  std::string notReadyBecause() const override {
    std::error_code ec;
    if (not_ready_file_.empty() || !std::filesystem::exists(not_ready_file_, ec)) return {};
    return "no test input while " + not_ready_file_.string() + " exists";
  }

 protected:
  void spinOnce() override {
    std::error_code ec;
    while (!hang_file_.empty() && std::filesystem::exists(hang_file_, ec))
      std::this_thread::sleep_for(std::chrono::milliseconds(50));  // the hang itself
  }

 private:
  std::filesystem::path hang_file_;
  std::filesystem::path not_ready_file_;
};
}  // namespace

int main(int argc, char** argv) {
  return tamp::dds::serviceMain(argc, argv, "echo", "TAMP echo node (service skeleton)",
                                [](const tamp::dds::ServiceArgs& a) -> tamp::Result<std::unique_ptr<tamp::dds::ServiceNode>> {
                                  return std::unique_ptr<tamp::dds::ServiceNode>(std::make_unique<EchoNode>(a));
                                });
}
