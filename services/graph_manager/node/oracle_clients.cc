#include "oracle_clients.h"

#include "effort_msgs.h"
#include "tamp/dds/convert.h"
#include "tamp/dds/world_sync.h"
#include "tamp/msg_validation/validate.h"

namespace tamp::graph_manager {
namespace {

dds::RpcClientOptions oracleRpcOptions() {
  dds::RpcClientOptions o;
  o.attempt_timeout_s = 2.0;
  o.max_attempts = 4;
  return o;
}

msgv::RejectLog& oracleRejects() {
  static msgv::RejectLog log("graph_manager");
  return log;
}

OracleFault::Type typeOf(msg::FaultType t) {
  switch (t) {
    case msg::FaultType::FAULT_DROP_HELD_OBJECT:
      return OracleFault::Type::kDropHeldObject;
    case msg::FaultType::FAULT_SPAWN_OBJECT:
      return OracleFault::Type::kSpawnObject;
    case msg::FaultType::FAULT_REMOVE_OBJECT:
      return OracleFault::Type::kRemoveObject;
    default:
      return OracleFault::Type::kFailAction;
  }
}

}  // namespace

OracleServiceClients::OracleServiceClients(std::shared_ptr<dds::Participant> p,
                                           ServiceClients& base)
    : base_(base), oracle_(std::move(p), dds::services::kOracle, oracleRpcOptions()) {}

std::vector<EffortAnswer> OracleServiceClients::effort(const std::vector<EffortQuery>& qs) {
  msg::OracleRequest req;
  for (const auto& q : qs) req.queries().push_back(toEffortMsg(q));
  req.want_truth(false);
  std::vector<EffortAnswer> out(qs.size());
  auto rep = oracle_.call(req, dds::CallOptions{5.0, {}});
  if (rep) {
    if (Status bad = msgv::screen(*rep, dds::services::kOracle.name, oracleRejects()); !bad.ok())
      rep = bad.error();
  }
  if (!rep) {
    for (auto& a : out) a.message = "oracle: " + rep.error().message;
    return out;
  }
  fillEffortAnswers(rep->durations(), out);
  return out;
}

Result<OracleKnowledge> OracleServiceClients::oracle() {
  msg::OracleRequest req;
  req.want_truth(true);
  auto rep = oracle_.call(req, dds::CallOptions{5.0, {}});
  if (!rep)
    return Error(rep.error().code, "oracle (" + std::string(dds::services::kOracle.name) +
                                       "): " + rep.error().message);
  if (Status bad = msgv::screen(*rep, dds::services::kOracle.name, oracleRejects()); !bad.ok())
    return bad.error();
  OracleKnowledge k;
  for (const auto& m : rep->hidden_objects()) {
    auto o = dds::fromMsg(m);
    if (!o)
      return Error(ErrorCode::kInvalidArgument, "oracle: hidden object: " + o.error().message);
    k.hidden.push_back(std::move(o).value());
  }
  for (const auto& m : rep->faults()) {
    OracleFault f;
    f.id = m.fault_id();
    f.type = typeOf(m.type());
    if (m.at_time())
      f.time_s = m.time_s();
    else if (m.step() >= 0)
      f.step = m.step();
    if (!m.any_action()) f.action = dds::fromMsg(m.action());
    f.object_id = m.object_id();
    k.faults.push_back(f);
  }
  k.action_count = rep->action_count();
  k.sim_time_s = rep->sim_time_s();
  return k;
}

}  // namespace tamp::graph_manager
