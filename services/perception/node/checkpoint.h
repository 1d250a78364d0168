#pragma once
/// @file
/// Perception's checkpoint in the run folder (issue 13, crash recovery: "nothing lost"). A
/// perception restarted mid-mission used to start from the scenario's prior: a box the robot had
/// moved was believed back where the scenario put it, and a box in the gripper was relearned from
/// one partial view (the kill -9 matrix failed on it). The node writes the movable objects it
/// tracks and the grasp it holds after every frame that changed them (atomically, fsynced); a
/// restarted node starts from the prior with these applied and takes the grasp up, and publishes
/// above the world version recorded (written before the world model is published): a version
/// never names two worlds, and the services' mirrors and the graph manager's questions, which name
/// versions, go on agreeing.
///
/// File (`$TAMP_RUN_DIR/perception.checkpoint`), one record per line:
///   tamp-perception-checkpoint 1
///   world_version <the world model version published with it>                  (at most once)
///   held <object id> <tool_T_object: 12 numbers, the 3x4 matrix row by row>   (at most once)
///   object <msg::WorldObject as CDR, in hex>                                  (one per movable)

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "tamp/core/error.h"
#include "tamp/perception/perception.h"
#include "tamp/world/world.h"

namespace tamp::perception {

struct PerceptionCheckpoint {
  std::vector<world::Object> movables;  ///< every movable object of the world model
  std::optional<Perception::HeldGrasp> held;
  std::uint64_t world_version{0};  ///< the version the world model was published at (0: none recorded)
};

/// The checkpoint's text for the world model `w` and the grasp `held`.
std::string formatCheckpoint(const world::World& w, const std::optional<Perception::HeldGrasp>& held,
                             std::uint64_t world_version = 0);
/// Parses a checkpoint; kParseError naming `file`, the line and the field for anything that is
/// not one (an unknown record, a bad number or payload, an invalid object).
Result<PerceptionCheckpoint> parseCheckpoint(const std::string& text, const std::string& file);
/// `prior` with the checkpoint applied: its movables where the checkpoint has them, movables the
/// checkpoint lacks (gone) removed, movables perception had found added. Static objects and
/// regions stay the prior's. kInvalidArgument naming the object when one cannot be applied.
Result<world::World> restoredPrior(const world::World& prior, const PerceptionCheckpoint& c);

}  // namespace tamp::perception
