// Grounding: lifted schemas -> relaxed reachability (semi-naive join over positive preconditions)
// -> ground operators with DNF-split preconditions and compiled negation (complement facts).
#include "tamp/symbolic_planner/grounding.h"

#include "tamp/symbolic_planner/flat_index.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <map>
#include <unordered_map>
#include <unordered_set>

namespace tamp::symbolic_planner {
namespace {

/// Interns sequences of uint32 (atoms: [pred, args...]; bindings: [schema, variant, values...]).
class SeqTable {
 public:
  SeqTable() : offs_{0}, slots_(1024, 0) {}
  size_t size() const { return offs_.size() - 1; }
  const uint32_t* data(uint32_t id) const { return pool_.data() + offs_[id]; }
  uint32_t length(uint32_t id) const { return offs_[id + 1] - offs_[id]; }

  /// Returns (id, inserted).
  std::pair<uint32_t, bool> insert(const uint32_t* b, uint32_t n) {
    if ((size() + 1) * 2 > slots_.size()) grow();
    size_t i = hash(b, n) & (slots_.size() - 1);
    while (slots_[i] != 0) {
      const uint32_t id = slots_[i] - 1;
      if (equal(id, b, n)) return {id, false};
      i = (i + 1) & (slots_.size() - 1);
    }
    const uint32_t id = static_cast<uint32_t>(size());
    pool_.insert(pool_.end(), b, b + n);
    offs_.push_back(static_cast<uint32_t>(pool_.size()));
    slots_[i] = id + 1;
    return {id, true};
  }
  int64_t find(const uint32_t* b, uint32_t n) const {
    size_t i = hash(b, n) & (slots_.size() - 1);
    while (slots_[i] != 0) {
      const uint32_t id = slots_[i] - 1;
      if (equal(id, b, n)) return id;
      i = (i + 1) & (slots_.size() - 1);
    }
    return -1;
  }

 private:
  static size_t hash(const uint32_t* b, uint32_t n) {
    uint64_t h = 0x9E3779B97F4A7C15ULL ^ n;
    for (uint32_t i = 0; i < n; ++i) {
      h ^= b[i] + 0x9E3779B97F4A7C15ULL + (h << 6) + (h >> 2);
      h *= 0xFF51AFD7ED558CCDULL;
    }
    return static_cast<size_t>(h ^ (h >> 29));
  }
  bool equal(uint32_t id, const uint32_t* b, uint32_t n) const {
    if (length(id) != n) return false;
    return std::equal(b, b + n, data(id));
  }
  void grow() {
    std::vector<uint32_t> s(slots_.size() * 2, 0);
    for (uint32_t id = 0; id < size(); ++id) {
      size_t i = hash(data(id), length(id)) & (s.size() - 1);
      while (s[i] != 0) i = (i + 1) & (s.size() - 1);
      s[i] = id + 1;
    }
    slots_.swap(s);
  }
  std::vector<uint32_t> pool_;
  std::vector<uint32_t> offs_;
  std::vector<uint32_t> slots_;
};

/// A lifted term: variable index (>= 0) or object id (encoded as -1 - id).
using LTerm = int32_t;
inline bool isVar(LTerm t) { return t >= 0; }
inline uint32_t objOf(LTerm t) { return static_cast<uint32_t>(-1 - t); }

enum class LKind { kTrue, kFalse, kAtom, kEq, kAnd, kOr, kForall, kExists };

/// Negation normal form over lifted atoms.
struct LFormula {
  LKind kind{LKind::kTrue};
  bool neg{false};          // kAtom / kEq
  uint32_t pred{0};         // kAtom
  std::vector<LTerm> args;  // kAtom / kEq
  std::vector<LFormula> children;
  std::vector<uint32_t> vars;  // kForall / kExists: variable indices
};

struct LAtom {
  uint32_t pred;
  std::vector<LTerm> args;
};

struct Variant {
  std::vector<uint32_t> vars;   // variables bound by the join (params + lifted existentials)
  std::vector<LAtom> pos;       // top-level positive atoms (static and fluent)
  std::vector<LFormula> eqs;    // top-level (in)equalities, checked early
  std::vector<LFormula> parts;  // the whole conjunction (instantiated at build time)
  bool flat{false};             // every part is a literal or an (in)equality: no nesting
};

struct LEffect {
  std::vector<uint32_t> forall;
  LFormula cond;
  bool del{false};
  LAtom atom;
};

struct LCost {
  bool is_function{false};
  double constant{0};
  uint32_t function{0};
  std::vector<LTerm> args;
};

struct Schema {
  std::string name;
  uint32_t num_params{0};
  std::vector<uint32_t> var_type;  // per variable
  std::vector<Variant> variants;
  std::vector<LEffect> effects;
  std::vector<LCost> costs;
};

/// Ground NNF formula over atom ids.
struct GFormula {
  enum Kind : uint8_t { kTrue, kFalse, kLit, kAnd, kOr } kind{kTrue};
  bool neg{false};
  AtomId atom{0};
  std::vector<GFormula> children;
};

using Conj = std::vector<AtomLiteral>;

}  // namespace

struct Grounder::Impl {
  pddl::Domain domain;
  pddl::Problem problem;
  GroundingLimits limits;
  GroundingStats stats;

  // Objects and types.
  std::vector<std::string> obj_names;
  std::unordered_map<std::string, uint32_t> obj_index;
  std::vector<std::vector<uint32_t>> type_objs;   // per type id
  std::vector<std::vector<char>> type_has;        // per type id, per object
  std::map<std::string, uint32_t> type_index;     // name (or "either a b") -> id

  // Predicates and functions.
  std::vector<std::string> pred_names;
  std::unordered_map<std::string, uint32_t> pred_index;
  std::vector<uint32_t> pred_arity;
  std::vector<char> pred_static;
  std::unordered_map<std::string, uint32_t> func_index;
  std::map<std::vector<uint32_t>, double> func_values;  // [func, args...] -> value

  std::vector<Schema> schemas;

  // Atoms and reachability.
  SeqTable atoms;
  DenseAtomIndex dense_atoms;  // atom ids of predicates with few tuples, looked up without hashing
  std::vector<char> reached;  // in R(U) (fluent) or in U (static)
  std::vector<AtomId> queue;
  size_t queue_head{0};
  std::vector<std::vector<AtomId>> by_pred;  // processed atoms
  ArgIndex by_arg;  // (pred, position, object) -> processed atoms, in processing order
  /// A positive precondition `pi` of variant `vi` of schema `si`: an atom of its predicate may
  /// extend the variant's bindings there.
  struct Trigger {
    uint32_t si, vi, pi;
  };
  /// pred -> its triggers in the order of processing (schema, variant, precondition).
  std::vector<std::vector<Trigger>> triggers;
  /// Triggers by a constant argument (pred, position, object) -> indexes into triggers[pred]
  /// (each trigger under the one of its constant positions whose list is shortest), and per pred
  /// the triggers without a constant: an atom is matched against only the triggers whose
  /// constants it could match, in the order of `triggers` (the same joins in the same order as
  /// against all of them; airport's per-instance domains: ~1 000 schemas of a dozen preconditions
  /// over the same predicates, constants in every one).
  ArgIndex trigger_by_const;
  std::vector<std::vector<uint32_t>> trigger_free;
  std::vector<uint32_t> trigger_buf_;  // scratch of explore(): an atom's candidate triggers
  bool initialized{false};
  SeqTable bindings;
  uint64_t work{0};

  // ---------------------------------------------------------------------------------------------
  // Compilation

  uint32_t typeId(const std::vector<std::string>& names) {
    std::string key;
    for (const auto& n : names) key += n + " ";
    auto it = type_index.find(key);
    if (it != type_index.end()) return it->second;
    const uint32_t id = static_cast<uint32_t>(type_objs.size());
    type_index[key] = id;
    std::vector<uint32_t> objs;
    std::vector<char> has(obj_names.size(), 0);
    for (uint32_t o = 0; o < obj_names.size(); ++o) {
      for (const auto& ot : obj_types[o]) {
        for (const auto& n : names) {
          if (domain.isSubtype(ot, n)) has[o] = 1;
        }
      }
      if (has[o]) objs.push_back(o);
    }
    type_objs.push_back(std::move(objs));
    type_has.push_back(std::move(has));
    return id;
  }
  std::vector<std::vector<std::string>> obj_types;

  Status addObject(const pddl::TypedName& o) {
    if (auto it = obj_index.find(o.name); it != obj_index.end()) {
      // Declared again (a domain constant repeated in the problem): the union of its types.
      auto& ts = obj_types[it->second];
      for (const auto& t : o.types) {
        if (std::find(ts.begin(), ts.end(), t) == ts.end()) ts.push_back(t);
      }
      return Status::Ok();
    }
    obj_index[o.name] = static_cast<uint32_t>(obj_names.size());
    obj_names.push_back(o.name);
    obj_types.push_back(o.types);
    return Status::Ok();
  }

  struct Scope {
    std::vector<std::pair<std::string, uint32_t>> vars;
    Schema* schema;
    std::vector<uint32_t>* var_type;
  };

  Result<LTerm> term(const pddl::Term& t, const Scope& sc) {
    if (t.isVariable()) {
      for (auto it = sc.vars.rbegin(); it != sc.vars.rend(); ++it) {
        if (it->first == t.name) return static_cast<LTerm>(it->second);
      }
      return Error(ErrorCode::kInvalidArgument, "variable '" + t.name + "' is not bound");
    }
    auto it = obj_index.find(t.name);
    if (it == obj_index.end()) return Error(ErrorCode::kInvalidArgument, "unknown object '" + t.name + "'");
    return static_cast<LTerm>(-1 - static_cast<int64_t>(it->second));
  }

  uint32_t newVar(Scope& sc, const pddl::TypedName& v) {
    const uint32_t idx = static_cast<uint32_t>(sc.var_type->size());
    sc.var_type->push_back(typeId(v.types));
    sc.vars.push_back({v.name, idx});
    return idx;
  }

  Result<LFormula> nnf(const pddl::Formula& f, bool negate, Scope& sc, const std::string& where) {
    using pddl::FormulaKind;
    LFormula out;
    switch (f.kind) {
      case FormulaKind::kTrue: out.kind = negate ? LKind::kFalse : LKind::kTrue; return out;
      case FormulaKind::kFalse: out.kind = negate ? LKind::kTrue : LKind::kFalse; return out;
      case FormulaKind::kAtom:
      case FormulaKind::kEquals: {
        out.kind = f.kind == FormulaKind::kAtom ? LKind::kAtom : LKind::kEq;
        out.neg = negate;
        if (out.kind == LKind::kAtom) {
          auto p = pred_index.find(f.atom.predicate);
          if (p == pred_index.end()) return Error(ErrorCode::kInvalidArgument, where + ": undeclared predicate '" + f.atom.predicate + "'");
          out.pred = p->second;
          if (pred_arity[out.pred] != f.atom.args.size()) return Error(ErrorCode::kInvalidArgument, where + ": arity mismatch for '" + f.atom.predicate + "'");
        }
        for (const auto& a : f.atom.args) {
          auto t = term(a, sc);
          if (!t) return Error(t.error().code, where + ": " + t.error().message);
          out.args.push_back(*t);
        }
        return out;
      }
      case FormulaKind::kNot: return nnf(f.children.at(0), !negate, sc, where);
      case FormulaKind::kAnd:
      case FormulaKind::kOr: {
        const bool is_and = (f.kind == FormulaKind::kAnd) != negate;
        out.kind = is_and ? LKind::kAnd : LKind::kOr;
        for (const auto& c : f.children) {
          auto r = nnf(c, negate, sc, where);
          if (!r) return r;
          out.children.push_back(std::move(*r));
        }
        return out;
      }
      case FormulaKind::kImply: {  // a -> b == (not a) or b
        const bool is_and = negate;  // not (a -> b) == a and not b
        out.kind = is_and ? LKind::kAnd : LKind::kOr;
        auto a = nnf(f.children.at(0), !negate, sc, where);
        if (!a) return a;
        auto b = nnf(f.children.at(1), negate, sc, where);
        if (!b) return b;
        out.children.push_back(std::move(*a));
        out.children.push_back(std::move(*b));
        return out;
      }
      case FormulaKind::kExists:
      case FormulaKind::kForall: {
        const bool is_forall = (f.kind == FormulaKind::kForall) != negate;
        out.kind = is_forall ? LKind::kForall : LKind::kExists;
        const size_t mark = sc.vars.size();
        for (const auto& v : f.vars) out.vars.push_back(newVar(sc, v));
        auto c = nnf(f.children.at(0), negate, sc, where);
        sc.vars.resize(mark);
        if (!c) return c;
        out.children.push_back(std::move(*c));
        return out;
      }
    }
    return out;
  }

  struct TopConj {
    std::vector<uint32_t> lifted;
    std::vector<LFormula> parts;
  };

  /// Top-level DNF with existentials lifted; falls back to one conjunct holding `f` when large.
  std::vector<TopConj> splitTop(const LFormula& f) {
    constexpr size_t kMaxVariants = 64;
    switch (f.kind) {
      case LKind::kTrue: return {TopConj{}};
      case LKind::kFalse: return {};
      case LKind::kOr: {
        std::vector<TopConj> out;
        for (const auto& c : f.children) {
          auto sub = splitTop(c);
          out.insert(out.end(), sub.begin(), sub.end());
          if (out.size() > kMaxVariants) return {TopConj{{}, {f}}};
        }
        return out;
      }
      case LKind::kAnd: {
        std::vector<TopConj> acc{TopConj{}};
        for (const auto& c : f.children) {
          auto sub = splitTop(c);
          if (acc.size() * sub.size() > kMaxVariants) {
            for (auto& a : acc) a.parts.push_back(c);
            continue;
          }
          std::vector<TopConj> next;
          for (const auto& a : acc) {
            for (const auto& b : sub) {
              TopConj t = a;
              t.lifted.insert(t.lifted.end(), b.lifted.begin(), b.lifted.end());
              t.parts.insert(t.parts.end(), b.parts.begin(), b.parts.end());
              next.push_back(std::move(t));
            }
          }
          acc = std::move(next);
        }
        return acc;
      }
      case LKind::kExists: {
        auto sub = splitTop(f.children[0]);
        for (auto& s : sub) s.lifted.insert(s.lifted.begin(), f.vars.begin(), f.vars.end());
        return sub;
      }
      default: return {TopConj{{}, {f}}};
    }
  }

  Status compileEffectAtom(const pddl::Atom& a, Scope& sc, LAtom& out, const std::string& where) {
    auto p = pred_index.find(a.predicate);
    if (p == pred_index.end()) return Error(ErrorCode::kInvalidArgument, where + ": undeclared predicate '" + a.predicate + "'");
    out.pred = p->second;
    for (const auto& t : a.args) {
      auto r = term(t, sc);
      if (!r) return r.error();
      out.args.push_back(*r);
    }
    return Status::Ok();
  }

  Status compile() {
    // Objects: constants, then problem objects.
    for (const auto& c : domain.constants) {
      if (Status s = addObject(c); !s.ok()) return s;
    }
    for (const auto& o : problem.objects) {
      if (Status s = addObject(o); !s.ok()) return s;
    }
    // Predicates: static = never in an effect.
    for (const auto& p : domain.predicates) {
      pred_index[p.name] = static_cast<uint32_t>(pred_names.size());
      pred_names.push_back(p.name);
      pred_arity.push_back(static_cast<uint32_t>(p.params.size()));
      pred_static.push_back(1);
    }
    for (const auto& a : domain.actions) {
      for (const auto& e : a.effects) {
        auto it = pred_index.find(e.atom.predicate);
        if (it != pred_index.end()) pred_static[it->second] = 0;
      }
    }
    for (const auto& f : domain.functions) func_index[f.name] = static_cast<uint32_t>(func_index.size());
    for (const auto& fv : problem.function_values) {
      auto fi = func_index.find(fv.term.predicate);
      if (fi == func_index.end()) continue;
      std::vector<uint32_t> key{fi->second};
      bool ok = true;
      for (const auto& t : fv.term.args) {
        auto o = obj_index.find(t.name);
        if (o == obj_index.end()) {
          ok = false;
          break;
        }
        key.push_back(o->second);
      }
      if (ok) func_values[key] = fv.value;
    }
    triggers.assign(pred_names.size(), {});
    by_pred.assign(pred_names.size(), {});
    by_arg = ArgIndex(pred_arity);
    // 2^16 tuples (256 KiB) per predicate, 2^18 in all: small tasks, where a lookup's hashing is
    // a visible share of the grounding time, get every predicate.
    dense_atoms = DenseAtomIndex(pred_arity, static_cast<uint32_t>(obj_names.size()), size_t{1} << 16,
                                 size_t{1} << 18);

    for (const auto& a : domain.actions) {
      Schema s;
      s.name = a.name;
      s.num_params = static_cast<uint32_t>(a.parameters.size());
      Scope sc{{}, &s, &s.var_type};
      for (const auto& p : a.parameters) newVar(sc, p);
      const std::string where = "action '" + a.name + "'";
      auto pre = nnf(a.precondition, false, sc, where);
      if (!pre) return pre.error();
      for (auto& tc : splitTop(*pre)) {
        Variant v;
        for (uint32_t i = 0; i < s.num_params; ++i) v.vars.push_back(i);
        v.vars.insert(v.vars.end(), tc.lifted.begin(), tc.lifted.end());
        for (const auto& part : tc.parts) {
          if (part.kind == LKind::kAtom && !part.neg) v.pos.push_back(LAtom{part.pred, part.args});
          if (part.kind == LKind::kEq) v.eqs.push_back(part);
        }
        v.flat = std::all_of(tc.parts.begin(), tc.parts.end(),
                             [](const LFormula& p) { return p.kind == LKind::kAtom || p.kind == LKind::kEq; });
        v.parts = std::move(tc.parts);
        s.variants.push_back(std::move(v));
      }
      for (const auto& e : a.effects) {
        LEffect le;
        Scope esc = sc;
        for (const auto& fv : e.forall) le.forall.push_back(newVar(esc, fv));
        auto cond = nnf(e.condition, false, esc, where);
        if (!cond) return cond.error();
        le.cond = std::move(*cond);
        le.del = e.negated;
        if (Status st = compileEffectAtom(e.atom, esc, le.atom, where); !st.ok()) return st;
        // forall variables were added to s.var_type through esc (shared pointer).
        s.effects.push_back(std::move(le));
      }
      for (const auto& c : a.costs) {
        LCost lc;
        lc.is_function = c.is_function;
        lc.constant = c.constant;
        if (c.is_function) {
          auto fi = func_index.find(c.function.predicate);
          if (fi == func_index.end()) return Error(ErrorCode::kInvalidArgument, where + ": undeclared function '" + c.function.predicate + "'");
          lc.function = fi->second;
          for (const auto& t : c.function.args) {
            auto r = term(t, sc);
            if (!r) return r.error();
            lc.args.push_back(*r);
          }
        }
        s.costs.push_back(std::move(lc));
      }
      schemas.push_back(std::move(s));
    }
    for (uint32_t si = 0; si < schemas.size(); ++si) {
      for (uint32_t vi = 0; vi < schemas[si].variants.size(); ++vi) {
        std::vector<uint32_t> seen;
        const auto& pos = schemas[si].variants[vi].pos;
        for (const auto& a : pos) {
          if (std::find(seen.begin(), seen.end(), a.pred) != seen.end()) continue;
          seen.push_back(a.pred);
          for (uint32_t pi = 0; pi < pos.size(); ++pi) {
            if (pos[pi].pred == a.pred) triggers[a.pred].push_back({si, vi, pi});
          }
        }
      }
    }
    // Index the triggers by a constant: count the triggers per (pred, position, object), then
    // put each under its constant position with the fewest.
    ArgIndex counts(pred_arity);
    auto constants = [&](const Trigger& tr, auto&& fn) {
      const LAtom& la = schemas[tr.si].variants[tr.vi].pos[tr.pi];
      for (uint32_t i = 0; i < la.args.size(); ++i) {
        if (!isVar(la.args[i])) fn(i, objOf(la.args[i]));
      }
    };
    for (uint32_t p = 0; p < triggers.size(); ++p) {
      for (const Trigger& tr : triggers[p]) constants(tr, [&](uint32_t i, uint32_t o) { counts.add(p, i, o, 0); });
    }
    trigger_by_const = ArgIndex(pred_arity);
    trigger_free.assign(triggers.size(), {});
    for (uint32_t p = 0; p < triggers.size(); ++p) {
      for (uint32_t t = 0; t < triggers[p].size(); ++t) {
        uint32_t best_pos = UINT32_MAX, best_obj = 0;
        size_t best_n = SIZE_MAX;
        constants(triggers[p][t], [&](uint32_t i, uint32_t o) {
          const size_t n = counts.get(p, i, o).size();
          if (n < best_n) {
            best_n = n;
            best_pos = i;
            best_obj = o;
          }
        });
        if (best_pos == UINT32_MAX) {
          trigger_free[p].push_back(t);
        } else {
          trigger_by_const.add(p, best_pos, best_obj, t);
        }
      }
    }
    return Status::Ok();
  }

  // ---------------------------------------------------------------------------------------------
  // Atoms

  Result<AtomId> intern(const std::string& predicate, const std::vector<std::string>& args) {
    auto p = pred_index.find(predicate);
    if (p == pred_index.end()) return Error(ErrorCode::kInvalidArgument, "unknown predicate '" + predicate + "'");
    if (pred_arity[p->second] != args.size()) {
      return Error(ErrorCode::kInvalidArgument, "'" + predicate + "' takes " + std::to_string(pred_arity[p->second]) +
                                                    " argument(s), got " + std::to_string(args.size()));
    }
    std::vector<uint32_t> key{p->second};
    for (const auto& a : args) {
      auto o = obj_index.find(a);
      if (o == obj_index.end()) return Error(ErrorCode::kInvalidArgument, "unknown object '" + a + "' in (" + predicate + " ...)");
      key.push_back(o->second);
    }
    return internKey(key.data(), static_cast<uint32_t>(key.size()));
  }

  AtomId internKey(const uint32_t* key, uint32_t n) {
    if (const int64_t d = dense_atoms.find(key, n); d >= 0) return static_cast<AtomId>(d);
    auto [id, inserted] = atoms.insert(key, n);
    if (inserted) {
      reached.push_back(0);
      dense_atoms.set(key, n, id);
    }
    return id;
  }

  std::string atomName(AtomId a) const {
    const uint32_t* k = atoms.data(a);
    std::string out = "(" + pred_names[k[0]];
    for (uint32_t i = 1; i < atoms.length(a); ++i) out += " " + obj_names[k[i]];
    return out + ")";
  }

  // ---------------------------------------------------------------------------------------------
  // Relaxed reachability

  void markReached(AtomId a) {
    if (reached[a]) return;
    reached[a] = 1;
    queue.push_back(a);
  }

  bool matchAtom(const LAtom& la, AtomId a, std::vector<int64_t>& bind, std::vector<uint32_t>& trail) const {
    const uint32_t* k = atoms.data(a);
    for (size_t i = 0; i < la.args.size(); ++i) {
      const LTerm t = la.args[i];
      const uint32_t obj = k[i + 1];
      if (!isVar(t)) {
        if (objOf(t) != obj) return false;
      } else if (bind[static_cast<size_t>(t)] >= 0) {
        if (bind[static_cast<size_t>(t)] != obj) return false;
      } else {
        bind[static_cast<size_t>(t)] = obj;
        trail.push_back(static_cast<uint32_t>(t));
      }
    }
    return true;
  }

  bool eqHolds(const LFormula& e, const std::vector<int64_t>& bind, bool* known) const {
    auto val = [&](LTerm t) -> int64_t { return isVar(t) ? bind[static_cast<size_t>(t)] : objOf(t); };
    const int64_t a = val(e.args[0]), b = val(e.args[1]);
    *known = a >= 0 && b >= 0;
    return *known && ((a == b) != e.neg);
  }

  Status join(uint32_t si, uint32_t vi, std::vector<int64_t>& bind, std::vector<char>& used, size_t remaining,
              const Termination& term) {
    const Variant& v = schemas[si].variants[vi];
    if ((++work & 1023) == 0 && term()) {
      return Error(term.reason() == StopReason::kDeadline ? ErrorCode::kTimeout : ErrorCode::kCancelled, "grounding interrupted");
    }
    for (const auto& e : v.eqs) {
      bool known = false;
      const bool ok = eqHolds(e, bind, &known);
      if (known && !ok) return Status::Ok();
    }
    if (remaining == 0) return enumerateFree(si, vi, bind, 0, term);
    // Pick the unmatched atom with the most bound arguments.
    size_t best = SIZE_MAX;
    int best_bound = -1;
    for (size_t i = 0; i < v.pos.size(); ++i) {
      if (used[i]) continue;
      int nb = 0;
      for (LTerm t : v.pos[i].args) nb += (!isVar(t) || bind[static_cast<size_t>(t)] >= 0) ? 1 : 0;
      if (nb > best_bound) {
        best_bound = nb;
        best = i;
      }
    }
    const LAtom& la = v.pos[best];
    const std::vector<AtomId>* cands = &by_pred[la.pred];
    for (size_t i = 0; i < la.args.size(); ++i) {
      const LTerm t = la.args[i];
      int64_t obj = isVar(t) ? bind[static_cast<size_t>(t)] : objOf(t);
      if (obj < 0) continue;
      const std::vector<AtomId>& with = by_arg.get(la.pred, static_cast<uint32_t>(i), static_cast<uint32_t>(obj));
      if (with.empty()) return Status::Ok();
      if (with.size() < cands->size()) cands = &with;
    }
    used[best] = 1;
    // The variables this level binds go on the shared trail above `mark` (no vector per call).
    const size_t mark = trail_.size();
    auto undo = [&]() {
      for (size_t t = mark; t < trail_.size(); ++t) bind[trail_[t]] = -1;
      trail_.resize(mark);
    };
    const size_t n = cands->size();  // the index may grow during the loop; new atoms are queued
    for (size_t c = 0; c < n; ++c) {
      const AtomId a = (*cands)[c];
      if (matchAtom(la, a, bind, trail_)) {
        if (Status s = join(si, vi, bind, used, remaining - 1, term); !s.ok()) {
          undo();
          used[best] = 0;
          return s;
        }
      }
      undo();
    }
    used[best] = 0;
    return Status::Ok();
  }
  std::vector<uint32_t> trail_;  // variables bound by the joins in progress (a stack)

  Status enumerateFree(uint32_t si, uint32_t vi, std::vector<int64_t>& bind, size_t k, const Termination& term) {
    const Schema& s = schemas[si];
    const Variant& v = s.variants[vi];
    while (k < v.vars.size() && bind[v.vars[k]] >= 0) {
      if (!type_has[s.var_type[v.vars[k]]][static_cast<size_t>(bind[v.vars[k]])]) return Status::Ok();
      ++k;
    }
    if (k == v.vars.size()) {
      for (const auto& e : v.eqs) {
        bool known = false;
        if (!eqHolds(e, bind, &known)) return Status::Ok();
      }
      return addBinding(si, vi, bind);
    }
    const uint32_t var = v.vars[k];
    for (uint32_t o : type_objs[s.var_type[var]]) {
      bind[var] = o;
      Status st = enumerateFree(si, vi, bind, k + 1, term);
      if (!st.ok()) {
        bind[var] = -1;
        return st;
      }
    }
    bind[var] = -1;
    return Status::Ok();
  }

  Status addBinding(uint32_t si, uint32_t vi, std::vector<int64_t>& bind) {
    const Schema& s = schemas[si];
    const Variant& v = s.variants[vi];
    std::vector<uint32_t>& key = key_buf_;
    key.assign({si, vi});
    for (uint32_t var : v.vars) key.push_back(static_cast<uint32_t>(bind[var]));
    auto [id, inserted] = bindings.insert(key.data(), static_cast<uint32_t>(key.size()));
    (void)id;
    if (!inserted) return Status::Ok();
    if (bindings.size() > limits.max_action_instances) {
      return Error(ErrorCode::kInvalidArgument, "grounding exceeds " + std::to_string(limits.max_action_instances) + " action instances");
    }
    // Relaxed effects: add every atom whose condition is not statically false.
    for (const auto& e : s.effects) {
      if (e.del) continue;
      Status st = forEachForall(e.forall, 0, bind, [&]() -> Status {
        if (evalStatic(e.cond, bind) == 0) return Status::Ok();
        std::vector<uint32_t>& k2 = key_buf_;
        k2.assign(1, e.atom.pred);
        for (LTerm t : e.atom.args) k2.push_back(isVar(t) ? static_cast<uint32_t>(bind[static_cast<size_t>(t)]) : objOf(t));
        const AtomId a = internKey(k2.data(), static_cast<uint32_t>(k2.size()));
        markReached(a);
        if (atoms.size() > limits.max_atoms) {
          return Error(ErrorCode::kInvalidArgument, "grounding exceeds " + std::to_string(limits.max_atoms) + " atoms");
        }
        return Status::Ok();
      });
      if (!st.ok()) return st;
    }
    return Status::Ok();
  }

  std::vector<uint32_t> key_buf_;  // scratch key of addBinding (bindings, then effect atoms)

  template <typename Fn>
  Status forEachForall(const std::vector<uint32_t>& vars, size_t k, std::vector<int64_t>& bind, const Fn& fn) {
    if (k == vars.size()) return fn();
    for (uint32_t o : type_objs[current_schema_var_type(vars[k])]) {
      bind[vars[k]] = o;
      Status st = forEachForall(vars, k + 1, bind, fn);
      if (!st.ok()) {
        bind[vars[k]] = -1;
        return st;
      }
    }
    bind[vars[k]] = -1;
    return Status::Ok();
  }
  // forEachForall needs the var types of the schema being processed.
  const std::vector<uint32_t>* cur_var_type{nullptr};
  uint32_t current_schema_var_type(uint32_t var) const { return (*cur_var_type)[var]; }

  /// Three-valued evaluation with statics and equality only: 0 false, 1 true, 2 unknown.
  int evalStatic(const LFormula& f, const std::vector<int64_t>& bind) const {
    switch (f.kind) {
      case LKind::kTrue: return 1;
      case LKind::kFalse: return 0;
      case LKind::kEq: {
        bool known = false;
        const bool ok = eqHolds(f, bind, &known);
        return known ? (ok ? 1 : 0) : 2;
      }
      case LKind::kAtom: {
        if (!pred_static[f.pred]) return 2;
        for (LTerm t : f.args) {
          if (isVar(t) && bind[static_cast<size_t>(t)] < 0) return 2;
        }
        const int64_t id = findAtom(f.pred, f.args, bind);
        const bool holds = id >= 0 && reached[static_cast<size_t>(id)];
        return holds != f.neg ? 1 : 0;
      }
      case LKind::kAnd: {
        int r = 1;
        for (const auto& c : f.children) {
          const int x = evalStatic(c, bind);
          if (x == 0) return 0;
          if (x == 2) r = 2;
        }
        return r;
      }
      case LKind::kOr: {
        int r = 0;
        for (const auto& c : f.children) {
          const int x = evalStatic(c, bind);
          if (x == 1) return 1;
          if (x == 2) r = 2;
        }
        return r;
      }
      default: return 2;
    }
  }

  Status explore(const Termination& term) {
    Stopwatch sw;
    std::vector<int64_t> bind;
    if (!initialized) {
      initialized = true;
      for (uint32_t si = 0; si < schemas.size(); ++si) {
        cur_var_type = &schemas[si].var_type;
        for (uint32_t vi = 0; vi < schemas[si].variants.size(); ++vi) {
          if (!schemas[si].variants[vi].pos.empty()) continue;
          bind.assign(schemas[si].var_type.size(), -1);
          std::vector<char> used;
          if (Status s = join(si, vi, bind, used, 0, term); !s.ok()) {
            initialized = false;
            return s;
          }
        }
      }
    }
    while (queue_head < queue.size()) {
      const AtomId a = queue[queue_head];
      const uint32_t* k = atoms.data(a);
      const uint32_t pred = k[0];
      // Index first, so joins can use `a` in other positions too.
      if (pending_index_ != a) {
        by_pred[pred].push_back(a);
        for (uint32_t i = 1; i < atoms.length(a); ++i) by_arg.add(pred, i - 1, k[i], a);
        pending_index_ = a;
      }
      // The triggers whose constants the atom's arguments equal, in processing order.
      std::vector<uint32_t>& cand = trigger_buf_;
      cand.assign(trigger_free[pred].begin(), trigger_free[pred].end());
      for (uint32_t i = 1; i < atoms.length(a); ++i) {
        const std::vector<uint32_t>& with = trigger_by_const.get(pred, i - 1, k[i]);
        cand.insert(cand.end(), with.begin(), with.end());
      }
      std::sort(cand.begin(), cand.end());
      for (size_t c = 0; c < cand.size(); ++c) {
        const auto [si, vi, pi] = triggers[pred][cand[c]];
        const Variant& v = schemas[si].variants[vi];
        cur_var_type = &schemas[si].var_type;
        bind.assign(schemas[si].var_type.size(), -1);
        std::vector<char>& used = used_buf_;
        used.assign(v.pos.size(), 0);
        trail_.clear();
        if (!matchAtom(v.pos[pi], a, bind, trail_)) continue;
        trail_.clear();  // the trigger's own bindings stay for this join
        used[pi] = 1;
        // Resuming after an interruption re-runs this atom's joins; bindings are deduplicated.
        // (A join may intern atoms and so move `atoms`' storage: `k` is not used past here.)
        if (Status s = join(si, vi, bind, used, v.pos.size() - 1, term); !s.ok()) return s;
      }
      ++queue_head;
    }
    stats.explore_seconds += sw.seconds();
    stats.reachable_atoms = 0;
    for (char r : reached) stats.reachable_atoms += r ? 1 : 0;
    stats.action_instances = bindings.size();
    return Status::Ok();
  }
  AtomId pending_index_{UINT32_MAX};
  std::vector<char> used_buf_;  // scratch of explore(): which positive atoms a join has matched

  // ---------------------------------------------------------------------------------------------
  // Task construction

  struct BuildCtx {
    const std::vector<char>* static_true;  // per atom (only static atoms are looked at)
    bool has_static_true(AtomId a) const { return a < static_true->size() && (*static_true)[a]; }
  };

  int64_t findAtom(uint32_t pred, const std::vector<LTerm>& args, const std::vector<int64_t>& bind) const {
    uint32_t k[16];
    std::vector<uint32_t> big;
    uint32_t* key = k;
    if (args.size() + 1 > 16) {
      big.resize(args.size() + 1);
      key = big.data();
    }
    key[0] = pred;
    for (size_t i = 0; i < args.size(); ++i) {
      const LTerm t = args[i];
      key[i + 1] = isVar(t) ? static_cast<uint32_t>(bind[static_cast<size_t>(t)]) : objOf(t);
    }
    const uint32_t n = static_cast<uint32_t>(args.size() + 1);
    if (const int64_t d = dense_atoms.find(key, n); d != DenseAtomIndex::kNotDense) return d;
    return atoms.find(key, n);
  }

  /// Instantiates and simplifies a lifted NNF formula under `bind`.
  GFormula instantiate(const LFormula& f, std::vector<int64_t>& bind, const BuildCtx& ctx,
                       const std::vector<uint32_t>& var_type) const {
    GFormula g;
    switch (f.kind) {
      case LKind::kTrue: g.kind = GFormula::kTrue; return g;
      case LKind::kFalse: g.kind = GFormula::kFalse; return g;
      case LKind::kEq: {
        bool known = false;
        const bool ok = eqHolds(f, bind, &known);
        g.kind = ok ? GFormula::kTrue : GFormula::kFalse;
        return g;
      }
      case LKind::kAtom: {
        const int64_t id = findAtom(f.pred, f.args, bind);
        bool holds_possible;
        if (pred_static[f.pred]) {
          const bool t = id >= 0 && ctx.has_static_true(static_cast<AtomId>(id));
          g.kind = (t != f.neg) ? GFormula::kTrue : GFormula::kFalse;
          return g;
        }
        holds_possible = id >= 0 && reached[static_cast<size_t>(id)];
        if (!holds_possible) {
          g.kind = f.neg ? GFormula::kTrue : GFormula::kFalse;
          return g;
        }
        g.kind = GFormula::kLit;
        g.atom = static_cast<AtomId>(id);
        g.neg = f.neg;
        return g;
      }
      case LKind::kAnd:
      case LKind::kOr: {
        const bool is_and = f.kind == LKind::kAnd;
        g.kind = is_and ? GFormula::kAnd : GFormula::kOr;
        for (const auto& c : f.children) {
          GFormula x = instantiate(c, bind, ctx, var_type);
          if (!absorb(g, std::move(x), is_and)) return g;
        }
        return finish(std::move(g), is_and);
      }
      case LKind::kForall:
      case LKind::kExists: {
        const bool is_and = f.kind == LKind::kForall;
        g.kind = is_and ? GFormula::kAnd : GFormula::kOr;
        bool stop = false;
        quantify(f.vars, 0, bind, var_type, [&]() {
          if (stop) return;
          GFormula x = instantiate(f.children[0], bind, ctx, var_type);
          if (!absorb(g, std::move(x), is_and)) stop = true;
        });
        if (stop) return g;
        return finish(std::move(g), is_and);
      }
    }
    return g;
  }

  /// Adds child `x` to and/or node `g`; returns false when `g` became constant (short circuit).
  static bool absorb(GFormula& g, GFormula x, bool is_and) {
    if (x.kind == GFormula::kTrue) {
      if (is_and) return true;
      g = GFormula{};
      g.kind = GFormula::kTrue;
      return false;
    }
    if (x.kind == GFormula::kFalse) {
      if (!is_and) return true;
      g = GFormula{};
      g.kind = GFormula::kFalse;
      return false;
    }
    if ((is_and && x.kind == GFormula::kAnd) || (!is_and && x.kind == GFormula::kOr)) {
      for (auto& c : x.children) g.children.push_back(std::move(c));
    } else {
      g.children.push_back(std::move(x));
    }
    return true;
  }
  static GFormula finish(GFormula g, bool is_and) {
    if (g.children.empty()) {
      GFormula t;
      t.kind = is_and ? GFormula::kTrue : GFormula::kFalse;
      return t;
    }
    if (g.children.size() == 1) return std::move(g.children[0]);
    return g;
  }

  template <typename Fn>
  void quantify(const std::vector<uint32_t>& vars, size_t k, std::vector<int64_t>& bind,
                const std::vector<uint32_t>& var_type, const Fn& fn) const {
    if (k == vars.size()) {
      fn();
      return;
    }
    for (uint32_t o : type_objs[var_type[vars[k]]]) {
      bind[vars[k]] = o;
      quantify(vars, k + 1, bind, var_type, fn);
    }
    bind[vars[k]] = -1;
  }

  /// DNF of a ground formula; false when it exceeds the limit.
  bool dnf(const GFormula& g, std::vector<Conj>& out) const {
    switch (g.kind) {
      case GFormula::kTrue: out = {Conj{}}; return true;
      case GFormula::kFalse: out.clear(); return true;
      case GFormula::kLit: out = {Conj{AtomLiteral{g.atom, g.neg}}}; return true;
      case GFormula::kOr: {
        out.clear();
        for (const auto& c : g.children) {
          std::vector<Conj> sub;
          if (!dnf(c, sub)) return false;
          out.insert(out.end(), sub.begin(), sub.end());
          if (out.size() > limits.max_dnf_terms) return false;
        }
        return true;
      }
      case GFormula::kAnd: {
        out = {Conj{}};
        for (const auto& c : g.children) {
          std::vector<Conj> sub;
          if (!dnf(c, sub)) return false;
          if (out.size() * sub.size() > limits.max_dnf_terms) return false;
          std::vector<Conj> next;
          next.reserve(out.size() * sub.size());
          for (const auto& a : out) {
            for (const auto& b : sub) {
              Conj t = a;
              t.insert(t.end(), b.begin(), b.end());
              // Drop contradictory conjuncts (p and not p).
              std::sort(t.begin(), t.end(), [](const AtomLiteral& x, const AtomLiteral& y) {
                return x.atom != y.atom ? x.atom < y.atom : x.negated < y.negated;
              });
              t.erase(std::unique(t.begin(), t.end(), [](const AtomLiteral& x, const AtomLiteral& y) {
                        return x.atom == y.atom && x.negated == y.negated;
                      }),
                      t.end());
              bool contradiction = false;
              for (size_t i = 1; i < t.size(); ++i) contradiction = contradiction || t[i].atom == t[i - 1].atom;
              if (!contradiction) next.push_back(std::move(t));
            }
          }
          out = std::move(next);
          if (out.empty()) return true;
        }
        return true;
      }
    }
    return true;
  }

  struct TaskBuilder {
    std::vector<int64_t> atom_fact;   // atom -> primary fact or -1
    std::vector<int64_t> atom_comp;   // atom -> complement fact or -1
    std::vector<AtomId> fact_atom;    // fact -> atom (primary or negated)
    std::vector<char> fact_is_comp;
  };

  FactId litFact(TaskBuilder& tb, const AtomLiteral& l) {
    if (!l.negated) return static_cast<FactId>(tb.atom_fact[l.atom]);
    if (tb.atom_comp[l.atom] < 0) {
      tb.atom_comp[l.atom] = static_cast<int64_t>(tb.fact_atom.size());
      tb.fact_atom.push_back(l.atom);
      tb.fact_is_comp.push_back(1);
    }
    return static_cast<FactId>(tb.atom_comp[l.atom]);
  }

  static void sortUnique(std::vector<FactId>& v) {
    std::sort(v.begin(), v.end());
    v.erase(std::unique(v.begin(), v.end()), v.end());
  }

  Result<std::shared_ptr<const Task>> build(const std::vector<AtomId>& init, const std::vector<AtomId>& neg_goal,
                                            bool use_costs, const Termination& term) {
    Stopwatch sw;
    std::vector<char> static_true(atoms.size(), 0);
    for (AtomId a : init) {
      if (a < atoms.size() && pred_static[atoms.data(a)[0]]) static_true[a] = 1;
    }
    BuildCtx ctx{&static_true};
    TaskBuilder tb;
    tb.atom_fact.assign(atoms.size(), -1);
    tb.atom_comp.assign(atoms.size(), -1);
    for (AtomId a = 0; a < atoms.size(); ++a) {
      if (reached[a] && !pred_static[atoms.data(a)[0]]) {
        tb.atom_fact[a] = static_cast<int64_t>(tb.fact_atom.size());
        tb.fact_atom.push_back(a);
        tb.fact_is_comp.push_back(0);
      }
    }
    auto task = std::make_shared<Task>();
    task->unit_cost = !use_costs;
    std::vector<int64_t> bind;
    std::vector<Conj> pre_dnf, cond_dnf;
    std::unordered_set<std::string> seen_ops;
    size_t op_name_size = 0;               // the longest name so far: one allocation per name
    std::vector<FactId> add_buf, del_buf;  // an operator's unconditional effects, reused
    for (uint32_t b = 0; b < bindings.size(); ++b) {
      if ((b & 255) == 0 && term()) {
        return Error(term.reason() == StopReason::kDeadline ? ErrorCode::kTimeout : ErrorCode::kCancelled, "task construction interrupted");
      }
      const uint32_t* key = bindings.data(b);
      const Schema& s = schemas[key[0]];
      const Variant& v = s.variants[key[1]];
      bind.assign(s.var_type.size(), -1);
      for (size_t i = 0; i < v.vars.size(); ++i) bind[v.vars[i]] = key[2 + i];
      // Precondition. Flat (a conjunction of literals and (in)equalities, as in STRIPS): its
      // one DNF term directly, as instantiate() + dnf() would give it, without the formula tree.
      if (v.flat) {
        if (!flatPrecondition(v, bind, ctx, pre_dnf)) continue;
      } else {
        GFormula pre;
        pre.kind = GFormula::kAnd;
        bool pre_false = false;
        for (const auto& part : v.parts) {
          if (!absorb(pre, instantiate(part, bind, ctx, s.var_type), true)) {
            pre_false = pre.kind == GFormula::kFalse;
            break;
          }
        }
        if (pre_false) continue;
        pre = finish(std::move(pre), true);
        if (pre.kind == GFormula::kFalse) continue;
        if (!dnf(pre, pre_dnf)) {
          return Error(ErrorCode::kUnsupported, "precondition of action '" + s.name + "' grounds to more than " +
                                                    std::to_string(limits.max_dnf_terms) + " disjuncts");
        }
      }
      if (pre_dnf.empty()) continue;
      // Cost.
      Cost cost = use_costs ? 0 : 1;
      bool cost_defined = true;
      if (use_costs) {
        double total = 0;
        for (const auto& c : s.costs) {
          if (!c.is_function) {
            total += c.constant;
            continue;
          }
          std::vector<uint32_t> fk{c.function};
          for (LTerm t : c.args) fk.push_back(isVar(t) ? static_cast<uint32_t>(bind[static_cast<size_t>(t)]) : objOf(t));
          auto it = func_values.find(fk);
          if (it == func_values.end()) {
            cost_defined = false;  // undefined cost term: the action is not applicable
            break;
          }
          total += it->second;
        }
        if (!cost_defined) continue;
        if (total < 0 || std::fabs(total - std::round(total)) > 1e-9) {
          return Error(ErrorCode::kUnsupported, "action '" + s.name + "' has cost " + std::to_string(total) +
                                                    "; only non-negative integer costs are supported");
        }
        cost = static_cast<Cost>(std::llround(total));
      }
      // Effects.
      Operator proto;
      proto.cost = cost;
      proto.name.reserve(op_name_size);
      proto.name = '(';
      proto.name += s.name;
      for (uint32_t i = 0; i < s.num_params; ++i) {
        proto.name += ' ';
        proto.name += obj_names[static_cast<size_t>(bind[i])];
      }
      proto.name += ')';
      op_name_size = std::max(op_name_size, proto.name.size());
      add_buf.clear();
      del_buf.clear();
      for (const auto& e : s.effects) {
        Status st = Status::Ok();
        quantify(e.forall, 0, bind, s.var_type, [&]() {
          if (!st.ok()) return;
          const int64_t id = findAtom(e.atom.pred, e.atom.args, bind);
          if (id < 0 || tb.atom_fact[static_cast<size_t>(id)] < 0) return;  // unreachable: delete is a no-op
          const FactId f = static_cast<FactId>(tb.atom_fact[static_cast<size_t>(id)]);
          GFormula c = instantiate(e.cond, bind, ctx, s.var_type);
          if (c.kind == GFormula::kFalse) return;
          if (c.kind == GFormula::kTrue) {
            (e.del ? del_buf : add_buf).push_back(f);
            return;
          }
          if (!dnf(c, cond_dnf)) {
            st = Error(ErrorCode::kUnsupported, "effect condition of action '" + s.name + "' grounds to more than " +
                                                    std::to_string(limits.max_dnf_terms) + " disjuncts");
            return;
          }
          for (const auto& conj : cond_dnf) {
            ConditionalEffect ce;
            for (const auto& l : conj) ce.cond.push_back(litFact(tb, l));
            sortUnique(ce.cond);
            (e.del ? ce.del : ce.add).push_back(f);
            proto.cond_effects.push_back(std::move(ce));
          }
        });
        if (!st.ok()) return st.error();
      }
      sortUnique(add_buf);
      sortUnique(del_buf);
      // Add wins over delete (both sorted: drop from del what add has).
      if (!add_buf.empty() && !del_buf.empty()) {
        del_buf.erase(std::remove_if(del_buf.begin(), del_buf.end(),
                                     [&](FactId f) {
                                       return std::binary_search(add_buf.begin(), add_buf.end(), f);
                                     }),
                      del_buf.end());
      }
      proto.add.assign(add_buf.begin(), add_buf.end());
      proto.del.assign(del_buf.begin(), del_buf.end());
      mergeConditionalEffects(proto);
      for (size_t k = 0; k < pre_dnf.size(); ++k) {
        const Conj& conj = pre_dnf[k];
        // The last (usually the only) term takes the prototype, the others a copy.
        Operator op = k + 1 == pre_dnf.size() ? std::move(proto) : proto;
        op.pre.reserve(conj.size());
        for (const auto& l : conj) op.pre.push_back(litFact(tb, l));
        sortUnique(op.pre);
        // Variants of one action (top-level disjunctions, existentials) can ground to the same
        // operator: keep one (effects depend on the action's own parameters only).
        if (s.variants.size() > 1) {
          std::string op_key = op.name;
          for (FactId f : op.pre) op_key += "," + std::to_string(f);
          if (!seen_ops.insert(std::move(op_key)).second) continue;
        }
        task->ops.push_back(std::move(op));
      }
    }
    for (AtomId a : neg_goal) {
      if (a < tb.atom_fact.size() && tb.atom_fact[a] >= 0) litFact(tb, AtomLiteral{a, true});
    }
    // Complement bookkeeping in every effect.
    auto addComplements = [&](std::vector<FactId>& add, std::vector<FactId>& del) {
      const size_t na = add.size(), nd = del.size();
      for (size_t i = 0; i < na; ++i) {
        const int64_t c = tb.atom_comp[tb.fact_atom[add[i]]];
        if (c >= 0 && !tb.fact_is_comp[add[i]]) del.push_back(static_cast<FactId>(c));
      }
      for (size_t i = 0; i < nd; ++i) {
        const int64_t c = tb.atom_comp[tb.fact_atom[del[i]]];
        if (c >= 0 && !tb.fact_is_comp[del[i]]) add.push_back(static_cast<FactId>(c));
      }
      sortUnique(add);
      sortUnique(del);
    };
    for (auto& op : task->ops) {
      addComplements(op.add, op.del);
      if (!op.cond_effects.empty()) {
        std::vector<FactId> all_add = op.add, all_del = op.del;
        for (auto& ce : op.cond_effects) {
          addComplements(ce.add, ce.del);
          all_add.insert(all_add.end(), ce.add.begin(), ce.add.end());
          all_del.insert(all_del.end(), ce.del.begin(), ce.del.end());
        }
        sortUnique(all_add);
        sortUnique(all_del);
        std::vector<FactId> both;
        std::set_intersection(all_add.begin(), all_add.end(), all_del.begin(), all_del.end(), std::back_inserter(both));
        op.needs_fixup = !both.empty();
      }
    }
    task->fact_names.resize(tb.fact_atom.size());
    task->complement.assign(tb.fact_atom.size(), -1);
    for (FactId f = 0; f < tb.fact_atom.size(); ++f) {
      const std::string n = atomName(tb.fact_atom[f]);
      task->fact_names[f] = tb.fact_is_comp[f] ? "(not " + n + ")" : n;
      const AtomId a = tb.fact_atom[f];
      task->complement[f] = static_cast<int32_t>(tb.fact_is_comp[f] ? tb.atom_fact[a] : tb.atom_comp[a]);
    }
    task->finalize();
    last_builder_ = std::move(tb);
    stats.facts = task->numFacts();
    stats.operators = task->ops.size();
    stats.build_seconds = sw.seconds();
    return std::shared_ptr<const Task>(std::move(task));
  }

  /// The DNF of a flat precondition (see Variant::flat) under `bind`: false when it is false (out
  /// is then unspecified), else `out` holds its one conjunct, sorted by (atom, negated) and without
  /// duplicates, exactly what dnf(instantiate(...)) gives (an empty `out` when p and not p meet).
  bool flatPrecondition(const Variant& v, const std::vector<int64_t>& bind, const BuildCtx& ctx,
                        std::vector<Conj>& out) const {
    out.resize(1);
    Conj& conj = out[0];
    conj.clear();
    // (In)equalities and static literals first: they are what usually fails (the relaxed
    // exploration over-approximates them); the result does not depend on the order.
    for (const LFormula& f : v.parts) {
      if (f.kind == LKind::kEq) {
        bool known = false;
        if (!eqHolds(f, bind, &known)) return false;
      } else if (pred_static[f.pred]) {
        const int64_t id = findAtom(f.pred, f.args, bind);
        const bool t = id >= 0 && ctx.has_static_true(static_cast<AtomId>(id));
        if (t == f.neg) return false;
      }
    }
    for (const LFormula& f : v.parts) {
      if (f.kind == LKind::kEq || pred_static[f.pred]) continue;
      const int64_t id = findAtom(f.pred, f.args, bind);
      if (id < 0 || !reached[static_cast<size_t>(id)]) {
        if (!f.neg) return false;
        continue;
      }
      conj.push_back(AtomLiteral{static_cast<AtomId>(id), f.neg});
    }
    if (conj.size() > 1) {
      std::sort(conj.begin(), conj.end(), [](const AtomLiteral& x, const AtomLiteral& y) {
        return x.atom != y.atom ? x.atom < y.atom : x.negated < y.negated;
      });
      conj.erase(std::unique(conj.begin(), conj.end(),
                             [](const AtomLiteral& x, const AtomLiteral& y) {
                               return x.atom == y.atom && x.negated == y.negated;
                             }),
                 conj.end());
      for (size_t i = 1; i < conj.size(); ++i) {
        if (conj[i].atom == conj[i - 1].atom) {
          out.clear();
          return true;
        }
      }
    }
    return true;
  }

  /// Merges conditional effects with identical conditions and moves empty-condition ones.
  static void mergeConditionalEffects(Operator& op) {
    if (op.cond_effects.size() < 2) return;
    std::sort(op.cond_effects.begin(), op.cond_effects.end(),
              [](const ConditionalEffect& a, const ConditionalEffect& b) { return a.cond < b.cond; });
    std::vector<ConditionalEffect> merged;
    for (auto& ce : op.cond_effects) {
      if (!merged.empty() && merged.back().cond == ce.cond) {
        merged.back().add.insert(merged.back().add.end(), ce.add.begin(), ce.add.end());
        merged.back().del.insert(merged.back().del.end(), ce.del.begin(), ce.del.end());
      } else {
        merged.push_back(std::move(ce));
      }
    }
    for (auto& ce : merged) {
      sortUnique(ce.add);
      sortUnique(ce.del);
    }
    op.cond_effects = std::move(merged);
  }

  TaskBuilder last_builder_;
  const Task* last_task_{nullptr};
};

// -------------------------------------------------------------------------------------------------

Grounder::Grounder() : impl_(std::make_unique<Impl>()) {}
Grounder::~Grounder() = default;

Result<std::unique_ptr<Grounder>> Grounder::create(const pddl::Domain& domain, const pddl::Problem& problem,
                                                   GroundingLimits limits) {
  std::unique_ptr<Grounder> g(new Grounder());
  g->impl_->domain = domain;
  g->impl_->problem = problem;
  g->impl_->limits = limits;
  if (Status s = g->impl_->compile(); !s.ok()) return s.error();
  return g;
}

const pddl::Domain& Grounder::domain() const { return impl_->domain; }
const pddl::Problem& Grounder::problem() const { return impl_->problem; }

Result<AtomId> Grounder::atomId(const pddl::Atom& atom) {
  std::vector<std::string> args;
  for (const auto& t : atom.args) args.push_back(t.name);
  return impl_->intern(atom.predicate, args);
}
Result<AtomId> Grounder::atomId(const std::string& predicate, const std::vector<std::string>& args) {
  return impl_->intern(predicate, args);
}
std::string Grounder::atomName(AtomId a) const { return impl_->atomName(a); }
pddl::Atom Grounder::atom(AtomId a) const {
  pddl::Atom out;
  const uint32_t* k = impl_->atoms.data(a);
  out.predicate = impl_->pred_names[k[0]];
  for (uint32_t i = 1; i < impl_->atoms.length(a); ++i) out.args.push_back(pddl::Term{impl_->obj_names[k[i]]});
  return out;
}
bool Grounder::isStaticAtom(AtomId a) const { return impl_->pred_static[impl_->atoms.data(a)[0]] != 0; }
size_t Grounder::numAtoms() const { return impl_->atoms.size(); }

bool Grounder::covers(const std::vector<AtomId>& init) const {
  if (!impl_->initialized || impl_->queue_head < impl_->queue.size()) return false;
  for (AtomId a : init) {
    if (a >= impl_->reached.size() || !impl_->reached[a]) return false;
  }
  return true;
}

Status Grounder::extend(const std::vector<AtomId>& init, const Termination& term) {
  for (AtomId a : init) {
    if (a < impl_->reached.size()) impl_->markReached(a);
  }
  return impl_->explore(term);
}

bool Grounder::isReachable(AtomId a) const { return a < impl_->reached.size() && impl_->reached[a]; }

Result<std::shared_ptr<const Task>> Grounder::buildTask(const std::vector<AtomId>& init,
                                                        const std::vector<AtomId>& negated_goal_atoms,
                                                        bool use_costs, const Termination& term) {
  auto r = impl_->build(init, negated_goal_atoms, use_costs, term);
  if (r) impl_->last_task_ = r->get();
  return r;
}

int64_t Grounder::factOf(const Task& task, AtomId a) const {
  (void)task;
  const auto& tb = impl_->last_builder_;
  if (a >= tb.atom_fact.size()) return -1;
  return tb.atom_fact[a];
}

StateBits Grounder::initialState(const Task& task, const std::vector<AtomId>& init) const {
  StateBits s(task.numWords(), 0);
  const auto& tb = impl_->last_builder_;
  std::vector<char> in(tb.atom_fact.size(), 0);
  for (AtomId a : init) {
    if (a < tb.atom_fact.size() && tb.atom_fact[a] >= 0) {
      setBit(s.data(), static_cast<FactId>(tb.atom_fact[a]));
      in[a] = 1;
    }
  }
  for (FactId f = 0; f < tb.fact_atom.size() && f < task.numFacts(); ++f) {
    if (tb.fact_is_comp[f] && !in[tb.fact_atom[f]]) setBit(s.data(), f);
  }
  return s;
}

Result<std::vector<AtomId>> Grounder::negatedAtoms(const pddl::Formula& goal) {
  Impl& I = *impl_;
  Schema scratch;
  Impl::Scope sc{{}, &scratch, &scratch.var_type};
  auto nnf = I.nnf(goal, false, sc, "goal");
  if (!nnf) return nnf.error();
  std::vector<AtomId> out;
  std::vector<int64_t> bind(scratch.var_type.size(), -1);
  std::function<void(const LFormula&)> walk = [&](const LFormula& f) {
    if (f.kind == LKind::kAtom && f.neg) {
      bool ground = true;
      for (LTerm t : f.args) ground = ground && (!isVar(t) || bind[static_cast<size_t>(t)] >= 0);
      if (ground) {
        const int64_t id = I.findAtom(f.pred, f.args, bind);
        if (id >= 0) out.push_back(static_cast<AtomId>(id));
      } else {
        // Quantified negative goal: every instance.
        std::vector<uint32_t> free;
        for (LTerm t : f.args) {
          if (isVar(t) && bind[static_cast<size_t>(t)] < 0) free.push_back(static_cast<uint32_t>(t));
        }
        std::sort(free.begin(), free.end());
        free.erase(std::unique(free.begin(), free.end()), free.end());
        I.quantify(free, 0, bind, scratch.var_type, [&]() {
          const int64_t id = I.findAtom(f.pred, f.args, bind);
          if (id >= 0) out.push_back(static_cast<AtomId>(id));
        });
      }
    }
    for (const auto& c : f.children) walk(c);
  };
  walk(*nnf);
  return out;
}

Result<Goal> Grounder::groundGoal(const pddl::Formula& goal, const Task& task, const std::vector<AtomId>& init) {
  Impl& I = *impl_;
  Schema scratch;
  Impl::Scope sc{{}, &scratch, &scratch.var_type};
  auto nnf = I.nnf(goal, false, sc, "goal");
  if (!nnf) return nnf.error();
  std::vector<char> static_true(I.atoms.size(), 0);
  for (AtomId a : init) {
    if (a < I.atoms.size() && I.pred_static[I.atoms.data(a)[0]]) static_true[a] = 1;
  }
  Impl::BuildCtx ctx{&static_true};
  std::vector<int64_t> bind(scratch.var_type.size(), -1);
  GFormula g = I.instantiate(*nnf, bind, ctx, scratch.var_type);
  std::vector<Conj> d;
  if (!I.dnf(g, d)) {
    return Error(ErrorCode::kUnsupported, "goal grounds to more than " + std::to_string(I.limits.max_dnf_terms) + " disjuncts");
  }
  Goal out;
  const auto& tb = I.last_builder_;
  for (const auto& conj : d) {
    GoalConjunct gc;
    for (const auto& l : conj) {
      const int64_t f = l.atom < tb.atom_fact.size() ? tb.atom_fact[l.atom] : -1;
      if (f < 0) continue;  // cannot happen: instantiate() resolved unreachable atoms
      if (!l.negated) {
        gc.pos.push_back(static_cast<FactId>(f));
      } else if (tb.atom_comp[l.atom] >= 0 && static_cast<size_t>(tb.atom_comp[l.atom]) < task.numFacts()) {
        gc.pos.push_back(static_cast<FactId>(tb.atom_comp[l.atom]));
      } else {
        gc.neg.push_back(static_cast<FactId>(f));
      }
    }
    std::sort(gc.pos.begin(), gc.pos.end());
    gc.pos.erase(std::unique(gc.pos.begin(), gc.pos.end()), gc.pos.end());
    out.conjuncts.push_back(std::move(gc));
  }
  return out;
}

const GroundingStats& Grounder::stats() const { return impl_->stats; }

}  // namespace tamp::symbolic_planner
