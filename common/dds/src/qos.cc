#include "tamp/dds/qos.h"

namespace tamp::dds {

const char* profilePrefix(QosClass qos) {
  switch (qos) {
    case QosClass::kState: return "state";
    case QosClass::kStream: return "stream";
    case QosClass::kCommand: return "command";
    case QosClass::kEvent: return "event";
    case QosClass::kRpc: return "rpc";
    case QosClass::kHeartbeat: return "heartbeat";
    case QosClass::kBulk: return "bulk";
  }
  return "command";
}

}  // namespace tamp::dds
