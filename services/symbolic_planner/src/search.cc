#include "tamp/symbolic_planner/search.h"

#include <deque>
#include <queue>
#include <limits>
#include <map>
#include <memory>

#include "tamp/symbolic_planner/landmarks.h"

#include <algorithm>
#include <cmath>
#include <condition_variable>
#include <coroutine>
#include <exception>
#include <functional>
#include <mutex>
#include <optional>
#include <stdexcept>
#include <stop_token>
#include <thread>
#include <utility>

namespace tamp::symbolic_planner {
namespace {

constexpr uint32_t kNone = UINT32_MAX;

/// A search that runs in steps: created suspended; each `resume()` runs it to its next
/// suspension (the end of a turn) or to its end, after which `result()` holds its answer. An
/// exception thrown inside comes out of the `resume()` that ran into it.
class SearchCoroutine {
 public:
  struct promise_type {
    SearchResult result;
    std::exception_ptr error;
    SearchCoroutine get_return_object() {
      return SearchCoroutine(std::coroutine_handle<promise_type>::from_promise(*this));
    }
    std::suspend_always initial_suspend() noexcept { return {}; }
    std::suspend_always final_suspend() noexcept { return {}; }
    void return_value(SearchResult r) { result = std::move(r); }
    void unhandled_exception() { error = std::current_exception(); }
  };
  explicit SearchCoroutine(std::coroutine_handle<promise_type> h) : h_(h) {}
  SearchCoroutine(SearchCoroutine&& o) noexcept : h_(std::exchange(o.h_, {})) {}
  SearchCoroutine& operator=(SearchCoroutine&&) = delete;
  SearchCoroutine(const SearchCoroutine&) = delete;
  ~SearchCoroutine() {
    if (h_) h_.destroy();
  }
  bool done() const { return h_.done(); }
  void resume() {
    h_.resume();
    if (h_.done() && h_.promise().error) std::rethrow_exception(std::exchange(h_.promise().error, nullptr));
  }
  /// Runs the rest of the search in one go.
  void runToEnd() {
    while (!done()) resume();
  }
  SearchResult& result() { return h_.promise().result; }
  const SearchResult& result() const { return h_.promise().result; }

 private:
  std::coroutine_handle<promise_type> h_;
};

/// What a hill-climbing run calls when another search takes turns with it
/// (`SearchOptions::ehc_lazy_beside`): `evaluated()` after each of its evaluations (and the other
/// search may run a turn inside it), `stopped()` once the other has given a final answer.
class TurnTaker {
 public:
  virtual ~TurnTaker() = default;
  virtual void evaluated() = 0;
  virtual bool stopped() const = 0;
};

/// What a search running in turns with another one on another thread calls after each of its
/// evaluations (`SearchOptions::unit_beside_time_share`): the thread's hook (`t_evaluation_hook`)
/// may hand the control to the other search there.
class EvaluationHook {
 public:
  virtual ~EvaluationHook() = default;
  virtual void evaluated() = 0;
  /// A hill-climbing run committed to a better state.
  virtual void climbed() {}
  /// A lazy search reached a state with `count` landmarks left, fewer than any before it.
  virtual void landmarksLeft(Cost /*count*/) {}
};

/// The hook of this thread's searches (none: nullptr).
thread_local EvaluationHook* t_evaluation_hook = nullptr;

/// Sets this thread's evaluation hook for its scope.
class ScopedEvaluationHook {
 public:
  explicit ScopedEvaluationHook(EvaluationHook* hook) : previous_(std::exchange(t_evaluation_hook, hook)) {}
  ~ScopedEvaluationHook() { t_evaluation_hook = previous_; }
  ScopedEvaluationHook(const ScopedEvaluationHook&) = delete;
  ScopedEvaluationHook& operator=(const ScopedEvaluationHook&) = delete;

 private:
  EvaluationHook* previous_;
};

/// A search run on a thread of its own that never runs at the same time as its caller: `resume()`
/// hands it the control and waits until it hands it back, after a number of evaluations, at a
/// time point (checked every 16 evaluations), or at its end. One of the two threads runs at a
/// time, so a search in turns with another evaluates the same states in every run (where a turn
/// ends at a time point aside). Its `Termination` has the caller's deadline and a stop token of
/// its own, also stopped by the caller's; `cancel()` stops it and runs it to its (near) end, which
/// frees its states.
class SearchFiber : public EvaluationHook {
 public:
  using Body = std::function<SearchResult(const Termination&)>;

  SearchFiber(Body body, const Termination& term)
      : link_(term.token(), StopRequest{&stop_}),
        term_(term.deadline(), stop_.get_token()),
        body_(std::move(body)),
        thread_([this] { main(); }) {}
  ~SearchFiber() override {
    try {
      cancel();
    } catch (...) {  // its exception has no caller left to go to
    }
    thread_.join();
  }
  SearchFiber(const SearchFiber&) = delete;
  SearchFiber& operator=(const SearchFiber&) = delete;

  /// Runs the search until it has done `evaluations` more evaluations, `until` has passed, or it
  /// has ended; an exception thrown in it comes out here.
  void resume(uint64_t evaluations, std::optional<Clock::time_point> until) {
    if (done_) return;
    until_evaluations_ = evaluations > UINT64_MAX - evaluated_ ? UINT64_MAX : evaluated_ + evaluations;
    until_ = until;
    Stopwatch sw;
    {
      std::unique_lock<std::mutex> lock(mutex_);
      running_ = true;
      cv_.notify_all();
      cv_.wait(lock, [this] { return !running_; });
    }
    seconds_ += sw.seconds();
    if (done_ && error_) std::rethrow_exception(std::exchange(error_, nullptr));
  }
  /// Stops the search and runs it to its end (a few evaluations at most), or, not yet started,
  /// ends it without running it (its result then says kCancelled).
  void cancel() {
    if (done_) return;
    stop_.request_stop();
    if (!started_) abandoned_ = true;
    while (!done_) resume(UINT64_MAX, std::nullopt);
  }
  bool done() const { return done_; }
  /// The search's answer (once done).
  SearchResult& result() { return result_; }
  /// The time it has run, in seconds.
  double seconds() const { return seconds_; }
  /// Its evaluations so far, and how many it had done when it last made progress: a
  /// hill-climbing step to a better state, or a landmark count below every one before in any of
  /// its lazy searches (0: none yet).
  uint64_t evaluations() const { return evaluated_; }
  uint64_t evaluationsAtProgress() const { return evaluated_at_progress_; }

  void climbed() override { evaluated_at_progress_ = evaluated_; }
  void landmarksLeft(Cost count) override {
    if (count >= fewest_landmarks_) return;
    fewest_landmarks_ = count;
    evaluated_at_progress_ = evaluated_;
  }

  void evaluated() override {
    ++evaluated_;
    if (evaluated_ < until_evaluations_ &&
        (!until_ || (evaluated_ & 15) != 0 || Clock::now() < *until_)) {
      return;
    }
    std::unique_lock<std::mutex> lock(mutex_);
    running_ = false;
    cv_.notify_all();
    cv_.wait(lock, [this] { return running_; });
  }

 private:
  struct StopRequest {
    std::stop_source* source;
    void operator()() const { source->request_stop(); }
  };

  void main() {
    t_evaluation_hook = this;
    {
      std::unique_lock<std::mutex> lock(mutex_);
      cv_.wait(lock, [this] { return running_; });
      started_ = true;
      if (abandoned_) {
        result_.status = SearchStatus::kCancelled;
        done_ = true;
        running_ = false;
        cv_.notify_all();
        return;
      }
    }
    try {
      result_ = body_(term_);
    } catch (...) {
      error_ = std::current_exception();
    }
    std::lock_guard<std::mutex> lock(mutex_);
    done_ = true;
    running_ = false;
    cv_.notify_all();
  }

  std::stop_source stop_;
  std::stop_callback<StopRequest> link_;
  Termination term_;
  Body body_;
  // Written by one thread while the other waits on the mutex: the hand-over orders them.
  SearchResult result_;
  std::exception_ptr error_;
  uint64_t evaluated_{0};
  uint64_t evaluated_at_progress_{0};
  Cost fewest_landmarks_{std::numeric_limits<Cost>::max()};
  uint64_t until_evaluations_{0};
  std::optional<Clock::time_point> until_;
  double seconds_{0.0};
  bool started_{false};
  bool abandoned_{false};
  bool done_{false};
  std::mutex mutex_;
  std::condition_variable cv_;
  bool running_{false};  // the fiber's turn (guarded by mutex_)
  std::thread thread_;   // last: started once the members above are made
};

/// All states of one search in one pool; an open-addressing hash set of ids.
class StateRegistry {
 public:
  explicit StateRegistry(size_t words) : w_(words == 0 ? 1 : words), slots_(1024, kNone) {}

  std::pair<uint32_t, bool> insert(const uint64_t* s) {
    if ((n_ + 1) * 4 > slots_.size() * 3) grow();
    const uint64_t h = hash(s);
    size_t i = h & (slots_.size() - 1);
    while (slots_[i] != kNone) {
      if (hashes_[slots_[i]] == static_cast<uint32_t>(h) && std::equal(s, s + w_, get(slots_[i]))) return {slots_[i], false};
      i = (i + 1) & (slots_.size() - 1);
    }
    const uint32_t id = static_cast<uint32_t>(n_++);
    pool_.insert(pool_.end(), s, s + w_);
    hashes_.push_back(static_cast<uint32_t>(h));
    slots_[i] = id;
    return {id, true};
  }
  /// The id of state `s`, or kNone when it is not registered.
  uint32_t find(const uint64_t* s) const {
    const uint64_t h = hash(s);
    size_t i = h & (slots_.size() - 1);
    while (slots_[i] != kNone) {
      if (hashes_[slots_[i]] == static_cast<uint32_t>(h) && std::equal(s, s + w_, get(slots_[i]))) return slots_[i];
      i = (i + 1) & (slots_.size() - 1);
    }
    return kNone;
  }
  const uint64_t* get(uint32_t id) const { return pool_.data() + static_cast<size_t>(id) * w_; }
  size_t size() const { return n_; }
  size_t bytes() const { return pool_.capacity() * 8 + slots_.size() * 4 + hashes_.capacity() * 4; }
  size_t words() const { return w_; }

 private:
  uint64_t hash(const uint64_t* s) const {
    uint64_t h = 0x243F6A8885A308D3ULL;
    for (size_t i = 0; i < w_; ++i) {
      h ^= s[i];
      h *= 0x9E3779B97F4A7C15ULL;
      h ^= h >> 32;
    }
    return h;
  }
  void grow() {
    std::vector<uint32_t> ns(slots_.size() * 2, kNone);
    for (uint32_t id = 0; id < n_; ++id) {
      size_t i = hash(get(id)) & (ns.size() - 1);
      while (ns[i] != kNone) i = (i + 1) & (ns.size() - 1);
      ns[i] = id;
    }
    slots_.swap(ns);
  }
  size_t w_;
  size_t n_{0};
  std::vector<uint64_t> pool_;
  std::vector<uint32_t> hashes_;
  std::vector<uint32_t> slots_;
};

struct HeapEntry {
  Cost key1;
  Cost key2;
  uint64_t order;
  uint32_t id;
};
struct HeapCmp {
  bool operator()(const HeapEntry& a, const HeapEntry& b) const {
    if (a.key1 != b.key1) return a.key1 > b.key1;
    if (a.key2 != b.key2) return a.key2 > b.key2;
    return a.order > b.order;
  }
};
class OpenList {
 public:
  void push(Cost k1, Cost k2, uint32_t id) {
    v_.push_back({k1, k2, counter_++, id});
    std::push_heap(v_.begin(), v_.end(), HeapCmp{});
  }
  HeapEntry pop() {
    std::pop_heap(v_.begin(), v_.end(), HeapCmp{});
    HeapEntry e = v_.back();
    v_.pop_back();
    return e;
  }
  bool empty() const { return v_.empty(); }
  size_t bytes() const { return v_.capacity() * sizeof(HeapEntry); }

 private:
  std::vector<HeapEntry> v_;
  uint64_t counter_{0};
};

/// FF's goal agenda (Koehler & Hoffmann 2000; FF-v2.3 `orderings.c`, approximation <=_h): goal j
/// is ordered before goal i when, with i true and kept true, j looks unachievable: every achiever
/// of j deletes i, or needs a precondition that only i-deleting achievers (or achievers needing a
/// fact of i's False set) provide. Returns the goal facts in entries to be achieved incrementally,
/// goals of equal rank in their given order. Uses the task's effect index (no per-call tables).
std::vector<std::vector<FactId>> goalAgenda(const Task& task, const std::vector<FactId>& goals) {
  const size_t n = goals.size();
  if (n < 2) return {goals};
  const EffectIndex& E = task.effects;
  auto range = [](const std::vector<uint32_t>& begin, const std::vector<uint32_t>& items, FactId f) {
    return std::pair<const uint32_t*, const uint32_t*>(items.data() + begin[f], items.data() + begin[f + 1]);
  };
  auto effPre = [&](uint32_t e, auto&& fn) {
    const Operator& op = task.ops[E.op[e]];
    for (FactId f : op.pre) fn(f);
    if (E.ce[e] >= 0) {
      for (FactId f : op.cond_effects[static_cast<size_t>(E.ce[e])].cond) fn(f);
    }
  };
  auto effDel = [&](uint32_t e, auto&& fn) {
    const Operator& op = task.ops[E.op[e]];
    for (FactId f : op.del) fn(f);
    if (E.ce[e] >= 0) {
      for (FactId f : op.cond_effects[static_cast<size_t>(E.ce[e])].del) fn(f);
    }
  };
  std::vector<char> usable(E.size(), 1);
  auto anyUsableAdder = [&](FactId p) {
    auto [b, e] = range(E.adders_begin, E.adders, p);
    for (const uint32_t* a = b; a != e; ++a) {
      if (usable[*a]) return true;
    }
    return false;
  };
  auto possiblyAchievable = [&](FactId f) {
    auto [b, e] = range(E.adders_begin, E.adders, f);
    for (const uint32_t* a = b; a != e; ++a) {
      if (!usable[*a]) continue;
      bool ok = true;
      effPre(*a, [&](FactId p) { ok = ok && anyUsableAdder(p); });
      if (ok) return true;
    }
    return false;
  };
  std::vector<uint32_t> del_count(task.numFacts(), 0);
  std::vector<FactId> touched;
  std::vector<std::vector<char>> m(n, std::vector<char>(n, 0));
  std::vector<uint32_t> excluded;
  for (size_t i = 0; i < n; ++i) {
    m[i][i] = 1;
    const FactId gi = goals[i];
    // False set: facts deleted by every achiever of gi.
    auto [ab, ae] = range(E.adders_begin, E.adders, gi);
    const size_t num_adders = static_cast<size_t>(ae - ab);
    touched.clear();
    for (const uint32_t* a = ab; a != ae; ++a) {
      effDel(*a, [&](FactId f) {
        if (del_count[f]++ == 0) touched.push_back(f);
      });
    }
    excluded.clear();
    for (FactId f : touched) {
      if (del_count[f] >= num_adders) {
        auto [ub, ue] = range(E.users_begin, E.users, f);
        excluded.insert(excluded.end(), ub, ue);
      }
      del_count[f] = 0;
    }
    auto [db, de] = range(E.deleters_begin, E.deleters, gi);
    excluded.insert(excluded.end(), db, de);
    for (uint32_t e : excluded) usable[e] = 0;
    for (size_t j = 0; j < n; ++j) {
      if (j != i && !possiblyAchievable(goals[j])) m[j][i] = 1;
    }
    for (uint32_t e : excluded) usable[e] = 1;
  }
  for (size_t j = 0; j < n; ++j) {
    for (size_t i = 0; i < n; ++i) {
      if (!m[i][j]) continue;
      for (size_t k = 0; k < n; ++k) {
        if (m[j][k]) m[i][k] = 1;
      }
    }
  }
  std::vector<int> degree(n, 0), hits(n, 0);
  for (size_t i = 0; i < n; ++i) {
    for (size_t j = 0; j < n; ++j) {
      if (i != j && m[i][j]) {
        --degree[i];
        ++degree[j];
        ++hits[i];
        ++hits[j];
      }
    }
  }
  std::vector<size_t> order(n);
  for (size_t i = 0; i < n; ++i) order[i] = i;
  std::stable_sort(order.begin(), order.end(), [&](size_t a, size_t b) {
    const bool da = hits[a] == 0, db = hits[b] == 0;
    if (da != db) return !da;  // disconnected goals last
    if (da) return false;
    return degree[a] < degree[b];
  });
  std::vector<std::vector<FactId>> agenda;
  for (size_t k = 0; k < n; ++k) {
    const size_t g = order[k];
    const bool new_entry = k == 0 || degree[g] != degree[order[k - 1]] ||
                           (hits[g] == 0) != (hits[order[k - 1]] == 0);
    if (new_entry) agenda.emplace_back();
    agenda.back().push_back(goals[g]);
  }
  return agenda;
}

/// Greedy action elimination (Nakhost & Mueller 2010): drop an action together with every later
/// action that becomes inapplicable without it, when the rest still reaches the goal. Never
/// increases the cost (costs are non-negative); repeated until no action can be dropped.
std::vector<OpId> eliminateRedundantActions(const Task& task, const StateBits& init, const Goal& goal,
                                            std::vector<OpId> plan, const Termination& term) {
  // One left-to-right pass: O(n^2) applications for a plan of n actions.
  const size_t w = task.numWords();
  StateBits prefix = init, cur(w), nxt(w);
  std::vector<OpId> kept;
  size_t i = 0;
  while (i < plan.size() && !term()) {
    cur = prefix;
    kept.assign(plan.begin(), plan.begin() + static_cast<std::ptrdiff_t>(i));
    for (size_t j = i + 1; j < plan.size(); ++j) {
      if (!task.applicable(cur.data(), plan[j])) continue;
      task.apply(cur.data(), plan[j], nxt.data());
      cur.swap(nxt);
      kept.push_back(plan[j]);
    }
    if (task.goalReached(cur.data(), goal)) {
      plan.swap(kept);  // drop plan[i] (and what depended on it); retry at the same position
      continue;
    }
    task.apply(prefix.data(), plan[i], nxt.data());
    prefix.swap(nxt);
    ++i;
  }
  return plan;
}

class Searcher {
 public:
  Searcher(const Task& task, const StateBits& init, const Goal& goal, const SearchOptions& opt, Heuristic& h,
           const Termination& term)
      : task_(task), init_(init), goal_(goal), opt_(opt), h_(h), term_(term), reg_(task.numWords()) {
    buf_.resize(task.numWords());
    succ_.resize(task.numWords());
  }

  /// The counters so far.
  const SearchStatistics& statistics() const { return stats_; }

  /// Hill-climbing runs: take turns with another search (see `TurnTaker`).
  void takeTurns(TurnTaker* turns) { turns_ = turns; }

  /// The lazy search prefers only its heuristic's preferred operators, none of the landmark
  /// count's (Fast Downward's `lama-first`: `lmcount(pref=false)`).
  void preferNoLandmarkAchievers() { landmark_preferred_ = false; }

  /// The lazy search counts the landmarks of `graph` (which must outlive the search and be the
  /// graph `makeLandmarkCounter` would build: the same task, initial state, goal and options)
  /// instead of building its own: two lazy searches beside one hill-climbing build it once.
  void shareLandmarkGraph(const LandmarkGraph* graph) { shared_landmarks_ = graph; }

  /// The lazy search (`kLazy`) from the start, suspended after every `turn` evaluations (> 0).
  SearchCoroutine lazyInTurns(uint64_t turn) {
    Stopwatch sw;
    h_.setGoal(goal_);
    SearchCoroutine steps = lazySteps(std::numeric_limits<Cost>::max(), turn);
    for (steps.resume(); !steps.done(); steps.resume()) co_await std::suspend_always{};
    co_return finished(std::move(steps.result()), sw, true);
  }

  SearchResult run() {
    Stopwatch sw;
    h_.setGoal(goal_);
    SearchResult r;
    if (goal_.unsatisfiable()) {
      r.status = SearchStatus::kUnsolvable;
    } else {
      switch (opt_.algorithm) {
        case SearchAlgorithm::kEhc: r = ehc(); break;
        case SearchAlgorithm::kGbfs: r = gbfs(); break;
        case SearchAlgorithm::kLazy: r = lazy(); break;
        case SearchAlgorithm::kWAstar: r = astar(opt_.weight); break;
        case SearchAlgorithm::kAstar: r = astar(1.0); break;
      }
    }
    const bool satisficing = opt_.algorithm == SearchAlgorithm::kEhc || opt_.algorithm == SearchAlgorithm::kGbfs ||
                             opt_.algorithm == SearchAlgorithm::kLazy;
    return finished(std::move(r), sw, satisficing);
  }

  /// One iteration of the anytime phase: `lazyWAstar(w, bound)` (w = 0: the lazy greedy search
  /// with landmarks, bounded), its plan (cost < bound) with
  /// redundant actions eliminated.
  SearchResult improve(double w, Cost bound) {
    Stopwatch sw;
    h_.setGoal(goal_);
    SearchResult r = w > 0 ? lazyWAstar(w, bound) : lazy(bound);
    return finished(std::move(r), sw, true);
  }

  /// Plan neighbourhood graph search (Nakhost & Mueller 2010): registers the states `plan` passes
  /// through and then, breadth-first from all of them, the states reached from them, until
  /// `max_states` are registered; returns the cheapest path from the initial state to a goal state
  /// through registered states only (uniform-cost). The plan's own path is among them, so the
  /// result costs at most the plan's. `*complete`: every registered state was expanded before the
  /// cap (the neighbourhood is the whole reachable space and the result is optimal).
  /// `grow`: when this searcher's last call built a neighbourhood of the same plan, go on from it
  /// (its breadth-first search resumes where the cap stopped it): the same states, in the same
  /// order, as a neighbourhood built afresh with the larger cap. The statistics are this call's.
  SearchResult neighbourhood(const std::vector<OpId>& plan, size_t max_states, bool grow, bool* complete) {
    Stopwatch sw;
    stats_ = SearchStatistics{};
    evaluated_at_check_ = 0;
    return finished(neighbourhoodSearch(plan, max_states, grow, complete), sw, true);
  }

 private:
  SearchResult neighbourhoodSearch(const std::vector<OpId>& plan, size_t max_states, bool grow, bool* complete) {
    *complete = false;
    bool is_new = false;
    if (!grow || !nbh_built_ || plan != nbh_plan_) {
      resetRegistry();
      std::copy(init_.begin(), init_.end(), buf_.begin());
      registerState(buf_.data(), &is_new);
      for (OpId o : plan) {
        task_.apply(buf_.data(), o, succ_.data());
        buf_.swap(succ_);
        registerState(buf_.data(), &is_new);
      }
      nbh_next_ = 0;
      nbh_plan_ = plan;
    }
    nbh_built_ = false;  // until this breadth-first search ends within its limits
    // Breadth-first: the registry's order is the queue's. A state whose expansion the cap cut
    // is expanded again when the neighbourhood grows (its registered successors are found, the
    // others added in the order a fresh build would add them).
    std::vector<OpId> ops;
    uint32_t next = nbh_next_;
    bool cut = false;
    while (next < reg_.size() && reg_.size() < max_states) {
      if (auto st = checkLimits()) return finish(*st);
      std::copy(reg_.get(next), reg_.get(next) + reg_.words(), buf_.begin());
      ++next;
      ++stats_.expanded;
      ops.clear();
      task_.applicableOps(buf_.data(), ops);
      for (size_t i = 0; i < ops.size(); ++i) {
        task_.apply(buf_.data(), ops[i], succ_.data());
        ++stats_.generated;
        registerState(succ_.data(), &is_new);
        if (reg_.size() >= max_states) {
          cut = i + 1 < ops.size();
          break;
        }
      }
    }
    nbh_next_ = cut ? next - 1 : next;
    nbh_built_ = true;
    *complete = !cut && next == reg_.size();
    // Uniform-cost search from the initial state (id 0) on the registered states.
    constexpr Cost kInf = std::numeric_limits<Cost>::max();
    std::fill(g_.begin(), g_.end(), kInf);
    g_[0] = 0;
    std::priority_queue<std::pair<Cost, uint32_t>, std::vector<std::pair<Cost, uint32_t>>, std::greater<>> open;
    open.emplace(0, 0);
    while (!open.empty()) {
      if (auto st = checkLimits()) return finish(*st);
      const auto [g, id] = open.top();
      open.pop();
      if (g != g_[id]) continue;
      std::copy(reg_.get(id), reg_.get(id) + reg_.words(), buf_.begin());
      if (task_.goalReached(buf_.data(), goal_)) return finish(SearchStatus::kSolved, path(id, kNone));
      ops.clear();
      task_.applicableOps(buf_.data(), ops);
      for (OpId o : ops) {
        task_.apply(buf_.data(), o, succ_.data());
        const uint32_t sid = reg_.find(succ_.data());
        if (sid == kNone || g + opCost(o) >= g_[sid]) continue;
        g_[sid] = g + opCost(o);
        parent_[sid] = id;
        op_[sid] = o;
        open.emplace(g_[sid], sid);
      }
    }
    return finish(SearchStatus::kUnsolvable);  // not reached: the plan's own path ends in a goal state
  }

 public:
  /// A search's result made final: redundant actions eliminated from a solved plan (when
  /// `eliminate` and the option say so), the statistics, and the plan's cost.
  SearchResult finished(SearchResult r, const Stopwatch& sw, bool eliminate) {
    if (r.status == SearchStatus::kSolved && eliminate && opt_.eliminate_redundant_actions) {
      const size_t before = r.plan.size();
      r.plan = eliminateRedundantActions(task_, init_, goal_, std::move(r.plan), term_);
      stats_.eliminated_actions = before - r.plan.size();
    }
    r.stats = stats_;
    r.stats.registered_states = reg_.size();
    r.stats.seconds = sw.seconds();
    r.cost = 0;
    for (OpId o : r.plan) r.cost += opCost(o);
    return r;
  }

 private:
  // --- per-state data ---------------------------------------------------------------------------
  uint32_t registerState(const uint64_t* s, bool* is_new) {
    auto [id, inserted] = reg_.insert(s);
    *is_new = inserted;
    if (inserted) {
      parent_.push_back(kNone);
      op_.push_back(kNone);
      g_.push_back(0);
      h_cache_.push_back(kUnknown);
      pref_begin_.push_back(0);
      pref_count_.push_back(0);
      flag_.push_back(0);
    }
    return id;
  }

  static constexpr Cost kUnknown = -1;

  Cost evaluate(uint32_t id) {
    if (h_cache_[id] != kUnknown) return h_cache_[id];
    ++stats_.evaluated;
    const Cost h = h_.evaluate(reg_.get(id));
    h_cache_[id] = h;
    if (h_.computesPreferred()) {
      const auto& p = h_.preferred();
      pref_begin_[id] = pref_pool_.size();
      pref_count_[id] = static_cast<uint32_t>(p.size());
      pref_pool_.insert(pref_pool_.end(), p.begin(), p.end());
    }
    if (turns_ != nullptr) turns_->evaluated();
    if (t_evaluation_hook != nullptr) t_evaluation_hook->evaluated();
    return h;
  }

  std::vector<OpId> path(uint32_t id, uint32_t stop) const {
    std::vector<OpId> out;
    while (id != stop && parent_[id] != kNone) {
      out.push_back(op_[id]);
      id = parent_[id];
    }
    std::reverse(out.begin(), out.end());
    return out;
  }

  size_t memoryBytes() const {
    return reg_.bytes() + parent_.capacity() * (4 + 4 + 8 + 8 + 8 + 4 + 1) + pref_pool_.capacity() * 4 +
           open_bytes_;
  }

  /// Checks time and memory every 256 calls, or sooner once kEvalsPerCheck states were evaluated
  /// since the last check (one evaluation of a task with 10^5 operators takes milliseconds, and
  /// a hill-climbing node may evaluate hundreds of successors); returns a terminal status or
  /// nullopt.
  ///
  /// Where evaluations are slow (more than kSlowCheckGap between two checks: a task with 10^5
  /// operators, 10-20 ms an evaluation on scanalyzer-30), the clock is read after every
  /// evaluation, so that the deadline is overrun by one evaluation at most; back to every
  /// kEvalsPerCheck once the checks come quickly again. Only when a limit is seen changes with
  /// it, never which states are evaluated.
  std::optional<SearchStatus> checkLimits() {
    if (turns_ != nullptr && turns_->stopped()) return SearchStatus::kCancelled;
    const bool few_evaluations = stats_.evaluated < evaluated_at_check_ + evals_per_check_;
    if ((++checks_ & 255) != 0 && few_evaluations) return std::nullopt;
    evaluated_at_check_ = stats_.evaluated;
    const Clock::time_point now = Clock::now();
    evals_per_check_ = now - last_check_ > kSlowCheckGap ? 1 : kEvalsPerCheck;
    last_check_ = now;
    const StopReason why = term_.reason();
    if (why == StopReason::kDeadline) return SearchStatus::kTimeout;
    if (why == StopReason::kStopRequested) return SearchStatus::kCancelled;
    if (opt_.memory_limit_mb > 0 && memoryBytes() > opt_.memory_limit_mb * 1024 * 1024) return SearchStatus::kOutOfMemory;
    return std::nullopt;
  }

  SearchResult finish(SearchStatus st, std::vector<OpId> plan = {}) {
    SearchResult r;
    r.status = st;
    r.plan = std::move(plan);
    return r;
  }

  // --- enforced hill-climbing ----------------------------------------------------------------
  SearchResult ehc() {
    bool is_new = false;
    uint32_t cur = registerState(init_.data(), &is_new);
    if (task_.goalReached(reg_.get(cur), goal_)) return finish(SearchStatus::kSolved);
    // Goal agenda (FF) for a single conjunctive goal; otherwise one entry with the whole goal.
    std::vector<std::vector<FactId>> agenda;
    if (opt_.goal_agenda && goal_.conjuncts.size() == 1 && goal_.conjuncts[0].neg.empty()) {
      agenda = goalAgenda(task_, goal_.conjuncts[0].pos);
    }
    std::vector<OpId> plan;
    if (agenda.size() <= 1) {
      return ehcTo(goal_, cur, plan, true);
    }
    std::vector<FactId> so_far;
    for (size_t k = 0; k < agenda.size(); ++k) {
      so_far.insert(so_far.end(), agenda[k].begin(), agenda[k].end());
      std::sort(so_far.begin(), so_far.end());
      Goal partial;
      partial.conjuncts.push_back(GoalConjunct{so_far, {}});
      const bool last = k + 1 == agenda.size();
      in_agenda_entry_before_last_ = !last;
      const uint64_t restarts = stats_.ehc_h2_restarts;
      SearchResult r = ehcTo(last ? goal_ : partial, cur, plan, k == 0);
      // A restart (ehc_h2_restart) inside the entry has hill-climbed to the whole goal.
      if (stats_.ehc_h2_restarts != restarts) return r;
      // After a fallback, the complete search has searched for the whole goal from the initial
      // state (FF): its answer (plan, proof, or limit) is final, whichever entry the hill-climbing
      // failed in. Going on to the next entry from the hill-climbing's own plan would discard
      // the complete search's plan and repeat it at the next failure.
      if (r.status != SearchStatus::kSolved || last || stats_.ehc_fallbacks > 0) return r;
      // Continue from the state the entry was reached in.
      StateBits st = init_;
      StateBits nxt(st.size());
      for (OpId o : plan) {
        task_.apply(st.data(), o, nxt.data());
        st.swap(nxt);
      }
      cur = registerState(st.data(), &is_new);
    }
    return finish(SearchStatus::kFailed);
  }

  /// Hill-climbs from `cur` to `goal`, appending to `plan`. On success returns kSolved with the
  /// whole plan so far; on failure returns `fallback()`'s result: the complete search from the
  /// initial state to the full goal `goal_`, not to `goal` (a plan for the whole task).
  SearchResult ehcTo(const Goal& goal, uint32_t cur, std::vector<OpId>& plan, bool first) {
    h_.setGoal(goal);
    std::fill(h_cache_.begin(), h_cache_.end(), kUnknown);
    pref_pool_.clear();
    bool is_new = false;
    if (task_.goalReached(reg_.get(cur), goal)) return finish(SearchStatus::kSolved, plan);
    Cost hcur = evaluate(cur);
    if (first) {
      stats_.initial_h = hcur;
      if (opt_.ehc_eval_budget_per_h > 0 && hcur != Heuristic::kDeadEnd) {
        eval_budget_ = opt_.ehc_eval_budget_per_h * static_cast<uint64_t>(std::max<Cost>(hcur, 2));
      }
      if (opt_.ehc_eval_budget > 0 && (eval_budget_ == 0 || opt_.ehc_eval_budget < eval_budget_)) {
        eval_budget_ = opt_.ehc_eval_budget;
      }
      if (opt_.ehc_fallback_budget_per_h > 0 && hcur != Heuristic::kDeadEnd) {
        fallback_budget_ = opt_.ehc_fallback_budget_min +
                           opt_.ehc_fallback_budget_per_h * static_cast<uint64_t>(std::max<Cost>(hcur, 1));
        if (opt_.ehc_fallback_budget_max > 0) fallback_budget_ = std::min(fallback_budget_, opt_.ehc_fallback_budget_max);
      }
    }
    if (hcur == Heuristic::kDeadEnd) {
      if (first && &goal == &goal_) return finish(SearchStatus::kUnsolvable);
      dead_end_proven_ = true;
      return fallback();
    }
    std::vector<uint32_t> queue;
    std::vector<OpId> all_ops;
    bool helpful_only = true;
    // ehc_h2_test_gap_max > 0: the states committed to since `alive` (the last state h^2 found
    // alive, or where this climb started), untested, each with the plan's length before it. At a
    // gap of 1 (at the start and after a dead end) states are tested before they are taken, as
    // without test_later, so that where dead ends are dense no bisection or search again is paid.
    const bool test_later = opt_.ehc_h2_test_gap_max > 0;
    std::vector<std::pair<uint32_t, size_t>> untested;
    uint32_t alive = cur;
    uint32_t gap = 1;
    // Tests the last untested state; when h^2 finds it a dead end, finds the first dead one by
    // bisection (dead ends are monotone along the path), marks it and those after it dead and
    // goes back to the state before it. Returns whether it went back.
    const auto goBackFromDeadEnd = [&]() -> bool {
      if (untested.empty() || term_()) return false;
      if (!h2DeadEnd(reg_.get(untested.back().first))) {
        alive = untested.back().first;
        untested.clear();
        gap = std::min<uint32_t>(gap * 2, opt_.ehc_h2_test_gap_max);
        return false;
      }
      size_t lo = 0, hi = untested.size() - 1;
      while (lo < hi) {
        const size_t mid = lo + (hi - lo) / 2;
        if (h2DeadEnd(reg_.get(untested[mid].first))) {
          hi = mid;
        } else {
          lo = mid + 1;
        }
      }
      for (size_t k = lo; k < untested.size(); ++k) h_cache_[untested[k].first] = Heuristic::kDeadEnd;
      plan.resize(untested[lo].second);
      cur = lo == 0 ? alive : untested[lo - 1].first;
      hcur = h_cache_[cur];
      alive = cur;
      untested.clear();
      gap = 1;
      return true;
    };
    // Evaluations a plateau searched again without pruning may use (0 = unbounded).
    const uint64_t retry_budget =
        opt_.ehc_retry_budget_share > 0 && fallback_budget_ > 0
            ? std::max<uint64_t>(1, static_cast<uint64_t>(opt_.ehc_retry_budget_share * static_cast<double>(fallback_budget_)))
            : 0;
    for (;;) {
      ++iter_;
      queue.clear();
      queue.push_back(cur);
      stamp_.resize(reg_.size(), 0);
      stamp_[cur] = iter_;
      uint32_t found = kNone;
      const uint64_t bfs_evals0 = stats_.evaluated;
      for (size_t head = 0; head < queue.size() && found == kNone; ++head) {
        if (auto st = checkLimits()) return finish(*st);
        if (eval_budget_ > 0 && stats_.evaluated > eval_budget_) return finish(SearchStatus::kFailed);
        if (!helpful_only && retry_budget > 0 && stats_.evaluated - bfs_evals0 > retry_budget) {
          // The plateau searched again without helpful-action pruning is too large: treat it as
          // a failed hill-climbing.
          ++stats_.ehc_retries_abandoned;
          return fallback();
        }
        if (fallback_budget_ > 0 && stats_.evaluated + opt_.ehc_fallback_budget_spent > fallback_budget_) {
          return fallback();
        }
        const uint32_t id = queue[head];
        std::copy(reg_.get(id), reg_.get(id) + reg_.words(), buf_.begin());
        ++stats_.expanded;
        if (helpful_only) {
          // Helpful actions of `id` (copied: the pool may grow while we generate).
          pref_tmp_.assign(pref_pool_.begin() + static_cast<std::ptrdiff_t>(pref_begin_[id]),
                           pref_pool_.begin() + static_cast<std::ptrdiff_t>(pref_begin_[id] + pref_count_[id]));
        } else {
          pref_tmp_.clear();
          task_.applicableOps(buf_.data(), pref_tmp_);
        }
        for (OpId o : pref_tmp_) {
          task_.apply(buf_.data(), o, succ_.data());
          ++stats_.generated;
          const uint32_t sid = registerState(succ_.data(), &is_new);
          if (stamp_.size() < reg_.size()) stamp_.resize(reg_.size(), 0);
          if (stamp_[sid] == iter_) continue;
          stamp_[sid] = iter_;
          parent_[sid] = id;
          op_[sid] = o;
          if (task_.goalReached(succ_.data(), goal)) {
            found = sid;
            h_cache_[sid] = 0;
            break;
          }
          const Cost h = evaluate(sid);
          if (auto st = checkLimits()) return finish(*st);
          if (h == Heuristic::kDeadEnd) continue;
          if (h < hcur && (found == kNone || h < h_cache_[found])) {
            if (h2_commits_ && (!test_later || gap == 1) && !term_() && h2DeadEnd(succ_.data())) {
              h_cache_[sid] = Heuristic::kDeadEnd;
              continue;
            }
            // A better state: finish this node's successors and keep the best of them
            // (FF takes the first; the best sibling gives shorter plans at little cost).
            found = sid;
            if (!opt_.ehc_best_sibling) break;
            continue;
          }
          if (found == kNone) queue.push_back(sid);
        }
      }
      if (found == kNone) {
        // A plateau: first make sure the state is not one of h^2's dead ends.
        if (h2_commits_ && test_later && goBackFromDeadEnd()) {
          helpful_only = true;
          continue;
        }
        // The helpful actions may have pruned the way out of this plateau: search it once more
        // with every applicable action before giving up on hill-climbing.
        if (helpful_only && opt_.ehc_full_retry) {
          helpful_only = false;
          ++stats_.ehc_retries;
          continue;
        }
        // Searched without pruning, the plateau held every state reachable from `cur`.
        dead_end_proven_ = !helpful_only;
        return fallback();
      }
      helpful_only = true;
      std::vector<OpId> seg = path(found, cur);
      const size_t plan_before = plan.size();
      plan.insert(plan.end(), seg.begin(), seg.end());
      cur = found;
      parent_[cur] = kNone;
      if (t_evaluation_hook != nullptr) t_evaluation_hook->climbed();
      if (task_.goalReached(reg_.get(cur), goal)) {
        // The goal of an agenda entry is where the next entry starts: not from a dead end. (A
        // goal state itself is not tested, as without test_later.)
        if (h2_commits_ && test_later && &goal != &goal_ && goBackFromDeadEnd()) continue;
        return finish(SearchStatus::kSolved, plan);
      }
      hcur = h_cache_[cur];
      if (h2_commits_ && test_later) {
        if (gap == 1) {
          // Tested before it was taken, as without test_later.
          alive = cur;
          gap = std::min<uint32_t>(2, opt_.ehc_h2_test_gap_max);
        } else {
          untested.emplace_back(cur, plan_before);
          if (untested.size() >= gap) goBackFromDeadEnd();
        }
      }
    }
  }

  SearchResult fallback() {
    if (dead_end_proven_ && opt_.ehc_h2_restart && !h2_commits_ && !term_()) {
      // The hill-climbing committed to a dead end: again from the start, testing what it
      // commits to with h^2 (SearchOptions::ehc_h2_restart).
      dead_end_proven_ = false;
      h2_commits_ = true;
      ++stats_.ehc_h2_restarts;
      return ehc();
    }
    stats_.ehc_failed = true;
    if (!opt_.ehc_fallback) return finish(SearchStatus::kFailed);
    ++stats_.ehc_fallbacks;
    if (in_agenda_entry_before_last_) ++stats_.ehc_fallbacks_in_agenda;
    h_.setGoal(goal_);
    return opt_.fallback == SearchAlgorithm::kGbfs ? gbfs() : lazy();
  }

  void resetRegistry() {
    reg_ = StateRegistry(task_.numWords());
    parent_.clear(); op_.clear(); g_.clear(); h_cache_.clear(); pref_begin_.clear(); pref_count_.clear(); flag_.clear();
    pref_pool_.clear();
  }

  // --- lazy greedy best-first search (LAMA) ----------------------------------------------------
  // Open entries are (parent, operator) keyed by the parent's h; a state is generated and
  // evaluated only when its entry is popped (deferred evaluation, Richter & Helmert 2009). Two
  // queues, all successors and preferred successors (reached by a helpful action of the parent),
  // alternate by priority; each improvement of the best h boosts the preferred queue.
  struct LazyEntry {
    uint32_t parent;
    OpId op;
  };
  /// A FIFO of lazy entries in chunks that double from 64 entries up to 8 192 (64 KiB): the same
  /// order as a std::deque, but freed in one call per chunk. A std::deque's 512-byte blocks made
  /// freeing a lazy search's open lists take seconds past the deadline: citycar-6's unit-cost run
  /// and childsnack-8, 1.6-2.4 s in glibc's free() of millions of blocks (docs/benchmarks.md,
  /// issue 14, thirty-fourth round).
  class EntryFifo {
   public:
    void push_back(const LazyEntry& e) {
      if (first_ == chunks_.size() || tail_ == chunks_.back().cap) {
        chunks_.push_back({std::make_unique_for_overwrite<LazyEntry[]>(next_cap_), next_cap_});
        next_cap_ = std::min<uint32_t>(next_cap_ * 2, kMaxChunk);
        tail_ = 0;
      }
      chunks_.back().data[tail_++] = e;
    }
    const LazyEntry& front() const { return chunks_[first_].data[head_]; }
    void pop_front() {
      if (++head_ < chunks_[first_].cap) return;
      chunks_[first_++].data.reset();
      head_ = 0;
      if (first_ == chunks_.size()) {
        chunks_.clear();
        first_ = 0;
      } else if (2 * first_ >= chunks_.size()) {
        chunks_.erase(chunks_.begin(), chunks_.begin() + static_cast<std::ptrdiff_t>(first_));
        first_ = 0;
      }
    }
    bool empty() const { return first_ == chunks_.size() || (first_ + 1 == chunks_.size() && head_ == tail_); }

   private:
    static constexpr uint32_t kMaxChunk = 8192;
    struct Chunk {
      std::unique_ptr<LazyEntry[]> data;
      uint32_t cap;
    };
    std::vector<Chunk> chunks_;  // chunks_[first_] is the front chunk
    size_t first_{0};
    uint32_t head_{0};  // next entry of the front chunk
    uint32_t tail_{0};  // entries of the back chunk in use
    uint32_t next_cap_{64};
  };
  /// Bucket open list (Fast Downward's for integer keys): one FIFO per key, so equal keys pop in
  /// insertion order, as a heap with an insertion counter would, at 8 bytes per entry (the heap
  /// entry was 24) and O(log #keys) per push/pop. Buckets are freed as they are emptied.
  class LazyOpen {
   public:
    void push(Cost k, uint32_t parent, OpId op) {
      if (k != last_key_ || last_ == nullptr) {
        last_ = &buckets_[k];
        last_key_ = k;
      }
      last_->push_back({parent, op});
      ++size_;
    }
    LazyEntry pop() {
      auto it = buckets_.begin();
      const LazyEntry e = it->second.front();
      it->second.pop_front();
      --size_;
      if (it->second.empty()) {
        if (last_ == &it->second) last_ = nullptr;
        buckets_.erase(it);
      }
      return e;
    }
    /// Key of the entry `pop()` would return (the list must not be empty).
    Cost minKey() const { return buckets_.begin()->first; }
    bool empty() const { return size_ == 0; }
    size_t bytes() const { return size_ * sizeof(LazyEntry) + buckets_.size() * 128; }

   private:
    std::map<Cost, EntryFifo> buckets_;
    EntryFifo* last_{nullptr};  // bucket of the last push (successors share keys)
    Cost last_key_{0};
    size_t size_{0};
  };

  /// Paths costing `bound` or more are pruned (the anytime phase's first iteration); g is the
  /// cost of the path found first (no re-opening).
  SearchResult lazy(Cost bound = std::numeric_limits<Cost>::max()) {
    SearchCoroutine steps = lazySteps(bound, 0);
    steps.runToEnd();
    return std::move(steps.result());
  }

  /// The lazy search as a coroutine: suspended after every `turn` evaluations (0: never).
  SearchCoroutine lazySteps(Cost bound, uint64_t turn) {
    resetRegistry();
    bool is_new = false;
    const uint32_t root = registerState(init_.data(), &is_new);
    g_[root] = 0;
    if (task_.goalReached(reg_.get(root), goal_)) co_return finish(SearchStatus::kSolved);
    const Cost h0 = evaluate(root);
    if (stats_.initial_h == 0) stats_.initial_h = h0;
    if (h0 == Heuristic::kDeadEnd) co_return finish(SearchStatus::kUnsolvable);
    const bool use_pref = opt_.preferred_operators && h_.computesPreferred();
    // LAMA's second heuristic: landmark count, with its own accepted-landmark set per state.
    std::unique_ptr<LandmarkCounter> lm;
    if (opt_.landmarks) {
      lm = makeLandmarkCounter();
      if (!lm->enabled()) lm.reset();
    }
    const size_t lw = lm ? lm->words() : 0;
    std::vector<uint64_t> accepted;  // lw words per registered state
    std::vector<Cost> hlm;           // per registered state
    std::vector<uint64_t> acc_tmp(lw);
    if (lm) {
      accepted.resize(lw);
      lm->initial(reg_.get(root), accepted.data());
      hlm.push_back(lm->value(reg_.get(root), accepted.data()));
      stats_.landmarks = lm->numLandmarks();
      stats_.landmarks_disjunctive = lm->graph().numDisjunctive();
      stats_.landmark_gn_orders = lm->graph().numOrders(LandmarkOrderKind::kGreedyNecessary);
      stats_.landmark_reasonable_orders = lm->graph().numOrders(LandmarkOrderKind::kReasonable);
    }
    // Lists: 0 h_FF, 1 h_FF preferred, 2 landmarks, 3 landmarks preferred.
    LazyOpen lists[4];
    int64_t prio[4] = {0, 0, 0, 0};
    const bool active[4] = {true, use_pref, lm != nullptr, lm != nullptr && use_pref};
    std::vector<uint32_t> pref_mark(task_.ops.size(), 0);
    uint32_t mark = 0;
    std::vector<OpId> ops, lm_pref;
    auto expand = [&](uint32_t id) {
      ++stats_.expanded;
      ++mark;
      for (uint32_t i = 0; i < pref_count_[id]; ++i) pref_mark[pref_pool_[pref_begin_[id] + i]] = mark;
      ops.clear();
      task_.applicableOps(reg_.get(id), ops);
      if (lm && use_pref && landmark_preferred_) {
        lm_pref.clear();
        lm->preferredAmong(reg_.get(id), accepted.data() + static_cast<size_t>(id) * lw, ops, lm_pref);
        for (OpId o : lm_pref) pref_mark[o] = mark;
      }
      const Cost hf = h_cache_[id];
      const Cost hl = lm ? hlm[id] : 0;
      for (OpId o : ops) {
        if (g_[id] + opCost(o) >= bound) continue;
        ++stats_.generated;
        const bool pref = use_pref && pref_mark[o] == mark;
        lists[0].push(hf, id, o);
        if (pref) lists[1].push(hf, id, o);
        if (lm) {
          lists[2].push(hl, id, o);
          if (pref) lists[3].push(hl, id, o);
        }
      }
    };
    expand(root);
    Cost best_ff = h0, best_lm = lm ? hlm[root] : 0;
    uint64_t turn_end = stats_.evaluated + turn;
    for (;;) {
      if (turn > 0 && stats_.evaluated >= turn_end) {
        co_await std::suspend_always{};
        turn_end = stats_.evaluated + turn;
      }
      if (auto st = checkLimits()) co_return finish(*st);
      open_bytes_ = lists[0].bytes() + lists[1].bytes() + lists[2].bytes() + lists[3].bytes() + accepted.capacity() * 8 +
                    hlm.capacity() * 8;
      int pick = -1;
      for (int i = 0; i < 4; ++i) {
        if (active[i] && !lists[i].empty() && (pick < 0 || prio[i] < prio[pick])) pick = i;
      }
      if (pick < 0) co_return finish(SearchStatus::kUnsolvable);
      ++prio[pick];
      const LazyEntry e = lists[pick].pop();
      std::copy(reg_.get(e.parent), reg_.get(e.parent) + reg_.words(), buf_.begin());
      task_.apply(buf_.data(), e.op, succ_.data());
      const uint32_t sid = registerState(succ_.data(), &is_new);
      if (!is_new) continue;  // evaluated (and expanded) before: closed
      parent_[sid] = e.parent;
      op_[sid] = e.op;
      g_[sid] = g_[e.parent] + opCost(e.op);
      if (task_.goalReached(succ_.data(), goal_)) co_return finish(SearchStatus::kSolved, path(sid, kNone));
      if (lm) {
        lm->progress(reg_.get(e.parent), accepted.data() + static_cast<size_t>(e.parent) * lw, succ_.data(),
                     acc_tmp.data());
        accepted.insert(accepted.end(), acc_tmp.begin(), acc_tmp.end());
        hlm.push_back(lm->value(succ_.data(), acc_tmp.data()));
      }
      const Cost h = evaluate(sid);
      if (h == Heuristic::kDeadEnd) continue;
      bool progress = false;
      if (h < best_ff) {
        best_ff = h;
        progress = true;
      }
      if (lm && hlm[sid] < best_lm) {
        best_lm = hlm[sid];
        progress = true;
        if (t_evaluation_hook != nullptr) t_evaluation_hook->landmarksLeft(best_lm);
      }
      if (progress) {
        prio[1] -= opt_.preferred_boost;
        prio[3] -= opt_.preferred_boost;
      }
      expand(sid);
    }
  }

  Cost opCost(OpId o) const { return task_.unit_cost ? 1 : task_.ops[o].cost; }

  std::unique_ptr<LandmarkCounter> makeLandmarkCounter() const {
    if (opt_.landmark_generator == LandmarkGenerator::kRhw) {
      return std::make_unique<LandmarkCounter>(
          task_, shared_landmarks_ != nullptr ? *shared_landmarks_ : rhwLandmarks(task_, init_, goal_, opt_.rhw, term_),
          LandmarkProgression::kPastAndFuture);
    }
    return std::make_unique<LandmarkCounter>(task_, init_, goal_);
  }

  // --- lazy weighted A* with a cost bound (LAMA's later iterations) ------------------------------
  // Entries (parent, operator) keyed by g(parent) + cost(op) + w * h(parent); two queues, all and
  // preferred successors, alternating with the boost on progress; a state reached again on a
  // cheaper path is re-opened; every path with g >= `bound` is pruned, so a plan found costs
  // less than `bound`, and an exhausted open list proves that no plan does.
  SearchResult lazyWAstar(double w, Cost bound) {
    resetRegistry();
    bool is_new = false;
    const uint32_t root = registerState(init_.data(), &is_new);
    if (task_.goalReached(reg_.get(root), goal_)) return finish(SearchStatus::kSolved);
    const Cost h0 = evaluate(root);
    stats_.initial_h = h0;
    if (h0 == Heuristic::kDeadEnd) return finish(SearchStatus::kUnsolvable);
    g_[root] = 0;
    const bool use_pref = opt_.preferred_operators && h_.computesPreferred();
    LazyOpen lists[2];
    int64_t prio[2] = {0, 0};
    std::vector<uint32_t> pref_mark(task_.ops.size(), 0);
    uint32_t mark = 0;
    std::vector<OpId> ops;
    auto weighted = [&](Cost h) { return static_cast<Cost>(std::ceil(w * static_cast<double>(h) - 1e-9)); };
    auto expand = [&](uint32_t id) {
      ++stats_.expanded;
      ++mark;
      for (uint32_t i = 0; i < pref_count_[id]; ++i) pref_mark[pref_pool_[pref_begin_[id] + i]] = mark;
      ops.clear();
      task_.applicableOps(reg_.get(id), ops);
      const Cost wh = weighted(h_cache_[id]);
      for (OpId o : ops) {
        const Cost ng = g_[id] + opCost(o);
        if (ng >= bound) continue;
        ++stats_.generated;
        lists[0].push(ng + wh, id, o);
        if (use_pref && pref_mark[o] == mark) lists[1].push(ng + wh, id, o);
      }
    };
    expand(root);
    Cost best_h = h0;
    for (;;) {
      if (auto st = checkLimits()) return finish(*st);
      open_bytes_ = lists[0].bytes() + lists[1].bytes();
      int pick = -1;
      for (int i = 0; i < 2; ++i) {
        if ((i == 0 || use_pref) && !lists[i].empty() && (pick < 0 || prio[i] < prio[pick])) pick = i;
      }
      if (pick < 0) return finish(SearchStatus::kUnsolvable);
      ++prio[pick];
      const LazyEntry e = lists[pick].pop();
      const Cost ng = g_[e.parent] + opCost(e.op);
      if (ng >= bound) continue;
      std::copy(reg_.get(e.parent), reg_.get(e.parent) + reg_.words(), buf_.begin());
      task_.apply(buf_.data(), e.op, succ_.data());
      const uint32_t sid = registerState(succ_.data(), &is_new);
      if (!is_new) {
        if (ng >= g_[sid] || h_cache_[sid] == Heuristic::kDeadEnd) continue;
        ++stats_.reopened;
      }
      g_[sid] = ng;
      parent_[sid] = e.parent;
      op_[sid] = e.op;
      if (task_.goalReached(succ_.data(), goal_)) return finish(SearchStatus::kSolved, path(sid, kNone));
      const Cost h = evaluate(sid);
      if (h == Heuristic::kDeadEnd) continue;
      if (h < best_h) {
        best_h = h;
        prio[1] -= opt_.preferred_boost;
      }
      expand(sid);
    }
  }

  // --- greedy best-first search ----------------------------------------------------------------
  SearchResult gbfs() {
    // A fresh registry: EHC's parent links are not valid for GBFS paths.
    resetRegistry();
    bool is_new = false;
    const uint32_t root = registerState(init_.data(), &is_new);
    if (task_.goalReached(reg_.get(root), goal_)) return finish(SearchStatus::kSolved);
    const Cost h0 = evaluate(root);
    if (stats_.initial_h == 0) stats_.initial_h = h0;
    if (h0 == Heuristic::kDeadEnd) return finish(SearchStatus::kUnsolvable);
    const bool use_pref = opt_.preferred_operators && h_.computesPreferred();
    OpenList regular, preferred;
    regular.push(h0, 0, root);
    if (use_pref) preferred.push(h0, 0, root);
    int64_t prio_regular = 0, prio_pref = 0;
    Cost best_h = h0;
    std::vector<OpId> ops;
    std::vector<uint32_t> pref_mark(task_.ops.size(), 0);
    uint32_t mark = 0;
    for (;;) {
      if (auto st = checkLimits()) return finish(*st);
      open_bytes_ = regular.bytes() + preferred.bytes();
      OpenList* list = nullptr;
      if (use_pref && !preferred.empty() && (regular.empty() || prio_pref <= prio_regular)) {
        list = &preferred;
        ++prio_pref;
      } else if (!regular.empty()) {
        list = &regular;
        ++prio_regular;
      } else if (use_pref && !preferred.empty()) {
        list = &preferred;
      } else {
        return finish(SearchStatus::kUnsolvable);
      }
      const uint32_t id = list->pop().id;
      if (flag_[id] & 1) continue;  // closed
      flag_[id] |= 1;
      ++stats_.expanded;
      std::copy(reg_.get(id), reg_.get(id) + reg_.words(), buf_.begin());
      ++mark;
      for (uint32_t i = 0; i < pref_count_[id]; ++i) pref_mark[pref_pool_[pref_begin_[id] + i]] = mark;
      ops.clear();
      task_.applicableOps(buf_.data(), ops);
      for (OpId o : ops) {
        task_.apply(buf_.data(), o, succ_.data());
        ++stats_.generated;
        const uint32_t sid = registerState(succ_.data(), &is_new);
        if (!is_new) continue;
        parent_[sid] = id;
        op_[sid] = o;
        if (task_.goalReached(succ_.data(), goal_)) return finish(SearchStatus::kSolved, path(sid, kNone));
        const Cost h = evaluate(sid);
        if (auto st = checkLimits()) return finish(*st);
        if (h == Heuristic::kDeadEnd) {
          flag_[sid] |= 1;
          continue;
        }
        regular.push(h, 0, sid);
        if (use_pref && pref_mark[o] == mark) preferred.push(h, 0, sid);
        if (h < best_h) {
          best_h = h;
          prio_pref -= opt_.preferred_boost;
        }
      }
    }
  }

  // --- (weighted) A* ----------------------------------------------------------------------------
  SearchResult astar(double w) {
    bool is_new = false;
    const uint32_t root = registerState(init_.data(), &is_new);
    const Cost h0 = evaluate(root);
    stats_.initial_h = h0;
    if (h0 == Heuristic::kDeadEnd) return finish(SearchStatus::kUnsolvable);
    auto fval = [&](Cost g, Cost h) { return g + static_cast<Cost>(std::ceil(w * static_cast<double>(h) - 1e-9)); };
    OpenList open;
    g_[root] = 0;
    open.push(fval(0, h0), h0, root);
    std::vector<OpId> ops;
    while (!open.empty()) {
      if (auto st = checkLimits()) return finish(*st);
      open_bytes_ = open.bytes();
      const HeapEntry e = open.pop();
      const uint32_t id = e.id;
      if (e.key1 != fval(g_[id], h_cache_[id])) continue;  // stale entry
      if (flag_[id] & 1) continue;
      flag_[id] |= 1;
      if (task_.goalReached(reg_.get(id), goal_)) return finish(SearchStatus::kSolved, path(id, kNone));
      ++stats_.expanded;
      std::copy(reg_.get(id), reg_.get(id) + reg_.words(), buf_.begin());
      ops.clear();
      task_.applicableOps(buf_.data(), ops);
      const Cost gid = g_[id];
      for (OpId o : ops) {
        task_.apply(buf_.data(), o, succ_.data());
        ++stats_.generated;
        const uint32_t sid = registerState(succ_.data(), &is_new);
        const Cost ng = gid + (task_.unit_cost ? 1 : task_.ops[o].cost);
        if (is_new) {
          const Cost h = evaluate(sid);
          if (auto st = checkLimits()) return finish(*st);
          if (h == Heuristic::kDeadEnd) {
            flag_[sid] |= 3;  // closed + dead
            continue;
          }
          g_[sid] = ng;
          parent_[sid] = id;
          op_[sid] = o;
          open.push(fval(ng, h), h, sid);
        } else if (!(flag_[sid] & 2) && ng < g_[sid]) {
          if (flag_[sid] & 1) {
            ++stats_.reopened;
            flag_[sid] &= static_cast<uint8_t>(~1U);
          }
          g_[sid] = ng;
          parent_[sid] = id;
          op_[sid] = o;
          open.push(fval(ng, h_cache_[sid]), h_cache_[sid], sid);
        }
      }
    }
    return finish(SearchStatus::kUnsolvable);
  }

  const Task& task_;
  const StateBits& init_;
  const Goal& goal_;
  const SearchOptions& opt_;
  Heuristic& h_;
  const Termination& term_;
  StateRegistry reg_;
  std::vector<uint32_t> parent_, op_;
  std::vector<Cost> g_, h_cache_;
  std::vector<size_t> pref_begin_;
  std::vector<uint32_t> pref_count_;
  std::vector<uint8_t> flag_;
  std::vector<OpId> pref_pool_, pref_tmp_;
  StateBits buf_, succ_;
  SearchStatistics stats_;
  uint64_t checks_{0};
  uint64_t evaluated_at_check_{0};            ///< stats_.evaluated at the last clock read
  uint64_t evals_per_check_{kEvalsPerCheck};  ///< 1 while evaluations are slow (checkLimits)
  Clock::time_point last_check_{Clock::now()};
  static constexpr std::chrono::milliseconds kSlowCheckGap{20};
  static constexpr uint64_t kEvalsPerCheck = 16;
  size_t open_bytes_{0};
  std::vector<uint32_t> stamp_;  // ehc: BFS iteration that reached each state
  uint64_t eval_budget_{0};      // ehc: give up after this many evaluations (0 = unlimited)
  uint64_t fallback_budget_{0};  // ehc: fall back after this many evaluations (0 = unlimited)
  uint32_t iter_{0};
  TurnTaker* turns_{nullptr};  // another search taking turns with this hill-climbing, if any
  bool landmark_preferred_{true};  // lazy: the landmark count's preferred operators too
  const LandmarkGraph* shared_landmarks_{nullptr};  // lazy, kRhw: the graph to count, if built before
  bool in_agenda_entry_before_last_{false};  // ehc: hill-climbing to a goal-agenda entry, not the last
  bool dead_end_proven_{false};  // ehc: the state the hill-climbing stands on is a proven dead end
  // Plan neighbourhood search: the plan the registry's neighbourhood was built around, whether it
  // is whole (not left by a time or memory limit), and the next state its breadth-first search
  // expands.
  std::vector<OpId> nbh_plan_;
  bool nbh_built_{false};
  uint32_t nbh_next_{0};
  bool h2_commits_{opt_.ehc_h2_commits};  // ehc: test states before committing to them (h^2)
  StateBits h2_state_;
  uint64_t h2_work_{0};  // ehc: words of work of this run's h^2 tests

  /// True when h^2 from `s` finds every conjunct of the goal unreachable (a goal fact or a pair of
  /// them): `s` is a dead end. False, untested, once the run's tests have done
  /// `ehc_h2_work_budget` words of work.
  bool h2DeadEnd(const uint64_t* s) {
    if (opt_.ehc_h2_work_budget > 0 && h2_work_ >= opt_.ehc_h2_work_budget) return false;
    ++stats_.ehc_h2_tests;
    h2_state_.assign(s, s + task_.numWords());
    for (const GoalConjunct& c : goal_.conjuncts) {
      uint64_t work = 0;
      const std::optional<bool> reached =
          MutexTable::reachesTogether(task_, h2_state_, c.pos, opt_.ehc_h2_mutexes, &work, term_);
      h2_work_ += work;
      if (!reached || *reached) return false;
    }
    ++stats_.ehc_h2_dead_ends;
    return true;
  }
};

CostType defaultCostType(const SearchOptions& o, const Task& t) {
  if (o.cost_type) return *o.cost_type;
  if (t.unit_cost) return CostType::kUnit;
  const bool optimal = o.algorithm == SearchAlgorithm::kAstar || o.algorithm == SearchAlgorithm::kWAstar;
  return optimal ? CostType::kCost : CostType::kPlusOne;
}

HeuristicKind defaultHeuristic(const SearchOptions& o) {
  if (o.heuristic) return *o.heuristic;
  const bool optimal = o.algorithm == SearchAlgorithm::kAstar || o.algorithm == SearchAlgorithm::kWAstar;
  return optimal ? HeuristicKind::kMax : HeuristicKind::kFF;
}

/// Adds an earlier run's effort counters to `into`: a search made of several runs reports what
/// all of them cost.
void addRunCosts(SearchStatistics& into, const SearchStatistics& from) {
  into.expanded += from.expanded;
  into.generated += from.generated;
  into.evaluated += from.evaluated;
  into.ehc_retries += from.ehc_retries;
  into.ehc_retries_abandoned += from.ehc_retries_abandoned;
  into.ehc_h2_restarts += from.ehc_h2_restarts;
  into.ehc_h2_tests += from.ehc_h2_tests;
  into.ehc_h2_dead_ends += from.ehc_h2_dead_ends;
  into.ehc_fallbacks += from.ehc_fallbacks;
  into.ehc_fallbacks_in_agenda += from.ehc_fallbacks_in_agenda;
  into.registered_states += from.registered_states;
  into.seconds += from.seconds;
  if (from.landmarks > into.landmarks) {  // the landmarks of the run that used them
    into.landmarks = from.landmarks;
    into.landmarks_disjunctive = from.landmarks_disjunctive;
    into.landmark_gn_orders = from.landmark_gn_orders;
    into.landmark_reasonable_orders = from.landmark_reasonable_orders;
  }
}

}  // namespace

std::optional<SearchAlgorithm> parseSearchAlgorithm(const std::string& name) {
  if (name == "ehc") return SearchAlgorithm::kEhc;
  if (name == "gbfs") return SearchAlgorithm::kGbfs;
  if (name == "lazy") return SearchAlgorithm::kLazy;
  if (name == "wastar") return SearchAlgorithm::kWAstar;
  if (name == "astar") return SearchAlgorithm::kAstar;
  return std::nullopt;
}

std::string toString(SearchAlgorithm a) {
  switch (a) {
    case SearchAlgorithm::kEhc: return "ehc";
    case SearchAlgorithm::kGbfs: return "gbfs";
    case SearchAlgorithm::kLazy: return "lazy";
    case SearchAlgorithm::kWAstar: return "wastar";
    case SearchAlgorithm::kAstar: return "astar";
  }
  return "unknown";
}

std::string toString(SearchStatus s) {
  switch (s) {
    case SearchStatus::kSolved: return "solved";
    case SearchStatus::kUnsolvable: return "unsolvable";
    case SearchStatus::kFailed: return "failed";
    case SearchStatus::kTimeout: return "timeout";
    case SearchStatus::kCancelled: return "cancelled";
    case SearchStatus::kOutOfMemory: return "out of memory";
  }
  return "unknown";
}

void SearchOptions::validate() const {
  if (!(weight >= 1.0) || !std::isfinite(weight)) {
    throw std::invalid_argument("SearchOptions::weight must be a finite number >= 1, got " + std::to_string(weight));
  }
  if (!(anytime_seconds >= 0.0) || !std::isfinite(anytime_seconds)) {
    throw std::invalid_argument("SearchOptions::anytime_seconds must be a finite number >= 0, got " +
                                std::to_string(anytime_seconds));
  }
  if (!(neighbourhood_time_share >= 0.0 && neighbourhood_time_share <= 1.0)) {
    throw std::invalid_argument("SearchOptions::neighbourhood_time_share must be in [0, 1], got " +
                                std::to_string(neighbourhood_time_share));
  }
  if (neighbourhood_first_states == 0) {
    throw std::invalid_argument("SearchOptions::neighbourhood_first_states must be > 0");
  }
  if (!(unit_beside_time_share >= 0.0 && unit_beside_time_share <= 1.0)) {
    throw std::invalid_argument("SearchOptions::unit_beside_time_share must be in [0, 1], got " +
                                std::to_string(unit_beside_time_share));
  }
  if (unit_beside_turn == 0) throw std::invalid_argument("SearchOptions::unit_beside_turn must be > 0, got 0");
  if (!(unit_beside_stall_share >= 0.0 && unit_beside_stall_share <= 1.0)) {
    throw std::invalid_argument("SearchOptions::unit_beside_stall_share must be in [0, 1], got " +
                                std::to_string(unit_beside_stall_share));
  }
  if (!(unit_first_time_share > 0.0 && unit_first_time_share <= 1.0)) {
    throw std::invalid_argument("SearchOptions::unit_first_time_share must be in (0, 1], got " +
                                std::to_string(unit_first_time_share));
  }
  if (!(ehc_retry_budget_share >= 0.0 && ehc_retry_budget_share <= 1.0)) {
    throw std::invalid_argument("SearchOptions::ehc_retry_budget_share must be in [0, 1], got " +
                                std::to_string(ehc_retry_budget_share));
  }
  if (ehc_h2_mutexes.max_work == 0) {
    throw std::invalid_argument("SearchOptions::ehc_h2_mutexes.max_work must be > 0, got 0");
  }
  if (ehc_lazy_turn_ehc == 0 || ehc_lazy_turn_lazy == 0) {
    throw std::invalid_argument("SearchOptions::ehc_lazy_turn_ehc and ehc_lazy_turn_lazy must be > 0, got " +
                                std::to_string(ehc_lazy_turn_ehc) + " and " + std::to_string(ehc_lazy_turn_lazy));
  }
  if (ehc_lazy_after == 0) throw std::invalid_argument("SearchOptions::ehc_lazy_after must be > 0, got 0");
  rhw.validate();
  if (preferred_boost < 0) {
    throw std::invalid_argument("SearchOptions::preferred_boost must be >= 0, got " + std::to_string(preferred_boost));
  }
}

namespace {

/// The configured search (with EHC's first run and fallback); with `turns`, every hill-climbing
/// run before the first plan takes turns with the lazy search (not the second run, which starts
/// once the hill-climbing has a plan).
SearchResult configuredSearch(const Task& task, const StateBits& init, const Goal& goal, const SearchOptions& options,
                              Heuristic& heuristic, const Termination& term, TurnTaker* turns) {
  if (options.algorithm == SearchAlgorithm::kEhc && options.ehc_ff_first && options.ehc_ff_budget_per_h > 0 &&
      heuristic.setFFStyle(true)) {
    // First run: EHC with FF-v2.3's relaxed plan, no fallback, bounded evaluations.
    SearchOptions first = options;
    first.ehc_fallback = false;
    first.ehc_eval_budget_per_h = options.ehc_ff_budget_per_h;
    first.ehc_h2_restart = options.ehc_h2_restart && options.ehc_ff_first_h2_restart;
    if (options.ehc_ff_first_improvement) first.ehc_best_sibling = false;
    SearchResult r1;
    try {
      Searcher s1(task, init, goal, first, heuristic, term);
      s1.takeTurns(turns);
      r1 = s1.run();
    } catch (...) {
      heuristic.setFFStyle(false);
      throw;
    }
    heuristic.setFFStyle(false);
    if (r1.status == SearchStatus::kSolved && options.ehc_second_budget_per_step > 0 &&
        options.ehc_second_budget_factor > 0 &&
        static_cast<double>(r1.plan.size()) >=
            options.ehc_second_trigger_ratio * static_cast<double>(std::max<Cost>(r1.stats.initial_h, 1))) {
      // The first plan is long for its initial h: try the default EHC too (bounded, no
      // fallback) and keep the cheaper plan.
      SearchOptions second = options;
      second.ehc_fallback = false;
      second.ehc_eval_budget =
          std::min<uint64_t>(options.ehc_second_budget_per_step * r1.plan.size(),
                             options.ehc_second_budget_factor * std::max<uint64_t>(r1.stats.evaluated, 1));
      Searcher s2(task, init, goal, second, heuristic, term);
      SearchResult r2 = s2.run();
      r1.stats.ehc_second_ran = true;
      if (r2.status == SearchStatus::kSolved && r2.cost < r1.cost) {
        r2.stats.ehc_second_ran = true;
        r2.stats.ehc_second_won = true;
        addRunCosts(r2.stats, r1.stats);
        r2.stats.initial_h = r1.stats.initial_h;
        return r2;
      }
      addRunCosts(r1.stats, r2.stats);
      return r1;
    }
    if (r1.status != SearchStatus::kFailed && r1.status != SearchStatus::kOutOfMemory) return r1;
    // Second run: the default search from the start, as if the first had not happened (but
    // within what is left of the hill-climbing budget).
    SearchOptions rest = options;
    rest.ehc_fallback_budget_spent = r1.stats.evaluated;
    Searcher s2(task, init, goal, rest, heuristic, term);
    s2.takeTurns(turns);
    SearchResult r2 = s2.run();
    r2.stats.ehc_ff_failed = true;
    addRunCosts(r2.stats, r1.stats);
    return r2;
  }
  Searcher s(task, init, goal, options, heuristic, term);
  s.takeTurns(turns);
  return s.run();
}

/// True when the operators do not all cost the same (plan cost is not plan length).
bool costsVary(const Task& task) {
  if (task.unit_cost) return false;
  for (const Operator& op : task.ops) {
    if (op.cost != task.ops.front().cost) return true;
  }
  return false;
}

/// SearchOptions::ehc_lazy_beside: the lazy search, started once the hill-climbing has used
/// `ehc_lazy_after` evaluations, then run for `ehc_lazy_turn_lazy` evaluations after every
/// `ehc_lazy_turn_ehc` of the hill-climbing's, inside the hill-climbing's own call (one thread:
/// a turn costs a function call). It has a searcher (states) and a heuristic of its own. With
/// `lazy_beside_both`, a second lazy search (LAMA-first's preferred operators) joins once the
/// hill-climbing and the first have used `lazy_second_after` evaluations since the first started
/// (or when the first ends without an answer), and the two take their turns one after the other;
/// both count the landmarks of one graph, built once. The first final answer of either is the
/// answer.
class LazyBeside : public TurnTaker {
 public:
  LazyBeside(const Task& task, const StateBits& init, const Goal& goal, const SearchOptions& options,
             const Termination& term)
      : task_(task), init_(init), goal_(goal), options_(options), term_(term), left_(options.ehc_lazy_after) {
    options_.algorithm = SearchAlgorithm::kLazy;
    lanes_.reserve(3);
  }

  void evaluated() override {
    if (!lanes_.empty()) ++ehc_since_start_;
    if (finished_ || --left_ > 0) return;
    left_ = options_.ehc_lazy_turn_ehc;
    start();
    for (size_t i = 0; i < lanes_.size() && !finished_; ++i) turn(i);
    maybeAddSecond();
  }
  /// The lazy search has given a final answer (a plan or a proof): the hill-climbing stops.
  bool stopped() const override { return finished_ && isFinal(lanes_[winner_]); }
  bool started() const { return !lanes_.empty(); }
  /// The lazy searches' counters so far (they must have started).
  const SearchStatistics& statistics() {
    sum_ = laneStatistics(lanes_[0]);
    for (size_t i = 1; i < lanes_.size(); ++i) addRunCosts(sum_, laneStatistics(lanes_[i]));
    return sum_;
  }
  bool finished() const { return finished_; }
  /// Runs the lazy searches in turns to the first final answer, or until all have ended (starting
  /// them if they have not started); the answer's counters include the others'.
  SearchResult& runToEnd() {
    start();
    for (size_t i = 0; !finished_; i = (i + 1) % lanes_.size()) {
      turn(i);
      if (i + 1 == lanes_.size()) maybeAddSecond();
    }
    SearchResult& r = lanes_[winner_].steps->result();
    for (size_t i = 0; i < lanes_.size(); ++i) {
      if (i != winner_) addRunCosts(r.stats, laneStatistics(lanes_[i]));
    }
    return r;
  }

 private:
  struct Lane {
    std::unique_ptr<Heuristic> heuristic;
    std::unique_ptr<Searcher> searcher;
    std::optional<SearchCoroutine> steps;
    uint64_t budget{0};  // > 0: dropped once it has used this many evaluations
    bool dropped{false};  // then its search, states and heuristic are freed
    SearchStatistics dropped_statistics;  // its counters when dropped
    bool ended() const { return dropped || steps->done(); }
  };
  static const SearchStatistics& laneStatistics(const Lane& l) {
    return l.dropped ? l.dropped_statistics : l.searcher->statistics();
  }
  static bool isFinal(const Lane& l) {
    if (l.dropped || !l.steps->done()) return false;
    const SearchStatus st = l.steps->result().status;
    return st == SearchStatus::kSolved || st == SearchStatus::kUnsolvable;
  }
  static void drop(Lane& l) {
    l.dropped_statistics = l.searcher->statistics();
    l.dropped = true;
    l.steps.reset();  // the coroutine frame first: it refers to the searcher
    l.searcher.reset();
    l.heuristic.reset();
  }
  /// Whether a second lane (LAMA-first's preferred operators) is to join the first.
  bool twoLanes() const { return options_.lazy_beside_both && !options_.lazy_plan_preferred; }
  /// A second lane is to join and has not yet.
  bool secondPending() const { return twoLanes() && lanes_.size() == 1; }
  /// One turn of lane i (none if it has ended); records the winner once a lane answers or all end
  /// (a second lane still to join joins then instead).
  void turn(size_t i) {
    Lane& l = lanes_[i];
    if (l.ended()) return;
    l.steps->resume();
    if (!l.steps->done()) {
      if (l.budget == 0 || l.searcher->statistics().evaluated < l.budget) return;
      drop(l);
    }
    bool all_done = true;
    for (const Lane& x : lanes_) all_done = all_done && x.ended();
    if (isFinal(l)) {
      finished_ = true;
      winner_ = i;
    } else if (all_done) {
      if (secondPending()) {
        addSecondLanes();
      } else {
        finished_ = true;
        winner_ = l.dropped ? 0 : i;  // the first lane is never dropped
      }
    }
  }
  void start() {
    if (!lanes_.empty()) return;
    if (options_.landmarks && options_.landmark_generator == LandmarkGenerator::kRhw && twoLanes()) {
      landmarks_.emplace(rhwLandmarks(task_, init_, goal_, options_.rhw, term_));
    }
    addLane(options_.lazy_plan_preferred);
    maybeAddSecond();
  }
  /// The second lane joins once the hill-climbing and the first lane have used
  /// `lazy_second_after` evaluations since the first started.
  void maybeAddSecond() {
    if (finished_ || !secondPending()) return;
    const uint64_t used = ehc_since_start_ + lanes_[0].searcher->statistics().evaluated;
    if (used >= options_.lazy_second_after) addSecondLanes();
  }
  /// The second lane and, with `lazy_hadd_lane_budget`, where h_FF takes FF's layered graph
  /// (the operators cost the same), the third: LAMA-first's h_FF through h_add's supporters.
  void addSecondLanes() {
    addLane(true, options_.lazy_second_hadd, 0);
    const CostType ct = defaultCostType(options_, task_);
    if (options_.lazy_hadd_lane_budget > 0 && !options_.lazy_second_hadd &&
        defaultHeuristic(options_) == HeuristicKind::kFF && (ct == CostType::kUnit || !costsVary(task_))) {
      addLane(true, true, options_.lazy_hadd_lane_budget);
    }
  }
  /// A lane; `hadd`: h_FF through h_add's best supporters, as Fast Downward's (with the default
  /// heuristic only); `budget` > 0: the lane is dropped after that many evaluations.
  void addLane(bool plan_preferred, bool hadd = false, uint64_t budget = 0) {
    Lane& l = lanes_.emplace_back();
    l.budget = budget;
    HeuristicKind kind = defaultHeuristic(options_);
    if (hadd && kind == HeuristicKind::kFF) kind = HeuristicKind::kFFHadd;
    l.heuristic = makeHeuristic(kind, task_, defaultCostType(options_, task_));
    l.searcher = std::make_unique<Searcher>(task_, init_, goal_, options_, *l.heuristic, term_);
    if (landmarks_) l.searcher->shareLandmarkGraph(&*landmarks_);
    if (plan_preferred && l.heuristic->setRelaxedPlanPreferred(true)) l.searcher->preferNoLandmarkAchievers();
    l.steps.emplace(l.searcher->lazyInTurns(options_.ehc_lazy_turn_lazy));
  }

  const Task& task_;
  const StateBits& init_;
  const Goal& goal_;
  SearchOptions options_;
  const Termination& term_;
  uint64_t left_;  // hill-climbing evaluations before the lazy searches' next turns
  uint64_t ehc_since_start_{0};  // hill-climbing evaluations since the first lane started
  std::optional<LandmarkGraph> landmarks_;  // with two lanes (kRhw): the graph both count
  std::vector<Lane> lanes_;
  size_t winner_{0};  // with finished_: the lane that answered (or ended last)
  SearchStatistics sum_;
  bool finished_{false};
};

/// `winner`'s result with `other`'s effort counted and the hill-climbing's own flags (`ehc`).
SearchResult withBothRuns(SearchResult winner, const SearchStatistics& other, const SearchStatistics& ehc) {
  addRunCosts(winner.stats, other);
  winner.stats.initial_h = ehc.initial_h;
  winner.stats.ehc_ff_failed = ehc.ehc_ff_failed;
  winner.stats.ehc_retries = ehc.ehc_retries;
  winner.stats.ehc_retries_abandoned = ehc.ehc_retries_abandoned;
  winner.stats.ehc_h2_restarts = ehc.ehc_h2_restarts;
  winner.stats.ehc_h2_tests = ehc.ehc_h2_tests;
  winner.stats.ehc_h2_dead_ends = ehc.ehc_h2_dead_ends;
  return winner;
}

/// The hill-climbing (without its fallback) with the lazy search beside it (`LazyBeside`). The
/// first final answer wins: a plan or a proof of either, or the deadline. When the hill-climbing
/// gives up (or runs out of memory), the lazy search goes on alone from where it is, or starts
/// now; its answer is then the answer, as the fallback's is without this option.
SearchResult ehcWithLazyBeside(const Task& task, const StateBits& init, const Goal& goal, const SearchOptions& options,
                               Heuristic& heuristic, const Termination& term) {
  LazyBeside lazy(task, init, goal, options, term);
  SearchOptions ehc_only = options;
  ehc_only.ehc_fallback = false;
  SearchResult ehc = configuredSearch(task, init, goal, ehc_only, heuristic, term, &lazy);
  ehc.stats.lazy_beside_started = lazy.started();
  if (lazy.stopped()) {  // the lazy search's plan or proof came first
    SearchResult r = withBothRuns(std::move(lazy.runToEnd()), ehc.stats, ehc.stats);
    r.stats.lazy_beside_started = r.stats.lazy_beside_won = true;
    return r;
  }
  const bool ehc_gave_up = ehc.status == SearchStatus::kFailed || ehc.status == SearchStatus::kOutOfMemory;
  if (!ehc_gave_up) {  // the hill-climbing's plan, proof or limit
    if (lazy.started()) addRunCosts(ehc.stats, lazy.statistics());
    return ehc;
  }
  // The fallback: the lazy search from where it is (or from the start), or its end if it ended
  // (out of memory) before.
  SearchResult r = withBothRuns(std::move(lazy.runToEnd()), ehc.stats, ehc.stats);
  r.stats.ehc_failed = true;
  r.stats.ehc_fallbacks = 1;
  r.stats.lazy_beside_started = ehc.stats.lazy_beside_started;
  return r;
}

/// The first plan: the configured search, with the lazy search beside the hill-climbing when
/// `ehc_lazy_beside` applies.
SearchResult firstPlan(const Task& task, const StateBits& init, const Goal& goal, const SearchOptions& options,
                       Heuristic& heuristic, const Termination& term) {
  if (init.size() != task.numWords()) {
    throw std::invalid_argument("search: initial state has " + std::to_string(init.size()) + " words, task needs " +
                                std::to_string(task.numWords()));
  }
  if (options.algorithm == SearchAlgorithm::kEhc && options.ehc_fallback &&
      options.fallback == SearchAlgorithm::kLazy && options.ehc_lazy_beside) {
    return ehcWithLazyBeside(task, init, goal, options, heuristic, term);
  }
  return configuredSearch(task, init, goal, options, heuristic, term, nullptr);
}

/// A plan or a proof: the answer of a search that ends the others.
bool isFinalAnswer(const SearchResult& r) {
  return r.status == SearchStatus::kSolved || r.status == SearchStatus::kUnsolvable;
}

/// The cost + 1 run's evaluation hook with the unit-cost run beside it
/// (`SearchOptions::unit_beside_time_share`): after every `turn` evaluations of its own, the
/// unit-cost run (`unit`) runs as many, while it has time left of its `budget` seconds in all;
/// past it, it is stopped. Once it has given a plan or a proof, the cost + 1 run is stopped
/// (`plus_stop`).
class UnitTurns : public EvaluationHook {
 public:
  UnitTurns(SearchFiber& unit, uint64_t turn, double budget, double stall_share, std::stop_source& plus_stop)
      : unit_(unit), turn_(turn), left_(turn), budget_(budget), stall_share_(stall_share), plus_stop_(plus_stop) {}

  /// `unit_beside_stall_share`: the unit-cost run has made no progress in the last share of its
  /// evaluations.
  static bool stalled(const SearchFiber& unit, double stall_share) {
    return stall_share > 0 && static_cast<double>(unit.evaluations() - unit.evaluationsAtProgress()) >
                                  stall_share * static_cast<double>(unit.evaluations());
  }

  void evaluated() override {
    if (unit_.done() || --left_ > 0) return;
    left_ = turn_;
    if (stalled(unit_, stall_share_)) {
      unit_.cancel();  // no progress of late: its states are freed
      return;
    }
    const double time_left = budget_ - unit_.seconds();
    if (time_left > 0) {
      unit_.resume(turn_, Clock::now() + std::chrono::duration_cast<Clock::duration>(
                                             std::chrono::duration<double>(time_left)));
    }
    if (unit_.done()) {
      if (isFinalAnswer(unit_.result())) plus_stop_.request_stop();
    } else if (unit_.seconds() >= budget_) {
      unit_.cancel();  // its share is used up: its states are freed
    }
  }

 private:
  SearchFiber& unit_;
  uint64_t turn_;
  uint64_t left_;
  double budget_;
  double stall_share_;
  std::stop_source& plus_stop_;
};

/// The first plan of the anytime phase (SearchOptions::unit_cost_first): with unit costs within a
/// share of the time left, then, if that run ran out of time or memory or gave up, with
/// `heuristic` (cost + 1) from the start; with `unit_beside_time_share`, the unit-cost run goes
/// on beside the cost + 1 run, in turns.
SearchResult unitCostFirstPlan(const Task& task, const StateBits& init, const Goal& goal, const SearchOptions& options,
                               Heuristic& heuristic, const Termination& term) {
  const double left = term.deadline().secondsLeft();
  if (std::isfinite(left) && options.unit_beside_time_share > options.unit_first_time_share) {
    SearchOptions unit_options = options;
    unit_options.cost_type = CostType::kUnit;  // also for the heuristic of a lazy search beside
    SearchFiber unit(
        [&](const Termination& t) {
          std::unique_ptr<Heuristic> unit_h = makeHeuristic(defaultHeuristic(options), task, CostType::kUnit);
          return firstPlan(task, init, goal, unit_options, *unit_h, t);
        },
        term);
    const auto in = [](double seconds) {
      return Clock::now() + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(seconds));
    };
    unit.resume(UINT64_MAX, in(options.unit_first_time_share * left));  // alone first
    if (options.unit_progress_alone) {
      // While it makes progress, the unit-cost run goes on alone, up to its share in all.
      const double budget = options.unit_beside_time_share * left;
      while (!unit.done() && !UnitTurns::stalled(unit, options.unit_beside_stall_share) && unit.seconds() < budget) {
        unit.resume(options.unit_beside_turn, in(budget - unit.seconds()));
      }
    }
    if (unit.done()) {
      const SearchStatus st = unit.result().status;
      const bool retry = st == SearchStatus::kOutOfMemory || st == SearchStatus::kFailed ||
                         (st == SearchStatus::kTimeout && !term());
      if (!retry) return std::move(unit.result());
    }
    if (options.unit_progress_alone) {
      // Stalled, out of its share, or given up: the cost + 1 run alone with the time left.
      unit.cancel();
      SearchResult r = firstPlan(task, init, goal, options, heuristic, term);
      r.stats.unit_first_failed = true;
      addRunCosts(r.stats, unit.result().stats);
      return r;
    }
    // The cost + 1 run from the start, the unit-cost run (if it goes on) in turns beside it.
    std::stop_source plus_stop;
    struct StopRequest {
      std::stop_source* source;
      void operator()() const { source->request_stop(); }
    };
    std::stop_callback<StopRequest> link(term.token(), StopRequest{&plus_stop});
    const Termination plus_term(term.deadline(), plus_stop.get_token());
    if (!unit.done() && UnitTurns::stalled(unit, options.unit_beside_stall_share)) unit.cancel();
    const bool beside = !unit.done();
    UnitTurns turns(unit, options.unit_beside_turn, options.unit_beside_time_share * left,
                    options.unit_beside_stall_share, plus_stop);
    SearchResult plus;
    {
      ScopedEvaluationHook hook(beside ? &turns : nullptr);
      plus = firstPlan(task, init, goal, options, heuristic, plus_term);
    }
    if (!unit.done() && (plus.status == SearchStatus::kFailed || plus.status == SearchStatus::kOutOfMemory)) {
      unit.resume(UINT64_MAX, std::nullopt);  // the cost + 1 run gave up: the unit-cost run alone
    }
    if (unit.done() && isFinalAnswer(unit.result())) {
      SearchResult r = std::move(unit.result());
      addRunCosts(r.stats, plus.stats);
      r.stats.unit_beside = true;
      return r;
    }
    unit.cancel();
    plus.stats.unit_first_failed = true;
    plus.stats.unit_beside = beside;
    addRunCosts(plus.stats, unit.result().stats);
    return plus;
  }
  SearchResult unit;
  {
    SearchOptions unit_options = options;
    unit_options.cost_type = CostType::kUnit;  // also for the heuristic of a lazy search beside
    std::unique_ptr<Heuristic> unit_h = makeHeuristic(defaultHeuristic(options), task, CostType::kUnit);
    const Termination share =
        std::isfinite(left) ? term.tightened(Deadline::in(options.unit_first_time_share * left)) : term;
    unit = firstPlan(task, init, goal, unit_options, *unit_h, share);
  }  // the unit-cost heuristic and the run's states are freed before the second run
  const bool retry = unit.status == SearchStatus::kOutOfMemory || unit.status == SearchStatus::kFailed ||
                     (unit.status == SearchStatus::kTimeout && !term());
  if (!retry) return unit;
  SearchResult r = firstPlan(task, init, goal, options, heuristic, term);
  r.stats.unit_first_failed = true;
  addRunCosts(r.stats, unit.stats);
  return r;
}

}  // namespace

SearchResult search(const Task& task, const StateBits& init, const Goal& goal, const SearchOptions& options,
                    Heuristic& heuristic, const Termination& term) {
  options.validate();
  if (init.size() != task.numWords()) {
    throw std::invalid_argument("search: initial state has " + std::to_string(init.size()) + " words, task needs " +
                                std::to_string(task.numWords()));
  }
  const bool satisficing = options.algorithm == SearchAlgorithm::kEhc || options.algorithm == SearchAlgorithm::kGbfs ||
                           options.algorithm == SearchAlgorithm::kLazy;
  const bool anytime = satisficing && options.anytime_seconds > 0 && costsVary(task);
  // LAMA 2011: the first plan with unit costs (an explicit cost type is kept), the improving
  // iterations with cost + 1.
  SearchResult best = anytime && options.unit_cost_first && !options.cost_type
                          ? unitCostFirstPlan(task, init, goal, options, heuristic, term)
                          : firstPlan(task, init, goal, options, heuristic, term);
  if (best.status != SearchStatus::kSolved || !anytime) return best;
  // Anytime phase (LAMA 2011): the lazy greedy search, then lazy weighted A* with w = 5, 3, 2, 1,
  // 1, ..., each bounded by the best cost so far, until the budget or the caller's deadline; an
  // exhausted weighted A* iteration proves the best plan optimal.
  const Termination until = term.tightened(Deadline::in(options.anytime_seconds));
  // Plan neighbourhood graph search on the first plan (and on each cheaper plan it finds), the
  // neighbourhood doubled while it finds nothing cheaper.
  if (options.neighbourhood_time_share > 0) {
    const double left = until.deadline().secondsLeft();
    const Termination share =
        std::isfinite(left) ? until.tightened(Deadline::in(options.neighbourhood_time_share * left)) : until;
    // One searcher while nothing cheaper is found, so that the neighbourhood grows in place
    // (`neighbourhood_grow`); a new one around each cheaper plan.
    std::unique_ptr<Searcher> s;
    for (size_t states = options.neighbourhood_first_states; !share() && best.cost > 0;) {
      if (!s) s = std::make_unique<Searcher>(task, init, goal, options, heuristic, share);
      bool complete = false;
      SearchResult r = s->neighbourhood(best.plan, states, options.neighbourhood_grow, &complete);
      ++best.stats.neighbourhood_runs;
      best.stats.neighbourhood_states = std::max<uint64_t>(best.stats.neighbourhood_states, r.stats.registered_states);
      best.stats.neighbourhood_seconds += r.stats.seconds;
      addRunCosts(best.stats, r.stats);
      if (r.status != SearchStatus::kSolved) break;  // out of time or memory
      const bool cheaper = r.cost < best.cost;
      if (cheaper) {
        ++best.stats.neighbourhood_improvements;
        best.plan = std::move(r.plan);
        best.cost = r.cost;
        s.reset();
      }
      if (complete) {  // the whole reachable space: the plan is optimal
        best.stats.anytime_proved_optimal = true;
        return best;
      }
      if (!cheaper) states *= 2;  // else the same size around the cheaper plan (Nakhost & Mueller)
    }
  }
  // 0: the lazy greedy search with landmarks (LAMA's first iteration, cost-aware heuristic).
  static constexpr double kWeights[] = {0.0, 5.0, 3.0, 2.0, 1.0};
  for (size_t i = 0; !until() && best.cost > 0; ++i) {
    Searcher s(task, init, goal, options, heuristic, until);
    const double w = kWeights[std::min<size_t>(i, 4)];
    SearchResult r = s.improve(w, best.cost);
    ++best.stats.anytime_iterations;
    addRunCosts(best.stats, r.stats);
    if (r.status == SearchStatus::kSolved && r.cost < best.cost) {
      ++best.stats.anytime_improvements;
      best.plan = std::move(r.plan);
      best.cost = r.cost;
    } else if (r.status == SearchStatus::kUnsolvable) {
      // Only weighted A* re-opens a state reached again more cheaply, so only its exhausted
      // space holds no cheaper plan. The lazy greedy search keeps the first path to each state:
      // its exhausted space proves nothing, and the next iteration runs (as LAMA 2011's
      // `continue_on_fail`).
      if (w == 0.0) continue;
      best.stats.anytime_proved_optimal = true;
      break;
    } else if (r.status != SearchStatus::kSolved) {
      break;  // out of time or memory
    }
  }
  return best;
}

SearchResult search(const Task& task, const StateBits& init, const Goal& goal, const SearchOptions& options,
                    const Termination& term) {
  options.validate();
  auto h = makeHeuristic(defaultHeuristic(options), task, defaultCostType(options, task));
  return search(task, init, goal, options, *h, term);
}

}  // namespace tamp::symbolic_planner
