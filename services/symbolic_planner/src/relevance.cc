#include "tamp/symbolic_planner/relevance.h"

#include <algorithm>
#include <stdexcept>
#include <string>

#include "tamp/core/termination.h"
#include "tamp/symbolic_planner/flat_index.h"

namespace tamp::symbolic_planner {
namespace {

bool contains(const std::vector<FactId>& sorted, FactId f) { return std::binary_search(sorted.begin(), sorted.end(), f); }

/// The fixpoint of the file comment over one task and goal.
class Analysis {
 public:
  Analysis(const Task& task, const Goal& goal) : t_(task), goal_(goal) {
    const size_t nf = task.numFacts();
    rel_.assign(nf, 0);
    neg_.assign(nf, 0);
    op_rel_.assign(task.ops.size(), 0);
    ce_first_.assign(task.ops.size() + 1, 0);
    for (size_t o = 0; o < task.ops.size(); ++o) {
      ce_first_[o + 1] = ce_first_[o] + static_cast<uint32_t>(task.ops[o].cond_effects.size());
    }
    ce_kept_.assign(ce_first_.back(), 0);
  }

  void run() {
    const EffectIndex& e = t_.effects;
    for (const auto& c : goal_.conjuncts) {
      for (FactId f : c.pos) markRel(f);
      for (FactId f : c.neg) neg_[f] = 1;
    }
    // Operators that make a fact false that a goal needs false.
    for (const auto& c : goal_.conjuncts) {
      for (FactId g : c.neg) {
        for (uint32_t k = e.deleters_begin[g]; k < e.deleters_begin[g + 1]; ++k) {
          const uint32_t x = e.deleters[k];
          const OpId o = e.op[x];
          if (e.ce[x] < 0) {
            makeRelevant(o);
          } else if (contains(t_.ops[o].cond_effects[static_cast<size_t>(e.ce[x])].del, g)) {
            makeRelevant(o);
            keepCe(o, static_cast<uint32_t>(e.ce[x]));
          }
        }
      }
    }
    while (!queue_.empty()) {
      const FactId f = queue_.back();
      queue_.pop_back();
      for (uint32_t k = e.adders_begin[f]; k < e.adders_begin[f + 1]; ++k) {
        const uint32_t x = e.adders[k];
        const OpId o = e.op[x];
        makeRelevant(o);
        if (e.ce[x] >= 0) keepCe(o, static_cast<uint32_t>(e.ce[x]));
      }
      for (uint32_t k = e.deleters_begin[f]; k < e.deleters_begin[f + 1]; ++k) {
        const uint32_t x = e.deleters[k];
        const OpId o = e.op[x];
        if (!op_rel_[o]) continue;
        if (e.ce[x] >= 0 && contains(t_.ops[o].cond_effects[static_cast<size_t>(e.ce[x])].del, f)) {
          keepCe(o, static_cast<uint32_t>(e.ce[x]));
        }
        if (t_.ops[o].needs_fixup) markComplement(f);
      }
      // A relevant operator that recomputes complements and adds f: f's complement too.
      for (uint32_t k = e.adders_begin[f]; k < e.adders_begin[f + 1]; ++k) {
        if (t_.ops[e.op[e.adders[k]]].needs_fixup) markComplement(f);
      }
    }
  }

  /// The completeness check of the file comment: false when leaving the irrelevant operators out
  /// of a plan could change a kept fact the wrong way.
  bool complete() {
    const size_t nf = t_.numFacts();
    std::vector<char> more_true(nf, 0);
    std::vector<FactId> work;
    auto raise = [&](FactId f) {
      if (!kept(f) || more_true[f]) return;
      more_true[f] = 1;
      work.push_back(f);
    };
    bool any_conditional = false;
    for (OpId o = 0; o < t_.ops.size(); ++o) {
      any_conditional = any_conditional || (op_rel_[o] && !t_.ops[o].cond_effects.empty());
    }
    if (!any_conditional) return true;  // kept facts change only unconditionally: monotone
    for (OpId o = 0; o < t_.ops.size(); ++o) {
      if (op_rel_[o]) continue;
      for (FactId f : t_.ops[o].del) raise(f);
      for (const auto& ce : t_.ops[o].cond_effects) {
        for (FactId f : ce.del) raise(f);
      }
    }
    const EffectIndex& e = t_.effects;
    while (!work.empty()) {
      const FactId f = work.back();
      work.pop_back();
      if (neg_[f]) return false;
      for (uint32_t k = e.users_begin[f]; k < e.users_begin[f + 1]; ++k) {
        const uint32_t x = e.users[k];
        const OpId o = e.op[x];
        if (!op_rel_[o] || e.ce[x] < 0) continue;
        const uint32_t c = static_cast<uint32_t>(e.ce[x]);
        if (!ce_kept_[ce_first_[o] + c]) continue;
        const ConditionalEffect& ce = t_.ops[o].cond_effects[c];
        if (!contains(ce.cond, f)) continue;
        // It may fire where it would not have: its deletes may make a relevant fact false, its
        // adds may make facts true (or recompute complements) where they would not be.
        for (FactId d : ce.del) {
          if (rel_[d]) return false;
        }
        for (FactId a : ce.add) raise(a);
        if (t_.ops[o].needs_fixup) {
          for (FactId a : ce.add) {
            if (t_.complement[a] >= 0 && rel_[static_cast<size_t>(t_.complement[a])]) return false;
          }
        }
      }
    }
    return true;
  }

  bool kept(FactId f) const { return rel_[f] || neg_[f]; }
  bool opRelevant(OpId o) const { return op_rel_[o] != 0; }
  bool ceKept(OpId o, size_t c) const { return ce_kept_[ce_first_[o] + c] != 0; }

 private:
  void markRel(FactId f) {
    if (rel_[f]) return;
    rel_[f] = 1;
    queue_.push_back(f);
  }
  void markComplement(FactId f) {
    const int32_t c = t_.complement[f];
    if (c >= 0) markRel(static_cast<FactId>(c));
  }
  /// The complements of the kept facts an effect adds or deletes (negative preconditions).
  template <class Facts>
  void markComplementsOfKept(const Facts& add, const Facts& del) {
    for (FactId f : add) {
      if (kept(f)) markComplement(f);
    }
    for (FactId f : del) {
      if (kept(f)) markComplement(f);
    }
  }
  bool touchesKept(const ConditionalEffect& ce) const {
    for (FactId f : ce.add) {
      if (kept(f)) return true;
    }
    for (FactId f : ce.del) {
      if (kept(f)) return true;
    }
    return false;
  }
  void makeRelevant(OpId o) {
    if (op_rel_[o]) return;
    op_rel_[o] = 1;
    const Operator& op = t_.ops[o];
    for (FactId f : op.pre) markRel(f);
    if (op.needs_fixup) markComplementsOfKept(op.add, op.del);
    for (uint32_t c = 0; c < op.cond_effects.size(); ++c) {
      if (touchesKept(op.cond_effects[c])) keepCe(o, c);
    }
  }
  void keepCe(OpId o, uint32_t c) {
    char& k = ce_kept_[ce_first_[o] + c];
    if (k) return;
    k = 1;
    const Operator& op = t_.ops[o];
    const ConditionalEffect& ce = op.cond_effects[c];
    for (FactId f : ce.cond) markRel(f);
    if (op.needs_fixup) markComplementsOfKept(ce.add, ce.del);
  }

  const Task& t_;
  const Goal& goal_;
  std::vector<char> rel_, neg_, op_rel_, ce_kept_;
  std::vector<uint32_t> ce_first_;
  std::vector<FactId> queue_;
};

uint64_t mixIn(uint64_t h, uint64_t x) {
  h ^= x + 0x9E3779B97F4A7C15ULL + (h << 6) + (h >> 2);
  return h;
}

/// Mixes the kept facts of `v` (by their new ids) into `h`, then a separator.
uint64_t hashKept(uint64_t h, const std::vector<FactId>& v, const std::vector<int32_t>& fact_map) {
  for (FactId f : v) {
    if (fact_map[f] >= 0) h = mixIn(h, static_cast<uint64_t>(fact_map[f]));
  }
  return mixIn(h, 0xFFFFFFFFFFULL);
}

/// The same precondition and effects (costs aside).
bool sameOnFacts(const Operator& a, const Operator& b) {
  if (a.pre != b.pre || a.add != b.add || a.del != b.del || a.cond_effects.size() != b.cond_effects.size()) return false;
  for (size_t c = 0; c < a.cond_effects.size(); ++c) {
    const auto& x = a.cond_effects[c];
    const auto& y = b.cond_effects[c];
    if (x.cond != y.cond || x.add != y.add || x.del != y.del) return false;
  }
  return true;
}

/// The kept facts of `in` by their new ids, into `res` (sized once: an operator's vectors are
/// allocated once each, not grown).
void mapKept(const std::vector<FactId>& in, const std::vector<int32_t>& fact_map, std::vector<FactId>& res) {
  size_t n = 0;
  for (FactId f : in) n += fact_map[f] >= 0 ? 1 : 0;
  res.clear();
  if (n == 0) return;
  res.reserve(n);
  for (FactId f : in) {
    if (fact_map[f] >= 0) res.push_back(static_cast<FactId>(fact_map[f]));
  }
}

/// Operator `o`'s hash on the kept facts (precondition, effects, kept conditional effects);
/// counts its dropped conditional effects into `dropped`.
uint64_t hashOnKept(const Operator& src, OpId o, const Analysis& a, const std::vector<int32_t>& fact_map,
                    size_t& dropped) {
  uint64_t h = hashKept(hashKept(hashKept(0, src.pre, fact_map), src.add, fact_map), src.del, fact_map);
  for (size_t c = 0; c < src.cond_effects.size(); ++c) {
    if (!a.ceKept(o, c)) {
      ++dropped;
      continue;
    }
    const ConditionalEffect& ce = src.cond_effects[c];
    h = hashKept(hashKept(hashKept(mixIn(h, 0xCE), ce.cond, fact_map), ce.add, fact_map), ce.del, fact_map);
  }
  return h;
}

/// Operator `o` on the kept facts, without its name (set by the caller when it is kept).
Operator projectOperator(const Operator& src, OpId o, const Analysis& a, const std::vector<int32_t>& fact_map) {
  Operator op;
  op.cost = src.cost;
  op.needs_fixup = src.needs_fixup;
  mapKept(src.pre, fact_map, op.pre);
  mapKept(src.add, fact_map, op.add);
  mapKept(src.del, fact_map, op.del);
  for (size_t c = 0; c < src.cond_effects.size(); ++c) {
    if (!a.ceKept(o, c)) continue;
    ConditionalEffect ce;
    mapKept(src.cond_effects[c].cond, fact_map, ce.cond);
    mapKept(src.cond_effects[c].add, fact_map, ce.add);
    mapKept(src.cond_effects[c].del, fact_map, ce.del);
    op.cond_effects.push_back(std::move(ce));
  }
  return op;
}

/// The pruned operators by their hash on the kept facts: a flat map to the first one of each
/// hash and a chain through the others (no allocation per operator).
class SameHashChains {
 public:
  explicit SameHashChains(size_t expected) : head_(expected) { next_.reserve(expected); }

  /// The pruned operator with hash `h` that is the same as `op` on the kept facts, or UINT32_MAX.
  uint32_t find(uint64_t h, const Operator& op, const std::vector<Operator>& ops) const {
    for (uint32_t j = head_.find(h); j != UINT32_MAX; j = next_[j]) {
      if (sameOnFacts(ops[j], op)) return j;
    }
    return UINT32_MAX;
  }
  /// Records pruned operator `j` (the next index) under hash `h`.
  void add(uint64_t h, uint32_t j) {
    next_.resize(std::max<size_t>(next_.size(), j + 1), UINT32_MAX);
    const auto [first, inserted] = head_.tryEmplace(h, j);
    if (!inserted) {  // after the first of the chain
      next_[j] = next_[first];
      next_[first] = j;
    }
  }

 private:
  U64IdMap head_;
  std::vector<uint32_t> next_;
};

}  // namespace

StateBits PrunedTask::projectState(const uint64_t* s, size_t original_words) const {
  StateBits out(task ? task->numWords() : 1, 0);
  for (size_t f = 0; f < fact_map.size(); ++f) {
    if (fact_map[f] < 0 || (f >> 6) >= original_words) continue;
    if (testBit(s, static_cast<FactId>(f))) setBit(out.data(), static_cast<FactId>(fact_map[f]));
  }
  return out;
}

PrunedTask pruneIrrelevant(const Task& task, const Goal& goal, const Termination& term) {
  Stopwatch sw;
  PrunedTask out;
  const size_t nf = task.numFacts();
  for (const auto& c : goal.conjuncts) {
    for (FactId f : c.pos) {
      if (f >= nf) throw std::invalid_argument("pruneIrrelevant: goal fact " + std::to_string(f) + " out of range");
    }
    for (FactId f : c.neg) {
      if (f >= nf) throw std::invalid_argument("pruneIrrelevant: goal fact " + std::to_string(f) + " out of range");
    }
  }
  RelevanceStats& st = out.stats;
  st.facts_before = st.facts_after = nf;
  st.ops_before = st.ops_relevant = st.ops_after = task.ops.size();
  if (goal.unsatisfiable()) return out;  // nothing to reach: the search says so at once
  auto stopped = [&] {
    st.stopped = true;
    st.seconds = sw.seconds();
    out.fact_map.clear();
    out.op_origin.clear();
    out.goal = Goal{};
    return out;
  };
  if (term()) return stopped();
  Analysis a(task, goal);
  a.run();
  if (term()) return stopped();
  if (!a.complete()) {
    st.unsafe = true;
    st.seconds = sw.seconds();
    return out;
  }
  out.fact_map.assign(nf, -1);
  size_t kept_facts = 0;
  for (FactId f = 0; f < nf; ++f) {
    if (a.kept(f)) out.fact_map[f] = static_cast<int32_t>(kept_facts++);
  }
  // Each relevant operator's hash on the kept facts; when no fact, operator or conditional effect
  // is dropped and no two hashes meet (no operators the same on the kept facts), the task stays
  // as it is, without building anything.
  std::vector<uint64_t> op_hash(task.ops.size(), 0);
  size_t relevant = 0;
  bool hashes_meet = false;
  {
    U64IdMap seen(task.ops.size());
    for (OpId o = 0; o < task.ops.size(); ++o) {
      if ((o & 1023) == 1023 && term()) return stopped();
      if (!a.opRelevant(o)) continue;
      ++relevant;
      op_hash[o] = hashOnKept(task.ops[o], o, a, out.fact_map, st.cond_effects_dropped);
      hashes_meet = !seen.tryEmplace(op_hash[o], o).second || hashes_meet;
    }
  }
  st.ops_relevant = relevant;
  if (kept_facts == nf && relevant == task.ops.size() && st.cond_effects_dropped == 0 && !hashes_meet) {
    out.fact_map.clear();
    st.seconds = sw.seconds();
    return out;  // nothing to drop: the original task
  }
  auto pruned = std::make_shared<Task>();
  pruned->unit_cost = task.unit_cost;
  pruned->fact_names.reserve(kept_facts);
  pruned->complement.reserve(kept_facts);
  for (FactId f = 0; f < nf; ++f) {
    if (out.fact_map[f] < 0) continue;
    pruned->fact_names.push_back(task.fact_names[f]);
    const int32_t c = task.complement[f];
    pruned->complement.push_back(c >= 0 ? out.fact_map[static_cast<size_t>(c)] : -1);
  }
  // Relevant operators on the kept facts; of those the same on them, the cheapest at the first
  // one's place (looked for only when two hashes met).
  pruned->ops.reserve(relevant);
  out.op_origin.reserve(relevant);
  SameHashChains same(hashes_meet ? relevant : 0);
  for (OpId o = 0; o < task.ops.size(); ++o) {
    if ((o & 1023) == 1023 && term()) return stopped();
    if (!a.opRelevant(o)) continue;
    const Operator& src = task.ops[o];
    Operator op = projectOperator(src, o, a, out.fact_map);
    const uint32_t j = hashes_meet ? same.find(op_hash[o], op, pruned->ops) : UINT32_MAX;
    if (j != UINT32_MAX) {
      if (src.cost < pruned->ops[j].cost) {
        pruned->ops[j].cost = src.cost;
        pruned->ops[j].name = src.name;
        out.op_origin[j] = o;
      }
      continue;
    }
    op.name = src.name;
    if (hashes_meet) same.add(op_hash[o], static_cast<uint32_t>(pruned->ops.size()));
    pruned->ops.push_back(std::move(op));
    out.op_origin.push_back(o);
  }
  st.facts_after = kept_facts;
  st.ops_after = pruned->ops.size();
  if (st.ops_after == task.ops.size() && kept_facts == nf && st.cond_effects_dropped == 0) {
    out.fact_map.clear();  // hashes met by chance only: the original task
    out.op_origin.clear();
    st.seconds = sw.seconds();
    return out;
  }
  for (const auto& c : goal.conjuncts) {
    GoalConjunct gc;
    mapKept(c.pos, out.fact_map, gc.pos);
    mapKept(c.neg, out.fact_map, gc.neg);
    out.goal.conjuncts.push_back(std::move(gc));
  }
  if (term()) return stopped();
  pruned->finalize();
  out.task = std::move(pruned);
  st.seconds = sw.seconds();
  return out;
}

}  // namespace tamp::symbolic_planner
