// Independent plan checker over the lifted AST (deliberately naive: sets of strings, recursion).
#include "tamp/symbolic_planner/validator.h"

#include <algorithm>

#include <cctype>
#include <map>
#include <set>
#include <unordered_map>
#include <unordered_set>

namespace tamp::symbolic_planner {
namespace {

using Binding = std::map<std::string, std::string>;

class Checker {
 public:
  Checker(const pddl::Domain& d, const pddl::Problem& p) : d_(d), p_(p) {
    for (const auto& c : d.constants) objects_[c.name] = c.types;
    for (const auto& o : p.objects) objects_[o.name] = o.types;
    for (const auto& fv : p.function_values) {
      std::string key = fv.term.predicate;
      for (const auto& a : fv.term.args) key += " " + a.name;
      functions_[key] = fv.value;
    }
  }

  bool objectHasType(const std::string& obj, const std::vector<std::string>& types) const {
    auto it = objects_.find(obj);
    if (it == objects_.end()) return false;
    for (const auto& ot : it->second) {
      for (const auto& t : types) {
        if (d_.isSubtype(ot, t)) return true;
      }
    }
    return false;
  }

  std::vector<std::string> objectsOf(const std::vector<std::string>& types) const {
    std::vector<std::string> out;
    for (const auto& [name, ts] : objects_) {
      (void)ts;
      if (objectHasType(name, types)) out.push_back(name);
    }
    return out;
  }

  std::string resolve(const pddl::Term& t, const Binding& b) const {
    if (!t.isVariable()) return t.name;
    auto it = b.find(t.name);
    return it == b.end() ? std::string("?unbound") : it->second;
  }

  std::string groundAtom(const pddl::Atom& a, const Binding& b) const {
    std::string s = a.predicate;
    for (const auto& t : a.args) s += " " + resolve(t, b);
    return s;
  }

  bool holds(const pddl::Formula& f, const std::set<std::string>& state, Binding& b) const {
    using K = pddl::FormulaKind;
    switch (f.kind) {
      case K::kTrue: return true;
      case K::kFalse: return false;
      case K::kAtom: return state.count(groundAtom(f.atom, b)) > 0;
      case K::kEquals: return resolve(f.atom.args[0], b) == resolve(f.atom.args[1], b);
      case K::kNot: return !holds(f.children[0], state, b);
      case K::kAnd:
        for (const auto& c : f.children) {
          if (!holds(c, state, b)) return false;
        }
        return true;
      case K::kOr:
        for (const auto& c : f.children) {
          if (holds(c, state, b)) return true;
        }
        return false;
      case K::kImply: return !holds(f.children[0], state, b) || holds(f.children[1], state, b);
      case K::kExists:
      case K::kForall: return quantified(f, 0, state, b, f.kind == K::kForall);
    }
    return false;
  }

  bool quantified(const pddl::Formula& f, size_t k, const std::set<std::string>& state, Binding& b, bool forall) const {
    if (k == f.vars.size()) return holds(f.children[0], state, b);
    const auto& v = f.vars[k];
    const auto saved = b.find(v.name) != b.end() ? std::optional<std::string>(b[v.name]) : std::nullopt;
    bool result = forall;
    for (const auto& o : objectsOf(v.types)) {
      b[v.name] = o;
      const bool r = quantified(f, k + 1, state, b, forall);
      if (forall && !r) {
        result = false;
        break;
      }
      if (!forall && r) {
        result = true;
        break;
      }
    }
    if (saved) b[v.name] = *saved; else b.erase(v.name);
    return result;
  }

  /// Collects the effect literals that fire (forall expanded, conditions in `state`).
  void effects(const pddl::Action& a, const std::set<std::string>& state, Binding& b,
               std::vector<std::string>& adds, std::vector<std::string>& dels) const {
    for (const auto& e : a.effects) expandEffect(e, 0, state, b, adds, dels);
  }

  void expandEffect(const pddl::EffectLiteral& e, size_t k, const std::set<std::string>& state, Binding& b,
                    std::vector<std::string>& adds, std::vector<std::string>& dels) const {
    if (k == e.forall.size()) {
      if (!holds(e.condition, state, b)) return;
      (e.negated ? dels : adds).push_back(groundAtom(e.atom, b));
      return;
    }
    const auto& v = e.forall[k];
    for (const auto& o : objectsOf(v.types)) {
      b[v.name] = o;
      expandEffect(e, k + 1, state, b, adds, dels);
    }
    b.erase(v.name);
  }

  std::optional<double> cost(const pddl::Action& a, const Binding& b) const {
    if (!p_.minimize_total_cost) return 1.0;
    double c = 0;
    for (const auto& ce : a.costs) {
      if (!ce.is_function) {
        c += ce.constant;
        continue;
      }
      std::string key = ce.function.predicate;
      for (const auto& t : ce.function.args) key += " " + resolve(t, b);
      auto it = functions_.find(key);
      if (it == functions_.end()) return std::nullopt;
      c += it->second;
    }
    return c;
  }

  const pddl::Domain& d_;
  const pddl::Problem& p_;
  std::unordered_map<std::string, std::vector<std::string>> objects_;
  std::unordered_map<std::string, double> functions_;
};

}  // namespace

std::string PlanStep::toString() const {
  std::string s = "(" + action;
  for (const auto& a : args) s += " " + a;
  return s + ")";
}

Result<std::vector<PlanStep>> parsePlan(const std::string& text, const std::string& name) {
  std::vector<PlanStep> out;
  int line = 1;
  size_t i = 0;
  auto err = [&](size_t pos_in_line, const std::string& msg) {
    return Error(ErrorCode::kParseError, msg, SourceLocation{name, line, static_cast<int>(pos_in_line) + 1, ""});
  };
  while (i <= text.size()) {
    size_t end = text.find('\n', i);
    if (end == std::string::npos) end = text.size();
    std::string l = text.substr(i, end - i);
    if (auto c = l.find(';'); c != std::string::npos) l.resize(c);
    size_t p = 0;
    auto skip = [&]() {
      while (p < l.size() && std::isspace(static_cast<unsigned char>(l[p]))) ++p;
    };
    skip();
    if (p < l.size()) {
      // Optional "N:" step prefix (some planners print it).
      size_t q = p;
      while (q < l.size() && std::isdigit(static_cast<unsigned char>(l[q]))) ++q;
      if (q > p && q < l.size() && l[q] == ':') {
        p = q + 1;
        skip();
      }
      if (l[p] != '(') return err(p, "expected '(' to start a plan step");
      ++p;
      PlanStep st;
      std::vector<std::string> toks;
      for (;;) {
        skip();
        if (p >= l.size()) return err(p, "expected ')' to end the plan step");
        if (l[p] == ')') {
          ++p;
          break;
        }
        std::string tok;
        while (p < l.size() && !std::isspace(static_cast<unsigned char>(l[p])) && l[p] != ')' && l[p] != '(') {
          tok.push_back(static_cast<char>(std::tolower(static_cast<unsigned char>(l[p]))));
          ++p;
        }
        if (tok.empty()) return err(p, "unexpected '(' inside a plan step");
        toks.push_back(std::move(tok));
      }
      if (toks.empty()) return err(p, "empty plan step '()'");
      skip();
      if (p < l.size()) return err(p, "unexpected text after the plan step");
      st.action = toks[0];
      st.args.assign(toks.begin() + 1, toks.end());
      out.push_back(std::move(st));
    }
    if (end == text.size()) break;
    i = end + 1;
    ++line;
  }
  return out;
}

namespace {
/// "(p a b)" for each internal "p a b", sorted.
std::vector<std::string> atomList(const std::set<std::string>& state) {
  std::vector<std::string> out;
  out.reserve(state.size());
  for (const auto& a : state) out.push_back("(" + a + ")");
  std::sort(out.begin(), out.end());
  return out;
}
}  // namespace

ValidationResult validatePlan(const pddl::Domain& domain, const pddl::Problem& problem,
                              const std::vector<PlanStep>& plan, const std::optional<std::vector<pddl::Atom>>& init,
                              const std::optional<pddl::Formula>& goal, bool record_states) {
  Checker ck(domain, problem);
  ValidationResult r;
  std::set<std::string> state;
  Binding empty;
  for (const auto& a : init ? *init : problem.init) state.insert(ck.groundAtom(a, empty));
  if (record_states) r.states.push_back(atomList(state));
  for (size_t i = 0; i < plan.size(); ++i) {
    const PlanStep& st = plan[i];
    const std::string where = "step " + std::to_string(i + 1) + " " + st.toString() + ": ";
    const pddl::Action* act = nullptr;
    for (const auto& a : domain.actions) {
      if (a.name == st.action) act = &a;
    }
    r.failed_step = static_cast<int>(i);
    if (!act) {
      r.message = where + "unknown action '" + st.action + "'";
      return r;
    }
    if (act->parameters.size() != st.args.size()) {
      r.message = where + "expected " + std::to_string(act->parameters.size()) + " argument(s)";
      return r;
    }
    Binding b;
    for (size_t k = 0; k < st.args.size(); ++k) {
      if (!ck.objectHasType(st.args[k], act->parameters[k].types)) {
        r.message = where + "argument '" + st.args[k] + "' is not an object of type " + act->parameters[k].types[0];
        return r;
      }
      b[act->parameters[k].name] = st.args[k];
    }
    if (!ck.holds(act->precondition, state, b)) {
      r.message = where + "precondition " + pddl::toString(act->precondition) + " does not hold";
      return r;
    }
    auto c = ck.cost(*act, b);
    if (!c) {
      r.message = where + "action cost is undefined (function value missing in :init)";
      return r;
    }
    r.cost += *c;
    std::vector<std::string> adds, dels;
    ck.effects(*act, state, b, adds, dels);
    for (const auto& d : dels) state.erase(d);
    for (const auto& a : adds) state.insert(a);
    if (record_states) r.states.push_back(atomList(state));
  }
  r.failed_step = -1;
  Binding b;
  if (!ck.holds(goal ? *goal : problem.goal, state, b)) {
    r.message = "the goal does not hold after the last step";
    return r;
  }
  r.valid = true;
  return r;
}

}  // namespace tamp::symbolic_planner
