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

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Plans with the FF-style symbolic planner; prints the plan in IPC format.\n"
               "Exit codes: 0 plan, 10 proven unsolvable, 11 incomplete search failed, 20 timeout,\n"
               "21 out of memory, 30 input error, 31 invalid plan (--validate), 39 internal error.",
               "tamp plan"};
  std::string domain, problem, search = "ehc", fallback = "lazy", heuristic, cost_type, plan_out, validate_plan;
  double timeout = 0.0, weight = 5.0, anytime = 5.0;
  size_t memory_mb = 4096;
  bool stats = false, no_check = false, no_fallback = false, no_agenda = false, first_improvement = false,
       no_ff_first = false, no_landmarks = false, no_unit_first = false,
       no_full_retry = false, ff_first_improvement = false, no_lazy_beside = false;
  uint64_t ff_budget = 300, second_budget = 300;
  const sp::SearchOptions defaults;
  uint64_t fallback_budget = defaults.ehc_fallback_budget_per_h, fallback_min = defaults.ehc_fallback_budget_min,
           fallback_max = defaults.ehc_fallback_budget_max;
  double unit_first_share = defaults.unit_first_time_share;
  double unit_beside_share = defaults.unit_beside_time_share;
  uint64_t unit_beside_turn = defaults.unit_beside_turn;
  double unit_beside_stall = defaults.unit_beside_stall_share;
  bool unit_progress_alone = defaults.unit_progress_alone;
  double neighbourhood_share = defaults.neighbourhood_time_share;
  bool neighbourhood_grow = defaults.neighbourhood_grow;
  int64_t heap_reserve_mib = 64;
  double retry_share = defaults.ehc_retry_budget_share;
  uint64_t lazy_after = defaults.ehc_lazy_after, lazy_turn_ehc = defaults.ehc_lazy_turn_ehc,
           lazy_turn_lazy = defaults.ehc_lazy_turn_lazy;
  app.add_option("domain", domain, "PDDL domain file")->required();
  app.add_option("problem", problem, "PDDL problem file")->required();
  app.add_option("--search", search,
                 "ehc (FF: hill-climbing, then best-first), gbfs (eager), lazy (LAMA's lazy GBFS), wastar, astar")
      ->check(CLI::IsMember({"ehc", "gbfs", "lazy", "wastar", "astar"}));
  app.add_option("--fallback", fallback, "ehc: the complete search after hill-climbing fails: lazy (default), gbfs")
      ->check(CLI::IsMember({"lazy", "gbfs"}));
  app.add_option("--heuristic", heuristic,
                 "ff, add, max, blind, ff-hadd (h_FF through h_add's supporters on every task) (default: ff; max "
                 "for wastar/astar)")
      ->check(CLI::IsMember({"ff", "add", "max", "blind", "ff-hadd"}));
  app.add_option("--cost-type", cost_type,
                 "how action costs enter the heuristic: unit, cost, plusone (default: plusone for ehc/gbfs "
                 "on tasks with costs, cost for wastar/astar)")
      ->check(CLI::IsMember({"unit", "cost", "plusone"}));
  app.add_option("--weight", weight, "weight of wastar (>= 1)")->check(CLI::Range(1.0, 1e6));
  app.add_option("--timeout", timeout, "time limit in seconds (0 = none)")->check(CLI::Range(0.0, 1e9));
  app.add_option("--memory-limit", memory_mb, "search memory budget in MiB (0 = none)");
  app.add_option("--heap-reserve", heap_reserve_mib,
                 "reserve this many MiB of heap at start-up (larger heap steps, no mmap per large block, "
                 "huge pages where available), so that short runs pay fewer page faults; 0 = malloc's "
                 "defaults; at most 4096")
      ->check(CLI::Range(int64_t{0}, kMaxHeapReserveMib));
  app.add_option("-o,--output", plan_out, "also write the plan to this file");
  app.add_option("--validate", validate_plan, "check this plan file against DOMAIN PROBLEM instead of planning");
  app.add_flag("--stats", stats, "print statistics to stderr");
  app.add_flag("--no-check", no_check, "do not replay the plan with the independent checker");
  bool no_watchdog = false;
  double debug_stall = 0.0;
  // Hidden: the planner sleeps this long before it starts, its deadline unchecked (a phase that does
  // not check it); for the watchdog's test only.
  app.add_option("--debug-stall-seconds", debug_stall)->check(CLI::Range(0.0, 3600.0))->group("");
  app.add_flag("--no-watchdog", no_watchdog,
               "with --timeout: no watchdog (by default one ends the process with the timeout answer when the "
               "planner has not stopped 0.5 s after its deadline)");
  app.add_flag("--no-fallback", no_fallback, "ehc: do not fall back to best-first search");
  app.add_flag("--no-goal-agenda", no_agenda, "ehc: pursue all goals at once (no FF goal agenda)");
  app.add_flag("--ehc-first-improvement", first_improvement,
               "ehc: continue from the first better state (FF) instead of the best sibling");
  app.add_flag("--no-ehc-full-retry", no_full_retry,
               "ehc: fall back as soon as a plateau is exhausted with helpful actions (FF), instead of searching "
               "it again with every applicable action");
  app.add_option("--ehc-retry-share", retry_share,
                 "ehc: a plateau searched again with every applicable action may use this share of the "
                 "hill-climbing budget before the complete search starts (0 = unbounded)")
      ->check(CLI::Range(0.0, 1.0));
  app.add_flag("--ehc-ff-first-improvement", ff_first_improvement,
               "ehc: the first run (FF-v2.3 variant) continues from the first better state, as FF (default: from "
               "the best sibling, as the default run)");
  app.add_flag("--no-ehc-ff-first", no_ff_first,
               "ehc: no first hill-climbing run with FF-v2.3's variant of the relaxed plan");
  app.add_option("--ehc-ff-budget", ff_budget,
                 "ehc: evaluations allowed to that first run per unit of the initial h (0 = no first run)");
  app.add_option("--ehc-second-budget", second_budget,
                 "ehc: when the first run's plan has >= 2 x h(init) actions, also run the default EHC with this "
                 "many evaluations per action of that plan and keep the cheaper plan (0 = never)");
  app.add_option("--ehc-fallback-budget", fallback_budget,
                 "ehc: fall back to the complete search after MIN + this many evaluations per unit of the "
                 "initial h (0 = never)");
  app.add_option("--anytime", anytime,
                 "tasks whose actions differ in cost: after the first plan, look for cheaper ones with "
                 "LAMA's weighted A* iterations for up to this many seconds (0 = first plan)")
      ->check(CLI::Range(0.0, 1e9));
  app.add_flag("--no-unit-first", no_unit_first,
               "with --anytime on tasks whose actions differ in cost: search for the first plan with "
               "cost + 1 at once (default: first with unit costs, as LAMA 2011, then cost + 1 if that fails)");
  app.add_option("--unit-first-share", unit_first_share,
                 "the share of the time left that the unit-cost first run may use, in (0, 1]")
      ->check(CLI::Range(1e-9, 1.0));
  app.add_option("--unit-beside-share", unit_beside_share,
                 "the unit-cost first run that has not answered within --unit-first-share goes on beside the "
                 "cost + 1 run, in turns, until it has used this share of the time left in all, in [0, 1] "
                 "(at most --unit-first-share: it stops at its first share, the cost + 1 run after it)")
      ->check(CLI::Range(0.0, 1.0));
  app.add_option("--unit-beside-stall", unit_beside_stall,
                 "with --unit-beside-share: the unit-cost run is stopped once it has made no progress (a hill-climbing "
                 "step, a landmark count below every one before) in this share of its evaluations, in [0, 1] (0: never)")
      ->check(CLI::Range(0.0, 1.0));
  app.add_option("--unit-progress-alone", unit_progress_alone,
                 "with --unit-beside-share and --unit-beside-stall: the unit-cost run that makes progress goes on "
                 "alone (the cost + 1 run after it, with the time left) instead of in turns (true/false)");
  app.add_option("--unit-beside-turn", unit_beside_turn,
                 "evaluations per turn of each of the unit-cost and cost + 1 runs in turns (> 0)")
      ->check(CLI::Range(uint64_t{1}, UINT64_MAX));
  app.add_option("--neighbourhood-share", neighbourhood_share,
                 "with --anytime: the share of its time for plan neighbourhood graph search on the first plan, "
                 "before LAMA's weighted A* iterations, in [0, 1] (0 = none)")
      ->check(CLI::Range(0.0, 1.0));
  app.add_option("--neighbourhood-grow", neighbourhood_grow,
                 "with --neighbourhood-share: grow a neighbourhood that found nothing cheaper in place (true, "
                 "the default) or build it again from the plan at each doubling (false); the same states either way");
  app.add_flag("--no-landmarks", no_landmarks, "lazy: h_FF only (no landmark-count heuristic)");
  std::string landmark_generator = defaults.landmark_generator == sp::LandmarkGenerator::kRhw ? "rhw" : "zg";
  size_t rhw_max_disjunction = defaults.rhw.max_disjunction_size;
  bool rhw_no_zg = !defaults.rhw.add_zhu_givan, rhw_keep_one_action = !defaults.rhw.skip_one_action_disjunctions;
  bool rhw_reasonable = defaults.rhw.reasonable_orders;
  bool h2_restart = defaults.ehc_h2_restart;
  bool prune_irrelevant = sp::PlanRequest{}.prune_irrelevant;
  uint32_t h2_test_gap_max = defaults.ehc_h2_test_gap_max;
  bool ff_first_h2_restart = defaults.ehc_ff_first_h2_restart;
  app.add_option("--landmarks", landmark_generator,
                 "lazy: the landmarks counted: rhw (Richter-Helmert-Westphal: disjunctive landmarks, greedy-necessary "
                 "orders, landmarks required again) or zg (Zhu-Givan fact landmarks)")
      ->check(CLI::IsMember({"rhw", "zg"}));
  app.add_option("--rhw-max-disjunction", rhw_max_disjunction,
                 "lazy with rhw: disjunctive landmarks of at most this many facts (< 2: none)");
  app.add_flag("--rhw-no-zg", rhw_no_zg, "lazy with rhw: do not add the Zhu-Givan landmarks the back-chaining misses");
  app.add_flag("--rhw-one-action-disjunctions", rhw_keep_one_action,
               "lazy with rhw: also the disjunctive landmarks that restate one action's disjunctive precondition (as Fast "
               "Downward)");
  app.add_option("--rhw-reasonable-orders", rhw_reasonable,
                 "lazy with rhw: reasonable orders (Hoffmann et al.'s, from h^2 mutexes) between the landmarks: "
                 "true or false");
  app.add_option("--ehc-h2-restart", h2_restart,
                 "ehc: after a hill-climbing run proves a state it committed to a dead end, run it again "
                 "from the start, testing every state it commits to with h^2 from that state: true or false");
  app.add_option("--ehc-h2-test-gap-max", h2_test_gap_max,
                 "ehc, testing with h^2: 0 tests every state before committing to it; n > 0 tests the last "
                 "state committed at a gap doubling up to n (and on a plateau), finding the first dead one by "
                 "bisection");
  app.add_option("--ehc-ff-first-h2-restart", ff_first_h2_restart,
                 "ehc: --ehc-h2-restart for the first run (FF-v2.3's variant) too: true or false");
  app.add_option("--prune-irrelevant", prune_irrelevant,
                 "search a task pruned to the facts and operators relevant to the goal (backward relevance, "
                 "operators the same on them merged): true or false");
  app.add_flag("--no-ehc-lazy-beside", no_lazy_beside,
               "ehc: the lazy search only after the hill-climbing fails (FF's order), not beside it");
  bool lazy_plan_preferred = defaults.lazy_plan_preferred;
  app.add_option("--lazy-plan-preferred", lazy_plan_preferred,
                 "ehc: the lazy search beside the hill-climbing prefers the relaxed plan's applicable operators "
                 "and none of the landmark count's (LAMA-first's), not FF's helpful actions and the landmarks' "
                 "achievers: true or false (default false)");
  bool lazy_beside_both = defaults.lazy_beside_both;
  app.add_option("--lazy-beside-both", lazy_beside_both,
                 "ehc: two lazy searches beside the hill-climbing in turns, one with the default preferred "
                 "operators, one with LAMA-first's (joining after --lazy-second-after): true or false (default true)");
  bool lazy_second_hadd = defaults.lazy_second_hadd;
  app.add_option("--lazy-second-hadd", lazy_second_hadd,
                 "ehc, --lazy-beside-both: the second lazy search's h_FF through h_add's best supporters (Fast "
                 "Downward's ff(), LAMA-first's) also where the operators cost the same: true or false (default " +
                     std::string(defaults.lazy_second_hadd ? "true" : "false") + ")");
  uint64_t lazy_hadd_lane_budget = defaults.lazy_hadd_lane_budget;
  app.add_option("--lazy-hadd-lane-budget", lazy_hadd_lane_budget,
                 "ehc, --lazy-beside-both without --lazy-second-hadd, operators of one cost: a third lazy search "
                 "with LAMA-first's h_FF (h_add's supporters) joins with the second and is dropped after this many "
                 "evaluations (0: none; default " + std::to_string(defaults.lazy_hadd_lane_budget) + ")");
  uint64_t lazy_second_after = defaults.lazy_second_after;
  app.add_option("--lazy-second-after", lazy_second_after,
                 "ehc, --lazy-beside-both: the second lazy search joins after this many evaluations of the "
                 "hill-climbing and the first lazy search since the first started (0: with the first; default 32000)");
  app.add_option("--ehc-lazy-after", lazy_after,
                 "ehc: the lazy search starts beside the hill-climbing after this many evaluations (> 0)")
      ->check(CLI::Range(uint64_t{1}, UINT64_MAX));
  app.add_option("--ehc-lazy-turn-ehc", lazy_turn_ehc, "ehc: evaluations of the hill-climbing per turn (> 0)")
      ->check(CLI::Range(uint64_t{1}, UINT64_MAX));
  app.add_option("--ehc-lazy-turn-lazy", lazy_turn_lazy, "ehc: evaluations of the lazy search per turn (> 0)")
      ->check(CLI::Range(uint64_t{1}, UINT64_MAX));
  app.add_option("--ehc-fallback-min", fallback_min, "ehc: the MIN of --ehc-fallback-budget");
  app.add_option("--ehc-fallback-max", fallback_max, "ehc: at most this many evaluations before falling back (0 = no cap)");
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int rc = app.exit(e);
    return rc == 0 ? 0 : tamp::cli::kExitInputError;
  }
  if (!validate_plan.empty()) return validate(domain, problem, validate_plan);
  reserveHeap(heap_reserve_mib);

  sp::PlanRequest req;
  req.domain_path = domain;
  req.problem_path = problem;
  req.search.algorithm = *sp::parseSearchAlgorithm(search);
  req.search.fallback = *sp::parseSearchAlgorithm(fallback);
  req.search.weight = weight;
  req.search.memory_limit_mb = memory_mb;
  req.search.ehc_fallback = !no_fallback;
  req.search.goal_agenda = !no_agenda;
  req.search.ehc_best_sibling = !first_improvement;
  req.search.ehc_full_retry = !no_full_retry;
  req.search.ehc_retry_budget_share = retry_share;
  req.search.ehc_ff_first_improvement = ff_first_improvement;
  req.search.ehc_ff_first = !no_ff_first;
  req.search.ehc_ff_budget_per_h = ff_budget;
  req.search.ehc_second_budget_per_step = second_budget;
  req.search.ehc_fallback_budget_per_h = fallback_budget;
  req.search.ehc_fallback_budget_min = fallback_min;
  req.search.ehc_fallback_budget_max = fallback_max;
  req.search.landmarks = !no_landmarks;
  req.search.landmark_generator = landmark_generator == "rhw" ? sp::LandmarkGenerator::kRhw : sp::LandmarkGenerator::kZhuGivan;
  req.search.rhw.max_disjunction_size = rhw_max_disjunction;
  req.search.rhw.add_zhu_givan = !rhw_no_zg;
  req.search.rhw.skip_one_action_disjunctions = !rhw_keep_one_action;
  req.search.rhw.reasonable_orders = rhw_reasonable;
  req.search.ehc_lazy_beside = !no_lazy_beside;
  req.search.lazy_plan_preferred = lazy_plan_preferred;
  req.search.lazy_beside_both = lazy_beside_both;
  req.search.lazy_second_after = lazy_second_after;
  req.search.lazy_second_hadd = lazy_second_hadd;
  req.search.lazy_hadd_lane_budget = lazy_hadd_lane_budget;
  req.search.ehc_h2_restart = h2_restart;
  req.search.ehc_h2_test_gap_max = h2_test_gap_max;
  req.search.ehc_ff_first_h2_restart = ff_first_h2_restart;
  req.search.ehc_lazy_after = lazy_after;
  req.search.ehc_lazy_turn_ehc = lazy_turn_ehc;
  req.search.ehc_lazy_turn_lazy = lazy_turn_lazy;
  req.search.anytime_seconds = anytime;
  req.search.unit_cost_first = !no_unit_first;
  req.search.unit_first_time_share = unit_first_share;
  req.search.unit_beside_time_share = unit_beside_share;
  req.search.unit_beside_turn = unit_beside_turn;
  req.search.unit_beside_stall_share = unit_beside_stall;
  req.search.unit_progress_alone = unit_progress_alone;
  req.search.neighbourhood_time_share = neighbourhood_share;
  req.search.neighbourhood_grow = neighbourhood_grow;
  if (heuristic == "ff") req.search.heuristic = sp::HeuristicKind::kFF;
  if (heuristic == "add") req.search.heuristic = sp::HeuristicKind::kAdd;
  if (heuristic == "max") req.search.heuristic = sp::HeuristicKind::kMax;
  if (heuristic == "blind") req.search.heuristic = sp::HeuristicKind::kBlind;
  if (heuristic == "ff-hadd") req.search.heuristic = sp::HeuristicKind::kFFHadd;
  if (cost_type == "unit") req.search.cost_type = sp::CostType::kUnit;
  if (cost_type == "cost") req.search.cost_type = sp::CostType::kCost;
  if (cost_type == "plusone") req.search.cost_type = sp::CostType::kPlusOne;
  req.timeout_seconds = timeout;
  req.check_plan = !no_check;
  req.return_states = false;  // only the plan is printed
  req.prune_irrelevant = prune_irrelevant;
  // The planner (and the grounding its cache keeps) is deliberately never destroyed: freeing the
  // grounding piece by piece at exit costs 0.2-0.3 ms per run, which is what a process-per-instance
  // benchmark measures; the OS reclaims it. Reachable through this static, so no leak report.
  static sp::Planner* const planner = new sp::Planner(1);
  // One deadline for the planner and the watchdog, from here.
  const tamp::Termination term = timeout > 0 ? tamp::Termination(tamp::Deadline::in(timeout)) : tamp::Termination();
  const bool watchdog = timeout > 0 && !no_watchdog;
  if (watchdog) armWatchdog(timeout + kWatchdogGraceSeconds, stats);
  if (debug_stall > 0) std::this_thread::sleep_for(std::chrono::duration<double>(debug_stall));
  const sp::PlanReply reply = planner->solve(req, term);
  if (watchdog) claimAnswer();
  if (stats) {
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
    if (reply.stats.neighbourhood_runs > 0) {
      std::fprintf(stderr, "; plan neighbourhood searches %llu, %llu improvements, up to %llu states, %.3f s",
                   static_cast<unsigned long long>(reply.stats.neighbourhood_runs),
                   static_cast<unsigned long long>(reply.stats.neighbourhood_improvements),
                   static_cast<unsigned long long>(reply.stats.neighbourhood_states),
                   reply.stats.neighbourhood_seconds);
    }
    if (reply.stats.relevance_ran) {
      const sp::RelevanceStats& r = reply.stats.relevance;
      std::fprintf(stderr, "; relevance %.4f s: facts %zu -> %zu, operators %zu -> %zu relevant -> %zu merged%s",
                   r.seconds, r.facts_before, r.facts_after, r.ops_before, r.ops_relevant, r.ops_after,
                   r.unsafe ? " (not complete here: nothing pruned)" : reply.stats.pruned ? "" : " (nothing pruned)");
    }
    std::fputc('\n', stderr);
  }
  if (reply.status != sp::PlanStatus::kSolved) {
    std::cerr << (reply.status == sp::PlanStatus::kInputError ? "error: " : "") << reply.message << "\n";
    std::cout << "; " << sp::toString(reply.status) << "\n";
    return exitCode(reply.status);
  }
  const std::string text = sp::formatPlan(reply.plan, reply.cost);
  std::fwrite(text.data(), 1, text.size(), stdout);
  if (!plan_out.empty()) {
    std::FILE* f = std::fopen(plan_out.c_str(), "w");
    if (!f || std::fwrite(text.data(), 1, text.size(), f) != text.size()) {
      std::cerr << "error: cannot write " << plan_out << "\n";
      if (f) std::fclose(f);
      return tamp::cli::kExitInputError;
    }
    std::fclose(f);
  }
  return tamp::cli::kExitOk;
}
