// tamp_execution_monitor_service: validates, executes and watches the graph manager's actions on
// the robot (issue 11, part 4) and forwards the robot's execution records to the effort estimator.
#include "execution_monitor_node.h"

int main(int argc, char** argv) {
  return tamp::dds::serviceMain(argc, argv, "execution_monitor",
                                "TAMP execution monitor: validate, execute and watch actions",
                                [](const tamp::dds::ServiceArgs& a) {
                                  return tamp::execution_monitor::ExecutionMonitorNode::create(a);
                                });
}
