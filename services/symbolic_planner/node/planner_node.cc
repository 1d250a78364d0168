#include "planner_node.h"

#include <cctype>
#include <sstream>

#include "tamp/config/yaml_reader.h"

namespace tamp::symbolic_planner {
namespace {

Error inputError(const std::string& field, const std::string& what) {
  return Error(ErrorCode::kInvalidArgument, what, SourceLocation{"", 0, 0, field});
}

/// Splits "(a b (c d) e)" into its top-level items: "a", "b", "(c d)", "e".
Result<std::vector<std::string>> listItems(const std::string& text) {
  std::string t = text;
  size_t b = t.find_first_not_of(" \t\r\n");
  size_t e = t.find_last_not_of(" \t\r\n");
  if (b == std::string::npos || t[b] != '(' || t[e] != ')') {
    return Error(ErrorCode::kParseError, "expected a parenthesised atom like '(on can table)', got '" + text + "'");
  }
  std::vector<std::string> items;
  int depth = 0;
  std::string cur;
  for (size_t i = b + 1; i < e; ++i) {
    const char c = t[i];
    if (c == '(') ++depth;
    if (c == ')') --depth;
    if (depth < 0) return Error(ErrorCode::kParseError, "unbalanced ')' in '" + text + "'");
    if (depth == 0 && std::isspace(static_cast<unsigned char>(c))) {
      if (!cur.empty()) items.push_back(std::move(cur));
      cur.clear();
    } else {
      cur += c;
    }
  }
  if (depth != 0) return Error(ErrorCode::kParseError, "unbalanced '(' in '" + text + "'");
  if (!cur.empty()) items.push_back(std::move(cur));
  if (items.empty()) return Error(ErrorCode::kParseError, "empty atom '" + text + "'");
  return items;
}

}  // namespace

Result<AtomSpec> parseAtom(const std::string& text) {
  auto items = listItems(text);
  if (!items) return items.error();
  AtomSpec a;
  a.predicate = (*items)[0];
  for (size_t i = 1; i < items->size(); ++i) {
    if ((*items)[i].front() == '(') {
      return Error(ErrorCode::kParseError, "atom arguments must be object names, got '" + text + "'");
    }
    a.args.push_back((*items)[i]);
  }
  return a;
}

Result<std::pair<AtomSpec, double>> parseFunctionValue(const std::string& text) {
  auto items = listItems(text);
  if (!items) return items.error();
  if (items->size() != 3 || (*items)[0] != "=") {
    return Error(ErrorCode::kParseError, "expected '(= (function args...) value)', got '" + text + "'");
  }
  auto f = parseAtom((*items)[1]);
  if (!f) return f.error();
  try {
    size_t pos = 0;
    const double v = std::stod((*items)[2], &pos);
    if (pos != (*items)[2].size()) throw std::invalid_argument("trailing");
    return std::make_pair(*f, v);
  } catch (...) {
    return Error(ErrorCode::kParseError, "function value is not a number in '" + text + "'");
  }
}

Result<PlannerNodeParams> PlannerNodeParams::load(const std::string& yaml_file) {
  PlannerNodeParams p;
  if (yaml_file.empty()) return p;
  auto doc = config::loadYamlFile(yaml_file);
  if (!doc) return doc.error();
  config::FieldReader r(*doc);
  unsigned cache = static_cast<unsigned>(p.cache_size), mem = static_cast<unsigned>(p.memory_limit_mb);
  r.optional("cache_size", cache);
  r.optional("max_timeout_s", p.max_timeout_s);
  r.optional("memory_limit_mb", mem);
  r.check(cache >= 1, "cache_size", "must be at least 1");
  r.check(p.max_timeout_s > 0, "max_timeout_s", "must be positive");
  r.refuseUnknownKeys();
  if (!r.ok()) return r.status().error();
  p.cache_size = cache;
  p.memory_limit_mb = mem;
  return p;
}

Result<PlanRequest> fromMsg(const msg::PlanRequest& m, const PlannerNodeParams& params) {
  PlanRequest r;
  r.domain_text = m.domain_pddl();
  r.domain_path = m.domain_path();
  if (r.domain_text.empty() && r.domain_path.empty()) {
    return inputError("domain_pddl", "give the domain as PDDL text (domain_pddl) or a path (domain_path)");
  }
  r.problem_text = m.problem_pddl();
  if (r.problem_text.empty()) {
    if (m.goal().empty()) return inputError("goal", "give a problem (problem_pddl) or objects, init and goal");
    for (size_t i = 0; i < m.objects().size(); ++i) {
      std::istringstream ss(m.objects()[i]);
      ObjectSpec o;
      std::string dash, type, extra;
      ss >> o.name >> dash >> type >> extra;
      if (o.name.empty() || (!dash.empty() && (dash != "-" || type.empty())) || !extra.empty()) {
        return inputError("objects[" + std::to_string(i) + "]", "expected 'name - type' or 'name', got '" +
                                                                   m.objects()[i] + "'");
      }
      if (!type.empty()) o.type = type;
      r.objects.push_back(std::move(o));
    }
    for (size_t i = 0; i < m.init().size(); ++i) {
      const std::string& text = m.init()[i];
      const std::string field = "init[" + std::to_string(i) + "]";
      if (text.find("(=") != std::string::npos) {
        auto fv = parseFunctionValue(text);
        if (!fv) return inputError(field, fv.error().message);
        r.function_values.push_back(*fv);
      } else {
        auto a = parseAtom(text);
        if (!a) return inputError(field, a.error().message);
        r.init.push_back(*a);
      }
    }
    std::string goal = "(and";
    for (const auto& g : m.goal()) goal += " " + g;
    r.goal = goal + ")";
    r.use_costs = m.use_costs();
  }
  switch (m.search()) {
    case msg::SEARCH_DEFAULT:
    case msg::SEARCH_EHC: r.search.algorithm = SearchAlgorithm::kEhc; break;
    case msg::SEARCH_GBFS: r.search.algorithm = SearchAlgorithm::kGbfs; break;
    case msg::SEARCH_WASTAR: r.search.algorithm = SearchAlgorithm::kWAstar; break;
    case msg::SEARCH_ASTAR: r.search.algorithm = SearchAlgorithm::kAstar; break;
    default: return inputError("search", "unknown search kind " + std::to_string(static_cast<int>(m.search())));
  }
  if (m.weight() > 0) {
    if (m.weight() < 1.0) return inputError("weight", "must be >= 1, got " + std::to_string(m.weight()));
    r.search.weight = m.weight();
  }
  r.search.memory_limit_mb = params.memory_limit_mb;
  r.timeout_seconds = params.max_timeout_s;
  return r;
}

msg::PlanReply toMsg(const PlanReply& r) {
  msg::PlanReply m;
  switch (r.status) {
    case PlanStatus::kSolved: m.status(msg::PLAN_SOLVED); break;
    case PlanStatus::kUnsolvable: m.status(msg::PLAN_UNSOLVABLE); break;
    case PlanStatus::kFailed: m.status(msg::PLAN_FAILED); break;
    case PlanStatus::kTimeout: m.status(msg::PLAN_TIMEOUT); break;
    case PlanStatus::kOutOfMemory: m.status(msg::PLAN_OUT_OF_MEMORY); break;
    case PlanStatus::kCancelled:
      m.status(msg::PLAN_FAILED);
      m.header().code(msg::STATUS_CANCELLED);
      break;
    case PlanStatus::kInputError:
      m.status(msg::PLAN_INVALID_INPUT);
      m.header().code(r.message.find("unsupported") != std::string::npos ? msg::STATUS_UNSUPPORTED
                                                                        : msg::STATUS_PARSE_ERROR);
      break;
    case PlanStatus::kInternalError:
      m.status(msg::PLAN_FAILED);
      m.header().code(msg::STATUS_INTERNAL);
      break;
  }
  m.header().message(r.message);
  std::vector<std::string> actions;
  for (const auto& step : r.plan) actions.push_back(step.toString());
  m.actions(std::move(actions));
  for (const auto& st : r.states) {
    msg::PlanState ps;
    ps.atoms(st);
    m.states().push_back(std::move(ps));
  }
  m.cost(static_cast<double>(r.cost));
  m.expanded(r.stats.expanded);
  m.evaluated(r.stats.evaluated);
  m.ground_time_s(r.stats.ground_seconds);
  m.search_time_s(r.stats.search_seconds);
  m.grounding_cached(r.stats.grounding_reused);
  m.facts(static_cast<uint32_t>(r.stats.facts));
  m.operators(static_cast<uint32_t>(r.stats.operators));
  return m;
}

Result<std::unique_ptr<dds::ServiceNode>> PlannerNode::create(const dds::ServiceArgs& args) {
  auto params = PlannerNodeParams::load(args.config_file);
  if (!params) return params.error();
  return std::unique_ptr<dds::ServiceNode>(std::make_unique<PlannerNode>(args, *params));
}

PlannerNode::PlannerNode(const dds::ServiceArgs& args, PlannerNodeParams params)
    : ServiceNode(args), params_(params), planner_(params.cache_size) {
  server_ = std::make_unique<dds::RpcServer<msg::PlanRequest, msg::PlanReply>>(
      participant(), dds::services::kPlan,
      [this](const msg::PlanRequest& req, const dds::RequestContext& ctx) { return handle(req, ctx); });
}

msg::PlanReply PlannerNode::handle(const msg::PlanRequest& req, const dds::RequestContext& ctx) {
  if (Status bad = msgv::screen(req, dds::services::kPlan.name, rejects_); !bad.ok()) {
    msg::PlanReply rep;
    rep.status(msg::PLAN_INVALID_INPUT);
    rep.header().code(msg::STATUS_INVALID_ARGUMENT);
    rep.header().message(bad.error().message);
    return rep;
  }
  auto request = fromMsg(req, params_);
  if (!request) {
    msg::PlanReply rep;
    rep.status(msg::PLAN_INVALID_INPUT);
    rep.header().code(dds::toMsg(request.error().code));
    rep.header().message(request.error().toString());
    return rep;
  }
  heartbeat().setState(msg::SERVICE_BUSY);
  PlanReply reply = planner_.solve(*request, ctx.termination);
  heartbeat().setState(msg::SERVICE_READY);
  if (reply.status == PlanStatus::kTimeout && ctx.termination.reason() == StopReason::kStopRequested) {
    reply.status = PlanStatus::kCancelled;
  }
  return toMsg(reply);
}

std::pair<uint64_t, uint64_t> PlannerNode::requestCounters() const {
  auto base = ServiceNode::requestCounters();
  if (!server_) return base;
  return {base.first + server_->served(), base.second + server_->failed() + server_->rejected()};
}

}  // namespace tamp::symbolic_planner
