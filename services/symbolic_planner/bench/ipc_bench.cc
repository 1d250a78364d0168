// IPC benchmark driver: runs `tamp-plan` once per instance (one process each, like the reference
// runs of FF and Fast Downward), measures end-to-end wall time and peak RSS of the child
// (wait4/getrusage), kills it at the time limit, checks every plan with the independent lifted
// plan checker, writes a per-instance CSV and prints a per-domain Markdown summary next to the
// reference planners of the benchmark's reference_results.csv.
//
// Two medians of wall time are reported: over each planner's own solved instances (the reference
// README's definition; a planner that solves more, harder instances is penalised), and over the
// instances solved by both our planner and the reference planner of that row (the usual IPC
// comparison). After the table, one line per domain says whether "median time <= FF" holds on
// each definition.
//
//   tamp_symbolic_planner_ipc_bench --planner build/planner/bin/tamp-plan
//       --set tests/data/benchmarks/pddl --out docs/bench/symbolic_planner_ipc.csv [--timeout 60]
//       [--domain blocks] [--problem instance-5] [--lock /tmp/tamp-build.lock] [--label ours]
//       [-- extra planner args]
// A set with a manifest.csv (domain,problem,domain_file,problem_file, relative to the set, as
// pddl-more with its per-instance domain files) is run from it; otherwise every <dir>/domain.pddl
// with its <dir>/instance-N.pddl.
//   tamp_symbolic_planner_ipc_bench --results docs/bench/symbolic_planner_ipc.csv
//       --set tests/data/benchmarks/pddl      (summary of an earlier run's CSV, nothing is run)
#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/file.h>
#include <sys/resource.h>
#include <sys/syscall.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "tamp/core/paths.h"
#include "tamp/symbolic_planner/pddl.h"
#include "tamp/symbolic_planner/validator.h"

namespace fs = std::filesystem;
namespace sp = tamp::symbolic_planner;

namespace {

struct Row {
  std::string domain, problem, planner;
  bool solved{false};
  double wall_s{0};
  double cpu_s{0};
  long plan_length{-1};
  double plan_cost{-1};
  long peak_kb{0};
  int exit_code{0};
  std::string note;
  std::string stats;  // the planner's `--stats` line (commas as semicolons), when it printed one
};

struct RunResult {
  int exit_code{-1};
  bool killed{false};
  double wall_s{0};
  double cpu_s{0};
  long peak_kb{0};
  std::string out;
  std::string err;
};

RunResult runChild(const std::vector<std::string>& argv, double timeout_s) {
  RunResult r;
  char tmpl[] = "/tmp/tamp_ipc_bench_XXXXXX";
  const int fd = mkstemp(tmpl);
  if (fd < 0) {
    r.out = "mkstemp failed";
    return r;
  }
  unlink(tmpl);
  char etmpl[] = "/tmp/tamp_ipc_bench_XXXXXX";
  const int efd = mkstemp(etmpl);
  if (efd < 0) {
    close(fd);
    r.out = "mkstemp failed";
    return r;
  }
  unlink(etmpl);
  const auto t0 = std::chrono::steady_clock::now();
  const pid_t pid = fork();
  if (pid == 0) {
    dup2(fd, STDOUT_FILENO);
    dup2(efd, STDERR_FILENO);
    std::vector<char*> args;
    for (const auto& a : argv) args.push_back(const_cast<char*>(a.c_str()));
    args.push_back(nullptr);
    execv(args[0], args.data());
    _exit(127);
  }
  int status = 0;
  struct rusage ru {};
  // A pidfd becomes readable when the child exits: the wall time ends at the exit, not at the
  // next poll. Without one (kernel < 5.3), poll wait4 finely at first, then back off.
  const int pidfd = static_cast<int>(syscall(SYS_pidfd_open, pid, 0));
  for (;;) {
    const pid_t w = wait4(pid, &status, WNOHANG, &ru);
    if (w == pid) break;
    const double el = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    if (el > timeout_s && !r.killed) {
      kill(pid, SIGKILL);
      r.killed = true;
    }
    if (pidfd >= 0) {
      pollfd pfd{};
      pfd.fd = pidfd;
      pfd.events = POLLIN;
      poll(&pfd, 1, r.killed ? -1 : static_cast<int>(std::ceil(1000 * (timeout_s - el))));
    } else {
      std::this_thread::sleep_for(el < 0.05 ? std::chrono::microseconds(100)
                                            : std::chrono::milliseconds(2));
    }
  }
  if (pidfd >= 0) close(pidfd);
  r.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  r.peak_kb = ru.ru_maxrss;
  r.cpu_s = static_cast<double>(ru.ru_utime.tv_sec + ru.ru_stime.tv_sec) +
            1e-6 * static_cast<double>(ru.ru_utime.tv_usec + ru.ru_stime.tv_usec);
  r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + (WIFSIGNALED(status) ? WTERMSIG(status) : 0);
  lseek(fd, 0, SEEK_SET);
  char buf[65536];
  ssize_t n;
  while ((n = read(fd, buf, sizeof buf)) > 0) r.out.append(buf, static_cast<size_t>(n));
  close(fd);
  lseek(efd, 0, SEEK_SET);
  while ((n = read(efd, buf, sizeof buf)) > 0) r.err.append(buf, static_cast<size_t>(n));
  close(efd);
  return r;
}

int instanceNumber(const fs::path& p) {
  const std::string s = p.stem().string();
  const auto dash = s.rfind('-');
  try {
    return std::stoi(s.substr(dash + 1));
  } catch (...) {
    return 0;
  }
}

double median(std::vector<double> v) {
  if (v.empty()) return -1;
  std::sort(v.begin(), v.end());
  const size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

std::vector<std::string> splitCsv(const std::string& line) {
  std::vector<std::string> out;
  std::stringstream ss(line);
  std::string f;
  while (std::getline(ss, f, ',')) out.push_back(f);
  if (!line.empty() && line.back() == ',') out.emplace_back();
  return out;
}

/// Wall-time median over the solved instances of one planner in one domain.
double ownSolvedMedian(const std::vector<Row>& rows) {
  std::vector<double> t;
  for (const auto& r : rows) {
    if (r.solved) t.push_back(r.wall_s);
  }
  return median(t);
}

/// Wall-time medians over the instances solved by both planners of a domain.
struct CommonMedians {
  size_t instances{0};
  double ours_s{-1};
  double theirs_s{-1};
};

CommonMedians commonMedians(const std::vector<Row>& ours, const std::vector<Row>& theirs) {
  std::vector<double> a, b;
  for (const auto& o : ours) {
    if (!o.solved) continue;
    const auto t = std::find_if(theirs.begin(), theirs.end(),
                                [&](const Row& r) { return r.solved && r.problem == o.problem; });
    if (t == theirs.end()) continue;
    a.push_back(o.wall_s);
    b.push_back(t->wall_s);
  }
  return {a.size(), median(a), median(b)};
}

std::string formatSeconds(double s) {
  if (s < 0) return "–";
  char b[32];
  std::snprintf(b, sizeof b, "%.4f", s);
  return b;
}

/// Rows of a per-instance CSV: the references' or one written by this driver (`--out`).
std::vector<Row> readRows(const fs::path& csv) {
  std::vector<Row> rows;
  std::ifstream in(csv);
  std::string line;
  std::vector<std::string> header;
  while (std::getline(in, line)) {
    if (!line.empty() && line.back() == '\r') line.pop_back();
    auto f = splitCsv(line);
    if (header.empty()) {
      header = f;
      continue;
    }
    std::map<std::string, std::string> m;
    for (size_t i = 0; i < header.size() && i < f.size(); ++i) m[header[i]] = f[i];
    Row r;
    r.domain = m["domain"];
    r.problem = m["problem"];
    r.planner = m["planner"];
    r.solved = m["solved"] == "1";
    r.wall_s = m["wall_s"].empty() ? 0 : std::stod(m["wall_s"]);
    r.cpu_s = m["cpu_s"].empty() ? 0 : std::stod(m["cpu_s"]);
    r.plan_length = m["plan_length"].empty() ? -1 : std::stol(m["plan_length"]);
    r.plan_cost = m.count("plan_cost") && !m["plan_cost"].empty() ? std::stod(m["plan_cost"]) : r.plan_length;
    r.peak_kb = m["peak_kb"].empty() ? 0 : std::stol(m["peak_kb"]);
    rows.push_back(r);
  }
  return rows;
}

}  // namespace

int main(int argc, char** argv) {
  std::string planner, set, out_csv, results_csv, only_domain, only_problem, lock_file, label = "tamp-plan";
  double timeout = 60;
  std::vector<std::string> extra;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    auto next = [&]() -> std::string {
      if (i + 1 >= argc) {
        std::cerr << "missing value after " << a << "\n";
        std::exit(30);
      }
      return argv[++i];
    };
    if (a == "--planner") planner = next();
    else if (a == "--set") set = next();
    else if (a == "--out") out_csv = next();
    else if (a == "--results") results_csv = next();
    else if (a == "--timeout") timeout = std::stod(next());
    else if (a == "--domain") only_domain = next();
    else if (a == "--problem") only_problem = next();
    else if (a == "--lock") lock_file = next();
    else if (a == "--label") label = next();
    else if (a == "--") {
      for (++i; i < argc; ++i) extra.push_back(argv[i]);
    } else {
      std::cerr << "usage: " << argv[0]
                << " --planner PATH --set BENCH_DIR [--out CSV] [--timeout S] [--domain D] "
                   "[--problem P] [--lock FILE] [--label L] [-- ARGS]\n"
                << "       " << argv[0]
                << " --results CSV --set BENCH_DIR [--domain D] [--label L]\n";
      return 30;
    }
  }
  if ((planner.empty() == results_csv.empty()) || set.empty()) {
    std::cerr << "--set and one of --planner, --results are required\n";
    return 30;
  }
  // The instances: the set's manifest.csv (domain,problem,domain_file,problem_file; paths relative
  // to the set) when there is one, else every <dir>/domain.pddl with its <dir>/instance-N.pddl.
  struct Instance {
    std::string domain, problem;
    fs::path domain_file, problem_file;
  };
  std::vector<Instance> instances;
  std::vector<std::string> dnames;
  const fs::path manifest = fs::path(set) / "manifest.csv";
  if (fs::exists(manifest)) {
    std::ifstream in(manifest);
    std::string line;
    std::vector<std::string> header;
    while (std::getline(in, line)) {
      if (!line.empty() && line.back() == '\r') line.pop_back();
      if (line.empty()) continue;
      auto f = splitCsv(line);
      if (header.empty()) {
        header = f;
        continue;
      }
      std::map<std::string, std::string> m;
      for (size_t i = 0; i < header.size() && i < f.size(); ++i) m[header[i]] = f[i];
      if (m["domain"].empty() || m["domain_file"].empty() || m["problem_file"].empty()) {
        std::cerr << manifest.string() << ": bad row '" << line << "'\n";
        return 30;
      }
      instances.push_back({m["domain"], m["problem"].empty() ? fs::path(m["problem_file"]).stem().string() : m["problem"],
                           fs::path(set) / m["domain_file"], fs::path(set) / m["problem_file"]});
    }
  } else {
    std::vector<fs::path> domains;
    for (const auto& e : fs::directory_iterator(set)) {
      if (e.is_directory() && fs::exists(e.path() / "domain.pddl")) domains.push_back(e.path());
    }
    std::sort(domains.begin(), domains.end());
    for (const auto& dir : domains) {
      std::vector<fs::path> inst;
      for (const auto& e : fs::directory_iterator(dir)) {
        const std::string n = e.path().filename().string();
        if (n.rfind("instance-", 0) == 0 && e.path().extension() == ".pddl") inst.push_back(e.path());
      }
      std::sort(inst.begin(), inst.end(), [](const fs::path& a, const fs::path& b) { return instanceNumber(a) < instanceNumber(b); });
      for (const auto& p : inst) instances.push_back({dir.filename().string(), p.stem().string(), dir / "domain.pddl", p});
    }
  }
  for (const auto& i : instances) {
    if ((only_domain.empty() || i.domain == only_domain) &&
        std::find(dnames.begin(), dnames.end(), i.domain) == dnames.end()) {
      dnames.push_back(i.domain);
    }
  }
  std::vector<Row> rows;
  if (!results_csv.empty()) {
    for (const auto& r : readRows(results_csv)) {
      if (r.planner == label && (only_domain.empty() || r.domain == only_domain)) rows.push_back(r);
    }
  }
  // With --lock, the lock is taken around each planner run only, so that builds can run between
  // instances but never during one.
  int lock_fd = -1;
  if (!lock_file.empty()) {
    lock_fd = open(lock_file.c_str(), O_RDWR | O_CREAT, 0666);
    if (lock_fd < 0) {
      std::cerr << "cannot open lock file " << lock_file << "\n";
      return 30;
    }
  }
  std::map<std::string, tamp::Result<sp::pddl::Domain>> parsed;  // by domain file
  for (const auto& inst : instances) {
    if (!results_csv.empty() || (!only_domain.empty() && inst.domain != only_domain)) continue;
    if (!only_problem.empty() && inst.problem != only_problem) continue;
    const std::string dkey = inst.domain_file.string();
    if (!parsed.count(dkey)) {
      auto dtext = tamp::readTextFile(inst.domain_file);
      parsed.emplace(dkey, dtext ? sp::pddl::parseDomain(*dtext, dkey) : tamp::Result<sp::pddl::Domain>(dtext.error()));
    }
    const auto& dom = parsed.at(dkey);
    const fs::path& p = inst.problem_file;
    std::vector<std::string> args{planner, dkey, p.string(), "--no-check"};
    args.insert(args.end(), extra.begin(), extra.end());
    if (lock_fd >= 0) flock(lock_fd, LOCK_EX);
    RunResult rr = runChild(args, timeout);
    if (lock_fd >= 0) flock(lock_fd, LOCK_UN);
    Row row;
    row.domain = inst.domain;
    row.problem = inst.problem;
    row.planner = label;
    row.wall_s = rr.wall_s;
    row.cpu_s = rr.cpu_s;
    row.peak_kb = rr.peak_kb;
    row.exit_code = rr.exit_code;
    // The planner's statistics line (`tamp plan --stats`), kept in the CSV as one field.
    for (size_t pos = 0; pos < rr.err.size();) {
      size_t end = rr.err.find('\n', pos);
      if (end == std::string::npos) end = rr.err.size();
      if (rr.err.compare(pos, 9, "; status ") == 0) row.stats = rr.err.substr(pos + 2, end - pos - 2);
      pos = end + 1;
    }
    std::replace(row.stats.begin(), row.stats.end(), ',', ';');
    if (rr.exit_code == 0 && !rr.killed && dom) {
      auto plan = sp::parsePlan(rr.out, p.string() + ".plan");
      auto ptext = tamp::readTextFile(p);
      if (plan && ptext) {
        auto prob = sp::pddl::parseProblem(*ptext, *dom, p.string());
        if (prob) {
          const sp::ValidationResult v =
              sp::validatePlan(*dom, *prob, *plan, std::nullopt, std::nullopt, /*record_states=*/false);
          row.solved = v.valid;
          row.plan_length = static_cast<long>(plan->size());
          row.plan_cost = v.cost;
          if (!v.valid) row.note = "INVALID: " + v.message;
        } else {
          row.note = "checker cannot parse the problem";
        }
      }
    } else if (rr.killed) {
      row.note = "killed at time limit";
    } else if (!dom) {
      row.note = "checker cannot parse the domain";
    }
    std::fprintf(stderr, "%-12s %-14s exit %3d  %8.3f s  %7ld KB  len %4ld  %s\n", row.domain.c_str(),
                 row.problem.c_str(), row.exit_code, row.wall_s, row.peak_kb, row.plan_length, row.note.c_str());
    rows.push_back(row);
  }
  if (!out_csv.empty()) {
    std::ofstream out(out_csv);
    out << "domain,problem,planner,solved,wall_s,cpu_s,plan_length,plan_cost,peak_kb,exit_code,note,stats\n";
    for (const auto& r : rows) {
      char b[1024];
      std::snprintf(b, sizeof b, "%s,%s,%s,%d,%.4f,%.4f,%s,%s,%ld,%d,%s,%s\n", r.domain.c_str(), r.problem.c_str(),
                    r.planner.c_str(), r.solved ? 1 : 0, r.wall_s, r.cpu_s,
                    r.solved ? std::to_string(r.plan_length).c_str() : "",
                    r.solved ? std::to_string(static_cast<long>(r.plan_cost)).c_str() : "", r.peak_kb, r.exit_code,
                    r.note.c_str(), r.stats.c_str());
      out << b;
    }
  }
  // Summary next to the references.
  const fs::path ref_csv = fs::path(set) / "reference_results.csv";
  std::vector<Row> ref = fs::exists(ref_csv) ? readRows(ref_csv) : std::vector<Row>{};
  std::map<std::string, std::vector<Row>> by;  // "domain|planner"
  std::vector<std::string> planners{label};
  for (const auto& r : ref) {
    if (!only_domain.empty() && r.domain != only_domain) continue;
    by[r.domain + "|" + r.planner].push_back(r);
    if (std::find(planners.begin(), planners.end(), r.planner) == planners.end()) planners.push_back(r.planner);
  }
  for (const auto& r : rows) by[r.domain + "|" + r.planner].push_back(r);
  const std::string kFF = "ff-v2.3";
  std::printf(
      "| domain | planner | coverage | median wall time (s) | median CPU time (s) | median length "
      "| median cost | median peak RSS (MB) | FF-solved by us | solved by both | common-solved "
      "median wall ours / this (s) |\n");
  std::printf("|---|---|---|---|---|---|---|---|---|---|---|\n");
  for (const auto& d : dnames) {
    for (const auto& pl : planners) {
      auto it = by.find(d + "|" + pl);
      if (it == by.end()) continue;
      std::vector<double> t, cpu, len, cost, kb;
      int solved = 0;
      for (const auto& r : it->second) {
        if (!r.solved) continue;
        ++solved;
        t.push_back(r.wall_s);
        cpu.push_back(r.cpu_s);
        len.push_back(static_cast<double>(r.plan_length));
        cost.push_back(r.plan_cost);
        kb.push_back(static_cast<double>(r.peak_kb) / 1024.0);
      }
      std::string ff_cov = "";
      std::string common_n = "", common_t = "";
      if (pl == label) {
        int ff_solved = 0, both = 0;
        for (const auto& r : ref) {
          if (r.domain != d || r.planner != kFF || !r.solved) continue;
          ++ff_solved;
          for (const auto& o : it->second) both += (o.problem == r.problem && o.solved) ? 1 : 0;
        }
        ff_cov = std::to_string(both) + "/" + std::to_string(ff_solved);
      } else if (auto ours = by.find(d + "|" + label); ours != by.end()) {
        const CommonMedians c = commonMedians(ours->second, it->second);
        common_n = std::to_string(c.instances);
        common_t = formatSeconds(c.ours_s) + " / " + formatSeconds(c.theirs_s);
      }
      const std::string cpu_s = pl == label ? std::to_string(median(cpu)).substr(0, 6) : "–";
      std::printf("| %s | %s | %d/%zu | %.4f | %s | %.1f | %.1f | %.1f | %s | %s | %s |\n",
                  d.c_str(), pl.c_str(), solved, it->second.size(), median(t), cpu_s.c_str(),
                  median(len), median(cost), median(kb), ff_cov.c_str(), common_n.c_str(),
                  common_t.c_str());
    }
  }
  // The time target of issue 3 ("median time no worse than FF's") on both definitions.
  std::printf(
      "\nMedian wall time <= %s's (own-solved: each planner's own solved instances; common-solved: "
      "instances solved by both):\n",
      kFF.c_str());
  for (const auto& d : dnames) {
    auto ours = by.find(d + "|" + label);
    auto ff = by.find(d + "|" + kFF);
    if (ours == by.end() || ff == by.end()) continue;
    auto verdict = [](double a, double b) {
      return a < 0 || b < 0 ? "n/a" : (a <= b ? "yes" : "no");
    };
    const double own_a = ownSolvedMedian(ours->second), own_b = ownSolvedMedian(ff->second);
    const CommonMedians c = commonMedians(ours->second, ff->second);
    std::printf("- %s: own-solved %s vs %s s: %s; common-solved (%zu instances) %s vs %s s: %s\n",
                d.c_str(), formatSeconds(own_a).c_str(), formatSeconds(own_b).c_str(),
                verdict(own_a, own_b), c.instances, formatSeconds(c.ours_s).c_str(),
                formatSeconds(c.theirs_s).c_str(), verdict(c.ours_s, c.theirs_s));
  }
  return 0;
}
