// tamp_sim_service: the simulated robot and world (issue 6) behind the robot's DDS topics.
#include "sim_node.h"

int main(int argc, char** argv) {
  return tamp::dds::serviceMain(argc, argv, "sim", "TAMP simulator: ground-truth world, robot, depth sensor",
                                [](const tamp::dds::ServiceArgs& a) { return tamp::sim::SimNode::create(a); });
}
