#include "tamp/symbolic_planner/heuristic.h"

#include <algorithm>
#include <stdexcept>

namespace tamp::symbolic_planner {
namespace {

constexpr Cost kInf = Heuristic::kDeadEnd;

/// A min-heap of (cost, fact) with reused storage.
class FactHeap {
 public:
  void clear() { v_.clear(); }
  bool empty() const { return v_.empty(); }
  void push(Cost c, FactId f) {
    v_.push_back({c, f});
    std::push_heap(v_.begin(), v_.end(), cmp);
  }
  std::pair<Cost, FactId> pop() {
    std::pop_heap(v_.begin(), v_.end(), cmp);
    auto e = v_.back();
    v_.pop_back();
    return e;
  }

 private:
  static bool cmp(const std::pair<Cost, FactId>& a, const std::pair<Cost, FactId>& b) { return a.first > b.first; }
  std::vector<std::pair<Cost, FactId>> v_;
};

class RelaxationHeuristic : public Heuristic {
 public:
  enum class Mode { kMax, kAdd, kFF };

  RelaxationHeuristic(const Task& task, CostType ct, Mode mode) : task_(task), mode_(mode) {
    const size_t nf = task.numFacts();
    std::vector<std::vector<uint32_t>> pre_of(nf);
    auto addRop = [&](OpId o, std::vector<FactId> pre, const std::vector<FactId>& add) {
      if (add.empty()) return;
      std::sort(pre.begin(), pre.end());
      pre.erase(std::unique(pre.begin(), pre.end()), pre.end());
      const uint32_t r = static_cast<uint32_t>(rop_op_.size());
      rop_op_.push_back(o);
      rop_pre_begin_.push_back(static_cast<uint32_t>(rop_pre_.size()));
      rop_pre_.insert(rop_pre_.end(), pre.begin(), pre.end());
      rop_add_begin_.push_back(static_cast<uint32_t>(rop_add_.size()));
      rop_add_.insert(rop_add_.end(), add.begin(), add.end());
      rop_count_.push_back(static_cast<uint32_t>(pre.size()));
      rop_base_.push_back(adjustedCost(task.ops[o], ct, task.unit_cost));
      for (FactId f : pre) pre_of[f].push_back(r);
      if (pre.empty()) no_pre_.push_back(r);
    };
    for (OpId o = 0; o < task.ops.size(); ++o) {
      const Operator& op = task.ops[o];
      addRop(o, op.pre, op.add);
      for (const auto& ce : op.cond_effects) {
        std::vector<FactId> pre = op.pre;
        pre.insert(pre.end(), ce.cond.begin(), ce.cond.end());
        addRop(o, std::move(pre), ce.add);
      }
    }
    rop_pre_begin_.push_back(static_cast<uint32_t>(rop_pre_.size()));
    rop_add_begin_.push_back(static_cast<uint32_t>(rop_add_.size()));
    {
      std::vector<std::vector<uint32_t>> adders(nf);
      for (uint32_t r = 0; r < rop_op_.size(); ++r) {
        for (uint32_t i = rop_add_begin_[r]; i < rop_add_begin_[r + 1]; ++i) adders[rop_add_[i]].push_back(r);
      }
      adders_begin_.resize(nf + 1);
      for (FactId f = 0; f < nf; ++f) {
        adders_begin_[f] = static_cast<uint32_t>(adders_.size());
        adders_.insert(adders_.end(), adders[f].begin(), adders[f].end());
      }
      adders_begin_[nf] = static_cast<uint32_t>(adders_.size());
    }
    // FF's own relaxed plan extraction (layers of h_max, achievers of least difficulty) when
    // every operator counts 1; otherwise FD-style extraction through h_add supporters.
    ff_layers_ = mode == Mode::kFF && (ct == CostType::kUnit || task.unit_cost);
    if (ff_layers_) mode_ = Mode::kMax;
    pre_of_begin_.resize(nf + 1);
    for (FactId f = 0; f < nf; ++f) {
      pre_of_begin_[f] = static_cast<uint32_t>(pre_of_.size());
      pre_of_.insert(pre_of_.end(), pre_of[f].begin(), pre_of[f].end());
    }
    pre_of_begin_[nf] = static_cast<uint32_t>(pre_of_.size());
    for (OpId o = 0; o < task.ops.size(); ++o) op_cost_.push_back(adjustedCost(task.ops[o], ct, task.unit_cost));
    fact_cost_.assign(nf, kInf);
    supporter_.assign(nf, UINT32_MAX);
    unsat_.resize(rop_op_.size());
    rop_cost_.resize(rop_op_.size());
    goal_stamp_.assign(nf, 0);
    fact_mark_.assign(nf, 0);
    op_mark_.assign(task.ops.size(), 0);
  }

  void setGoal(const Goal& goal) override {
    goal_ = goal;
    // Goal facts: a counter per conjunct for early termination.
    goal_of_.assign(task_.numFacts(), {});
    for (uint32_t c = 0; c < goal_.conjuncts.size(); ++c) {
      for (FactId f : goal_.conjuncts[c].pos) goal_of_[f].push_back(c);
    }
  }

  bool computesPreferred() const override { return mode_ == Mode::kFF || ff_layers_; }
  const std::vector<OpId>& preferred() const override { return preferred_; }

  Cost evaluate(const uint64_t* s) override {
    preferred_.clear();
    if (goal_.conjuncts.empty()) return kInf;
    if (task_.goalReached(s, goal_)) return 0;
    explore(s);
    // Best conjunct.
    Cost best = kInf;
    int best_c = -1;
    for (uint32_t c = 0; c < goal_.conjuncts.size(); ++c) {
      Cost v = 0;
      for (FactId f : goal_.conjuncts[c].pos) {
        const Cost fc = fact_cost_[f];
        if (fc == kInf) {
          v = kInf;
          break;
        }
        v = mode_ == Mode::kMax ? std::max(v, fc) : v + fc;
      }
      if (v < best) {
        best = v;
        best_c = static_cast<int>(c);
      }
    }
    if (best == kInf) return kInf;
    if (ff_layers_) return extractLayered(s, goal_.conjuncts[static_cast<size_t>(best_c)], best);
    if (mode_ != Mode::kFF) return best;
    return extract(s, goal_.conjuncts[static_cast<size_t>(best_c)]);
  }

 private:
  void explore(const uint64_t* s) {
    const size_t nf = task_.numFacts();
    std::fill(fact_cost_.begin(), fact_cost_.end(), kInf);
    std::copy(rop_count_.begin(), rop_count_.end(), unsat_.begin());
    std::fill(rop_cost_.begin(), rop_cost_.end(), 0);
    heap_.clear();
    ++stamp_;
    remaining_.assign(goal_.conjuncts.size(), 0);
    for (uint32_t c = 0; c < goal_.conjuncts.size(); ++c) remaining_[c] = static_cast<uint32_t>(goal_.conjuncts[c].pos.size());
    const size_t words = task_.numWords();
    for (size_t w = 0; w < words; ++w) {
      uint64_t word = s[w];
      while (word) {
        const FactId f = static_cast<FactId>(w * 64 + static_cast<size_t>(__builtin_ctzll(word)));
        word &= word - 1;
        if (f >= nf) break;
        fact_cost_[f] = 0;
        supporter_[f] = UINT32_MAX;
        heap_.push(0, f);
      }
    }
    for (uint32_t r : no_pre_) fire(r, 0);
    while (!heap_.empty()) {
      auto [c, f] = heap_.pop();
      if (c > fact_cost_[f]) continue;
      if (goal_stamp_[f] == stamp_) continue;  // already settled (duplicate entry, same cost)
      goal_stamp_[f] = stamp_;
      bool done = false;
      for (uint32_t gc : goal_of_[f]) {
        if (--remaining_[gc] == 0) done = true;
      }
      if (done) break;
      for (uint32_t i = pre_of_begin_[f]; i < pre_of_begin_[f + 1]; ++i) {
        const uint32_t r = pre_of_[i];
        if (mode_ == Mode::kMax) {
          rop_cost_[r] = std::max(rop_cost_[r], c);
        } else {
          rop_cost_[r] += c;
        }
        if (--unsat_[r] == 0) fire(r, rop_cost_[r]);
      }
    }
  }

  void fire(uint32_t r, Cost pre_cost) {
    const Cost nc = pre_cost + rop_base_[r];
    for (uint32_t i = rop_add_begin_[r]; i < rop_add_begin_[r + 1]; ++i) {
      const FactId g = rop_add_[i];
      if (nc < fact_cost_[g]) {
        fact_cost_[g] = nc;
        supporter_[g] = r;
        heap_.push(nc, g);
      }
    }
  }

  bool ropApplicable(const uint64_t* s, uint32_t r) const {
    for (uint32_t i = rop_pre_begin_[r]; i < rop_pre_begin_[r + 1]; ++i) {
      if (!testBit(s, rop_pre_[i])) return false;
    }
    return true;
  }

  Cost extract(const uint64_t* s, const GoalConjunct& gc) {
    ++mark_;
    if (mark_ == 0) {
      std::fill(fact_mark_.begin(), fact_mark_.end(), 0);
      std::fill(op_mark_.begin(), op_mark_.end(), 0);
      mark_ = 1;
    }
    Cost h = 0;
    stack_.clear();
    g1_.clear();
    plan_first_.clear();
    for (FactId f : gc.pos) stack_.push_back(f);
    while (!stack_.empty()) {
      const FactId f = stack_.back();
      stack_.pop_back();
      if (fact_mark_[f] == mark_ || testBit(s, f)) continue;
      fact_mark_[f] = mark_;
      const uint32_t r = supporter_[f];
      if (r == UINT32_MAX) continue;  // cannot happen for reached facts
      const OpId o = rop_op_[r];
      if (op_mark_[o] != mark_) {
        op_mark_[o] = mark_;
        h += op_cost_[o];
      }
      bool first_layer = true;
      for (uint32_t i = rop_pre_begin_[r]; i < rop_pre_begin_[r + 1]; ++i) {
        const FactId p = rop_pre_[i];
        if (!testBit(s, p)) {
          first_layer = false;
          stack_.push_back(p);
        }
      }
      if (first_layer) g1_.push_back(f);
    }
    // Helpful actions (FF): applicable operators that add a first-layer sub-goal.
    collectHelpful(s);
    return h;
  }

  /// FF's extraction (Hoffmann & Nebel 2001, Sec. 4.3): sub-goals are placed at their layer; from
  /// the top layer down, each open sub-goal gets the achiever of the previous layer with the least
  /// difficulty (sum of its preconditions' layers); the achiever's add effects count as true at
  /// this layer and the one below, so one action serves every sub-goal it adds.
  Cost extractLayered(const uint64_t* s, const GoalConjunct& gc, Cost top) {
    ++mark_;
    if (mark_ == 0) {
      std::fill(fact_mark_.begin(), fact_mark_.end(), 0);
      std::fill(op_mark_.begin(), op_mark_.end(), 0);
      mark_ = 1;
    }
    if (true_a_.size() != fact_mark_.size()) {
      true_a_.assign(fact_mark_.size(), 0);
      true_b_.assign(fact_mark_.size(), 0);
    }
    const size_t layers = static_cast<size_t>(top) + 1;
    if (layer_goals_.size() < layers) layer_goals_.resize(layers);
    for (size_t i = 0; i < layers; ++i) layer_goals_[i].clear();
    const uint64_t base = static_cast<uint64_t>(mark_) << 32;
    auto isTrue = [&](FactId f, Cost t) {
      const uint64_t v = base | static_cast<uint32_t>(t);
      return true_a_[f] == v || true_b_[f] == v;
    };
    auto addGoal = [&](FactId f) {
      if (fact_mark_[f] == mark_ || testBit(s, f)) return;
      fact_mark_[f] = mark_;
      layer_goals_[static_cast<size_t>(fact_cost_[f])].push_back(f);
    };
    for (FactId f : gc.pos) addGoal(f);
    Cost h = 0;
    g1_.clear();
    plan_first_.clear();
    for (size_t i = layers - 1; i >= 1; --i) {
      for (size_t k = 0; k < layer_goals_[i].size(); ++k) {
        const FactId g = layer_goals_[i][k];
        if (i == 1) g1_.push_back(g);
        if (isTrue(g, static_cast<Cost>(i))) continue;
        // Achiever at layer i-1 with the least difficulty.
        uint32_t best = UINT32_MAX;
        Cost best_d = kInf;
        for (uint32_t a = adders_begin_[g]; a < adders_begin_[g + 1]; ++a) {
          const uint32_t r = adders_[a];
          if (unsat_[r] != 0 || rop_cost_[r] != static_cast<Cost>(i - 1)) continue;
          Cost d = 0;
          for (uint32_t p = rop_pre_begin_[r]; p < rop_pre_begin_[r + 1]; ++p) d += fact_cost_[rop_pre_[p]];
          if (d < best_d) {
            best_d = d;
            best = r;
          }
        }
        if (best == UINT32_MAX) continue;  // cannot happen: g has level i
        const OpId o = rop_op_[best];
        if (op_mark_[o] != mark_) {
          op_mark_[o] = mark_;
          h += 1;
          if (i == 1) plan_first_.push_back(o);
        }
        for (uint32_t p = rop_pre_begin_[best]; p < rop_pre_begin_[best + 1]; ++p) {
          const FactId q = rop_pre_[p];
          if (fact_cost_[q] != 0 && !isTrue(q, static_cast<Cost>(i - 1))) addGoal(q);
        }
        for (uint32_t a = rop_add_begin_[best]; a < rop_add_begin_[best + 1]; ++a) {
          const FactId f = rop_add_[a];
          true_a_[f] = base | static_cast<uint32_t>(i);
          true_b_[f] = base | static_cast<uint32_t>(i - 1);
        }
      }
      if (i == 1) break;
    }
    collectHelpful(s);
    return h;
  }

  void collectHelpful(const uint64_t* s) {
    ++pref_mark_;
    if (pref_mark_ == 0 || pref_stamp_.size() != task_.ops.size()) {
      pref_stamp_.assign(task_.ops.size(), 0);
      pref_mark_ = 1;
    }
    // The relaxed plan's own first-layer actions first (EHC tries helpful actions in order).
    for (OpId o : plan_first_) {
      if (pref_stamp_[o] == pref_mark_ || !task_.applicable(s, o)) continue;
      pref_stamp_[o] = pref_mark_;
      preferred_.push_back(o);
    }
    for (FactId g : g1_) {
      for (OpId o : task_.achievers[g]) {
        if (pref_stamp_[o] == pref_mark_) continue;
        if (!task_.applicable(s, o) || !addsIn(s, o, g)) continue;
        pref_stamp_[o] = pref_mark_;
        preferred_.push_back(o);
      }
    }
  }

  bool addsIn(const uint64_t* s, OpId o, FactId g) const {
    const Operator& op = task_.ops[o];
    if (std::binary_search(op.add.begin(), op.add.end(), g)) return true;
    for (const auto& ce : op.cond_effects) {
      if (!std::binary_search(ce.add.begin(), ce.add.end(), g)) continue;
      bool ok = true;
      for (FactId f : ce.cond) ok = ok && testBit(s, f);
      if (ok) return true;
    }
    return false;
  }

  const Task& task_;
  Mode mode_;
  bool ff_layers_{false};
  std::vector<uint32_t> adders_begin_, adders_;
  std::vector<uint64_t> true_a_, true_b_;
  std::vector<std::vector<FactId>> layer_goals_;
  Goal goal_;
  std::vector<std::vector<uint32_t>> goal_of_;
  std::vector<uint32_t> remaining_;
  // Relaxed operators (CSR).
  std::vector<OpId> rop_op_;
  std::vector<uint32_t> rop_pre_begin_, rop_pre_, rop_add_begin_, rop_add_, rop_count_;
  std::vector<Cost> rop_base_, op_cost_;
  std::vector<uint32_t> pre_of_begin_, pre_of_, no_pre_;
  // Per evaluation.
  std::vector<Cost> fact_cost_, rop_cost_;
  std::vector<uint32_t> supporter_, unsat_;
  std::vector<uint32_t> goal_stamp_;
  uint32_t stamp_{0};
  FactHeap heap_;
  std::vector<uint32_t> fact_mark_, op_mark_, pref_stamp_;
  uint32_t mark_{0}, pref_mark_{0};
  std::vector<FactId> stack_, g1_;
  std::vector<OpId> plan_first_;
  std::vector<OpId> preferred_;
};

class BlindHeuristic : public Heuristic {
 public:
  explicit BlindHeuristic(const Task& task) : task_(task) {}
  void setGoal(const Goal& g) override { goal_ = g; }
  Cost evaluate(const uint64_t* s) override {
    if (goal_.conjuncts.empty()) return kDeadEnd;
    return task_.goalReached(s, goal_) ? 0 : 1;
  }

 private:
  const Task& task_;
  Goal goal_;
};

}  // namespace

std::unique_ptr<Heuristic> makeHeuristic(HeuristicKind kind, const Task& task, CostType cost_type) {
  switch (kind) {
    case HeuristicKind::kFF: return std::make_unique<RelaxationHeuristic>(task, cost_type, RelaxationHeuristic::Mode::kFF);
    case HeuristicKind::kAdd: return std::make_unique<RelaxationHeuristic>(task, cost_type, RelaxationHeuristic::Mode::kAdd);
    case HeuristicKind::kMax: return std::make_unique<RelaxationHeuristic>(task, cost_type, RelaxationHeuristic::Mode::kMax);
    case HeuristicKind::kBlind: return std::make_unique<BlindHeuristic>(task);
  }
  throw std::invalid_argument("makeHeuristic: unknown heuristic kind " + std::to_string(static_cast<int>(kind)));
}

}  // namespace tamp::symbolic_planner
