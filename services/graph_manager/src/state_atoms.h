#pragma once
// Operations on symbolic states (sorted dynamic atoms), shared by online replanning and
// conditional planning. Internal to the graph manager library.
#include <algorithm>
#include <set>
#include <string>
#include <vector>

#include "tamp/graph_manager/abstraction.h"

namespace tamp::graph_manager::detail {

/// True when the ground atom names one of `ids` as an argument.
inline bool mentions(const std::string& atom, const std::vector<std::string>& ids) {
  const auto t = atomTokens(atom);
  for (std::size_t i = 1; i < t.size(); ++i)
    if (std::find(ids.begin(), ids.end(), t[i]) != ids.end()) return true;
  return false;
}

/// Literals whose conjunction holds exactly in `target` (given the atoms of `from`): the target's
/// atoms, and the negation of every atom of `from` it does not have.
inline std::vector<std::string> exactly(const std::vector<std::string>& from, const std::vector<std::string>& target) {
  std::vector<std::string> goal = target;
  for (const auto& a : from)
    if (!std::binary_search(target.begin(), target.end(), a)) goal.push_back("(not " + a + ")");
  return goal;
}

/// `state` changed as `before` -> `after` changed (the frame assumption for carried atoms).
inline std::vector<std::string> applyChange(const std::vector<std::string>& state, const std::vector<std::string>& before,
                                     const std::vector<std::string>& after) {
  std::set<std::string> s(state.begin(), state.end());
  for (const auto& a : before)
    if (!std::binary_search(after.begin(), after.end(), a)) s.erase(a);
  for (const auto& a : after)
    if (!std::binary_search(before.begin(), before.end(), a)) s.insert(a);
  return {s.begin(), s.end()};
}

/// `atom` (or a ground action) with the argument `from` renamed `to`; unchanged when it does not
/// name `from`.
inline std::string renamed(const std::string& atom, const std::string& from, const std::string& to) {
  const auto t = atomTokens(atom);
  if (std::find(t.begin() + (t.empty() ? 0 : 1), t.end(), from) == t.end()) return atom;
  std::string out = "(";
  for (std::size_t i = 0; i < t.size(); ++i) out += (i ? " " : "") + (i > 0 && t[i] == from ? to : t[i]);
  return out + ")";
}

}  // namespace tamp::graph_manager::detail
