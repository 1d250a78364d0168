// tamp_echo_node: the bare service skeleton (heartbeat + echo endpoint, nothing else). Used by the
// multi-process tests, the round-trip benchmark, and to check a deployment's DDS connectivity.
#include "tamp/dds/service_node.h"

namespace {
class EchoNode : public tamp::dds::ServiceNode {
 public:
  explicit EchoNode(const tamp::dds::ServiceArgs& args) : ServiceNode(args) {}
};
}  // namespace

int main(int argc, char** argv) {
  return tamp::dds::serviceMain(argc, argv, "echo", "TAMP echo node (service skeleton)",
                                [](const tamp::dds::ServiceArgs& a) -> tamp::Result<std::unique_ptr<tamp::dds::ServiceNode>> {
                                  return std::unique_ptr<tamp::dds::ServiceNode>(std::make_unique<EchoNode>(a));
                                });
}
