// libFuzzer target for the PDDL parser (and, on inputs that parse, the grounder): the input is
// split at the first NUL byte into a domain and a problem. Nothing may crash, hang or leak; every
// failure must come back as an Error. Built only with the `fuzz` preset (clang, TAMP_FUZZ=ON):
//   cmake --preset fuzz && cmake --build --preset fuzz --target fuzz_pddl_parser
//   build/fuzz/bin/fuzz_pddl_parser -max_total_time=300 config/pddl
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "tamp/symbolic_planner/grounding.h"
#include "tamp/symbolic_planner/pddl.h"

namespace sp = tamp::symbolic_planner;

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  std::string_view all(reinterpret_cast<const char*>(data), size);
  const size_t cut = all.find('\0');
  const std::string_view dom = all.substr(0, cut);
  const std::string_view prob =
      cut == std::string_view::npos ? std::string_view() : all.substr(cut + 1);
  auto d = sp::pddl::parseDomain(dom, "fuzz-domain");
  if (!d) {
    (void)d.error().toString();
    return 0;
  }
  for (const auto& a : d->actions) (void)sp::pddl::toString(a.precondition);
  auto p = sp::pddl::parseProblem(prob, *d, "fuzz-problem");
  if (!p) return 0;
  // Ground small tasks only (bounded work per input).
  sp::GroundingLimits limits;
  limits.max_atoms = 20000;
  limits.max_action_instances = 20000;
  limits.max_dnf_terms = 64;
  auto g = sp::Grounder::create(*d, *p, limits);
  if (!g) return 0;
  std::vector<sp::AtomId> init;
  for (const auto& a : p->init) {
    auto id = (*g)->atomId(a);
    if (id) init.push_back(*id);
  }
  tamp::Termination term = tamp::Termination::after(1.0);
  if (!(*g)->extend(init, term).ok()) return 0;
  auto t = (*g)->buildTask(init, {}, p->minimize_total_cost, term);
  if (t) (void)(*g)->groundGoal(p->goal, **t, init);
  return 0;
}
