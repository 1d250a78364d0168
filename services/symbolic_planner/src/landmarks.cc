#include "tamp/symbolic_planner/landmarks.h"

#include <algorithm>
#include <bit>
#include <deque>
#include <map>
#include <stdexcept>
#include <string>
#include <unordered_map>
#include <utility>

namespace tamp::symbolic_planner {

size_t LandmarkGraph::numDisjunctive() const {
  return static_cast<size_t>(std::count_if(landmarks.begin(), landmarks.end(),
                                           [](const auto& l) { return l.size() > 1; }));
}

size_t LandmarkGraph::numOrders(LandmarkOrderKind kind) const {
  return static_cast<size_t>(
      std::count_if(orders.begin(), orders.end(), [&](const auto& o) { return o.kind == kind; }));
}

namespace {

/// Each effect of the task (an operator's unconditional part, or one conditional effect) as a
/// relaxed operator: its precondition facts (the operator's and the effect's condition, unique),
/// in CSR form, and the effects that need each fact.
struct RelaxedEffects {
  std::vector<uint32_t> pre_begin;
  std::vector<FactId> pre;
  std::vector<uint32_t> users_begin, users;

  explicit RelaxedEffects(const Task& task) {
    const size_t n = task.numFacts();
    const EffectIndex& E = task.effects;
    pre_begin.assign(E.size() + 1, 0);
    users_begin.assign(n + 1, 0);
    for (uint32_t e = 0; e < E.size(); ++e) {
      const Operator& op = task.ops[E.op[e]];
      const size_t from = pre.size();
      pre.insert(pre.end(), op.pre.begin(), op.pre.end());
      if (E.ce[e] >= 0) {
        const auto& c = op.cond_effects[static_cast<size_t>(E.ce[e])].cond;
        pre.insert(pre.end(), c.begin(), c.end());
      }
      std::sort(pre.begin() + static_cast<std::ptrdiff_t>(from), pre.end());
      pre.erase(std::unique(pre.begin() + static_cast<std::ptrdiff_t>(from), pre.end()), pre.end());
      pre_begin[e + 1] = static_cast<uint32_t>(pre.size());
      for (size_t k = from; k < pre.size(); ++k) ++users_begin[pre[k] + 1];
    }
    for (size_t f = 0; f < n; ++f) users_begin[f + 1] += users_begin[f];
    users.resize(users_begin[n]);
    std::vector<uint32_t> fill(users_begin.begin(), users_begin.end() - 1);
    for (uint32_t e = 0; e < E.size(); ++e) {
      for (uint32_t k = pre_begin[e]; k < pre_begin[e + 1]; ++k) users[fill[pre[k]]++] = e;
    }
  }
  uint32_t numPre(uint32_t e) const { return pre_begin[e + 1] - pre_begin[e]; }
};

const std::vector<FactId>& effectAdds(const Task& task, uint32_t e) {
  const EffectIndex& E = task.effects;
  const Operator& op = task.ops[E.op[e]];
  return E.ce[e] < 0 ? op.add : op.cond_effects[static_cast<size_t>(E.ce[e])].add;
}

bool positiveConjunctiveGoal(const Goal& goal) {
  return goal.conjuncts.size() == 1 && goal.conjuncts[0].neg.empty();
}

}  // namespace

LandmarkGraph zhuGivanLandmarks(const Task& task, const StateBits& init, const Goal& goal,
                                size_t max_label_entries) {
  LandmarkGraph graph;
  if (!positiveConjunctiveGoal(goal)) return graph;
  const std::vector<FactId>& goals = goal.conjuncts[0].pos;
  const size_t n = task.numFacts();
  const EffectIndex& E = task.effects;
  const RelaxedEffects R(task);

  // Label propagation to a fixpoint (worklist over effects whose preconditions are all reached).
  std::vector<std::vector<FactId>> label(n);
  std::vector<uint8_t> reached(n, 0), queued(E.size(), 0);
  std::vector<uint32_t> missing(E.size());
  std::vector<uint32_t> queue;
  size_t entries = 0;
  for (uint32_t e = 0; e < E.size(); ++e) {
    missing[e] = R.numPre(e);
    if (missing[e] == 0) {
      queue.push_back(e);
      queued[e] = 1;
    }
  }
  auto reach = [&](FactId f) {
    reached[f] = 1;
    for (uint32_t k = R.users_begin[f]; k < R.users_begin[f + 1]; ++k) {
      const uint32_t e = R.users[k];
      if (--missing[e] == 0 && !queued[e]) {
        queued[e] = 1;
        queue.push_back(e);
      }
    }
  };
  for (FactId f = 0; f < n; ++f) {
    if (testBit(init.data(), f)) {
      label[f] = {f};
      ++entries;
    }
  }
  for (FactId f = 0; f < n; ++f) {
    if (testBit(init.data(), f)) reach(f);
  }
  std::vector<FactId> lab, tmp;
  for (size_t head = 0; head < queue.size(); ++head) {
    if (entries > max_label_entries) return graph;
    const uint32_t e = queue[head];
    queued[e] = 0;
    lab.clear();
    for (uint32_t k = R.pre_begin[e]; k < R.pre_begin[e + 1]; ++k) {
      const auto& l = label[R.pre[k]];
      tmp.clear();
      std::set_union(lab.begin(), lab.end(), l.begin(), l.end(), std::back_inserter(tmp));
      lab.swap(tmp);
    }
    for (FactId f : effectAdds(task, e)) {
      if (testBit(init.data(), f)) continue;  // label {f}: cannot shrink
      tmp = lab;
      if (!std::binary_search(tmp.begin(), tmp.end(), f))
        tmp.insert(std::lower_bound(tmp.begin(), tmp.end(), f), f);
      bool changed = false;
      if (!reached[f]) {
        entries += tmp.size();
        label[f].swap(tmp);
        reach(f);
        changed = true;
      } else {
        std::vector<FactId> inter;
        std::set_intersection(label[f].begin(), label[f].end(), tmp.begin(), tmp.end(),
                              std::back_inserter(inter));
        if (inter.size() != label[f].size()) {
          entries -= label[f].size() - inter.size();
          label[f].swap(inter);
          changed = true;
        }
      }
      if (changed) {
        for (uint32_t k = R.users_begin[f]; k < R.users_begin[f + 1]; ++k) {
          const uint32_t u = R.users[k];
          if (missing[u] == 0 && !queued[u]) {
            queued[u] = 1;
            queue.push_back(u);
          }
        }
      }
    }
    // Keep the queue from growing without bound: compact the processed prefix now and then.
    if (head > 1'000'000 && head * 2 > queue.size()) {
      queue.erase(queue.begin(), queue.begin() + static_cast<std::ptrdiff_t>(head) + 1);
      head = static_cast<size_t>(-1);
    }
  }
  std::vector<FactId> lms;
  for (FactId g : goals) {
    if (!reached[g]) return graph;  // relaxed unreachable: h_FF reports the dead end
    lms.insert(lms.end(), label[g].begin(), label[g].end());
  }
  std::sort(lms.begin(), lms.end());
  lms.erase(std::unique(lms.begin(), lms.end()), lms.end());
  std::vector<int32_t> index(n, -1);
  for (uint32_t i = 0; i < lms.size(); ++i) {
    index[lms[i]] = static_cast<int32_t>(i);
    graph.landmarks.push_back({lms[i]});
  }
  graph.is_goal.assign(lms.size(), 0);
  for (FactId g : goals) graph.is_goal[static_cast<size_t>(index[g])] = 1;
  for (uint32_t i = 0; i < lms.size(); ++i) {
    for (FactId p : label[lms[i]]) {
      if (p != lms[i] && index[p] >= 0)
        graph.orders.push_back({static_cast<uint32_t>(index[p]), i, LandmarkOrderKind::kNatural});
    }
  }
  return graph;
}

void RhwLandmarkOptions::validate() const {
  if (max_work == 0) throw std::invalid_argument("RhwLandmarkOptions::max_work must be > 0, got 0");
  mutexes.validate();
}

namespace {

/// The PDDL predicate of each fact (complements apart), as a dense class id; -1 for a fact whose
/// name has no predicate.
std::vector<int32_t> predicateClasses(const Task& task) {
  std::unordered_map<std::string, int32_t> index;
  std::vector<int32_t> cls(task.numFacts(), -1);
  for (FactId f = 0; f < task.numFacts(); ++f) {
    const std::string& name = task.fact_names[f];
    if (name.empty() || name[0] != '(') continue;
    size_t start = 1;
    std::string prefix;
    if (name.rfind("(not (", 0) == 0) {
      start = 6;
      prefix = "not ";
    }
    const size_t end = name.find_first_of(" )", start);
    if (end == std::string::npos || end == start) continue;
    const std::string key = prefix + name.substr(start, end - start);
    cls[f] = index.emplace(key, static_cast<int32_t>(index.size())).first->second;
  }
  return cls;
}

/// Richter, Helmert & Westphal's back-chaining (see landmarks.h), on the STRIPS task.
class RhwBuilder {
 public:
  RhwBuilder(const Task& task, const StateBits& init, const RhwLandmarkOptions& options)
      : task_(task), init_(init), opt_(options), R_(task), cls_(predicateClasses(task)) {
    const size_t n = task.numFacts();
    simple_of_.assign(n, -1);
    disj_of_.assign(n, -1);
    reached_.assign(n, 0);
    excluded_fact_.assign(n, 0);
    count_.assign(n, 0);
    excluded_op_.assign(task.ops.size(), 0);
    missing_.resize(task.effects.size());
    int32_t classes = 0;
    for (int32_t c : cls_) classes = std::max(classes, c + 1);
    class_ops_.assign(static_cast<size_t>(classes), 0);
    class_last_op_.assign(static_cast<size_t>(classes), UINT32_MAX);
    class_facts_.resize(static_cast<size_t>(classes));
  }

  LandmarkGraph run(const std::vector<FactId>& goals) {
    explore({});
    for (FactId g : goals) {
      if (!reached_[g]) return {};  // relaxed unreachable: h_FF reports the dead end
    }
    for (FactId g : goals) foundSimple(g, UINT32_MAX, LandmarkOrderKind::kGreedyNecessary);
    drain();
    if (opt_.add_zhu_givan) {
      const LandmarkGraph zg = zhuGivanLandmarks(task_, init_, goalOf(goals));
      for (const auto& l : zg.landmarks) foundSimple(l[0], UINT32_MAX, LandmarkOrderKind::kNatural);
      drain();
    }
    LandmarkGraph graph;
    graph.landmarks = std::move(lms_);
    graph.is_goal.assign(graph.landmarks.size(), 0);
    for (FactId g : goals) graph.is_goal[static_cast<size_t>(simple_of_[g])] = 1;
    for (const auto& [key, kind] : orders_) graph.orders.push_back({key.first, key.second, kind});
    return graph;
  }

 private:
  static Goal goalOf(const std::vector<FactId>& goals) {
    Goal g;
    g.conjuncts.push_back(GoalConjunct{goals, {}});
    return g;
  }

  bool holdsInit(uint32_t l) const {
    return std::any_of(lms_[l].begin(), lms_[l].end(),
                       [&](FactId f) { return testBit(init_.data(), f); });
  }

  void push(uint32_t l) {
    if (l >= in_open_.size()) in_open_.resize(l + 1, 0);
    if (in_open_[l]) return;
    in_open_[l] = 1;
    open_.push_back(l);
  }

  void drain() {
    while (!open_.empty()) {
      const uint32_t l = open_.front();
      open_.pop_front();
      in_open_[l] = 0;
      if (work_ > opt_.max_work) continue;  // over budget: the landmarks found stay, unexpanded
      if (!holdsInit(l)) backchain(l);
    }
  }

  void addOrder(uint32_t from, uint32_t to, LandmarkOrderKind kind) {
    if (to == UINT32_MAX || from == to) return;
    if (kind == LandmarkOrderKind::kReasonable) {
      auto rev = orders_.find({to, from});
      if (rev != orders_.end()) {
        if (rev->second != LandmarkOrderKind::kReasonable)
          return;  // a stronger order the other way
        orders_.erase(rev);
      }
    }
    auto [it, inserted] = orders_.emplace(std::make_pair(from, to), kind);
    if (!inserted && it->second < kind) it->second = kind;
  }

  void foundSimple(FactId a, uint32_t to, LandmarkOrderKind kind) {
    if (simple_of_[a] >= 0) {
      addOrder(static_cast<uint32_t>(simple_of_[a]), to, kind);
      return;
    }
    if (disj_of_[a] >= 0) {
      // A simple landmark says more than a disjunction holding it: the disjunctive landmark
      // becomes simple; its orders to others no longer follow and are dropped (as Fast Downward).
      const auto d = static_cast<uint32_t>(disj_of_[a]);
      for (FactId g : lms_[d]) disj_of_[g] = -1;
      lms_[d] = {a};
      simple_of_[a] = static_cast<int32_t>(d);
      std::erase_if(orders_, [&](const auto& o) { return o.first.first == d; });
      addOrder(d, to, kind);
      push(d);
      return;
    }
    const auto l = static_cast<uint32_t>(lms_.size());
    lms_.push_back({a});
    simple_of_[a] = static_cast<int32_t>(l);
    addOrder(l, to, kind);
    push(l);
  }

  void foundDisjunctive(const std::vector<FactId>& facts, uint32_t to) {
    for (FactId f : facts) {
      if (testBit(init_.data(), f) || simple_of_[f] >= 0) return;
    }
    for (FactId f : facts) {
      if (disj_of_[f] >= 0) {
        const auto d = static_cast<uint32_t>(disj_of_[f]);
        if (lms_[d] == facts) addOrder(d, to, LandmarkOrderKind::kGreedyNecessary);
        return;  // the same landmark, or one overlapping it: not added
      }
    }
    const auto l = static_cast<uint32_t>(lms_.size());
    lms_.push_back(facts);
    for (FactId f : facts) disj_of_[f] = static_cast<int32_t>(l);
    addOrder(l, to, LandmarkOrderKind::kGreedyNecessary);
    push(l);
  }

  /// Relaxed reachability from the initial state without the facts `excluded` and without the
  /// operators that add one of them unconditionally: `reached_`.
  void explore(const std::vector<FactId>& excluded) {
    const EffectIndex& E = task_.effects;
    ++stamp_;
    for (FactId f : excluded) {
      excluded_fact_[f] = stamp_;
      for (uint32_t k = E.adders_begin[f]; k < E.adders_begin[f + 1]; ++k) {
        if (E.ce[E.adders[k]] < 0) excluded_op_[E.op[E.adders[k]]] = stamp_;
      }
    }
    std::fill(reached_.begin(), reached_.end(), 0);
    queue_.clear();
    for (uint32_t e = 0; e < E.size(); ++e) {
      missing_[e] = R_.numPre(e);
      if (missing_[e] == 0) queue_.push_back(e);
    }
    work_ += E.size() + task_.numFacts();
    auto reach = [&](FactId f) {
      if (reached_[f] || excluded_fact_[f] == stamp_) return;
      reached_[f] = 1;
      work_ += R_.users_begin[f + 1] - R_.users_begin[f];
      for (uint32_t k = R_.users_begin[f]; k < R_.users_begin[f + 1]; ++k) {
        if (--missing_[R_.users[k]] == 0) queue_.push_back(R_.users[k]);
      }
    };
    for (FactId f = 0; f < task_.numFacts(); ++f) {
      if (testBit(init_.data(), f)) reach(f);
    }
    for (size_t head = 0; head < queue_.size(); ++head) {
      const uint32_t e = queue_[head];
      if (excluded_op_[E.op[e]] == stamp_) continue;
      for (FactId f : effectAdds(task_, e)) reach(f);
    }
  }

  bool effectPossible(uint32_t e) const {
    for (uint32_t k = R_.pre_begin[e]; k < R_.pre_begin[e + 1]; ++k) {
      if (!reached_[R_.pre[k]]) return false;
    }
    return true;
  }

  /// The operators that can achieve landmark `l` first (`explore(lms_[l])` done), each with the
  /// preconditions it has when it does: its own and the conditions its achieving effects share.
  std::vector<std::vector<FactId>> firstAchieverPreconditions(uint32_t l) const {
    const EffectIndex& E = task_.effects;
    std::vector<std::pair<OpId, uint32_t>> achievers;  // (operator, effect)
    for (FactId f : lms_[l]) {
      for (uint32_t k = E.adders_begin[f]; k < E.adders_begin[f + 1]; ++k) {
        const uint32_t e = E.adders[k];
        if (effectPossible(e)) achievers.emplace_back(E.op[e], e);
      }
    }
    std::sort(achievers.begin(), achievers.end());
    achievers.erase(std::unique(achievers.begin(), achievers.end()), achievers.end());
    std::vector<std::vector<FactId>> result;
    achiever_names_.clear();
    for (size_t i = 0; i < achievers.size();) {
      const OpId o = achievers[i].first;
      const Operator& op = task_.ops[o];
      std::vector<FactId> cond;
      bool first = true;
      for (; i < achievers.size() && achievers[i].first == o; ++i) {
        const int32_t ce = E.ce[achievers[i].second];
        std::vector<FactId> c;
        if (ce >= 0) {
          c = op.cond_effects[static_cast<size_t>(ce)].cond;
          std::sort(c.begin(), c.end());
        }
        if (first) {
          cond = std::move(c);
          first = false;
        } else {
          std::vector<FactId> both;
          std::set_intersection(cond.begin(), cond.end(), c.begin(), c.end(),
                                std::back_inserter(both));
          cond.swap(both);
        }
      }
      std::vector<FactId> pre = op.pre;
      pre.insert(pre.end(), cond.begin(), cond.end());
      std::sort(pre.begin(), pre.end());
      pre.erase(std::unique(pre.begin(), pre.end()), pre.end());
      result.push_back(std::move(pre));
      achiever_names_.push_back(&op.name);
    }
    return result;
  }

  /// The `n` first achievers last collected are one ground action, split by grounding into one
  /// operator per alternative of its disjunctive precondition (they share its name).
  bool oneGroundAction(size_t n) const {
    for (size_t i = 1; i < n; ++i) {
      if (*achiever_names_[i] != *achiever_names_[0]) return false;
    }
    return true;
  }

  void backchain(uint32_t l) {
    explore(lms_[l]);
    const std::vector<std::vector<FactId>> pres = firstAchieverPreconditions(l);
    if (pres.empty()) return;  // unreachable without itself: left to h_FF's dead-end test
    const auto num_ops = static_cast<uint32_t>(pres.size());
    // Shared preconditions: simple landmarks, greedy-necessarily before l.
    std::vector<FactId> touched;
    for (const auto& pre : pres) {
      for (FactId f : pre) {
        if (count_[f]++ == 0) touched.push_back(f);
      }
    }
    std::vector<FactId> shared;
    for (FactId f : touched) {
      if (count_[f] == num_ops) shared.push_back(f);
      count_[f] = 0;
    }
    std::sort(shared.begin(), shared.end());
    for (FactId f : shared) foundSimple(f, l, LandmarkOrderKind::kGreedyNecessary);
    if (opt_.max_disjunction_size < 2) return;
    if (opt_.skip_one_action_disjunctions && oneGroundAction(pres.size())) return;
    // Disjunctive preconditions: one fact of one predicate from every achiever.
    std::vector<int32_t> classes;
    for (uint32_t i = 0; i < num_ops; ++i) {
      for (FactId f : pres[i]) {
        const int32_t c = cls_[f];
        if (c < 0 || simple_of_[f] >= 0) continue;
        const auto cu = static_cast<size_t>(c);
        if (class_last_op_[cu] != i) {
          if (class_ops_[cu] == 0) classes.push_back(c);
          class_last_op_[cu] = i;
          ++class_ops_[cu];
        }
        class_facts_[cu].push_back(f);
      }
    }
    std::sort(classes.begin(), classes.end());
    for (int32_t c : classes) {
      const auto cu = static_cast<size_t>(c);
      std::vector<FactId> facts = std::move(class_facts_[cu]);
      const bool everywhere = class_ops_[cu] == num_ops;
      class_facts_[cu].clear();
      class_ops_[cu] = 0;
      class_last_op_[cu] = UINT32_MAX;
      if (!everywhere) continue;
      std::sort(facts.begin(), facts.end());
      facts.erase(std::unique(facts.begin(), facts.end()), facts.end());
      if (facts.size() > 1 && facts.size() <= opt_.max_disjunction_size) foundDisjunctive(facts, l);
    }
  }

  const Task& task_;
  const StateBits& init_;
  const RhwLandmarkOptions& opt_;
  const RelaxedEffects R_;
  const std::vector<int32_t> cls_;
  std::vector<std::vector<FactId>> lms_;
  std::map<std::pair<uint32_t, uint32_t>, LandmarkOrderKind> orders_;
  std::vector<int32_t> simple_of_, disj_of_;
  std::deque<uint32_t> open_;
  std::vector<uint8_t> in_open_;
  // Scratch of the explorations and the intersections.
  std::vector<uint8_t> reached_;
  std::vector<uint32_t> excluded_fact_, excluded_op_, missing_, queue_, count_;
  std::vector<uint32_t> class_ops_, class_last_op_;
  std::vector<std::vector<FactId>> class_facts_;
  uint32_t stamp_{0};
  uint64_t work_{0};
  /// The names of the operators `firstAchieverPreconditions` returned, in its order.
  mutable std::vector<const std::string*> achiever_names_;
};

}  // namespace

LandmarkGraph rhwLandmarks(const Task& task, const StateBits& init, const Goal& goal,
                           const RhwLandmarkOptions& options, const Termination& term) {
  options.validate();
  if (!positiveConjunctiveGoal(goal)) return {};
  RhwBuilder builder(task, init, options);
  LandmarkGraph graph = builder.run(goal.conjuncts[0].pos);
  if (options.reasonable_orders && !graph.empty() && !term()) {
    const MutexTable mutexes(task, init, options.mutexes, term);
    if (term()) return graph;
    addReasonableOrders(task, init, mutexes, graph, options.max_interference_tests);
  }
  return graph;
}

namespace {

/// addReasonableOrders' state: the graph's orders by landmark, the interference tests.
class ReasonableOrderer {
 public:
  ReasonableOrderer(const Task& task, const MutexTable& mutexes, LandmarkGraph& graph,
                    uint64_t max_tests)
      : task_(task), mutexes_(mutexes), graph_(graph), max_tests_(max_tests) {
    const size_t n = graph.landmarks.size();
    parents_.resize(n);
    gn_children_.resize(n);
    for (const LandmarkOrder& o : graph.orders) {
      orders_[{o.from, o.to}] = o.kind;
      if (o.kind != LandmarkOrderKind::kReasonable) parents_[o.to].push_back({o.from, o.kind});
      if (o.kind == LandmarkOrderKind::kGreedyNecessary) gn_children_[o.from].push_back(o.to);
    }
    shared_.resize(n);
  }

  /// Adds the orders into B, a simple landmark not true initially.
  void ordersInto(uint32_t b) {
    if (graph_.is_goal[b]) {
      for (uint32_t a = 0; a < graph_.landmarks.size(); ++a) test(a, b);
      return;
    }
    std::vector<uint8_t> interesting(graph_.landmarks.size(), 0);
    std::vector<uint32_t> list;
    for (uint32_t c : gn_children_[b]) {
      for (const auto& [p, kind] : parents_[c]) {
        if (p == b || graph_.landmarks[p].size() > 1) continue;
        collectWithAncestors(p, interesting, list);
      }
    }
    for (uint32_t a : list) test(a, b);
  }

  void writeBack() {
    graph_.orders.clear();
    for (const auto& [key, kind] : orders_) graph_.orders.push_back({key.first, key.second, kind});
  }
  size_t added() const { return added_; }

 private:
  /// What every operator adding fact `a` also adds, and what it surely deletes.
  struct SharedEffects {
    bool computed{false};
    std::vector<FactId> adds, dels;
  };

  void collectWithAncestors(uint32_t p, std::vector<uint8_t>& seen, std::vector<uint32_t>& list) {
    if (seen[p]) return;
    seen[p] = 1;
    list.push_back(p);
    for (size_t head = list.size() - 1; head < list.size(); ++head) {
      for (const auto& [q, kind] : parents_[list[head]]) {
        if (!seen[q]) {
          seen[q] = 1;
          list.push_back(q);
        }
      }
    }
  }

  void test(uint32_t a, uint32_t b) {
    if (a == b || graph_.landmarks[a].size() > 1 || tests_ >= max_tests_) return;
    ++tests_;
    if (interferes(a, b)) addReasonable(a, b);
  }

  void addReasonable(uint32_t from, uint32_t to) {
    auto rev = orders_.find({to, from});
    if (rev != orders_.end()) {
      if (rev->second != LandmarkOrderKind::kReasonable) return;  // a stronger order the other way
      orders_.erase(rev);
      --added_;
    }
    if (orders_.emplace(std::make_pair(from, to), LandmarkOrderKind::kReasonable).second) ++added_;
  }

  /// Achieving landmark `a` after landmark `b` would delete b (see addReasonableOrders).
  bool interferes(uint32_t a, uint32_t b) {
    const FactId fa = graph_.landmarks[a][0], fb = graph_.landmarks[b][0];
    if (fa == fb) return false;
    if (mutexes_.mutex(fa, fb)) return true;
    const SharedEffects& s = shared(a);
    if (std::binary_search(s.dels.begin(), s.dels.end(), fb)) return true;
    for (FactId e : s.adds) {
      if (e != fa && e != fb && mutexes_.mutex(e, fb)) return true;
    }
    for (const auto& [x, kind] : parents_[a]) {
      if (kind != LandmarkOrderKind::kGreedyNecessary) continue;
      const auto& facts = graph_.landmarks[x];
      if (std::all_of(facts.begin(), facts.end(), [&](FactId f) { return mutexes_.mutex(f, fb); }))
        return true;
    }
    return false;
  }

  const SharedEffects& shared(uint32_t a) {
    SharedEffects& s = shared_[a];
    if (s.computed) return s;
    s.computed = true;
    const FactId fa = graph_.landmarks[a][0];
    const EffectIndex& E = task_.effects;
    bool first = true;
    for (uint32_t k = E.adders_begin[fa]; k < E.adders_begin[fa + 1]; ++k) {
      std::vector<FactId> adds, dels;
      effectsOf(E.adders[k], adds, dels);
      if (first) {
        s.adds = std::move(adds);
        s.dels = std::move(dels);
        first = false;
      } else {
        intersectInto(s.adds, adds);
        intersectInto(s.dels, dels);
      }
      if (s.adds.empty() && s.dels.empty()) break;
    }
    return s;
  }

  /// The facts effect `e` adds with its operator, and those it deletes and does not add.
  void effectsOf(uint32_t e, std::vector<FactId>& adds, std::vector<FactId>& dels) const {
    const Operator& op = task_.ops[task_.effects.op[e]];
    const int32_t ce = task_.effects.ce[e];
    adds = op.add;
    dels = op.del;
    if (ce >= 0) {
      const ConditionalEffect& c = op.cond_effects[static_cast<size_t>(ce)];
      adds.insert(adds.end(), c.add.begin(), c.add.end());
      dels.insert(dels.end(), c.del.begin(), c.del.end());
    }
    std::sort(adds.begin(), adds.end());
    adds.erase(std::unique(adds.begin(), adds.end()), adds.end());
    std::sort(dels.begin(), dels.end());
    std::vector<FactId> kept;
    std::set_difference(dels.begin(), dels.end(), adds.begin(), adds.end(),
                        std::back_inserter(kept));
    kept.erase(std::unique(kept.begin(), kept.end()), kept.end());
    dels.swap(kept);
  }

  static void intersectInto(std::vector<FactId>& into, const std::vector<FactId>& other) {
    std::vector<FactId> both;
    std::set_intersection(into.begin(), into.end(), other.begin(), other.end(),
                          std::back_inserter(both));
    into.swap(both);
  }

  const Task& task_;
  const MutexTable& mutexes_;
  LandmarkGraph& graph_;
  const uint64_t max_tests_;
  uint64_t tests_{0};
  size_t added_{0};
  std::map<std::pair<uint32_t, uint32_t>, LandmarkOrderKind> orders_;
  std::vector<std::vector<std::pair<uint32_t, LandmarkOrderKind>>> parents_;
  std::vector<std::vector<uint32_t>> gn_children_;
  std::vector<SharedEffects> shared_;
};

}  // namespace

size_t addReasonableOrders(const Task& task, const StateBits& init, const MutexTable& mutexes,
                           LandmarkGraph& graph, uint64_t max_tests) {
  if (graph.is_goal.size() != graph.landmarks.size())
    throw std::invalid_argument("addReasonableOrders: is_goal must have one entry per landmark");
  ReasonableOrderer orderer(task, mutexes, graph, max_tests);
  for (uint32_t b = 0; b < graph.landmarks.size(); ++b) {
    const auto& facts = graph.landmarks[b];
    if (facts.size() != 1 || testBit(init.data(), facts[0])) continue;
    orderer.ordersInto(b);
  }
  orderer.writeBack();
  return orderer.added();
}

namespace {

void buildCsr(size_t n, const std::vector<std::pair<uint32_t, uint32_t>>& edges,
              std::vector<uint32_t>& begin, std::vector<uint32_t>& items) {
  begin.assign(n + 1, 0);
  for (const auto& [key, value] : edges) ++begin[key + 1];
  for (size_t i = 0; i < n; ++i) begin[i + 1] += begin[i];
  items.resize(edges.size());
  std::vector<uint32_t> fill(begin.begin(), begin.end() - 1);
  for (const auto& [key, value] : edges) items[fill[key]++] = value;
}

}  // namespace

LandmarkCounter::LandmarkCounter(const Task& task, LandmarkGraph graph,
                                 LandmarkProgression progression)
    : task_(task), graph_(std::move(graph)), progression_(progression) {
  const size_t n = graph_.landmarks.size();
  if (graph_.is_goal.size() != n)
    throw std::invalid_argument("LandmarkCounter: is_goal must have one entry per landmark");
  for (const auto& l : graph_.landmarks) {
    if (l.empty()) throw std::invalid_argument("LandmarkCounter: a landmark without facts");
    if (l.size() > 1 && progression_ == LandmarkProgression::kAcceptedAfterParents) {
      throw std::invalid_argument(
          "LandmarkCounter: kAcceptedAfterParents counts simple landmarks only, got one of " +
          std::to_string(l.size()) + " facts");
    }
    for (FactId f : l) {
      if (f >= task.numFacts())
        throw std::invalid_argument("LandmarkCounter: fact " + std::to_string(f) + " out of range");
    }
  }
  std::vector<std::pair<uint32_t, uint32_t>> parents, gn_children, reasonable_parents;
  for (const LandmarkOrder& o : graph_.orders) {
    if (o.from >= n || o.to >= n) {
      throw std::invalid_argument("LandmarkCounter: order " + std::to_string(o.from) + " -> " +
                                  std::to_string(o.to) + " names no landmark (" +
                                  std::to_string(n) + " landmarks)");
    }
    if (o.kind != LandmarkOrderKind::kReasonable) parents.emplace_back(o.to, o.from);
    if (o.kind == LandmarkOrderKind::kGreedyNecessary) gn_children.emplace_back(o.from, o.to);
    if (o.kind == LandmarkOrderKind::kReasonable) reasonable_parents.emplace_back(o.to, o.from);
  }
  buildCsr(n, parents, parents_begin_, parents_);
  buildCsr(n, gn_children, gn_children_begin_, gn_children_);
  buildCsr(n, reasonable_parents, reasonable_parents_begin_, reasonable_parents_);
  lm_words_ = (n + 63) / 64;
}

LandmarkCounter::LandmarkCounter(const Task& task, const StateBits& init, const Goal& goal,
                                 size_t max_label_entries)
    : LandmarkCounter(task, zhuGivanLandmarks(task, init, goal, max_label_entries),
                      LandmarkProgression::kAcceptedAfterParents) {}

bool LandmarkCounter::holds(uint32_t l, const uint64_t* state) const {
  for (FactId f : graph_.landmarks[l]) {
    if (testBit(state, f)) return true;
  }
  return false;
}

bool LandmarkCounter::parentsAccepted(uint32_t l, const uint64_t* accepted) const {
  for (uint32_t k = parents_begin_[l]; k < parents_begin_[l + 1]; ++k) {
    if (!testBit(accepted, parents_[k])) return false;
  }
  return true;
}

void LandmarkCounter::initial(const uint64_t* state, uint64_t* out) const {
  std::fill(out, out + words(), 0);
  const auto n = static_cast<uint32_t>(graph_.landmarks.size());
  for (uint32_t l = 0; l < n; ++l) {
    const bool h = holds(l, state);
    if (h) setBit(out, l);
    if (progression_ == LandmarkProgression::kPastAndFuture &&
        (!h || reasonable_parents_begin_[l] != reasonable_parents_begin_[l + 1])) {
      setBit(out + lm_words_, l);
    }
  }
}

void LandmarkCounter::progress(const uint64_t* parent_state, const uint64_t* parent,
                               const uint64_t* state, uint64_t* out) const {
  const auto n = static_cast<uint32_t>(graph_.landmarks.size());
  if (progression_ == LandmarkProgression::kAcceptedAfterParents) {
    std::copy(parent, parent + lm_words_, out);
    for (uint32_t l = 0; l < n; ++l) {
      if (!testBit(parent, l) && holds(l, state) && parentsAccepted(l, parent)) setBit(out, l);
    }
    return;
  }
  const uint64_t* parent_past = parent;
  const uint64_t* parent_future = parent + lm_words_;
  uint64_t* past = out;
  uint64_t* future = out + lm_words_;
  std::copy(parent_past, parent_past + lm_words_, past);
  std::fill(future, future + lm_words_, 0);
  // `holds` per landmark once: bit l of `past` is set below when it holds now.
  std::vector<uint64_t>& now = now_;
  now.assign(lm_words_, 0);
  for (uint32_t l = 0; l < n; ++l) {
    if (holds(l, state)) {
      setBit(now.data(), l);
      setBit(past, l);
    }
  }
  for (uint32_t l = 0; l < n; ++l) {
    const bool h = testBit(now.data(), l);
    bool fut =
        testBit(parent_future, l) && (!h || holds(l, parent_state));  // not added by this step
    if (!fut && !h && graph_.is_goal[l]) fut = true;
    if (!fut && !h) {
      for (uint32_t k = gn_children_begin_[l]; k < gn_children_begin_[l + 1] && !fut; ++k) {
        fut = !testBit(past, gn_children_[k]);  // required again
      }
    }
    for (uint32_t k = reasonable_parents_begin_[l]; k < reasonable_parents_begin_[l + 1] && !fut;
         ++k) {
      fut = !testBit(past, reasonable_parents_[k]);
    }
    if (fut) setBit(future, l);
  }
}

Cost LandmarkCounter::value(const uint64_t* state, const uint64_t* status) const {
  if (progression_ == LandmarkProgression::kPastAndFuture) {
    Cost h = 0;
    for (size_t w = 0; w < lm_words_; ++w) h += std::popcount(status[lm_words_ + w]);
    return h;
  }
  Cost h = 0;
  const auto n = static_cast<uint32_t>(graph_.landmarks.size());
  for (uint32_t l = 0; l < n; ++l) {
    if (!testBit(status, l)) {
      ++h;
    } else if (graph_.is_goal[l] && !holds(l, state)) {
      ++h;  // a goal accepted earlier and deleted since: required again
    }
  }
  return h;
}

void LandmarkCounter::preferred(const uint64_t* state, const uint64_t* status,
                                std::vector<OpId>& out) const {
  const EffectIndex& E = task_.effects;
  const auto n = static_cast<uint32_t>(graph_.landmarks.size());
  for (uint32_t l = 0; l < n; ++l) {
    if (progression_ == LandmarkProgression::kPastAndFuture) {
      if (!testBit(status + lm_words_, l) || holds(l, state)) continue;
    } else if (testBit(status, l) || !parentsAccepted(l, status)) {
      continue;
    }
    for (FactId f : graph_.landmarks[l]) {
      for (uint32_t k = E.adders_begin[f]; k < E.adders_begin[f + 1]; ++k) {
        const uint32_t e = E.adders[k];
        const OpId o = E.op[e];
        if (!task_.applicable(state, o)) continue;
        if (E.ce[e] >= 0) {
          bool ok = true;
          for (FactId c : task_.ops[o].cond_effects[static_cast<size_t>(E.ce[e])].cond)
            ok = ok && testBit(state, c);
          if (!ok) continue;
        }
        out.push_back(o);
      }
    }
  }
}

void LandmarkCounter::preferredAmong(const uint64_t* state, const uint64_t* status,
                                     const std::vector<OpId>& applicable,
                                     std::vector<OpId>& out) const {
  if (fact_mark_.size() != task_.numFacts()) {
    fact_mark_.assign(task_.numFacts(), 0);
    fact_epoch_ = 0;
  }
  if (++fact_epoch_ == 0) {
    std::fill(fact_mark_.begin(), fact_mark_.end(), 0);
    fact_epoch_ = 1;
  }
  const auto n = static_cast<uint32_t>(graph_.landmarks.size());
  bool any = false;
  for (uint32_t l = 0; l < n; ++l) {
    if (progression_ == LandmarkProgression::kPastAndFuture) {
      if (!testBit(status + lm_words_, l) || holds(l, state)) continue;
    } else if (testBit(status, l) || !parentsAccepted(l, status)) {
      continue;
    }
    for (FactId f : graph_.landmarks[l]) fact_mark_[f] = fact_epoch_;
    any = true;
  }
  if (!any) return;
  for (OpId o : applicable) {
    const Operator& op = task_.ops[o];
    bool adds = false;
    for (FactId f : op.add) {
      if (fact_mark_[f] == fact_epoch_) {
        adds = true;
        break;
      }
    }
    for (size_t c = 0; !adds && c < op.cond_effects.size(); ++c) {
      const ConditionalEffect& ce = op.cond_effects[c];
      bool marked = false;
      for (FactId f : ce.add) marked = marked || fact_mark_[f] == fact_epoch_;
      if (!marked) continue;
      bool holds_all = true;
      for (FactId f : ce.cond) holds_all = holds_all && testBit(state, f);
      adds = holds_all;
    }
    if (adds) out.push_back(o);
  }
}

}  // namespace tamp::symbolic_planner
