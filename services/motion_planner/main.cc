// tamp_motion_planner_service: the motion planning service (lazy paths with blocking objects, full paths,
// placements, grasps) as a DDS process.
#include "motion_planner_node.h"

int main(int argc, char** argv) {
  return tamp::dds::serviceMain(argc, argv, "motion_planner",
                                "TAMP motion planner (lazy KPIECE with blocking objects, placements, grasps)",
                                [](const tamp::dds::ServiceArgs& a) { return tamp::motion_planner::MotionPlannerNode::create(a); });
}
