// tamp plan DOMAIN PROBLEM: plans with the symbolic planner and prints the plan in IPC format.
// Exit codes: 0 plan found, 10 proven unsolvable, 11 incomplete search gave up, 20 timeout,
// 21 out of memory, 30 input error, 31 invalid plan (--validate), 39 internal error.
#include <malloc.h>
#include <sys/mman.h>
#include <unistd.h>

#include <sys/time.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <iostream>
#include <optional>
#include <string>
#include <thread>

#include <CLI/CLI.hpp>

#include "cli_common.h"
#include "tamp/core/paths.h"
#include "tamp/symbolic_planner/planner.h"

namespace sp = tamp::symbolic_planner;

namespace {

int exitCode(sp::PlanStatus s) {
  switch (s) {
    case sp::PlanStatus::kSolved: return tamp::cli::kExitOk;
    case sp::PlanStatus::kUnsolvable: return tamp::cli::kExitNoSolution;
    case sp::PlanStatus::kFailed: return tamp::cli::kExitNoSolution + 1;
    case sp::PlanStatus::kTimeout:
    case sp::PlanStatus::kCancelled: return tamp::cli::kExitTimeout;
    case sp::PlanStatus::kOutOfMemory: return tamp::cli::kExitTimeout + 1;
    case sp::PlanStatus::kInputError: return tamp::cli::kExitInputError;
    case sp::PlanStatus::kInternalError: return tamp::cli::kExitInputError + 9;
  }
  return tamp::cli::kExitInputError + 9;
}

int validate(const std::string& domain_path, const std::string& problem_path, const std::string& plan_path) {
  auto dt = tamp::readTextFile(domain_path);
  if (!dt) return std::cerr << "error: " << dt.error().toString() << "\n", tamp::cli::kExitInputError;
  auto pt = tamp::readTextFile(problem_path);
  if (!pt) return std::cerr << "error: " << pt.error().toString() << "\n", tamp::cli::kExitInputError;
  auto lt = tamp::readTextFile(plan_path);
  if (!lt) return std::cerr << "error: " << lt.error().toString() << "\n", tamp::cli::kExitInputError;
  auto d = sp::pddl::parseDomain(*dt, domain_path);
  if (!d) return std::cerr << "error: " << d.error().toString() << "\n", tamp::cli::kExitInputError;
  auto p = sp::pddl::parseProblem(*pt, *d, problem_path);
  if (!p) return std::cerr << "error: " << p.error().toString() << "\n", tamp::cli::kExitInputError;
  auto plan = sp::parsePlan(*lt, plan_path);
  if (!plan) return std::cerr << "error: " << plan.error().toString() << "\n", tamp::cli::kExitInputError;
  const sp::ValidationResult v = sp::validatePlan(*d, *p, *plan);
  if (!v.valid) {
    std::cout << "invalid plan: " << v.message << "\n";
    return tamp::cli::kExitInputError + 1;
  }
  std::cout << "valid plan: " << plan->size() << " steps, cost " << v.cost << "\n";
  return tamp::cli::kExitOk;
}

/// The block that fills the heap up to its first huge page (reserveHeap); volatile, so that the
/// compiler keeps an allocation that nothing reads.
void* volatile heap_gap = nullptr;

/// The largest --heap-reserve accepted, MiB.
constexpr int64_t kMaxHeapReserveMib = 4096;

/// Reserves `mib` MiB of heap up front so that a short run does not pay for growing it (issue 14,
/// twelfth round): the heap grows in steps of `mib` (M_TOP_PAD) and keeps what is freed
/// (M_TRIM_THRESHOLD); blocks up to glibc's cap of 32 MiB come from the heap (M_MMAP_THRESHOLD)
/// instead of a fresh mmap per large vector, which is unmapped again when freed and faulted in
/// page by page when the vector regrows; the reserved range is marked MADV_HUGEPAGE, so that where
/// transparent huge pages are enabled ("madvise" or "always") one fault maps 2 MiB, not 4 KiB.
/// Address space only: pages are touched (and count in the RSS) when the planner uses them.
/// Best effort: a mallopt or madvise the system refuses leaves malloc's defaults.
void reserveHeap(int64_t mib) {
  if (mib <= 0) return;
  const size_t bytes = static_cast<size_t>(mib) << 20;
  constexpr size_t kMmapThresholdCap = size_t{32} << 20;  // glibc refuses more (64-bit)
  const size_t mmap_threshold = bytes < kMmapThresholdCap ? bytes : kMmapThresholdCap;
  mallopt(M_MMAP_THRESHOLD, static_cast<int>(mmap_threshold));
  mallopt(M_TOP_PAD, static_cast<int>(bytes < (size_t{1} << 30) ? bytes : (size_t{1} << 30)));
  mallopt(M_TRIM_THRESHOLD, static_cast<int>(bytes < (size_t{1} << 30) ? 2 * bytes : (size_t{1} << 30)));
  // Grow the heap now: a block just under the mmap threshold comes from the top of the heap, which
  // then grows by it plus the pad; freed, it stays in the heap (above the trim threshold).
  const size_t probe = mmap_threshold / 2;
  void* block = std::malloc(probe);
  if (block == nullptr) return;
  const auto page = static_cast<uintptr_t>(2) << 20;
  const auto at = reinterpret_cast<uintptr_t>(block);
  const auto begin = (at + page - 1) & ~(page - 1);
  const auto end = reinterpret_cast<uintptr_t>(sbrk(0)) & ~(page - 1);
#ifdef MADV_HUGEPAGE
  if (end > begin) madvise(reinterpret_cast<void*>(begin), end - begin, MADV_HUGEPAGE);
#endif
  std::free(block);
  // Issue 14, thirteenth round: the heap starts at a random 4 KiB offset, so the memory between
  // the block and the first 2 MiB boundary (0-2 MiB, below `begin`) can only have 4 KiB pages,
  // and it is what the planner would use first: up to 512 page faults, 2-4 ms on this VM, on a
  // run of 10 ms. Fill that gap with a block that is never used nor freed (address space only:
  // malloc writes its header, one page), so that what comes next starts at the boundary.
  // malloc puts a freed block back at the top of the heap and carves the next request from its
  // start, with a header of two words; the size below makes the next chunk's data begin at `begin`
  // (were it a few bytes off, it would still lie in the huge page that starts there).
  constexpr size_t kChunkHeader = 2 * sizeof(size_t);
  if (begin - at > kChunkHeader && end > begin) heap_gap = std::malloc(begin - at - kChunkHeader);
}

/// How long after its deadline the planner may take to stop before the watchdog ends it (the
/// handler's message says so).
constexpr double kWatchdogGraceSeconds = 0.5;

/// The process-level bound of `--timeout` (issue 14, thirty-fourth round). The planner checks its
/// deadline in every loop known to be long (grounding, relevance analysis, h^2 tables,
/// searches; evaluations one at a time where they are slow) and frees its open lists in large
/// chunks, so it stops within a fraction of a second of it; but a phase that does not check (an
/// unseen domain's grounding, a search freeing gigabytes) must not keep `tamp plan` running. A
/// real-time timer (setitimer: no thread to start, which a run of milliseconds would pay for)
/// goes off at the deadline plus the grace; unless the answer has been claimed by then
/// (`claimAnswer()`), its handler writes the timeout answer (stdout "; timeout", a message naming
/// the watchdog on stderr) and ends the process with the timeout code at once (`_exit`: no
/// destructors; the OS takes the memory back). It may run on any thread (the planner's turns
/// run one on a thread of its own); it uses only write() and _exit().
std::atomic<bool> g_answer_claimed{false};
std::atomic<bool> g_watchdog_stats{false};

void onWatchdog(int) {
  if (g_answer_claimed.load()) return;
  auto put = [](int fd, const char* text) {
    size_t n = std::strlen(text);
    while (n > 0) {
      const ssize_t w = write(fd, text, n);
      if (w <= 0) return;
      text += w;
      n -= static_cast<size_t>(w);
    }
  };
  if (g_watchdog_stats.load()) put(2, "; status timeout; stopped by tamp plan's watchdog\n");
  put(2, "search timeout (the planner had not stopped 0.5 s after its deadline: ended by tamp plan's watchdog)\n");
  put(1, "; timeout\n");
  _exit(tamp::cli::kExitTimeout);
}

/// Arms the watchdog `seconds` from now.
void armWatchdog(double seconds, bool stats) {
  static_assert(kWatchdogGraceSeconds == 0.5, "the handler's message says 0.5 s");
  g_watchdog_stats = stats;
  struct sigaction sa {};
  sa.sa_handler = onWatchdog;
  sigemptyset(&sa.sa_mask);
  sa.sa_flags = SA_RESTART;
  sigaction(SIGALRM, &sa, nullptr);
  itimerval v{};
  const double whole = std::floor(seconds);
  v.it_value.tv_sec = static_cast<time_t>(whole);
  v.it_value.tv_usec = static_cast<suseconds_t>((seconds - whole) * 1e6) + 1;  // never 0 (= disarmed)
  setitimer(ITIMER_REAL, &v, nullptr);
}

/// The planner has answered: the watchdog stands down (a handler already past its check is
/// ending the process; this thread then prints nothing more before it does).
void claimAnswer() {
  g_answer_claimed = true;
  itimerval off{};
  setitimer(ITIMER_REAL, &off, nullptr);
}

/// The planner's search settings' defaults, which several options start from.
const sp::SearchOptions kSearchDefaults;

/// Everything `tamp plan`'s command line sets, with its defaults. Validated by the checks each
/// option is declared with (CLI11 refuses a value outside them: exit 30), so the run takes it as is.
struct CliOptions {
  // Input, output and the run.
  std::string domain, problem, plan_out, validate_plan;
  std::string search = "ehc", fallback = "lazy", heuristic, cost_type;  // empty: the planner's default
  double timeout = 0.0, weight = 5.0;
  size_t memory_mb = 4096;
  int64_t heap_reserve_mib = 64;
  bool stats = false, no_check = false, no_watchdog = false;
  double debug_stall = 0.0;
  // Enforced hill-climbing and its fallback.
  bool no_fallback = false, no_agenda = false, first_improvement = false, no_full_retry = false;
  double retry_share = kSearchDefaults.ehc_retry_budget_share;
  bool ff_first_improvement = false, no_ff_first = false;
  uint64_t ff_budget = 300, second_budget = 300;
  uint64_t fallback_budget = kSearchDefaults.ehc_fallback_budget_per_h;
  uint64_t fallback_min = kSearchDefaults.ehc_fallback_budget_min;
  uint64_t fallback_max = kSearchDefaults.ehc_fallback_budget_max;
  // Tasks whose actions differ in cost: the first plan and the anytime search.
  double anytime = 5.0;
  bool no_unit_first = false;
  double unit_first_share = kSearchDefaults.unit_first_time_share;
  double unit_beside_share = kSearchDefaults.unit_beside_time_share;
  double unit_beside_stall = kSearchDefaults.unit_beside_stall_share;
  bool unit_progress_alone = kSearchDefaults.unit_progress_alone;
  uint64_t unit_beside_turn = kSearchDefaults.unit_beside_turn;
  double neighbourhood_share = kSearchDefaults.neighbourhood_time_share;
  bool neighbourhood_grow = kSearchDefaults.neighbourhood_grow;
  // Landmarks.
  bool no_landmarks = false;
  std::string landmark_generator = kSearchDefaults.landmark_generator == sp::LandmarkGenerator::kRhw ? "rhw" : "zg";
  size_t rhw_max_disjunction = kSearchDefaults.rhw.max_disjunction_size;
  bool rhw_no_zg = !kSearchDefaults.rhw.add_zhu_givan;
  bool rhw_keep_one_action = !kSearchDefaults.rhw.skip_one_action_disjunctions;
  bool rhw_reasonable = kSearchDefaults.rhw.reasonable_orders;
  // h^2 dead-end tests and relevance pruning.
  bool h2_restart = kSearchDefaults.ehc_h2_restart;
  uint32_t h2_test_gap_max = kSearchDefaults.ehc_h2_test_gap_max;
  bool ff_first_h2_restart = kSearchDefaults.ehc_ff_first_h2_restart;
  bool prune_irrelevant = sp::PlanRequest{}.prune_irrelevant;
  // The lazy searches beside the hill-climbing.
  bool no_lazy_beside = false;
  bool lazy_plan_preferred = kSearchDefaults.lazy_plan_preferred;
  bool lazy_beside_both = kSearchDefaults.lazy_beside_both;
  bool lazy_second_hadd = kSearchDefaults.lazy_second_hadd;
  uint64_t lazy_hadd_lane_budget = kSearchDefaults.lazy_hadd_lane_budget;
  uint64_t lazy_second_after = kSearchDefaults.lazy_second_after;
  uint64_t lazy_after = kSearchDefaults.ehc_lazy_after;
  uint64_t lazy_turn_ehc = kSearchDefaults.ehc_lazy_turn_ehc;
  uint64_t lazy_turn_lazy = kSearchDefaults.ehc_lazy_turn_lazy;
};

constexpr const char* kAbout =
    "Plans with the FF-style symbolic planner; prints the plan in IPC format.\n"
    "Exit codes: 0 plan, 10 proven unsolvable, 11 incomplete search failed, 20 timeout,\n"
    "21 out of memory, 30 input error, 31 invalid plan (--validate), 39 internal error.";

/// The files, the search, the limits and what is printed.
void addRunOptions(CLI::App& app, CliOptions& o) {
  app.add_option("domain", o.domain, "PDDL domain file")->required();
  app.add_option("problem", o.problem, "PDDL problem file")->required();
  app.add_option("--search", o.search,
                 "ehc (FF: hill-climbing, then best-first), gbfs (eager), lazy (LAMA's lazy GBFS), wastar, astar")
      ->check(CLI::IsMember({"ehc", "gbfs", "lazy", "wastar", "astar"}));
  app.add_option("--fallback", o.fallback, "ehc: the complete search after hill-climbing fails: lazy (default), gbfs")
      ->check(CLI::IsMember({"lazy", "gbfs"}));
  app.add_option("--heuristic", o.heuristic,
                 "ff, add, max, blind, ff-hadd (h_FF through h_add's supporters on every task) (default: ff; max "
                 "for wastar/astar)")
      ->check(CLI::IsMember({"ff", "add", "max", "blind", "ff-hadd"}));
  app.add_option("--cost-type", o.cost_type,
                 "how action costs enter the heuristic: unit, cost, plusone (default: plusone for ehc/gbfs "
                 "on tasks with costs, cost for wastar/astar)")
      ->check(CLI::IsMember({"unit", "cost", "plusone"}));
  app.add_option("--weight", o.weight, "weight of wastar (>= 1)")->check(CLI::Range(1.0, 1e6));
  app.add_option("--timeout", o.timeout, "time limit in seconds (0 = none)")->check(CLI::Range(0.0, 1e9));
  app.add_option("--memory-limit", o.memory_mb, "search memory budget in MiB (0 = none)");
  app.add_option("--heap-reserve", o.heap_reserve_mib,
                 "reserve this many MiB of heap at start-up (larger heap steps, no mmap per large block, "
                 "huge pages where available), so that short runs pay fewer page faults; 0 = malloc's "
                 "defaults; at most 4096")
      ->check(CLI::Range(int64_t{0}, kMaxHeapReserveMib));
  app.add_option("-o,--output", o.plan_out, "also write the plan to this file");
  app.add_option("--validate", o.validate_plan, "check this plan file against DOMAIN PROBLEM instead of planning");
  app.add_flag("--stats", o.stats, "print statistics to stderr");
  app.add_flag("--no-check", o.no_check, "do not replay the plan with the independent checker");
  // Hidden: the planner sleeps this long before it starts, its deadline unchecked (a phase that does
  // not check it); for the watchdog's test only.
  app.add_option("--debug-stall-seconds", o.debug_stall)->check(CLI::Range(0.0, 3600.0))->group("");
  app.add_flag("--no-watchdog", o.no_watchdog,
               "with --timeout: no watchdog (by default one ends the process with the timeout answer when the "
               "planner has not stopped 0.5 s after its deadline)");
}

/// Enforced hill-climbing: its variants, its budgets and when it falls back.
void addEhcOptions(CLI::App& app, CliOptions& o) {
  app.add_flag("--no-fallback", o.no_fallback, "ehc: do not fall back to best-first search");
  app.add_flag("--no-goal-agenda", o.no_agenda, "ehc: pursue all goals at once (no FF goal agenda)");
  app.add_flag("--ehc-first-improvement", o.first_improvement,
               "ehc: continue from the first better state (FF) instead of the best sibling");
  app.add_flag("--no-ehc-full-retry", o.no_full_retry,
               "ehc: fall back as soon as a plateau is exhausted with helpful actions (FF), instead of searching "
               "it again with every applicable action");
  app.add_option("--ehc-retry-share", o.retry_share,
                 "ehc: a plateau searched again with every applicable action may use this share of the "
                 "hill-climbing budget before the complete search starts (0 = unbounded)")
      ->check(CLI::Range(0.0, 1.0));
  app.add_flag("--ehc-ff-first-improvement", o.ff_first_improvement,
               "ehc: the first run (FF-v2.3 variant) continues from the first better state, as FF (default: from "
               "the best sibling, as the default run)");
  app.add_flag("--no-ehc-ff-first", o.no_ff_first,
               "ehc: no first hill-climbing run with FF-v2.3's variant of the relaxed plan");
  app.add_option("--ehc-ff-budget", o.ff_budget,
                 "ehc: evaluations allowed to that first run per unit of the initial h (0 = no first run)");
  app.add_option("--ehc-second-budget", o.second_budget,
                 "ehc: when the first run's plan has >= 2 x h(init) actions, also run the default EHC with this "
                 "many evaluations per action of that plan and keep the cheaper plan (0 = never)");
  app.add_option("--ehc-fallback-budget", o.fallback_budget,
                 "ehc: fall back to the complete search after MIN + this many evaluations per unit of the "
                 "initial h (0 = never)");
}

/// Tasks whose actions differ in cost: the unit-cost first run, the anytime search after it.
void addCostTaskOptions(CLI::App& app, CliOptions& o) {
  app.add_option("--anytime", o.anytime,
                 "tasks whose actions differ in cost: after the first plan, look for cheaper ones with "
                 "LAMA's weighted A* iterations for up to this many seconds (0 = first plan)")
      ->check(CLI::Range(0.0, 1e9));
  app.add_flag("--no-unit-first", o.no_unit_first,
               "with --anytime on tasks whose actions differ in cost: search for the first plan with "
               "cost + 1 at once (default: first with unit costs, as LAMA 2011, then cost + 1 if that fails)");
  app.add_option("--unit-first-share", o.unit_first_share,
                 "the share of the time left that the unit-cost first run may use, in (0, 1]")
      ->check(CLI::Range(1e-9, 1.0));
  app.add_option("--unit-beside-share", o.unit_beside_share,
                 "the unit-cost first run that has not answered within --unit-first-share goes on beside the "
                 "cost + 1 run, in turns, until it has used this share of the time left in all, in [0, 1] "
                 "(at most --unit-first-share: it stops at its first share, the cost + 1 run after it)")
      ->check(CLI::Range(0.0, 1.0));
  app.add_option("--unit-beside-stall", o.unit_beside_stall,
                 "with --unit-beside-share: the unit-cost run is stopped once it has made no progress (a hill-climbing "
                 "step, a landmark count below every one before) in this share of its evaluations, in [0, 1] (0: never)")
      ->check(CLI::Range(0.0, 1.0));
  app.add_option("--unit-progress-alone", o.unit_progress_alone,
                 "with --unit-beside-share and --unit-beside-stall: the unit-cost run that makes progress goes on "
                 "alone (the cost + 1 run after it, with the time left) instead of in turns (true/false)");
  app.add_option("--unit-beside-turn", o.unit_beside_turn,
                 "evaluations per turn of each of the unit-cost and cost + 1 runs in turns (> 0)")
      ->check(CLI::Range(uint64_t{1}, UINT64_MAX));
  app.add_option("--neighbourhood-share", o.neighbourhood_share,
                 "with --anytime: the share of its time for plan neighbourhood graph search on the first plan, "
                 "before LAMA's weighted A* iterations, in [0, 1] (0 = none)")
      ->check(CLI::Range(0.0, 1.0));
  app.add_option("--neighbourhood-grow", o.neighbourhood_grow,
                 "with --neighbourhood-share: grow a neighbourhood that found nothing cheaper in place (true, "
                 "the default) or build it again from the plan at each doubling (false); the same states either way");
}

/// The landmark-count heuristic of the lazy search and how its landmarks are found.
void addLandmarkOptions(CLI::App& app, CliOptions& o) {
  app.add_flag("--no-landmarks", o.no_landmarks, "lazy: h_FF only (no landmark-count heuristic)");
  app.add_option("--landmarks", o.landmark_generator,
                 "lazy: the landmarks counted: rhw (Richter-Helmert-Westphal: disjunctive landmarks, greedy-necessary "
                 "orders, landmarks required again) or zg (Zhu-Givan fact landmarks)")
      ->check(CLI::IsMember({"rhw", "zg"}));
  app.add_option("--rhw-max-disjunction", o.rhw_max_disjunction,
                 "lazy with rhw: disjunctive landmarks of at most this many facts (< 2: none)");
  app.add_flag("--rhw-no-zg", o.rhw_no_zg, "lazy with rhw: do not add the Zhu-Givan landmarks the back-chaining misses");
  app.add_flag("--rhw-one-action-disjunctions", o.rhw_keep_one_action,
               "lazy with rhw: also the disjunctive landmarks that restate one action's disjunctive precondition (as Fast "
               "Downward)");
  app.add_option("--rhw-reasonable-orders", o.rhw_reasonable,
                 "lazy with rhw: reasonable orders (Hoffmann et al.'s, from h^2 mutexes) between the landmarks: "
                 "true or false");
}

/// Dead-end tests with h^2 in the hill-climbing, and pruning to what is relevant to the goal.
void addPruningOptions(CLI::App& app, CliOptions& o) {
  app.add_option("--ehc-h2-restart", o.h2_restart,
                 "ehc: after a hill-climbing run proves a state it committed to a dead end, run it again "
                 "from the start, testing every state it commits to with h^2 from that state: true or false");
  app.add_option("--ehc-h2-test-gap-max", o.h2_test_gap_max,
                 "ehc, testing with h^2: 0 tests every state before committing to it; n > 0 tests the last "
                 "state committed at a gap doubling up to n (and on a plateau), finding the first dead one by "
                 "bisection");
  app.add_option("--ehc-ff-first-h2-restart", o.ff_first_h2_restart,
                 "ehc: --ehc-h2-restart for the first run (FF-v2.3's variant) too: true or false");
  app.add_option("--prune-irrelevant", o.prune_irrelevant,
                 "search a task pruned to the facts and operators relevant to the goal (backward relevance, "
                 "operators the same on them merged): true or false");
}

/// The lazy searches that run in turns beside the hill-climbing.
void addLazyBesideOptions(CLI::App& app, CliOptions& o) {
  app.add_flag("--no-ehc-lazy-beside", o.no_lazy_beside,
               "ehc: the lazy search only after the hill-climbing fails (FF's order), not beside it");
  app.add_option("--lazy-plan-preferred", o.lazy_plan_preferred,
                 "ehc: the lazy search beside the hill-climbing prefers the relaxed plan's applicable operators "
                 "and none of the landmark count's (LAMA-first's), not FF's helpful actions and the landmarks' "
                 "achievers: true or false (default false)");
  app.add_option("--lazy-beside-both", o.lazy_beside_both,
                 "ehc: two lazy searches beside the hill-climbing in turns, one with the default preferred "
                 "operators, one with LAMA-first's (joining after --lazy-second-after): true or false (default true)");
  app.add_option("--lazy-second-hadd", o.lazy_second_hadd,
                 "ehc, --lazy-beside-both: the second lazy search's h_FF through h_add's best supporters (Fast "
                 "Downward's ff(), LAMA-first's) also where the operators cost the same: true or false (default " +
                     std::string(kSearchDefaults.lazy_second_hadd ? "true" : "false") + ")");
  app.add_option("--lazy-hadd-lane-budget", o.lazy_hadd_lane_budget,
                 "ehc, --lazy-beside-both without --lazy-second-hadd, operators of one cost: a third lazy search "
                 "with LAMA-first's h_FF (h_add's supporters) joins with the second and is dropped after this many "
                 "evaluations (0: none; default " + std::to_string(kSearchDefaults.lazy_hadd_lane_budget) + ")");
  app.add_option("--lazy-second-after", o.lazy_second_after,
                 "ehc, --lazy-beside-both: the second lazy search joins after this many evaluations of the "
                 "hill-climbing and the first lazy search since the first started (0: with the first; default 32000)");
  app.add_option("--ehc-lazy-after", o.lazy_after,
                 "ehc: the lazy search starts beside the hill-climbing after this many evaluations (> 0)")
      ->check(CLI::Range(uint64_t{1}, UINT64_MAX));
  app.add_option("--ehc-lazy-turn-ehc", o.lazy_turn_ehc, "ehc: evaluations of the hill-climbing per turn (> 0)")
      ->check(CLI::Range(uint64_t{1}, UINT64_MAX));
  app.add_option("--ehc-lazy-turn-lazy", o.lazy_turn_lazy, "ehc: evaluations of the lazy search per turn (> 0)")
      ->check(CLI::Range(uint64_t{1}, UINT64_MAX));
}

/// The bounds of --ehc-fallback-budget (declared last: their place in --help).
void addEhcFallbackBoundOptions(CLI::App& app, CliOptions& o) {
  app.add_option("--ehc-fallback-min", o.fallback_min, "ehc: the MIN of --ehc-fallback-budget");
  app.add_option("--ehc-fallback-max", o.fallback_max, "ehc: at most this many evaluations before falling back (0 = no cap)");
}

/// Declares every option of `tamp plan` on `app`, bound to `o`, in the order --help lists them.
void defineOptions(CLI::App& app, CliOptions& o) {
  addRunOptions(app, o);
  addEhcOptions(app, o);
  addCostTaskOptions(app, o);
  addLandmarkOptions(app, o);
  addPruningOptions(app, o);
  addLazyBesideOptions(app, o);
  addEhcFallbackBoundOptions(app, o);
}

/// Parses the command line; an exit code when the process ends here (--help: 0, printed by CLI11;
/// a usage error: 30, CLI11's message on stderr), none when it goes on.
std::optional<int> parseCommandLine(CLI::App& app, int argc, char** argv) {
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int rc = app.exit(e);
    return rc == 0 ? 0 : tamp::cli::kExitInputError;
  }
  return std::nullopt;
}

/// The hill-climbing's settings, its fallback's and those of the lazy searches beside it.
void setEhcSearch(const CliOptions& o, sp::SearchOptions& s) {
  s.ehc_fallback = !o.no_fallback;
  s.goal_agenda = !o.no_agenda;
  s.ehc_best_sibling = !o.first_improvement;
  s.ehc_full_retry = !o.no_full_retry;
  s.ehc_retry_budget_share = o.retry_share;
  s.ehc_ff_first_improvement = o.ff_first_improvement;
  s.ehc_ff_first = !o.no_ff_first;
  s.ehc_ff_budget_per_h = o.ff_budget;
  s.ehc_second_budget_per_step = o.second_budget;
  s.ehc_fallback_budget_per_h = o.fallback_budget;
  s.ehc_fallback_budget_min = o.fallback_min;
  s.ehc_fallback_budget_max = o.fallback_max;
  s.ehc_lazy_beside = !o.no_lazy_beside;
  s.lazy_plan_preferred = o.lazy_plan_preferred;
  s.lazy_beside_both = o.lazy_beside_both;
  s.lazy_second_after = o.lazy_second_after;
  s.lazy_second_hadd = o.lazy_second_hadd;
  s.lazy_hadd_lane_budget = o.lazy_hadd_lane_budget;
  s.ehc_h2_restart = o.h2_restart;
  s.ehc_h2_test_gap_max = o.h2_test_gap_max;
  s.ehc_ff_first_h2_restart = o.ff_first_h2_restart;
  s.ehc_lazy_after = o.lazy_after;
  s.ehc_lazy_turn_ehc = o.lazy_turn_ehc;
  s.ehc_lazy_turn_lazy = o.lazy_turn_lazy;
}

/// The landmarks the lazy search counts.
void setLandmarks(const CliOptions& o, sp::SearchOptions& s) {
  s.landmarks = !o.no_landmarks;
  s.landmark_generator = o.landmark_generator == "rhw" ? sp::LandmarkGenerator::kRhw : sp::LandmarkGenerator::kZhuGivan;
  s.rhw.max_disjunction_size = o.rhw_max_disjunction;
  s.rhw.add_zhu_givan = !o.rhw_no_zg;
  s.rhw.skip_one_action_disjunctions = !o.rhw_keep_one_action;
  s.rhw.reasonable_orders = o.rhw_reasonable;
}

/// The first plan and the anytime search on tasks whose actions differ in cost.
void setCostTaskSearch(const CliOptions& o, sp::SearchOptions& s) {
  s.anytime_seconds = o.anytime;
  s.unit_cost_first = !o.no_unit_first;
  s.unit_first_time_share = o.unit_first_share;
  s.unit_beside_time_share = o.unit_beside_share;
  s.unit_beside_turn = o.unit_beside_turn;
  s.unit_beside_stall_share = o.unit_beside_stall;
  s.unit_progress_alone = o.unit_progress_alone;
  s.neighbourhood_time_share = o.neighbourhood_share;
  s.neighbourhood_grow = o.neighbourhood_grow;
}

/// The heuristic and how action costs enter it; an empty choice keeps the planner's default.
void setHeuristic(const CliOptions& o, sp::SearchOptions& s) {
  if (o.heuristic == "ff") s.heuristic = sp::HeuristicKind::kFF;
  if (o.heuristic == "add") s.heuristic = sp::HeuristicKind::kAdd;
  if (o.heuristic == "max") s.heuristic = sp::HeuristicKind::kMax;
  if (o.heuristic == "blind") s.heuristic = sp::HeuristicKind::kBlind;
  if (o.heuristic == "ff-hadd") s.heuristic = sp::HeuristicKind::kFFHadd;
  if (o.cost_type == "unit") s.cost_type = sp::CostType::kUnit;
  if (o.cost_type == "cost") s.cost_type = sp::CostType::kCost;
  if (o.cost_type == "plusone") s.cost_type = sp::CostType::kPlusOne;
}

/// The planner's request for the command line's task and settings.
sp::PlanRequest planRequest(const CliOptions& o) {
  sp::PlanRequest req;
  req.domain_path = o.domain;
  req.problem_path = o.problem;
  req.search.algorithm = *sp::parseSearchAlgorithm(o.search);
  req.search.fallback = *sp::parseSearchAlgorithm(o.fallback);
  req.search.weight = o.weight;
  req.search.memory_limit_mb = o.memory_mb;
  setEhcSearch(o, req.search);
  setLandmarks(o, req.search);
  setCostTaskSearch(o, req.search);
  setHeuristic(o, req.search);
  req.timeout_seconds = o.timeout;
  req.check_plan = !o.no_check;
  req.return_states = false;  // only the plan is printed
  req.prune_irrelevant = o.prune_irrelevant;
  return req;
}

/// Solves `req` within --timeout, the watchdog armed for the time the planner runs.
sp::PlanReply solveWithinTimeout(const CliOptions& o, const sp::PlanRequest& req) {
  // The planner (and the grounding its cache keeps) is deliberately never destroyed: freeing the
  // grounding piece by piece at exit costs 0.2-0.3 ms per run, which is what a process-per-instance
  // benchmark measures; the OS reclaims it. Reachable through this static, so no leak report.
  static sp::Planner* const planner = new sp::Planner(1);
  // One deadline for the planner and the watchdog, from here.
  const tamp::Termination term = o.timeout > 0 ? tamp::Termination(tamp::Deadline::in(o.timeout)) : tamp::Termination();
  const bool watchdog = o.timeout > 0 && !o.no_watchdog;
  if (watchdog) armWatchdog(o.timeout + kWatchdogGraceSeconds, o.stats);
  if (o.debug_stall > 0) std::this_thread::sleep_for(std::chrono::duration<double>(o.debug_stall));
  sp::PlanReply reply = planner->solve(req, term);
  if (watchdog) claimAnswer();
  return reply;
}

/// --stats: the status, the phases' times and the searches' counters (one stderr line, unfinished).
void printSearchStats(const sp::PlanReply& reply) {
  std::fprintf(stderr,
               "; status %s; parse %.4f s, ground %.4f s, search %.4f s, check %.4f s; facts %zu, operators %zu; "
               "expanded %llu, evaluated %llu, initial h %lld; ehc plateau retries %llu (%llu abandoned); ehc fallbacks "
               "%llu (%llu in a goal-agenda entry before the last); anytime %llu "
               "iterations, %llu improvements; landmarks %llu (%llu disjunctive, %llu greedy-necessary, %llu reasonable orders); ehc h^2 restarts %llu (%llu tests, %llu dead ends)%s%s%s%s%s%s",
               sp::toString(reply.status).c_str(), reply.stats.parse_seconds, reply.stats.ground_seconds,
               reply.stats.search_seconds, reply.stats.check_seconds, reply.stats.facts, reply.stats.operators,
               static_cast<unsigned long long>(reply.stats.expanded),
               static_cast<unsigned long long>(reply.stats.evaluated), static_cast<long long>(reply.stats.initial_h),
               static_cast<unsigned long long>(reply.stats.ehc_retries),
               static_cast<unsigned long long>(reply.stats.ehc_retries_abandoned),
               static_cast<unsigned long long>(reply.stats.ehc_fallbacks),
               static_cast<unsigned long long>(reply.stats.ehc_fallbacks_in_agenda),
               static_cast<unsigned long long>(reply.stats.anytime_iterations),
               static_cast<unsigned long long>(reply.stats.anytime_improvements),
               static_cast<unsigned long long>(reply.stats.landmarks),
               static_cast<unsigned long long>(reply.stats.landmarks_disjunctive),
               static_cast<unsigned long long>(reply.stats.landmark_gn_orders),
               static_cast<unsigned long long>(reply.stats.landmark_reasonable_orders),
               static_cast<unsigned long long>(reply.stats.ehc_h2_restarts),
               static_cast<unsigned long long>(reply.stats.ehc_h2_tests),
               static_cast<unsigned long long>(reply.stats.ehc_h2_dead_ends),
               reply.stats.ehc_ff_failed ? "; ehc with FF-v2.3's relaxed plan failed, restarted" : "",
               reply.stats.ehc_second_won   ? "; second ehc run gave the shorter plan"
               : reply.stats.ehc_second_ran ? "; second ehc run, first plan kept"
                                            : "",
               reply.stats.ehc_failed ? "; ehc failed, fell back to best-first search" : "",
               reply.stats.lazy_beside_won       ? "; lazy search beside ehc gave the answer"
               : reply.stats.lazy_beside_started ? "; lazy search beside ehc started"
                                                 : "",
               reply.stats.unit_first_failed ? "; unit-cost first run failed, first plan with cost + 1" : "",
               !reply.stats.unit_beside         ? ""
               : reply.stats.unit_first_failed ? " (the unit-cost run in turns beside it)"
                                               : "; unit-cost first run answered in turns beside the cost + 1 run");
}

/// --stats: the plan neighbourhood searches, where they ran (continues the line).
void printNeighbourhoodStats(const sp::PlanStatistics& stats) {
  if (stats.neighbourhood_runs == 0) return;
  std::fprintf(stderr, "; plan neighbourhood searches %llu, %llu improvements, up to %llu states, %.3f s",
               static_cast<unsigned long long>(stats.neighbourhood_runs),
               static_cast<unsigned long long>(stats.neighbourhood_improvements),
               static_cast<unsigned long long>(stats.neighbourhood_states), stats.neighbourhood_seconds);
}

/// --stats: the relevance analysis, where it ran (continues the line).
void printRelevanceStats(const sp::PlanStatistics& stats) {
  if (!stats.relevance_ran) return;
  const sp::RelevanceStats& r = stats.relevance;
  std::fprintf(stderr, "; relevance %.4f s: facts %zu -> %zu, operators %zu -> %zu relevant -> %zu merged%s",
               r.seconds, r.facts_before, r.facts_after, r.ops_before, r.ops_relevant, r.ops_after,
               r.unsafe ? " (not complete here: nothing pruned)" : stats.pruned ? "" : " (nothing pruned)");
}

/// --stats: the whole statistics line on stderr.
void printStats(const sp::PlanReply& reply) {
  printSearchStats(reply);
  printNeighbourhoodStats(reply.stats);
  printRelevanceStats(reply.stats);
  std::fputc('\n', stderr);
}

/// No plan: the planner's message on stderr, "; STATUS" on stdout; the status's exit code.
int reportNoPlan(const sp::PlanReply& reply) {
  std::cerr << (reply.status == sp::PlanStatus::kInputError ? "error: " : "") << reply.message << "\n";
  std::cout << "; " << sp::toString(reply.status) << "\n";
  return exitCode(reply.status);
}

/// Writes `text` to the file `path`; false (and a message on stderr) if it cannot.
bool writePlanFile(const std::string& path, const std::string& text) {
  std::FILE* f = std::fopen(path.c_str(), "w");
  if (!f || std::fwrite(text.data(), 1, text.size(), f) != text.size()) {
    std::cerr << "error: cannot write " << path << "\n";
    if (f) std::fclose(f);
    return false;
  }
  std::fclose(f);
  return true;
}

/// A plan: printed in IPC format on stdout, and written to -o's file if asked; the exit code.
int reportPlan(const sp::PlanReply& reply, const std::string& plan_out) {
  const std::string text = sp::formatPlan(reply.plan, reply.cost);
  std::fwrite(text.data(), 1, text.size(), stdout);
  if (!plan_out.empty() && !writePlanFile(plan_out, text)) return tamp::cli::kExitInputError;
  return tamp::cli::kExitOk;
}

/// Plans the command line's task: the answer on stdout (and -o), the statistics on stderr; the exit code.
int runPlanner(const CliOptions& o) {
  reserveHeap(o.heap_reserve_mib);
  const sp::PlanRequest req = planRequest(o);
  const sp::PlanReply reply = solveWithinTimeout(o, req);
  if (o.stats) printStats(reply);
  if (reply.status != sp::PlanStatus::kSolved) return reportNoPlan(reply);
  return reportPlan(reply, o.plan_out);
}

}  // namespace

int main(int argc, char** argv) {
  CliOptions o;
  CLI::App app{kAbout, "tamp plan"};  // alive until the end: the heap the planner starts from as before
  defineOptions(app, o);
  if (const std::optional<int> rc = parseCommandLine(app, argc, argv)) return *rc;
  if (!o.validate_plan.empty()) return validate(o.domain, o.problem, o.validate_plan);
  return runPlanner(o);
}
