#include "tamp/symbolic_planner/task.h"

#include <algorithm>
#include <bit>

namespace tamp::symbolic_planner {

void Task::finalize() {
  const size_t n = numFacts();
  constexpr OpId kNoOp = UINT32_MAX;
  // Every list is sized first and filled after (one allocation each; same contents and order as
  // appending): achievers (an operator once per fact), operators by key precondition.
  std::vector<uint32_t> pre_count(n, 0), ach_count(n, 0);
  std::vector<OpId> last(n, kNoOp);
  auto countAch = [&](OpId o, FactId f) {
    if (last[f] != o) {
      last[f] = o;
      ++ach_count[f];
    }
  };
  for (OpId o = 0; o < ops.size(); ++o) {
    const auto& op = ops[o];
    for (FactId f : op.add) countAch(o, f);
    for (const auto& ce : op.cond_effects) {
      for (FactId f : ce.add) countAch(o, f);
    }
    for (FactId f : op.pre) ++pre_count[f];
  }
  achievers.assign(n, {});
  for (size_t f = 0; f < n; ++f) achievers[f].reserve(ach_count[f]);
  for (OpId o = 0; o < ops.size(); ++o) {
    auto& op = ops[o];
    auto addAch = [&](FactId f) {
      if (achievers[f].empty() || achievers[f].back() != o) achievers[f].push_back(o);
    };
    for (FactId f : op.add) addAch(f);
    for (const auto& ce : op.cond_effects) {
      for (FactId f : ce.add) addAch(f);
    }
  }
  buildEffectIndex();
  // Key precondition: the one whose fact has the fewest... we use a proxy for "rarely true":
  // facts that are preconditions of few operators are specific (e.g. an object's position);
  // facts shared by many operators (hand-empty) are often true.
  std::vector<FactId> keys(ops.size(), 0);
  std::vector<uint32_t> key_count(n, 0);
  size_t without_pre = 0;
  for (OpId o = 0; o < ops.size(); ++o) {
    const auto& pre = ops[o].pre;
    if (pre.empty()) {
      ++without_pre;
      continue;
    }
    FactId key = pre[0];
    for (FactId f : pre) {
      if (pre_count[f] < pre_count[key]) key = f;
    }
    keys[o] = key;
    ++key_count[key];
  }
  ops_by_key_.assign(n, {});
  for (size_t f = 0; f < n; ++f) ops_by_key_[f].reserve(key_count[f]);
  ops_without_pre_.clear();
  ops_without_pre_.reserve(without_pre);
  for (OpId o = 0; o < ops.size(); ++o) {
    if (ops[o].pre.empty()) {
      ops_without_pre_.push_back(o);
    } else {
      ops_by_key_[keys[o]].push_back(o);
    }
  }
}

void Task::buildEffectIndex() {
  const size_t n = numFacts();
  EffectIndex& e = effects;
  e = EffectIndex{};
  size_t num_effects = ops.size();
  for (const auto& op : ops) num_effects += op.cond_effects.size();
  e.op.reserve(num_effects);
  e.ce.reserve(num_effects);
  for (OpId o = 0; o < ops.size(); ++o) {
    e.op.push_back(o);
    e.ce.push_back(-1);
  }
  for (OpId o = 0; o < ops.size(); ++o) {
    for (size_t c = 0; c < ops[o].cond_effects.size(); ++c) {
      e.op.push_back(o);
      e.ce.push_back(static_cast<int32_t>(c));
    }
  }
  // Two passes per index: count, then fill (effects stay in increasing order per fact).
  auto build = [&](std::vector<uint32_t>& begin, std::vector<uint32_t>& out, auto&& forEach) {
    begin.assign(n + 1, 0);
    for (uint32_t x = 0; x < e.size(); ++x) forEach(x, [&](FactId f) { ++begin[f + 1]; });
    for (size_t f = 0; f < n; ++f) begin[f + 1] += begin[f];
    out.resize(begin[n]);
    std::vector<uint32_t> fill(begin.begin(), begin.end() - 1);
    for (uint32_t x = 0; x < e.size(); ++x) forEach(x, [&](FactId f) { out[fill[f]++] = x; });
  };
  build(e.adders_begin, e.adders, [&](uint32_t x, auto&& fn) {
    const Operator& op = ops[e.op[x]];
    for (FactId f : e.ce[x] < 0 ? op.add : op.cond_effects[static_cast<size_t>(e.ce[x])].add) fn(f);
  });
  build(e.users_begin, e.users, [&](uint32_t x, auto&& fn) {
    const Operator& op = ops[e.op[x]];
    for (FactId f : op.pre) fn(f);
    if (e.ce[x] >= 0) {
      for (FactId f : op.cond_effects[static_cast<size_t>(e.ce[x])].cond) fn(f);
    }
  });
  build(e.deleters_begin, e.deleters, [&](uint32_t x, auto&& fn) {
    const Operator& op = ops[e.op[x]];
    for (FactId f : op.del) fn(f);
    if (e.ce[x] >= 0) {
      for (FactId f : op.cond_effects[static_cast<size_t>(e.ce[x])].del) fn(f);
    }
  });
}

void Task::apply(const uint64_t* s, OpId o, uint64_t* out) const {
  const size_t w = numWords();
  std::copy(s, s + w, out);
  const Operator& op = ops[o];
  for (FactId f : op.del) clearBit(out, f);
  if (op.cond_effects.empty()) {
    for (FactId f : op.add) setBit(out, f);
    return;
  }
  // Conditions are evaluated in the old state `s`; deletes before adds.
  thread_local std::vector<const ConditionalEffect*> firing;
  firing.clear();
  for (const auto& ce : op.cond_effects) {
    bool ok = true;
    for (FactId f : ce.cond) {
      if (!testBit(s, f)) {
        ok = false;
        break;
      }
    }
    if (ok) firing.push_back(&ce);
  }
  for (const auto* ce : firing) {
    for (FactId f : ce->del) clearBit(out, f);
  }
  for (FactId f : op.add) setBit(out, f);
  for (const auto* ce : firing) {
    for (FactId f : ce->add) setBit(out, f);
  }
  if (op.needs_fixup) {
    auto fix = [&](FactId f) {
      const int32_t c = complement[f];
      if (c < 0) return;
      // A primary fact and its complement: the complement is the negation of the primary.
      const bool f_is_primary = f < static_cast<FactId>(c);
      const FactId p = f_is_primary ? f : static_cast<FactId>(c);
      const FactId q = f_is_primary ? static_cast<FactId>(c) : f;
      if (testBit(out, p)) clearBit(out, q); else setBit(out, q);
    };
    for (FactId f : op.add) fix(f);
    for (FactId f : op.del) fix(f);
    for (const auto* ce : firing) {
      for (FactId f : ce->add) fix(f);
      for (FactId f : ce->del) fix(f);
    }
  }
}

void Task::applicableOps(const uint64_t* s, std::vector<OpId>& out) const {
  for (OpId o : ops_without_pre_) out.push_back(o);
  const size_t w = numWords();
  for (size_t i = 0; i < w; ++i) {
    uint64_t word = s[i];
    while (word) {
      const int b = std::countr_zero(word);
      word &= word - 1;
      const FactId f = static_cast<FactId>(i * 64 + static_cast<size_t>(b));
      for (OpId o : ops_by_key_[f]) {
        if (applicable(s, o)) out.push_back(o);
      }
    }
  }
}

bool Task::goalReached(const uint64_t* s, const Goal& g) const {
  for (const auto& c : g.conjuncts) {
    bool ok = true;
    for (FactId f : c.pos) {
      if (!testBit(s, f)) {
        ok = false;
        break;
      }
    }
    if (!ok) continue;
    for (FactId f : c.neg) {
      if (testBit(s, f)) {
        ok = false;
        break;
      }
    }
    if (ok) return true;
  }
  return false;
}

}  // namespace tamp::symbolic_planner
