#pragma once
/// @file
/// QoS classes. Each maps to a data-writer and a data-reader profile in config/dds/tamp_profiles.xml
/// ("<class>_writer", "<class>_reader"), so QoS is tuned in XML, not in code.

#include <string>

namespace tamp::dds {

enum class QosClass {
  kState,      ///< RELIABLE + TRANSIENT_LOCAL, KEEP_LAST 1 per instance: world model, models, graph
  kStream,     ///< BEST_EFFORT, KEEP_LAST small: robot state, point clouds
  kCommand,    ///< RELIABLE, VOLATILE, KEEP_LAST 64: commands
  kEvent,      ///< RELIABLE, TRANSIENT_LOCAL, KEEP_LAST 100: events, results, execution records
  kRpc,        ///< RELIABLE, VOLATILE, KEEP_LAST 64: request/reply topics
  kHeartbeat,  ///< RELIABLE + TRANSIENT_LOCAL, KEEP_LAST 1 per instance: service liveness
  kBulk,       ///< RELIABLE, VOLATILE, KEEP_LAST 2: point clouds (large, fragmented)
};

/// "state", "stream", ... (the XML profile prefix).
const char* profilePrefix(QosClass qos);
inline std::string writerProfile(QosClass qos) { return std::string(profilePrefix(qos)) + "_writer"; }
inline std::string readerProfile(QosClass qos) { return std::string(profilePrefix(qos)) + "_reader"; }

}  // namespace tamp::dds
