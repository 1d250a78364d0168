// Process-level tests of `tamp plan` / `tamp-plan`: output format and exit codes.
#include <elf.h>
#include <gtest/gtest.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <utility>
#include <vector>

#include "test_util.h"

namespace tamp::symbolic_planner {
namespace {

struct CliRun {
  int code{-1};
  std::string out;
};

CliRun runCli(const std::string& args) {
  const std::string cmd = std::string(TAMP_BIN_DIR) + "/tamp-plan " + args + " 2>&1";
  CliRun r;
  FILE* p = popen(cmd.c_str(), "r");
  if (!p) return r;
  std::array<char, 4096> buf{};
  size_t n;
  while ((n = fread(buf.data(), 1, buf.size(), p)) > 0) r.out.append(buf.data(), n);
  const int st = pclose(p);
  r.code = WIFEXITED(st) ? WEXITSTATUS(st) : -1;
  return r;
}

std::string tmpFile(const std::string& name, const std::string& text) {
  const auto p = std::filesystem::temp_directory_path() / ("tamp_plan_cli_" + name);
  std::ofstream(p) << text;
  return p.string();
}

class Cli : public ::testing::Test {
 protected:
  void SetUp() override {
    if (!std::filesystem::exists(std::string(TAMP_BIN_DIR) + "/tamp-plan")) GTEST_SKIP() << "tamp-plan not built";
  }
  const std::string dom_ = (test::sourceDir() / "config/pddl/mobile_manipulation.pddl").string();
  const std::string prob_ = (test::sourceDir() / "config/pddl/problems/occluded_can.pddl").string();
};

TEST_F(Cli, PrintsAnIpcPlanThatValidates) {
  CliRun r = runCli(dom_ + " " + prob_);
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_EQ(r.out.rfind("(move_base start near_table)", 0), 0U) << r.out;
  EXPECT_NE(r.out.find("; cost = "), std::string::npos);
  const std::string plan = tmpFile("plan.txt", r.out);
  CliRun v = runCli(dom_ + " " + prob_ + " --validate " + plan);
  EXPECT_EQ(v.code, 0) << v.out;
  EXPECT_NE(v.out.find("valid plan"), std::string::npos);
  const std::string bad = tmpFile("bad.txt", "(pick can table over_table)\n");
  CliRun b = runCli(dom_ + " " + prob_ + " --validate " + bad);
  EXPECT_EQ(b.code, 31) << b.out;
  EXPECT_NE(b.out.find("step 1 (pick can table over_table)"), std::string::npos) << b.out;
}

TEST_F(Cli, EverySearchAlgorithm) {
  for (const char* s : {"ehc", "gbfs", "wastar", "astar"}) {
    CliRun r = runCli(dom_ + " " + prob_ + " --search " + s);
    EXPECT_EQ(r.code, 0) << s << ": " << r.out;
  }
  CliRun r = runCli(dom_ + " " + prob_ + " --search dfs");
  EXPECT_EQ(r.code, 30) << r.out;
}

TEST_F(Cli, HeapReserveKeepsThePlanAndRefusesBadValues) {
  CliRun def = runCli(dom_ + " " + prob_);
  ASSERT_EQ(def.code, 0) << def.out;
  for (const char* mib : {"0", "1", "64", "4096"}) {
    CliRun r = runCli(dom_ + " " + prob_ + " --heap-reserve " + mib);
    EXPECT_EQ(r.code, 0) << mib << ": " << r.out;
    EXPECT_EQ(r.out, def.out) << mib;  // the reserve changes where memory comes from, not the plan
  }
  for (const char* bad : {"-1", "4097", "100000000000", "lots", "1.5"}) {
    CliRun r = runCli(dom_ + " " + prob_ + " --heap-reserve " + bad);
    EXPECT_EQ(r.code, 30) << bad << ": " << r.out;
    EXPECT_NE(r.out.find("--heap-reserve"), std::string::npos) << bad << ": " << r.out;
    EXPECT_EQ(r.out.find("(move_base"), std::string::npos) << bad << ": planned anyway: " << r.out;
  }
}

/// Whether the ELF executable at `path` asks for a dynamic loader (a PT_INTERP program header) and
/// how many shared libraries it names (DT_NEEDED entries); false, -1 when it is not a 64-bit ELF.
struct ElfLinkage {
  bool interp{false};
  int needed{-1};
};
ElfLinkage elfLinkage(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  const std::vector<char> b((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  ElfLinkage r;
  Elf64_Ehdr eh;
  if (b.size() < sizeof(eh)) return r;
  std::memcpy(&eh, b.data(), sizeof(eh));
  if (std::memcmp(eh.e_ident, ELFMAG, SELFMAG) != 0 || eh.e_ident[EI_CLASS] != ELFCLASS64) return r;
  r.needed = 0;
  for (size_t i = 0; i < eh.e_phnum; ++i) {
    Elf64_Phdr ph;
    const size_t at = eh.e_phoff + i * eh.e_phentsize;
    if (at + sizeof(ph) > b.size()) break;
    std::memcpy(&ph, b.data() + at, sizeof(ph));
    if (ph.p_type == PT_INTERP) r.interp = true;
    if (ph.p_type != PT_DYNAMIC) continue;
    for (size_t d = ph.p_offset; d + sizeof(Elf64_Dyn) <= b.size() && d < ph.p_offset + ph.p_filesz;
         d += sizeof(Elf64_Dyn)) {
      Elf64_Dyn dyn;
      std::memcpy(&dyn, b.data() + d, sizeof(dyn));
      if (dyn.d_tag == DT_NULL) break;
      if (dyn.d_tag == DT_NEEDED) ++r.needed;
    }
  }
  return r;
}

// Issue 14, thirteenth round: tamp-plan is linked statically (static-pie), which takes 1-2 ms
// off a run on a small task; only a build that says it could not (TAMP_PLAN_STATIC_EXPECTED=0:
// sanitizers, no libc.a, TAMP_PLAN_STATIC=OFF) expects a dynamic one.
TEST_F(Cli, LinkedStaticallyWhereTheBuildCan) {
  const ElfLinkage l = elfLinkage(std::string(TAMP_BIN_DIR) + "/tamp-plan");
  ASSERT_GE(l.needed, 0) << "tamp-plan is not a 64-bit ELF executable";
#if !defined(TAMP_PLAN_STATIC_EXPECTED) || TAMP_PLAN_STATIC_EXPECTED
  EXPECT_FALSE(l.interp) << "tamp-plan asks for a dynamic loader";
  EXPECT_EQ(l.needed, 0) << "tamp-plan names shared libraries";
#else
  EXPECT_TRUE(l.interp);
#endif
  // Static or not, it plans.
  CliRun r = runCli(dom_ + " " + prob_);
  EXPECT_EQ(r.code, 0) << r.out;
}

/// Runs tamp-plan with `args` (stdout and stderr to /dev/null); returns its exit code and the
/// minor page faults it took, or -1, -1.
std::pair<int, long> runCounted(const std::vector<std::string>& args) {
  const std::string bin = std::string(TAMP_BIN_DIR) + "/tamp-plan";
  std::vector<char*> argv{const_cast<char*>(bin.c_str())};
  for (const auto& a : args) argv.push_back(const_cast<char*>(a.c_str()));
  argv.push_back(nullptr);
  const pid_t pid = fork();
  if (pid < 0) return {-1, -1};
  if (pid == 0) {
    if (FILE* null = std::fopen("/dev/null", "w")) {
      dup2(fileno(null), 1);
      dup2(fileno(null), 2);
    }
    execv(bin.c_str(), argv.data());
    _exit(127);
  }
  int st = 0;
  rusage ru{};
  if (wait4(pid, &st, 0, &ru) != pid) return {-1, -1};
  return {WIFEXITED(st) ? WEXITSTATUS(st) : -1, ru.ru_minflt};
}

// Issue 14, thirteenth round: the heap reserved at start-up begins at a huge page boundary, so a
// small task takes a steady ~90-130 page faults (static / dynamic executable on the VM of
// docs/benchmarks.md). Before, the first 0-2 MiB of the heap (a random share, from where the heap
// happened to start) had 4 KiB pages: 108-476 faults on this task, 2-4 ms more on that VM.
TEST_F(Cli, HeapReserveStartsAtAHugePage) {
#if defined(__SANITIZE_ADDRESS__)
  GTEST_SKIP() << "the sanitizers' allocator ignores the heap options";
#endif
  std::ifstream thp("/sys/kernel/mm/transparent_hugepage/enabled");
  std::string mode((std::istreambuf_iterator<char>(thp)), std::istreambuf_iterator<char>());
  if (mode.find("[never]") != std::string::npos || mode.empty()) {
    GTEST_SKIP() << "no transparent huge pages";
  }
  const auto dir = test::benchmarksDir() / "pddl-more/trucks";
  const std::vector<std::string> args{(dir / "domain.pddl").string(),
                                      (dir / "instance-6.pddl").string()};
  long most = 0;
  for (int run = 0; run < 5; ++run) {
    const auto [code, faults] = runCounted(args);
    ASSERT_EQ(code, 0);
    most = std::max(most, faults);
  }
  EXPECT_LE(most, 200) << "page faults of the most costly of 5 runs";
}

TEST_F(Cli, ReasonableOrdersAreCountedInTheStatsWhenAskedFor) {
  const auto blocks = test::benchmarksDir() / "pddl/blocks";
  const std::string task = (blocks / "domain.pddl").string() + " " + (blocks / "instance-10.pddl").string();
  CliRun on = runCli(task + " --search lazy --stats --rhw-reasonable-orders true");
  ASSERT_EQ(on.code, 0) << on.out;
  EXPECT_EQ(on.out.find(" 0 reasonable orders)"), std::string::npos) << on.out;
  EXPECT_NE(on.out.find(" reasonable orders)"), std::string::npos) << on.out;
  CliRun off = runCli(task + " --search lazy --stats --rhw-reasonable-orders false");
  ASSERT_EQ(off.code, 0) << off.out;
  EXPECT_NE(off.out.find(" 0 reasonable orders)"), std::string::npos) << off.out;
  CliRun bad = runCli(task + " --rhw-reasonable-orders sometimes");
  EXPECT_EQ(bad.code, 30) << bad.out;
}

// Issue 14, twenty-eighth round: the plan's replay by the independent checker is timed in --stats,
// and not run with --no-check.
TEST_F(Cli, TheChecksTimeIsInTheStats) {
  const auto miconic = test::benchmarksDir() / "pddl/miconic";  // 99 steps: a replay of >= 0.1 ms
  const std::string task = (miconic / "domain.pddl").string() + " " + (miconic / "instance-150.pddl").string();
  CliRun on = runCli(task + " --stats");
  ASSERT_EQ(on.code, 0) << on.out;
  ASSERT_NE(on.out.find(", check "), std::string::npos) << on.out;
  EXPECT_EQ(on.out.find(", check 0.0000 s"), std::string::npos) << on.out;  // it ran (>= 50 us)
  CliRun off = runCli(task + " --stats --no-check");
  ASSERT_EQ(off.code, 0) << off.out;
  EXPECT_NE(off.out.find(", check 0.0000 s"), std::string::npos) << off.out;
}

TEST_F(Cli, ExitCodes) {
  // 30: input error, with file:line:column.
  const std::string broken = tmpFile("broken.pddl", "(define (problem x)\n  (:domain mobile-manipulation)\n  (:init (robot-at nowhere))\n  (:goal (hand-empty)))\n");
  CliRun e = runCli(dom_ + " " + broken);
  EXPECT_EQ(e.code, 30) << e.out;
  EXPECT_NE(e.out.find(broken + ":3:20: unknown object 'nowhere'"), std::string::npos) << e.out;
  CliRun missing = runCli(dom_ + " /nonexistent.pddl");
  EXPECT_EQ(missing.code, 30) << missing.out;
  // 10: proven unsolvable (nothing reaches the counter).
  const std::string unsolvable = tmpFile("unsolvable.pddl",
      "(define (problem u) (:domain mobile-manipulation) (:objects a - location c - item r - region)\n"
      " (:init (robot-at a) (arm-at stow) (hand-empty) (on c r) (graspable c))\n (:goal (holding c)))\n");
  CliRun u = runCli(dom_ + " " + unsolvable);
  EXPECT_EQ(u.code, 10) << u.out;
  // 20: timeout.
  const auto blocks = test::benchmarksDir() / "pddl/blocks";
  ASSERT_TRUE(std::filesystem::exists(blocks / "instance-80.pddl")) << blocks;
  CliRun t = runCli((blocks / "domain.pddl").string() + " " + (blocks / "instance-80.pddl").string() + " --timeout 0.2");
  EXPECT_EQ(t.code, 20) << t.out;
}

// Issue 14, thirty-fourth round: --timeout ends the run with the timeout answer in every phase
// of a large task (scanalyzer-30: 207 360 operators; grounding 0.3-0.6 s, the relevance analysis
// 0.25-0.45 s, an evaluation 10-20 ms; the deadline falls in each of them for one of the limits
// below). How soon after the deadline is measured in docs/benchmarks.md, not asserted here.
TEST_F(Cli, ATinyTimeoutOnALargeTaskEndsWithTheTimeoutAnswer) {
  const auto scan = test::benchmarksDir() / "pddl-more/scanalyzer";
  ASSERT_TRUE(std::filesystem::exists(scan / "instance-30.pddl")) << scan;
  const std::string task = (scan / "domain.pddl").string() + " " + (scan / "instance-30.pddl").string();
  for (const char* limit : {"0.01", "0.4", "0.8"}) {
    CliRun r = runCli(task + " --timeout " + limit);
    EXPECT_EQ(r.code, 20) << limit << ": " << r.out;
    EXPECT_NE(r.out.find("; timeout\n"), std::string::npos) << limit << ": " << r.out;
  }
}

// A planner that does not stop at its deadline (here: a hidden stall before it starts, its
// deadline unchecked) is ended by tamp plan's watchdog with the timeout answer, and only then.
TEST_F(Cli, TheWatchdogEndsAPlannerThatDoesNotStopAtItsDeadline) {
  CliRun w = runCli(dom_ + " " + prob_ + " --timeout 0.05 --debug-stall-seconds 30");
  EXPECT_EQ(w.code, 20) << w.out;
  EXPECT_NE(w.out.find("; timeout\n"), std::string::npos) << w.out;
  EXPECT_NE(w.out.find("ended by tamp plan's watchdog"), std::string::npos) << w.out;
  // Without it, the planner answers the same once it sees the deadline (after the stall).
  CliRun n = runCli(dom_ + " " + prob_ + " --timeout 0.05 --debug-stall-seconds 0.2 --no-watchdog");
  EXPECT_EQ(n.code, 20) << n.out;
  EXPECT_EQ(n.out.find("watchdog"), std::string::npos) << n.out;
  // A plan found in time is printed whole; the watchdog stays silent.
  CliRun p = runCli(dom_ + " " + prob_ + " --timeout 30");
  EXPECT_EQ(p.code, 0) << p.out;
  EXPECT_EQ(p.out.find("watchdog"), std::string::npos) << p.out;
}

}  // namespace
}  // namespace tamp::symbolic_planner
