#include "tamp/symbolic_planner/planner.h"

#include <algorithm>
#include <functional>

#include "tamp/core/paths.h"

namespace tamp::symbolic_planner {
namespace {

PlanStatus fromSearch(SearchStatus s) {
  switch (s) {
    case SearchStatus::kSolved: return PlanStatus::kSolved;
    case SearchStatus::kUnsolvable: return PlanStatus::kUnsolvable;
    case SearchStatus::kFailed: return PlanStatus::kFailed;
    case SearchStatus::kTimeout: return PlanStatus::kTimeout;
    case SearchStatus::kCancelled: return PlanStatus::kCancelled;
    case SearchStatus::kOutOfMemory: return PlanStatus::kOutOfMemory;
  }
  return PlanStatus::kInternalError;
}

PlanReply errorReply(const Error& e) {
  PlanReply r;
  switch (e.code) {
    case ErrorCode::kTimeout: r.status = PlanStatus::kTimeout; break;
    case ErrorCode::kCancelled: r.status = PlanStatus::kCancelled; break;
    case ErrorCode::kInternal: r.status = PlanStatus::kInternalError; break;
    default: r.status = PlanStatus::kInputError; break;
  }
  r.message = e.toString();
  return r;
}

PlanStep stepOf(const std::string& ipc) {
  PlanStep st;
  std::string tok;
  for (size_t i = 1; i + 1 <= ipc.size(); ++i) {
    const char c = ipc[i];
    if (c == ' ' || c == ')') {
      if (!tok.empty()) {
        if (st.action.empty()) st.action = tok; else st.args.push_back(tok);
        tok.clear();
      }
    } else {
      tok.push_back(c);
    }
  }
  return st;
}

bool sameGoal(const Goal& a, const Goal& b) {
  if (a.conjuncts.size() != b.conjuncts.size()) return false;
  for (size_t c = 0; c < a.conjuncts.size(); ++c) {
    if (a.conjuncts[c].pos != b.conjuncts[c].pos || a.conjuncts[c].neg != b.conjuncts[c].neg) return false;
  }
  return true;
}

bool hasCosts(const pddl::Domain& d) {
  for (const auto& a : d.actions) {
    if (!a.costs.empty()) return true;
  }
  return false;
}

}  // namespace

std::string toString(PlanStatus s) {
  switch (s) {
    case PlanStatus::kSolved: return "solved";
    case PlanStatus::kUnsolvable: return "unsolvable";
    case PlanStatus::kFailed: return "failed";
    case PlanStatus::kTimeout: return "timeout";
    case PlanStatus::kCancelled: return "cancelled";
    case PlanStatus::kOutOfMemory: return "out of memory";
    case PlanStatus::kInputError: return "input error";
    case PlanStatus::kInternalError: return "internal error";
  }
  return "unknown";
}

std::string formatPlan(const std::vector<PlanStep>& plan, Cost cost) {
  std::string out;
  for (const auto& s : plan) out += s.toString() + "\n";
  out += "; cost = " + std::to_string(cost) + "\n";
  return out;
}

// -------------------------------------------------------------------------------------------------
// PlanningSession

Result<std::unique_ptr<PlanningSession>> PlanningSession::create(pddl::Domain domain, pddl::Problem problem,
                                                                 bool use_costs, GroundingLimits limits) {
  std::unique_ptr<PlanningSession> s(new PlanningSession());
  s->domain_ = std::move(domain);
  s->problem_ = std::move(problem);
  s->use_costs_ = use_costs;
  s->limits_ = limits;
  if (Status st = s->ensureGrounder(); !st.ok()) return st.error();
  return s;
}

Result<std::unique_ptr<PlanningSession>> PlanningSession::fromText(const std::string& domain_text,
                                                                   const std::string& problem_text,
                                                                   const std::string& domain_name,
                                                                   const std::string& problem_name) {
  auto d = pddl::parseDomain(domain_text, domain_name);
  if (!d) return d.error();
  auto p = pddl::parseProblem(problem_text, *d, problem_name);
  if (!p) return p.error();
  const bool costs = p->minimize_total_cost && hasCosts(*d);
  return create(std::move(*d), std::move(*p), costs);
}

Status PlanningSession::ensureGrounder() {
  if (grounder_) return Status::Ok();
  auto g = Grounder::create(domain_, problem_, limits_);
  if (!g) return g.error();
  grounder_ = std::move(*g);
  task_.reset();
  heuristics_.clear();
  prune_tried_ = false;
  pruned_ = PrunedTask{};
  pruned_heuristics_.clear();
  task_statics_.clear();
  task_negated_.clear();
  return Status::Ok();
}

const GroundingStats& PlanningSession::groundingStats() const { return grounder_->stats(); }

Result<AtomId> PlanningSession::atomId(const AtomSpec& atom) {
  if (Status s = ensureGrounder(); !s.ok()) return s.error();
  std::vector<std::string> args = atom.args;
  std::string pred = atom.predicate;
  auto lower = [](std::string& x) {
    std::transform(x.begin(), x.end(), x.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  };
  lower(pred);
  for (auto& a : args) lower(a);
  return grounder_->atomId(pred, args);
}

Result<std::vector<AtomId>> PlanningSession::atomIds(const std::vector<AtomSpec>& atoms) {
  std::vector<AtomId> out;
  out.reserve(atoms.size());
  for (const auto& a : atoms) {
    auto id = atomId(a);
    if (!id) return id.error();
    out.push_back(*id);
  }
  return out;
}

Result<std::vector<AtomId>> PlanningSession::problemInit() {
  if (Status s = ensureGrounder(); !s.ok()) return s.error();
  std::vector<AtomId> out;
  for (const auto& a : problem_.init) {
    auto id = grounder_->atomId(a);
    if (!id) return id.error();
    out.push_back(*id);
  }
  return out;
}

Status PlanningSession::addObjects(const std::vector<ObjectSpec>& objects) {
  bool added = false;
  for (const auto& o : objects) {
    if (!domain_.findType(o.type)) return Error(ErrorCode::kInvalidArgument, "object '" + o.name + "': unknown type '" + o.type + "'");
    bool exists = false;
    for (const auto& e : problem_.objects) {
      if (e.name == o.name) {
        exists = true;
        if (e.types.size() != 1 || e.types[0] != o.type) {
          return Error(ErrorCode::kInvalidArgument, "object '" + o.name + "' already exists with another type");
        }
      }
    }
    for (const auto& c : domain_.constants) exists = exists || c.name == o.name;
    if (exists) continue;
    problem_.objects.push_back(pddl::TypedName{o.name, {o.type}, {}});
    added = true;
  }
  if (!added) return Status::Ok();
  // Carry the seeds (union of initial states seen) over to the new grounding by name.
  std::vector<pddl::Atom> carried;
  for (AtomId a : seed_ids_) carried.push_back(grounder_->atom(a));
  grounder_.reset();
  seed_ids_.clear();
  ++generation_;
  if (Status s = ensureGrounder(); !s.ok()) return s;
  for (const auto& a : carried) {
    auto id = grounder_->atomId(a);
    if (id) seed_ids_.push_back(*id);
  }
  return Status::Ok();
}

PlanReply PlanningSession::solve(const Query& q, const Termination& term) {
  q.search.validate();
  PlanReply reply;
  Stopwatch sw;
  if (Status s = ensureGrounder(); !s.ok()) return errorReply(s.error());
  for (AtomId a : q.init) {
    if (a >= grounder_->numAtoms()) {
      return errorReply(Error(ErrorCode::kInvalidArgument, "initial atom id " + std::to_string(a) + " is not an atom of this session"));
    }
  }
  // 1. Grounding: extend when the query has atoms outside R(U).
  bool rebuilt = false;
  if (!grounder_->covers(q.init)) {
    std::vector<AtomId> seeds = q.init;
    seeds.insert(seeds.end(), seed_ids_.begin(), seed_ids_.end());  // non-empty after re-grounding
    for (AtomId a : q.init) {
      if (!grounder_->isReachable(a)) seed_ids_.push_back(a);
    }
    if (Status s = grounder_->extend(seeds, term); !s.ok()) return errorReply(s.error());
    rebuilt = true;
  }
  // 2. The task for this query's statics (and negated goal atoms).
  std::vector<AtomId> statics;
  for (AtomId a : q.init) {
    if (grounder_->isStaticAtom(a)) statics.push_back(a);
  }
  std::sort(statics.begin(), statics.end());
  statics.erase(std::unique(statics.begin(), statics.end()), statics.end());
  std::vector<AtomId> negated = task_negated_;
  if (q.goal_formula) {
    auto n = grounder_->negatedAtoms(*q.goal_formula);
    if (!n) return errorReply(n.error());
    negated.insert(negated.end(), n->begin(), n->end());
  }
  for (const auto& l : q.goal_literals) {
    if (l.negated) negated.push_back(l.atom);
  }
  std::sort(negated.begin(), negated.end());
  negated.erase(std::unique(negated.begin(), negated.end()), negated.end());
  if (!task_ || rebuilt || statics != task_statics_ || negated != task_negated_) {
    auto t = grounder_->buildTask(q.init, negated, use_costs_, term);
    if (!t) return errorReply(t.error());
    task_ = *t;
    task_statics_ = statics;
    task_negated_ = negated;
    heuristics_.clear();
    prune_tried_ = false;
    pruned_ = PrunedTask{};
    pruned_heuristics_.clear();
    rebuilt = true;
  }
  reply.stats.grounding_reused = !rebuilt;
  reply.stats.ground_seconds = sw.seconds();
  // 3. Goal and initial state.
  Goal goal;
  if (q.goal_formula) {
    auto g = grounder_->groundGoal(*q.goal_formula, *task_, q.init);
    if (!g) return errorReply(g.error());
    goal = std::move(*g);
  } else {
    GoalConjunct gc;
    bool sat = true;
    std::vector<char> in_init;
    for (const auto& l : q.goal_literals) {
      if (l.atom >= grounder_->numAtoms()) {
        return errorReply(Error(ErrorCode::kInvalidArgument, "goal atom id " + std::to_string(l.atom) + " is not an atom of this session"));
      }
      if (grounder_->isStaticAtom(l.atom)) {
        const bool holds = std::binary_search(statics.begin(), statics.end(), l.atom);
        if (holds == l.negated) sat = false;
        continue;
      }
      const int64_t f = grounder_->factOf(*task_, l.atom);
      if (f < 0) {  // unreachable atom: false in every reachable state
        if (!l.negated) sat = false;
        continue;
      }
      if (!l.negated) {
        gc.pos.push_back(static_cast<FactId>(f));
      } else if (task_->complement[static_cast<size_t>(f)] >= 0) {
        gc.pos.push_back(static_cast<FactId>(task_->complement[static_cast<size_t>(f)]));
      } else {
        gc.neg.push_back(static_cast<FactId>(f));
      }
    }
    if (sat) {
      std::sort(gc.pos.begin(), gc.pos.end());
      gc.pos.erase(std::unique(gc.pos.begin(), gc.pos.end()), gc.pos.end());
      goal.conjuncts.push_back(std::move(gc));
    }
  }
  StateBits init = grounder_->initialState(*task_, q.init);
  // 4. The task to search: pruned to what is relevant to the goal (see Query::prune_irrelevant).
  const Task* task = task_.get();
  std::vector<HeuristicCache>* tables = &heuristics_;
  // The caller's deadline between the phases (each checks it inside too, but for the heuristic's
  // tables, linear in the operators): a deadline that passed during one ends the query at once.
  auto stoppedReply = [&](const char* phase) {
    reply.status = term.reason() == StopReason::kStopRequested ? PlanStatus::kCancelled : PlanStatus::kTimeout;
    reply.message = std::string(phase) + " " + toString(reply.status);
    return reply;
  };
  if (term()) return stoppedReply("grounding");
  if (q.prune_irrelevant && !prune_tried_ && heuristics_.empty()) {
    pruned_ = pruneIrrelevant(*task_, goal, term);
    prune_tried_ = !pruned_.stats.stopped;  // a stopped analysis is run again by the next query
    pruned_for_ = goal;
    pruned_heuristics_.clear();
    reply.stats.relevance_ran = true;
    reply.stats.relevance = pruned_.stats;
    if (pruned_.stats.stopped) return stoppedReply("relevance analysis");
  }
  if (q.prune_irrelevant && pruned_.pruned() && sameGoal(goal, pruned_for_)) {
    init = pruned_.projectState(init.data(), init.size());
    goal = pruned_.goal;
    task = pruned_.task.get();
    tables = &pruned_heuristics_;
    reply.stats.pruned = true;
  }
  // 5. Search, with a cached heuristic.
  SearchOptions opt = q.search;
  const bool optimal = opt.algorithm == SearchAlgorithm::kAstar || opt.algorithm == SearchAlgorithm::kWAstar;
  const HeuristicKind hk = opt.heuristic ? *opt.heuristic : (optimal ? HeuristicKind::kMax : HeuristicKind::kFF);
  const CostType ct = opt.cost_type ? *opt.cost_type
                                    : (task->unit_cost ? CostType::kUnit : (optimal ? CostType::kCost : CostType::kPlusOne));
  Heuristic* h = nullptr;
  for (auto& c : *tables) {
    if (c.kind == hk && c.cost_type == ct) h = c.h.get();
  }
  if (!h) {
    tables->push_back({hk, ct, makeHeuristic(hk, *task, ct)});
    h = tables->back().h.get();
  }
  if (term()) return stoppedReply("heuristic set-up");
  Stopwatch ssw;
  SearchResult sr = search(*task, init, goal, opt, *h, term);
  reply.stats.search_seconds = ssw.seconds();
  reply.stats.facts = task->numFacts();
  reply.stats.operators = task->ops.size();
  reply.stats.expanded = sr.stats.expanded;
  reply.stats.generated = sr.stats.generated;
  reply.stats.evaluated = sr.stats.evaluated;
  reply.stats.initial_h = sr.stats.initial_h;
  reply.stats.ehc_failed = sr.stats.ehc_failed;
  reply.stats.ehc_ff_failed = sr.stats.ehc_ff_failed;
  reply.stats.ehc_second_ran = sr.stats.ehc_second_ran;
  reply.stats.ehc_second_won = sr.stats.ehc_second_won;
  reply.stats.ehc_retries = sr.stats.ehc_retries;
  reply.stats.ehc_retries_abandoned = sr.stats.ehc_retries_abandoned;
  reply.stats.ehc_h2_restarts = sr.stats.ehc_h2_restarts;
  reply.stats.ehc_h2_tests = sr.stats.ehc_h2_tests;
  reply.stats.ehc_h2_dead_ends = sr.stats.ehc_h2_dead_ends;
  reply.stats.ehc_fallbacks = sr.stats.ehc_fallbacks;
  reply.stats.ehc_fallbacks_in_agenda = sr.stats.ehc_fallbacks_in_agenda;
  reply.stats.lazy_beside_started = sr.stats.lazy_beside_started;
  reply.stats.lazy_beside_won = sr.stats.lazy_beside_won;
  reply.stats.anytime_iterations = sr.stats.anytime_iterations;
  reply.stats.anytime_improvements = sr.stats.anytime_improvements;
  reply.stats.neighbourhood_runs = sr.stats.neighbourhood_runs;
  reply.stats.neighbourhood_improvements = sr.stats.neighbourhood_improvements;
  reply.stats.neighbourhood_states = sr.stats.neighbourhood_states;
  reply.stats.neighbourhood_seconds = sr.stats.neighbourhood_seconds;
  reply.stats.unit_first_failed = sr.stats.unit_first_failed;
  reply.stats.unit_beside = sr.stats.unit_beside;
  reply.stats.landmarks = sr.stats.landmarks;
  reply.stats.landmarks_disjunctive = sr.stats.landmarks_disjunctive;
  reply.stats.landmark_gn_orders = sr.stats.landmark_gn_orders;
  reply.stats.landmark_reasonable_orders = sr.stats.landmark_reasonable_orders;
  reply.status = fromSearch(sr.status);
  if (sr.status == SearchStatus::kSolved) {
    reply.cost = sr.cost;
    reply.plan.reserve(sr.plan.size());
    for (OpId o : sr.plan) reply.plan.push_back(stepOf(task->ops[o].name));
  } else {
    reply.message = "search " + toString(sr.status);
  }
  return reply;
}

// -------------------------------------------------------------------------------------------------
// Planner

namespace {

Result<std::string> textOrFile(const std::string& text, const std::string& path, const std::string& what) {
  if (!text.empty()) return text;
  if (path.empty()) return Error(ErrorCode::kInvalidArgument, "request has neither " + what + " text nor " + what + " path");
  return readTextFile(path);
}

}  // namespace

PlanReply Planner::solve(const PlanRequest& req, const Termination& caller_term) {
  Termination term = req.timeout_seconds > 0 ? caller_term.tightened(Deadline::in(req.timeout_seconds)) : caller_term;
  try {
    Stopwatch sw;
    auto dtext = textOrFile(req.domain_text, req.domain_path, "domain");
    if (!dtext) return errorReply(dtext.error());
    const std::string dname = req.domain_text.empty() ? req.domain_path : "<domain>";
    const bool have_problem = !req.problem_text.empty() || !req.problem_path.empty();
    std::string ptext;
    std::string pname = "<problem>";
    if (have_problem) {
      auto t = textOrFile(req.problem_text, req.problem_path, "problem");
      if (!t) return errorReply(t.error());
      ptext = std::move(*t);
      if (req.problem_text.empty()) pname = req.problem_path;
    }
    auto domain = pddl::parseDomain(*dtext, dname);
    if (!domain) return errorReply(domain.error());
    pddl::Problem problem;
    if (have_problem) {
      auto p = pddl::parseProblem(ptext, *domain, pname);
      if (!p) return errorReply(p.error());
      problem = std::move(*p);
    } else {
      problem.name = "request";
      problem.domain_name = domain->name;
      for (const auto& o : req.objects) {
        if (!domain->findType(o.type)) {
          return errorReply(Error(ErrorCode::kInvalidArgument, "object '" + o.name + "': unknown type '" + o.type + "'"));
        }
        problem.objects.push_back(pddl::TypedName{o.name, {o.type}, {}});
      }
      for (const auto& [a, v] : req.function_values) {
        pddl::FunctionValue fv;
        fv.term.predicate = a.predicate;
        for (const auto& x : a.args) fv.term.args.push_back(pddl::Term{x});
        fv.value = v;
        problem.function_values.push_back(std::move(fv));
      }
      problem.minimize_total_cost = req.use_costs;
      auto atoms = pddl::parseAtomList([&] {
        std::string s;
        for (const auto& a : req.init) {
          s += "(" + a.predicate;
          for (const auto& x : a.args) s += " " + x;
          s += ") ";
        }
        return s;
      }(), *domain, problem, "<init>");
      if (!atoms) return errorReply(atoms.error());
      problem.init = std::move(*atoms);
      auto goal = pddl::parseGoalFormula(req.goal.empty() ? std::string("(and)") : req.goal, *domain, problem, "<goal>");
      if (!goal) return errorReply(goal.error());
      problem.goal = std::move(*goal);
    }
    const double parse_s = sw.seconds();
    const bool use_costs = problem.minimize_total_cost && hasCosts(*domain);
    // Session cache key: domain text + objects + function values + cost mode.
    std::string key = *dtext;
    key += '\x1f';
    for (const auto& o : problem.objects) key += o.name + ":" + (o.types.empty() ? "" : o.types[0]) + ",";
    key += '\x1f';
    for (const auto& fv : problem.function_values) key += pddl::toString(fv.term) + "=" + std::to_string(fv.value) + ",";
    key += use_costs ? "1" : "0";

    std::lock_guard<std::mutex> lock(mutex_);
    PlanningSession* session = nullptr;
    for (size_t i = 0; i < cache_.size(); ++i) {
      if (cache_[i].key == key) {
        std::rotate(cache_.begin() + static_cast<std::ptrdiff_t>(i), cache_.begin() + static_cast<std::ptrdiff_t>(i) + 1, cache_.end());
        session = cache_.back().session.get();
        break;
      }
    }
    std::unique_ptr<PlanningSession> owned;
    if (!session) {
      auto s = PlanningSession::create(*domain, problem, use_costs);
      if (!s) return errorReply(s.error());
      owned = std::move(*s);
      session = owned.get();
    }
    Query q;
    // This request's initial state (a cached session was created from another request's).
    std::vector<AtomSpec> init_specs;
    init_specs.reserve(problem.init.size());
    for (const auto& a : problem.init) {
      AtomSpec spec{a.predicate, {}};
      for (const auto& t : a.args) spec.args.push_back(t.name);
      init_specs.push_back(std::move(spec));
    }
    auto init = session->atomIds(init_specs);
    if (!init) return errorReply(init.error());
    q.init = std::move(*init);
    q.goal_formula = problem.goal;
    q.search = req.search;
    q.prune_irrelevant = req.prune_irrelevant;
    PlanReply reply = session->solve(q, term);
    reply.stats.parse_seconds = parse_s;
    if (reply.status == PlanStatus::kSolved && req.check_plan) {
      Stopwatch check_sw;
      ValidationResult v =
          validatePlan(*domain, problem, reply.plan, std::nullopt, std::nullopt, req.return_states);
      reply.stats.check_seconds = check_sw.seconds();
      if (!v.valid) {
        reply.status = PlanStatus::kInternalError;
        reply.message = "plan checker rejected the plan: " + v.message;
      } else {
        reply.states = std::move(v.states);
      }
    }
    if (owned && cache_size_ > 0) {
      cache_.push_back({std::move(key), std::move(owned)});
      if (cache_.size() > cache_size_) cache_.erase(cache_.begin());
    }
    return reply;
  } catch (const std::invalid_argument& e) {
    return errorReply(Error(ErrorCode::kInvalidArgument, e.what()));
  } catch (const std::bad_alloc&) {
    PlanReply r;
    r.status = PlanStatus::kOutOfMemory;
    r.message = "out of memory";
    return r;
  }
}

PlanReply plan(const PlanRequest& request, const Termination& term) {
  Planner p(0);
  return p.solve(request, term);
}

}  // namespace tamp::symbolic_planner
