// tamp_effort_estimator_service: execution-time estimates behind tamp/effort_estimator/estimate,
// refitted online from tamp/execution/record, models published on tamp/effort/model.
#include "effort_estimator_node.h"

int main(int argc, char** argv) {
  return tamp::dds::serviceMain(argc, argv, "effort_estimator",
                                "Effort estimator service (execution-time models refitted online)",
                                tamp::effort_estimator::EffortEstimatorNode::create);
}
