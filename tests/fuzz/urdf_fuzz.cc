// libFuzzer target: the URDF loader (tinyxml2 + urdfdom + our validation and KDL conversion) must
// return an error, never crash, on any input.
#include <cstddef>
#include <cstdint>
#include <string>

#include "tamp/robot/robot_model.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  auto model = tamp::robot::RobotModel::fromUrdfString(text, "fuzz.urdf");
  if (model.ok() && model->armDof() > 0) {
    const auto s = model->defaultState();
    (void)model->toolPose(s.arm);
    std::vector<Eigen::Isometry3d> poses;
    model->linkPoses(s, poses);
  }
  return 0;
}
