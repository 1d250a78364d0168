// tamp_perception_service: the perception service (depth frames -> world model, events, occupancy).
#include "perception_node.h"

int main(int argc, char** argv) {
  return tamp::dds::serviceMain(argc, argv, "perception", "TAMP perception service (PCL + OctoMap)",
                                tamp::perception::PerceptionNode::create);
}
