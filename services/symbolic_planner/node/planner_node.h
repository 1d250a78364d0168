#pragma once
/// @file
/// The symbolic planner as a DDS service: answers `tamp/symbolic_planner/plan` requests
/// (msg::PlanRequest -> msg::PlanReply) with `symbolic_planner::Planner`, whose grounding cache makes
/// repeated queries on one domain and object set cheap (the graph manager's TP(v, s) calls).
///
/// Status mapping: solved / unsolvable (proven) / failed (incomplete search gave up) / timeout /
/// out of memory go into `PlanReply::status` with header code OK; malformed or unsupported input
/// gives header code PARSE_ERROR / INVALID_ARGUMENT / UNSUPPORTED with the planner's message (file,
/// line, column) and status PLAN_INVALID_INPUT; a cancelled request gives header code CANCELLED.

#include <memory>
#include <string>

#include "tamp/dds/service_node.h"
#include "tamp/msg_validation/validate.h"
#include "tamp/symbolic_planner/planner.h"

namespace tamp::symbolic_planner {

/// Service parameters (config/services/symbolic_planner.yaml).
struct PlannerNodeParams {
  size_t cache_size{8};            ///< groundings kept (one per domain + object set)
  double max_timeout_s{300.0};     ///< cap on a request's budget; must be positive
  size_t memory_limit_mb{4096};    ///< search memory per request; 0 = unlimited

  /// Errors name the file, line and field.
  static Result<PlannerNodeParams> load(const std::string& yaml_file);
};

/// Atom text "(on can table)" -> AtomSpec; "(= (total-cost) 0)" is a function value.
/// Errors name the offending text.
Result<AtomSpec> parseAtom(const std::string& text);
Result<std::pair<AtomSpec, double>> parseFunctionValue(const std::string& text);

/// msg::PlanRequest -> PlanRequest (objects "name - type", init atoms, goal literals, search).
Result<PlanRequest> fromMsg(const msg::PlanRequest& m, const PlannerNodeParams& params);
/// PlanReply -> msg::PlanReply (status, actions in IPC form, cost, statistics, header code).
msg::PlanReply toMsg(const PlanReply& r);

class PlannerNode : public dds::ServiceNode {
 public:
  static Result<std::unique_ptr<dds::ServiceNode>> create(const dds::ServiceArgs& args);
  PlannerNode(const dds::ServiceArgs& args, PlannerNodeParams params);

  /// The request handler (public for tests).
  msg::PlanReply handle(const msg::PlanRequest& req, const dds::RequestContext& ctx);

 protected:
  std::pair<uint64_t, uint64_t> requestCounters() const override;

 private:
  msgv::RejectLog rejects_{"symbolic_planner"};  // malformed input: logged once per kind, rate-limited
  PlannerNodeParams params_;
  Planner planner_;
  std::unique_ptr<dds::RpcServer<msg::PlanRequest, msg::PlanReply>> server_;
};

}  // namespace tamp::symbolic_planner
