#include "tamp/symbolic_planner/landmarks.h"

#include <algorithm>

namespace tamp::symbolic_planner {

LandmarkCounter::LandmarkCounter(const Task& task, const StateBits& init, const Goal& goal, size_t max_label_entries)
    : task_(task) {
  if (goal.conjuncts.size() != 1 || !goal.conjuncts[0].neg.empty()) return;
  const std::vector<FactId>& goals = goal.conjuncts[0].pos;
  const size_t n = task.numFacts();
  const EffectIndex& E = task.effects;
  // Each effect (an operator's unconditional part, or one conditional effect with its condition)
  // as a relaxed operator: its precondition facts (unique) and the facts it adds.
  std::vector<uint32_t> pre_begin(E.size() + 1, 0), users_begin(n + 1, 0);
  std::vector<FactId> pre;
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
  std::vector<uint32_t> users(users_begin[n]), fill(users_begin.begin(), users_begin.end() - 1);
  for (uint32_t e = 0; e < E.size(); ++e) {
    for (uint32_t k = pre_begin[e]; k < pre_begin[e + 1]; ++k) users[fill[pre[k]]++] = e;
  }
  auto adds = [&](uint32_t e) -> const std::vector<FactId>& {
    const Operator& op = task.ops[E.op[e]];
    return E.ce[e] < 0 ? op.add : op.cond_effects[static_cast<size_t>(E.ce[e])].add;
  };

  // Label propagation to a fixpoint (worklist over effects whose preconditions are all reached).
  std::vector<std::vector<FactId>> label(n);
  std::vector<uint8_t> reached(n, 0), queued(E.size(), 0);
  std::vector<uint32_t> missing(E.size());
  std::vector<uint32_t> queue;
  size_t entries = 0;
  for (uint32_t e = 0; e < E.size(); ++e) {
    missing[e] = pre_begin[e + 1] - pre_begin[e];
    if (missing[e] == 0) {
      queue.push_back(e);
      queued[e] = 1;
    }
  }
  auto reach = [&](FactId f) {
    reached[f] = 1;
    for (uint32_t k = users_begin[f]; k < users_begin[f + 1]; ++k) {
      const uint32_t e = users[k];
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
    if (entries > max_label_entries) return;
    const uint32_t e = queue[head];
    queued[e] = 0;
    lab.clear();
    for (uint32_t k = pre_begin[e]; k < pre_begin[e + 1]; ++k) {
      const auto& l = label[pre[k]];
      tmp.clear();
      std::set_union(lab.begin(), lab.end(), l.begin(), l.end(), std::back_inserter(tmp));
      lab.swap(tmp);
    }
    for (FactId f : adds(e)) {
      if (testBit(init.data(), f)) continue;  // label {f}: cannot shrink
      tmp = lab;
      if (!std::binary_search(tmp.begin(), tmp.end(), f)) tmp.insert(std::lower_bound(tmp.begin(), tmp.end(), f), f);
      bool changed = false;
      if (!reached[f]) {
        entries += tmp.size();
        label[f].swap(tmp);
        reach(f);
        changed = true;
      } else {
        std::vector<FactId> inter;
        std::set_intersection(label[f].begin(), label[f].end(), tmp.begin(), tmp.end(), std::back_inserter(inter));
        if (inter.size() != label[f].size()) {
          entries -= label[f].size() - inter.size();
          label[f].swap(inter);
          changed = true;
        }
      }
      if (changed) {
        for (uint32_t k = users_begin[f]; k < users_begin[f + 1]; ++k) {
          const uint32_t u = users[k];
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
    if (!reached[g]) return;  // relaxed unreachable: h_FF reports the dead end
    lms.insert(lms.end(), label[g].begin(), label[g].end());
  }
  std::sort(lms.begin(), lms.end());
  lms.erase(std::unique(lms.begin(), lms.end()), lms.end());
  landmarks_ = lms;
  words_ = (landmarks_.size() + 63) / 64;
  std::vector<int32_t> index(n, -1);
  for (uint32_t i = 0; i < landmarks_.size(); ++i) index[landmarks_[i]] = static_cast<int32_t>(i);
  is_goal_.assign(landmarks_.size(), 0);
  for (FactId g : goals) is_goal_[static_cast<size_t>(index[g])] = 1;
  parents_begin_.assign(landmarks_.size() + 1, 0);
  for (uint32_t i = 0; i < landmarks_.size(); ++i) {
    for (FactId p : label[landmarks_[i]]) {
      if (p != landmarks_[i] && index[p] >= 0) parents_.push_back(static_cast<uint32_t>(index[p]));
    }
    parents_begin_[i + 1] = static_cast<uint32_t>(parents_.size());
  }
}

bool LandmarkCounter::parentsAccepted(uint32_t l, const uint64_t* accepted) const {
  for (uint32_t k = parents_begin_[l]; k < parents_begin_[l + 1]; ++k) {
    if (!testBit(accepted, parents_[k])) return false;
  }
  return true;
}

void LandmarkCounter::initialAccepted(const uint64_t* state, uint64_t* out) const {
  std::fill(out, out + words_, 0);
  for (uint32_t i = 0; i < landmarks_.size(); ++i) {
    if (testBit(state, landmarks_[i])) setBit(out, i);
  }
}

void LandmarkCounter::progress(const uint64_t* parent, const uint64_t* state, uint64_t* out) const {
  std::copy(parent, parent + words_, out);
  for (uint32_t i = 0; i < landmarks_.size(); ++i) {
    if (!testBit(parent, i) && testBit(state, landmarks_[i]) && parentsAccepted(i, parent)) setBit(out, i);
  }
}

Cost LandmarkCounter::value(const uint64_t* state, const uint64_t* accepted) const {
  Cost h = 0;
  for (uint32_t i = 0; i < landmarks_.size(); ++i) {
    if (!testBit(accepted, i)) {
      ++h;
    } else if (is_goal_[i] && !testBit(state, landmarks_[i])) {
      ++h;  // a goal accepted earlier and deleted since: required again
    }
  }
  return h;
}

void LandmarkCounter::preferred(const uint64_t* state, const uint64_t* accepted, std::vector<OpId>& out) const {
  const EffectIndex& E = task_.effects;
  for (uint32_t i = 0; i < landmarks_.size(); ++i) {
    if (testBit(accepted, i) || !parentsAccepted(i, accepted)) continue;
    const FactId f = landmarks_[i];
    for (uint32_t k = E.adders_begin[f]; k < E.adders_begin[f + 1]; ++k) {
      const uint32_t e = E.adders[k];
      const OpId o = E.op[e];
      if (!task_.applicable(state, o)) continue;
      if (E.ce[e] >= 0) {
        bool ok = true;
        for (FactId c : task_.ops[o].cond_effects[static_cast<size_t>(E.ce[e])].cond) ok = ok && testBit(state, c);
        if (!ok) continue;
      }
      out.push_back(o);
    }
  }
}

}  // namespace tamp::symbolic_planner
