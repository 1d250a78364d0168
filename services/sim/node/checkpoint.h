#pragma once
/// @file
/// The simulator's checkpoint in the run folder (issue 13, crash recovery). The simulator stands
/// in for the robot's drivers *and* the physical world: when the driver's process dies (kill -9)
/// the robot, the objects and what the gripper holds stay where they were. The node writes
/// `Simulator::snapshot()` atomically (writeFileAtomically: temporary file, fsync, rename, folder
/// fsync) when an action starts and ends, when a fault fires, and every
/// `SimParams::checkpoint_period_s` of simulated time while an action runs (every
/// `checkpoint_idle_period_s` while idle, so that stamps go on from close to where the killed
/// process left them); a simulator started
/// in a run folder that holds one resumes from it (`Simulator::resume`) instead of the scenario's
/// start state. The same run folder is the same run (`tamp launch` of one run id); a new run has a
/// new folder.
///
/// File (`$TAMP_RUN_DIR/sim.checkpoint`), one record per line, numbers in full precision:
///   tamp-sim-checkpoint 1
///   time <simulated s>
///   epoch <wall-clock s since the Unix epoch at simulated time 0: stamps go on from there>
///   robot <base x> <base y> <base theta> <gripper> <arm joint values, in the robot's order>
///   held <object id> <link> <link_T_object: 12 numbers, the 3x4 matrix row by row>  (at most once)
///   object <visible|hidden> <msg::WorldObject as CDR in hex (its kind: static or movable)>
///   fired <scripted fault id>        (a scripted fault that fired)
///   pending <scripted fault id>      (a fail-action fault waiting for an action of its kind)
///   action <step> <start s> <kind> <command id> running
///   action <step> <start s> <kind> <command id> <outcome> <duration s> <progress> <blocking id>
///          <reason>
/// (one `object` record per object, one `action` record per accepted command, in order; command
/// ids, blocking ids and reasons in hex, "-" when empty: ids and free text may hold spaces.)

#include <filesystem>
#include <string>

#include "tamp/core/error.h"
#include "tamp/sim/simulator.h"

namespace tamp::sim {

/// The checkpoint's name in a run folder.
inline constexpr const char* kCheckpointFileName = "sim.checkpoint";

/// The checkpoint's text for `snapshot`.
std::string formatCheckpoint(const SimSnapshot& snapshot);
/// Parses a checkpoint; kParseError naming `file`, the line and the field for anything that is
/// not one (a missing header, time or robot record, an unknown record, a bad number, outcome or
/// payload, an invalid object).
Result<SimSnapshot> parseCheckpoint(const std::string& text, const std::string& file);
/// Reads and parses `file` (kNotFound when it does not exist; kIo, kParseError naming the file).
Result<SimSnapshot> readCheckpoint(const std::filesystem::path& file);

}  // namespace tamp::sim
