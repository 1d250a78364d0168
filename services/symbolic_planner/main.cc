// tamp_symbolic_planner_service: the FF planner behind tamp/symbolic_planner/plan.
#include "planner_node.h"

int main(int argc, char** argv) {
  return tamp::dds::serviceMain(argc, argv, "symbolic_planner", "FF task planner service (PDDL)",
                                tamp::symbolic_planner::PlannerNode::create);
}
