// tamp_graph_manager_service: the mission loop (issue 11) -- reachability graph, Traverse, execution.
#include "graph_manager_node.h"

int main(int argc, char** argv) {
  return tamp::dds::serviceMain(argc, argv, "graph_manager", "TAMP graph manager: plans, executes and repairs missions",
                                [](const tamp::dds::ServiceArgs& a) { return tamp::graph_manager::GraphManagerNode::create(a); });
}
