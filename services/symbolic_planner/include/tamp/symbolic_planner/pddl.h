#pragma once
/// @file
/// The lifted PDDL representation and its parser.
///
/// Supported fragment (FF's ADL subset plus action costs): `:strips`, `:typing` (type hierarchies,
/// `either`), domain `:constants`, `:negative-preconditions`, `:equality`,
/// `:disjunctive-preconditions`, `:existential-preconditions`, `:universal-preconditions`
/// (`:quantified-preconditions`), `:conditional-effects` (`forall`/`when` effects, nested), `:adl`,
/// and `:action-costs` (`(increase (total-cost) N)` or `(increase (total-cost) (f args))` with `f`
/// a static function defined in `:init`; `(:metric minimize (total-cost))`).
///
/// Refused by name, where the construct is used: `:derived` axioms, durative actions, numeric
/// conditions and effects other than `(increase (total-cost) ...)`, timed initial literals,
/// preferences, `:constraints`, object-valued functions.
///
/// Accepted as FF and Fast Downward accept them (each has a parser test):
/// - `:requirements` missing, understated or over-declared: requirements are never enforced
///   against the constructs used, and any requirement name is accepted; a construct outside the
///   fragment is refused where it occurs, whatever was declared (real IPC files declare sloppily).
/// - types declared more than once or with several parents, `(either ...)` as a parent, parents
///   used but never declared (see `TypeDecl` for the semantics: the union of the declarations);
/// - `(either t1 t2 ...)` wherever a type may stand (`:types` parents, `:constants`, `:objects`,
///   parameters, predicate and function arguments, `forall`/`exists` variables);
/// - domain constants used in the problem, and re-declared in the problem's `:objects` (pathways);
///   an object declared more than once (in the domain and the problem, or twice in one list)
///   has the union of its declared types;
/// - `;` comments, any case, any whitespace (CR, tabs, form feeds) between any two tokens, and a
///   UTF-8 byte-order mark at the start of a file.
///
/// Names are case-insensitive (stored lower-case); they may start with a digit (as in Fast
/// Downward) but not be a number.
///
/// Every error names the file, line and column and what was expected. The parser never crashes
/// or recurses without bound on malformed input (nesting depth is limited).

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "tamp/core/error.h"

namespace tamp::symbolic_planner::pddl {

/// Line/column of a construct in its source text (1-based; 0 = unknown / programmatic).
struct Loc {
  int line{0};
  int column{0};
};

/// A variable (`?x`) or an object/constant name. Names are lower-case.
struct Term {
  std::string name;
  bool isVariable() const { return !name.empty() && name[0] == '?'; }
  bool operator==(const Term&) const = default;
};

/// A variable or object with its type: one type name, or several for `(either a b)`.
struct TypedName {
  std::string name;
  std::vector<std::string> types;  ///< never empty after parsing ("object" when untyped)
  Loc loc;
};

/// An atom `(p t1 ... tn)`.
struct Atom {
  std::string predicate;
  std::vector<Term> args;
  Loc loc;
};

enum class FormulaKind { kTrue, kFalse, kAtom, kEquals, kNot, kAnd, kOr, kImply, kExists, kForall };

/// A first-order formula (precondition, effect condition or goal).
struct Formula {
  FormulaKind kind{FormulaKind::kTrue};
  Atom atom;                       ///< kAtom; for kEquals, args holds the two terms
  std::vector<Formula> children;   ///< kNot (1), kAnd/kOr (n), kImply (2), kExists/kForall (1)
  std::vector<TypedName> vars;     ///< kExists/kForall
  Loc loc;

  static Formula makeTrue() { return Formula{}; }
};

/// One literal of an effect after flattening `and`/`forall`/`when`:
/// `forall vars: when condition: [not] atom`.
struct EffectLiteral {
  std::vector<TypedName> forall;   ///< universally quantified variables (outermost first)
  Formula condition;               ///< kTrue when unconditional
  bool negated{false};             ///< a delete effect
  Atom atom;
};

/// The cost an action adds to `total-cost`: a non-negative constant, or a static function term.
struct CostExpr {
  bool is_function{false};
  double constant{0.0};
  Atom function;  ///< when is_function: function name in `predicate`, arguments in `args`
  Loc loc;
};

struct Action {
  std::string name;
  std::vector<TypedName> parameters;
  Formula precondition;                ///< kTrue when absent
  std::vector<EffectLiteral> effects;
  std::vector<CostExpr> costs;         ///< summed; empty = cost 0 under a metric, 1 otherwise
  Loc loc;
};

struct PredicateDecl {
  std::string name;
  std::vector<TypedName> params;
  Loc loc;
};

/// A declared type and its direct parents.
///
/// Semantics of several parents (a type declared more than once, `t - object` on one line and
/// `t - u` on another, or `t - (either u v)`): **the union of the declarations**. Every
/// declaration `t - u` states that every object of type `t` is also of type `u`, so an object of
/// type `t` belongs to every parent and to all their ancestors (the types form a DAG, not a tree).
/// This is the reading that loses no declaration: choosing one parent (first or last) would make
/// objects of `t` invisible to the parameters typed with the other parent, and a domain that
/// declares both means them to be usable there. FF, which accepts such domains, likewise keeps
/// every declaration. `object` is the implicit root; it is dropped from `parents` when a type has
/// another parent (it is implied). A parent used but never declared is declared implicitly under
/// `object`, as FF and Fast Downward do.
struct TypeDecl {
  std::string name;
  std::vector<std::string> parents;  ///< direct parents, sorted; empty only for "object" itself
  Loc loc;                           ///< first declaration
};

struct Domain {
  std::string file;   ///< as given to the parser (for messages)
  std::string name;
  std::vector<std::string> requirements;  ///< lower-case, with the leading ':'
  std::vector<TypeDecl> types;            ///< always contains "object"
  std::vector<TypedName> constants;
  std::vector<PredicateDecl> predicates;
  std::vector<PredicateDecl> functions;   ///< declared functions (total-cost and static costs)
  std::vector<Action> actions;

  const PredicateDecl* findPredicate(std::string_view name) const;
  const PredicateDecl* findFunction(std::string_view name) const;
  const TypeDecl* findType(std::string_view name) const;
  /// True when `type` equals `ancestor` or descends from it through any chain of parents.
  bool isSubtype(std::string_view type, std::string_view ancestor) const;
};

/// `(= (f o1 .. on) v)` in `:init`.
struct FunctionValue {
  Atom term;  ///< function name in `predicate`, objects in `args`
  double value{0.0};
};

struct Problem {
  std::string file;
  std::string name;
  std::string domain_name;
  std::vector<TypedName> objects;
  std::vector<Atom> init;
  std::vector<FunctionValue> function_values;
  Formula goal;
  bool minimize_total_cost{false};  ///< `(:metric minimize (total-cost))`
};

/// Parses a domain. `file` is used in messages only. Every structural error comes back as one
/// Error (kParseError or kUnsupported) naming file:line:column; semantic errors (undeclared
/// predicates/types, arity mismatches, unbound variables) are all collected into one Error
/// whose message lists them, one per line.
Result<Domain> parseDomain(std::string_view text, const std::string& file = "<domain>");

/// Parses a problem against `domain` (object types, predicate arities, function names).
Result<Problem> parseProblem(std::string_view text, const Domain& domain,
                             const std::string& file = "<problem>");

/// Parses one formula (goal syntax) over the objects of `domain` + `problem`, e.g.
/// `(and (on a b) (not (clear c)))`. Used by API callers who give goals as text.
Result<Formula> parseGoalFormula(std::string_view text, const Domain& domain, const Problem& problem,
                                 const std::string& name = "<goal>");

/// Parses a whitespace-separated list of ground atoms, e.g. `(on a b) (clear a)`.
Result<std::vector<Atom>> parseAtomList(std::string_view text, const Domain& domain,
                                        const Problem& problem, const std::string& name = "<atoms>");

/// PDDL text of a formula / atom (lower-case, canonical spacing), for messages and round trips.
std::string toString(const Formula& f);
std::string toString(const Atom& a);

}  // namespace tamp::symbolic_planner::pddl
