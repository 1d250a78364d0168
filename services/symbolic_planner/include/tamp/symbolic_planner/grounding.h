#pragma once
/// @file
/// Grounding with relaxed reachability, cached across queries.
///
/// A `Grounder` owns one domain and one object set. It grounds from a set of *seed* atoms (the
/// union of every initial state it has seen): a semi-naive fixpoint over the lifted
/// preconditions' positive atoms (static atoms joined against the seeds, equality checked,
/// everything else over-approximated) gives the relaxed-reachable atoms `R(U)` and the action
/// instances whose positive preconditions are reachable. Because `R` is monotone and idempotent,
/// the grounding is complete for every query whose initial atoms lie in `R(U)`; a query with an
/// atom outside it extends the seeds and the fixpoint continues where it stopped (ids stay
/// stable). Static atoms of a query are applied when the `Task` is built, so queries that drop a
/// static fact get a task without the operators that need it.

#include <cstdint>
#include <memory>
#include <string>
#include <unordered_map>
#include <vector>

#include "tamp/core/error.h"
#include "tamp/core/termination.h"
#include "tamp/symbolic_planner/pddl.h"
#include "tamp/symbolic_planner/task.h"

namespace tamp::symbolic_planner {

/// Index of a ground atom in a Grounder's atom table (stable for the Grounder's lifetime).
using AtomId = uint32_t;

/// A ground literal over atom ids.
struct AtomLiteral {
  AtomId atom{0};
  bool negated{false};
};

/// Limits that keep grounding bounded on adversarial input.
struct GroundingLimits {
  size_t max_atoms{20'000'000};
  size_t max_action_instances{20'000'000};
  size_t max_dnf_terms{4096};  ///< per ground precondition / effect condition / goal
};

/// Statistics of the last exploration/build (for logs and replies).
struct GroundingStats {
  size_t reachable_atoms{0};
  size_t action_instances{0};
  size_t facts{0};
  size_t operators{0};
  double explore_seconds{0.0};
  double build_seconds{0.0};
};

class Grounder {
 public:
  /// Compiles the domain's schemas over the objects of `problem` (and the domain's constants)
  /// and takes the problem's function values (action costs). Does not explore yet.
  /// Errors: kUnsupported for constructs outside the fragment, kInvalidArgument for type errors.
  static Result<std::unique_ptr<Grounder>> create(const pddl::Domain& domain, const pddl::Problem& problem,
                                                  GroundingLimits limits = {});
  ~Grounder();
  Grounder(const Grounder&) = delete;
  Grounder& operator=(const Grounder&) = delete;

  const pddl::Domain& domain() const;
  const pddl::Problem& problem() const;  ///< objects and function values (init/goal unused)

  /// The atom id of a ground atom (interned); errors name unknown predicates/objects or arity.
  Result<AtomId> atomId(const pddl::Atom& atom);
  Result<AtomId> atomId(const std::string& predicate, const std::vector<std::string>& args);
  std::string atomName(AtomId a) const;
  /// The atom as an AST atom (predicate and object names).
  pddl::Atom atom(AtomId a) const;
  bool isStaticAtom(AtomId a) const;
  size_t numAtoms() const;

  /// True when every atom of `init` is in R(U): the current grounding is complete for it.
  bool covers(const std::vector<AtomId>& init) const;
  /// Adds atoms to the seeds U and continues the fixpoint. kTimeout/kCancelled on termination
  /// (the grounder stays usable: a later call continues), kInvalidArgument when limits are hit.
  Status extend(const std::vector<AtomId>& init, const Termination& term);
  bool isReachable(AtomId a) const;

  /// Builds the search task for the statics of `init` (fluent atoms of `init` are ignored here).
  /// `negated_goal_atoms` are given complement facts so that negative goals are informative.
  Result<std::shared_ptr<const Task>> buildTask(const std::vector<AtomId>& init,
                                                const std::vector<AtomId>& negated_goal_atoms,
                                                bool use_costs, const Termination& term);

  /// Fact id of an atom in `task`, or -1 when the atom is static or unreachable. `task` must be
  /// the task most recently returned by buildTask() (the same holds for initialState/groundGoal).
  int64_t factOf(const Task& task, AtomId a) const;
  /// The initial state of `task` for the atoms `init` (fluent atoms; statics are ignored).
  StateBits initialState(const Task& task, const std::vector<AtomId>& init) const;
  /// Grounds a goal formula (objects of this grounder) against `task` and the statics of `init`.
  Result<Goal> groundGoal(const pddl::Formula& goal, const Task& task, const std::vector<AtomId>& init);
  /// Atoms that occur negated in `goal` (candidates for complement facts).
  Result<std::vector<AtomId>> negatedAtoms(const pddl::Formula& goal);

  const GroundingStats& stats() const;

 private:
  Grounder();
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace tamp::symbolic_planner
