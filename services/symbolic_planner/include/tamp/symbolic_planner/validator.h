#pragma once
/// @file
/// An independent plan checker: replays a plan against the *lifted* PDDL semantics.
///
/// It shares only the parser's AST with the planner. States are sets of ground atoms (strings);
/// preconditions, effect conditions and goals are evaluated recursively with quantifiers ranging
/// over the typed objects; conditional effects are evaluated in the state before the action;
/// deletes are applied before adds; the cost is summed from the actions' `total-cost` increases
/// (function values from `:init`), or counts actions when the problem has no metric. None of the
/// grounder's or search's code (normalisation, DNF, complement facts, operator tables) is used,
/// so a bug there cannot hide itself.

#include <optional>
#include <string>
#include <vector>

#include "tamp/core/error.h"
#include "tamp/symbolic_planner/pddl.h"

namespace tamp::symbolic_planner {

/// One plan step: action name and object arguments (lower-case).
struct PlanStep {
  std::string action;
  std::vector<std::string> args;
  /// IPC form "(action a b)".
  std::string toString() const;
  bool operator==(const PlanStep&) const = default;
};

/// Parses IPC plan text: one `(action arg ...)` per line; `;` comments and blank lines ignored.
/// Errors name the line and column.
Result<std::vector<PlanStep>> parsePlan(const std::string& text, const std::string& name = "<plan>");

struct ValidationResult {
  bool valid{false};          ///< every step applicable and the goal holds at the end
  int failed_step{-1};        ///< 0-based index of the first inapplicable step, or -1
  std::string message;        ///< why it is invalid ("step 3 (pick a b): precondition ... is false")
  double cost{0.0};           ///< total cost (plan length without a metric)
  /// Every true ground atom ("(on a b)", sorted) of each state the replay went through:
  /// states[0] the initial state, states[i + 1] after step i (up to the failed step).
  std::vector<std::vector<std::string>> states;
};

/// Replays `plan` from `init` (default: the problem's `:init`) and checks `goal` (default: the
/// problem's goal) at the end.
ValidationResult validatePlan(const pddl::Domain& domain, const pddl::Problem& problem,
                              const std::vector<PlanStep>& plan,
                              const std::optional<std::vector<pddl::Atom>>& init = std::nullopt,
                              const std::optional<pddl::Formula>& goal = std::nullopt);

}  // namespace tamp::symbolic_planner
