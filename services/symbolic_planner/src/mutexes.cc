#include "tamp/symbolic_planner/mutexes.h"

#include <algorithm>
#include <bit>
#include <stdexcept>
#include <string>

namespace tamp::symbolic_planner {

void H2MutexOptions::validate() const {
  if (max_work == 0) throw std::invalid_argument("H2MutexOptions::max_work must be > 0, got 0");
}

namespace {

/// Operators whose rows may have changed since they were last processed: a tick per row change.
struct ChangeClock {
  uint64_t now{1};
  std::vector<uint64_t> row_tick;  ///< fact -> tick of its row's last change
  uint64_t reached_tick{1};        ///< tick of the last newly reached fact
  std::vector<uint64_t> op_tick;   ///< operator -> tick when last processed (0 = never)

  bool stale(const Operator& op, OpId o) const {
    if (op_tick[o] == 0) return true;
    if (op.pre.empty() && reached_tick >= op_tick[o]) return true;
    for (FactId f : op.pre) {
      if (row_tick[f] >= op_tick[o]) return true;
    }
    for (const ConditionalEffect& ce : op.cond_effects) {
      for (FactId f : ce.cond) {
        if (row_tick[f] >= op_tick[o]) return true;
      }
    }
    return false;
  }
};

}  // namespace

MutexTable::MutexTable(const Task& task, const StateBits& init, const H2MutexOptions& options,
                       const Termination& term) {
  compute(task, init, options, nullptr, term);
}

std::optional<bool> MutexTable::reachesTogether(const Task& task, const StateBits& from,
                                                const std::vector<FactId>& facts,
                                                const H2MutexOptions& options, uint64_t* work,
                                                const Termination& term) {
  MutexTable t;
  t.compute(task, from, options, &facts, term);
  if (work != nullptr) *work = t.work_;
  if (t.n_ == 0) return std::nullopt;
  return t.stop_left_ == 0;
}

void MutexTable::compute(const Task& task, const StateBits& init, const H2MutexOptions& options,
                         const std::vector<FactId>* stop_facts, const Termination& term) {
  options.validate();
  if (init.size() < task.numWords()) {
    throw std::invalid_argument("MutexTable: the initial state has " + std::to_string(init.size()) +
                                " words, the task needs " + std::to_string(task.numWords()));
  }
  const size_t n = task.numFacts();
  if (n == 0 || n > options.max_facts) return;
  n_ = n;
  words_ = task.numWords();
  rows_.assign(n * words_, 0);
  compat_.assign(words_, 0);
  adds_.assign(words_, 0);
  for (FactId f = 0; f < n; ++f) {
    if (testBit(init.data(), f)) std::copy(init.begin(), init.begin() + words_, row(f));
  }
  if (stop_facts != nullptr) {
    stop_flag_.assign(n, 0);
    std::vector<FactId> distinct;
    for (FactId f : *stop_facts) {
      if (f >= n)
        throw std::invalid_argument("MutexTable::reachesTogether: fact " + std::to_string(f) +
                                    " of " + std::to_string(n));
      if (stop_flag_[f] == 0) distinct.push_back(f);
      stop_flag_[f] = 1;
    }
    stop_left_ = distinct.size() * (distinct.size() + 1) / 2;
    for (size_t i = 0; i < distinct.size(); ++i) {
      for (size_t j = i; j < distinct.size(); ++j) {
        if (pairReachable(distinct[i], distinct[j])) --stop_left_;
      }
    }
    if (stop_left_ == 0) return;
  }
  ChangeClock clock;
  clock.row_tick.assign(n, 1);
  clock.op_tick.assign(task.ops.size(), 0);
  // markPairs stamps the rows it changes with the tick after the operator's; only an operator
  // without precondition reads which facts they were (the reached ones make it stale).
  row_tick_ = clock.row_tick.data();
  struct Unset {
    uint64_t*& p;
    ~Unset() { p = nullptr; }
  } unset{row_tick_};  // the clock is compute()'s own
  track_new_ = std::any_of(task.ops.begin(), task.ops.end(), [](const Operator& op) { return op.pre.empty(); });
  for (bool changed = true; changed;) {
    changed = false;
    for (OpId o = 0; o < task.ops.size(); ++o) {
      if ((o & 63) == 0 && term()) {
        const uint64_t work = work_;
        *this = MutexTable();
        work_ = work;
        return;
      }
      if (!clock.stale(task.ops[o], o)) continue;
      clock.op_tick[o] = ++clock.now;
      tick_ = clock.now + 1;
      new_bits_.clear();
      if (!processOperator(task, o)) continue;
      changed = true;
      ++clock.now;
      for (FactId f : new_bits_) {
        if (pairReachable(f, f)) clock.reached_tick = clock.now;
      }
      if (work_ > options.max_work) {
        const uint64_t work = work_;
        *this = MutexTable();
        work_ = work;
        return;
      }
      if (stop_facts != nullptr && stop_left_ == 0) return;
    }
  }
}

bool MutexTable::allPairsReachable(const std::vector<FactId>& facts) const {
  for (size_t i = 0; i < facts.size(); ++i) {
    for (size_t j = i; j < facts.size(); ++j) {
      if (!pairReachable(facts[i], facts[j])) return false;
    }
  }
  return true;
}

/// One h^2 step of operator `o`: when its precondition is pairwise reachable, every fact it may
/// add is paired with every other such fact and with every fact that survives it and is
/// pairwise reachable with the precondition. Returns whether a pair was new; the facts whose rows
/// changed are appended to `new_bits_`.
bool MutexTable::processOperator(const Task& task, OpId o) {
  const Operator& op = task.ops[o];
  if (!allPairsReachable(op.pre)) return false;
  add_list_.assign(op.add.begin(), op.add.end());
  std::vector<FactId> pre_and_cond;
  for (const ConditionalEffect& ce : op.cond_effects) {
    pre_and_cond.assign(op.pre.begin(), op.pre.end());
    pre_and_cond.insert(pre_and_cond.end(), ce.cond.begin(), ce.cond.end());
    if (allPairsReachable(pre_and_cond))
      add_list_.insert(add_list_.end(), ce.add.begin(), ce.add.end());
  }
  if (add_list_.empty()) return false;
  // Facts that may hold with the precondition; the reachable ones when there is none.
  if (op.pre.empty()) {
    std::fill(compat_.begin(), compat_.end(), 0);
    for (FactId f = 0; f < n_; ++f) {
      if (pairReachable(f, f)) setBit(compat_.data(), f);
    }
  } else {
    const uint64_t* first = rows_.data() + static_cast<size_t>(op.pre[0]) * words_;
    std::copy(first, first + words_, compat_.begin());
    for (size_t k = 1; k < op.pre.size(); ++k) {
      const uint64_t* r = rows_.data() + static_cast<size_t>(op.pre[k]) * words_;
      for (size_t w = 0; w < words_; ++w) compat_[w] &= r[w];
    }
  }
  for (FactId p : add_list_) setBit(adds_.data(), p);
  for (FactId d : op.del) {
    if (!testBit(adds_.data(), d)) clearBit(compat_.data(), d);  // deleted for sure
  }
  for (size_t w = 0; w < words_; ++w) compat_[w] |= adds_[w];
  work_ += (op.pre.size() + add_list_.size() + 1) * words_;
  bool changed = false;
  for (FactId p : add_list_) changed = markPairs(p, compat_.data()) || changed;
  for (FactId p : add_list_) clearBit(adds_.data(), p);
  return changed;
}

/// Marks {p, q} reachable for every q set in `with` (both rows), stamping the changed rows with
/// `tick_` (and listing them in `new_bits_` when `track_new_`). Returns whether one was new.
bool MutexTable::markPairs(FactId p, const uint64_t* with) {
  uint64_t* rp = row(p);
  bool changed = false;
  for (size_t w = 0; w < words_; ++w) {
    uint64_t fresh = with[w] & ~rp[w];
    if (fresh == 0) continue;
    changed = true;
    rp[w] |= fresh;
    row_tick_[p] = tick_;
    if (track_new_) new_bits_.push_back(p);
    while (fresh != 0) {
      const auto q = static_cast<FactId>(w * 64 + static_cast<size_t>(std::countr_zero(fresh)));
      fresh &= fresh - 1;
      if (stop_left_ > 0 && stop_flag_[p] != 0 && stop_flag_[q] != 0) --stop_left_;
      setBit(row(q), p);
      row_tick_[q] = tick_;
      if (track_new_) new_bits_.push_back(q);
    }
  }
  return changed;
}

size_t MutexTable::numMutexPairs() const {
  if (n_ == 0) return 0;
  std::vector<uint64_t> reached(words_, 0);
  for (FactId f = 0; f < n_; ++f) {
    if (pairReachable(f, f)) setBit(reached.data(), f);
  }
  size_t count = 0;
  for (FactId a = 0; a < n_; ++a) {
    if (!pairReachable(a, a)) continue;
    const uint64_t* r = rows_.data() + static_cast<size_t>(a) * words_;
    for (size_t w = 0; w < words_; ++w)
      count += static_cast<size_t>(std::popcount(reached[w] & ~r[w]));
  }
  return count / 2;
}

}  // namespace tamp::symbolic_planner
