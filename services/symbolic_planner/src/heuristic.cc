#include "tamp/symbolic_planner/heuristic.h"

#include "tamp/symbolic_planner/flat_index.h"

#include <algorithm>
#include <stdexcept>

namespace tamp::symbolic_planner {
namespace {

constexpr Cost kInf = Heuristic::kDeadEnd;
constexpr uint32_t kNone = UINT32_MAX;

/// The delete relaxation of a task in flat (CSR) arrays. A relaxed operator ("rop", FF's
/// "effect") is an operator's unconditional part or one of its conditional effects, with the
/// effect condition added to the precondition. Built once per heuristic object.
/// Grouping by shared keys (h_FF's precondition groups, the operator merging): item r has the
/// keys keys[first_key[r] .. first_key[r + 1]), key k is shared by key_count[k] items. Per item,
/// `chosen` is the index into `keys` of its key shared by the most items (more than one; the first
/// on ties), kNone when none is shared; `members_of_key` counts the items that chose each key.
void chooseLargestKeys(const std::vector<uint32_t>& first_key, const std::vector<uint32_t>& keys,
                       const std::vector<uint32_t>& key_count, std::vector<uint32_t>& chosen,
                       std::vector<uint32_t>& members_of_key) {
  const size_t n = first_key.size() - 1;
  chosen.assign(n, kNone);
  members_of_key.assign(key_count.size(), 0);
  for (size_t r = 0; r < n; ++r) {
    uint32_t best = kNone, best_n = 1;
    for (uint32_t i = first_key[r]; i < first_key[r + 1]; ++i) {
      if (key_count[keys[i]] > best_n) {
        best_n = key_count[keys[i]];
        best = i;
      }
    }
    if (best == kNone) continue;
    chosen[r] = best;
    ++members_of_key[keys[best]];
  }
}

struct RelaxedOps {
  std::vector<OpId> op;              ///< rop -> operator
  std::vector<int32_t> ce;           ///< rop -> conditional effect index, -1 = unconditional part
  std::vector<uint32_t> pre_begin, pre;
  std::vector<uint32_t> add_begin, add;
  std::vector<uint32_t> count;       ///< number of preconditions
  std::vector<Cost> cost;            ///< adjusted cost of the operator
  std::vector<uint32_t> pre_of_begin, pre_of;  ///< fact -> rops that need it
  std::vector<uint32_t> adders_begin, adders;  ///< fact -> rops that add it (in rop order)
  std::vector<uint32_t> no_pre;
  /// rop -> other rops of the same operator that fire whenever it fires (their condition is a
  /// subset of its condition; FF's "implied effects").
  std::vector<uint32_t> implied_begin, implied;
  /// Merged rops (`build(..., merge = true)`): operators that differ in one precondition fact
  /// only (same adds, same other preconditions, no conditional effects) are one rop whose
  /// precondition is the common part plus *one of* the differing facts (its "members"); `count`
  /// counts that disjunction as one precondition. The relaxation of the group is exactly that
  /// of its operators: the rop fires when the first of them would. rop -> members (fact, operator)
  /// in operator order (empty: not merged); fact -> merged rops with a member on it.
  std::vector<uint32_t> member_begin;
  std::vector<std::pair<FactId, OpId>> members;
  std::vector<uint32_t> member_of_begin, member_of;

  /// Counting through shared preconditions (`factor()`; only the layered graph uses it). Rops
  /// that have all preconditions but one in common with other rops (openstacks'
  /// `ship-order(o, s, s')` for every stack count s: the same `started` and `made` facts, one
  /// `stacks-avail s` each) count that common part through one *conjunction node*: the node
  /// counts its facts, and when the last one is reached, it counts as one reached precondition
  /// of each of its rops, at once (same layer). A rop's precondition count is then 2 (the node
  /// and its own fact) instead of |pre|, and a common fact has one edge to the node instead of
  /// one to each rop. When each rop becomes active, and so every level, is unchanged; `pre`,
  /// `pre_of` and `count` keep the rops' own preconditions (extraction and the cost-based
  /// heuristics use those).
  std::vector<uint32_t> cnt_count;                     ///< rop -> preconditions counted
  std::vector<uint32_t> cnt_pre_of_begin, cnt_pre_of;  ///< fact -> rops that count it themselves
  std::vector<uint32_t> node_count;                    ///< node -> its facts
  std::vector<uint32_t> node_of_begin, node_of;        ///< fact -> nodes that count it
  std::vector<uint32_t> node_rops_begin, node_rops;    ///< node -> its rops, in rop order

  size_t size() const { return op.size(); }
  bool merged(uint32_t r) const { return member_begin[r] != member_begin[r + 1]; }
  size_t numNodes() const { return node_count.size(); }

  /// Builds the counting structure above: each rop that is not merged and has at least four
  /// preconditions joins the largest group of such rops that share all its preconditions but
  /// one (over its choices of that one; first on ties); a group of two or more is a node. With
  /// three preconditions (nodes of two facts) it did not pay: on grid, mprime and mystery nearly
  /// every rop formed such nodes, 21-31 % fewer edges, and neither the search of grid-5 got
  /// faster nor did building them (0.5-0.8 ms on mprime-21 and mystery-30) pay off.
  void factor() {
    const uint32_t n = static_cast<uint32_t>(size());
    const size_t nf = pre_of_begin.size() - 1;
    auto mix = [](uint64_t x) {  // splitmix64's finaliser: a commutative sum of these is the key
      x += 0x9E3779B97F4A7C15ULL;
      x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ULL;
      x = (x ^ (x >> 27)) * 0x94D049BB133111EBULL;
      return x ^ (x >> 31);
    };
    auto eligible = [&](uint32_t r) { return !merged(r) && count[r] >= 4; };
    // Do rops a and b have the same preconditions once a's skip-th and b's skip-th are left out?
    // (Preconditions are sorted.)
    auto same = [&](uint32_t a, uint32_t sa, uint32_t b, uint32_t sb) {
      if (count[a] != count[b]) return false;
      for (uint32_t k = 0; k + 1 < count[a]; ++k) {
        if (pre[pre_begin[a] + k + (k >= sa ? 1 : 0)] != pre[pre_begin[b] + k + (k >= sb ? 1 : 0)]) return false;
      }
      return true;
    };
    size_t num_keys = 0;
    for (uint32_t r = 0; r < n; ++r) num_keys += eligible(r) ? count[r] : 0;
    U64IdMap key_id(num_keys);
    std::vector<uint32_t> key_count;
    std::vector<std::pair<uint32_t, uint32_t>> key_rep;  // key -> its first (rop, skip)
    std::vector<uint32_t> first_key(n + 1, 0), keys;
    keys.reserve(num_keys);
    for (uint32_t r = 0; r < n; ++r) {
      first_key[r] = static_cast<uint32_t>(keys.size());
      if (!eligible(r)) continue;
      uint64_t total = 0;
      for (uint32_t p = pre_begin[r]; p < pre_begin[r + 1]; ++p) total += mix(pre[p]);
      for (uint32_t i = 0; i < count[r]; ++i) {
        const uint64_t h = (total - mix(pre[pre_begin[r] + i])) ^ count[r];
        auto [id, inserted] = key_id.tryEmplace(h, static_cast<uint32_t>(key_count.size()));
        if (inserted) {
          key_count.push_back(0);
          key_rep.push_back({r, i});
        } else if (!same(key_rep[id].first, key_rep[id].second, r, i)) {
          id = static_cast<uint32_t>(key_count.size());  // a hash collision: a key of its own
          key_count.push_back(0);
          key_rep.push_back({r, i});
        }
        ++key_count[id];
        keys.push_back(id);
      }
    }
    first_key[n] = static_cast<uint32_t>(keys.size());
    std::vector<uint32_t> chosen, members_of_key;
    chooseLargestKeys(first_key, keys, key_count, chosen, members_of_key);
    // Nodes, and per rop its node (kNone: counts every precondition itself) and own fact.
    std::vector<uint32_t> node_of_key(key_count.size(), kNone), node(n, kNone), own(n, 0);
    std::vector<uint32_t> node_rep;  // node -> (rop whose preconditions, bar one, are its facts)
    std::vector<uint32_t> node_skip;
    for (uint32_t r = 0; r < n; ++r) {
      if (chosen[r] == kNone) continue;
      const uint32_t kid = keys[chosen[r]];
      if (members_of_key[kid] < 2) continue;
      if (node_of_key[kid] == kNone) {
        node_of_key[kid] = static_cast<uint32_t>(node_count.size());
        node_count.push_back(count[r] - 1);
        node_rep.push_back(r);
        node_skip.push_back(chosen[r] - first_key[r]);
      }
      node[r] = node_of_key[kid];
      own[r] = pre[pre_begin[r] + chosen[r] - first_key[r]];
    }
    const uint32_t nn = static_cast<uint32_t>(node_count.size());
    cnt_count.resize(n);
    std::vector<uint32_t> direct(nf + 1, 0), of_node(nf + 1, 0), rops_of_node(nn + 1, 0);
    for (uint32_t r = 0; r < n; ++r) {
      if (node[r] == kNone) {
        cnt_count[r] = count[r];
        for (uint32_t p = pre_begin[r]; p < pre_begin[r + 1]; ++p) ++direct[pre[p]];
      } else {
        cnt_count[r] = 2;
        ++direct[own[r]];
        ++rops_of_node[node[r]];
      }
    }
    for (uint32_t x = 0; x < nn; ++x) {
      const uint32_t r = node_rep[x];
      for (uint32_t k = 0; k < node_count[x]; ++k) ++of_node[pre[pre_begin[r] + k + (k >= node_skip[x] ? 1 : 0)]];
    }
    // Counting sorts: every list in increasing order.
    auto offsets = [](const std::vector<uint32_t>& counts, size_t num, std::vector<uint32_t>& begin) {
      begin.assign(num + 1, 0);
      for (size_t i = 0; i < num; ++i) begin[i + 1] = begin[i] + counts[i];
      return std::vector<uint32_t>(begin.begin(), begin.end() - 1);
    };
    std::vector<uint32_t> fill = offsets(direct, nf, cnt_pre_of_begin);
    cnt_pre_of.resize(cnt_pre_of_begin[nf]);
    std::vector<uint32_t> fill_rops = offsets(rops_of_node, nn, node_rops_begin);
    node_rops.resize(node_rops_begin[nn]);
    for (uint32_t r = 0; r < n; ++r) {
      if (node[r] == kNone) {
        for (uint32_t p = pre_begin[r]; p < pre_begin[r + 1]; ++p) cnt_pre_of[fill[pre[p]]++] = r;
      } else {
        cnt_pre_of[fill[own[r]]++] = r;
        node_rops[fill_rops[node[r]]++] = r;
      }
    }
    std::vector<uint32_t> fill_nodes = offsets(of_node, nf, node_of_begin);
    node_of.resize(node_of_begin[nf]);
    for (uint32_t x = 0; x < nn; ++x) {
      const uint32_t r = node_rep[x];
      for (uint32_t k = 0; k < node_count[x]; ++k) {
        node_of[fill_nodes[pre[pre_begin[r] + k + (k >= node_skip[x] ? 1 : 0)]]++] = x;
      }
    }
  }

  /// `implied`: also the implied effects (only FF's layered extraction needs them). `merge`:
  /// merge operators as above (only where every operator costs the same).
  void build(const Task& task, CostType ct, bool implied_effects = true, bool merge = false) {
    const size_t nf = task.numFacts();
    std::vector<uint32_t> pre_count(nf + 1, 0), add_count(nf + 1, 0), member_count(nf + 1, 0);
    std::vector<FactId> tmp;
    std::vector<uint32_t> op_first(task.ops.size() + 1, 0);
    // Groups of operators to merge: group id per operator (kNone: alone), the differing fact.
    std::vector<uint32_t> group(task.ops.size(), kNone);
    std::vector<FactId> varying(task.ops.size(), 0);
    std::vector<std::vector<OpId>> groups;
    if (merge) findGroups(task, group, varying, groups);
    auto addRop = [&](OpId o, int32_t c, const std::vector<FactId>& p1, const std::vector<FactId>* p2,
                      const std::vector<FactId>& adds) {
      if (adds.empty()) return;
      tmp.assign(p1.begin(), p1.end());
      if (p2) {
        tmp.insert(tmp.end(), p2->begin(), p2->end());
        std::sort(tmp.begin(), tmp.end());
        tmp.erase(std::unique(tmp.begin(), tmp.end()), tmp.end());
      }
      op.push_back(o);
      ce.push_back(c);
      pre_begin.push_back(static_cast<uint32_t>(pre.size()));
      pre.insert(pre.end(), tmp.begin(), tmp.end());
      add_begin.push_back(static_cast<uint32_t>(add.size()));
      add.insert(add.end(), adds.begin(), adds.end());
      count.push_back(static_cast<uint32_t>(tmp.size()));
      cost.push_back(adjustedCost(task.ops[o], ct, task.unit_cost));
      for (FactId f : tmp) ++pre_count[f];
      for (FactId f : adds) ++add_count[f];
    };
    member_begin.push_back(0);
    for (OpId o = 0; o < task.ops.size(); ++o) {
      const Operator& x = task.ops[o];
      op_first[o] = static_cast<uint32_t>(op.size());
      if (group[o] != kNone) {
        const std::vector<OpId>& g = groups[group[o]];
        if (g.front() != o) continue;  // merged into the rop of the group's first operator
        std::vector<FactId> common;
        for (FactId f : x.pre) {
          if (f != varying[o]) common.push_back(f);
        }
        addRop(o, -1, common, nullptr, x.add);
        ++count.back();  // the disjunction of the members
        for (OpId m : g) {
          members.push_back({varying[m], m});
          ++member_count[varying[m]];
        }
        member_begin.push_back(static_cast<uint32_t>(members.size()));
        continue;
      }
      addRop(o, -1, x.pre, nullptr, x.add);
      while (member_begin.size() < op.size() + 1) member_begin.push_back(static_cast<uint32_t>(members.size()));
      for (size_t c = 0; c < x.cond_effects.size(); ++c) {
        addRop(o, static_cast<int32_t>(c), x.pre, &x.cond_effects[c].cond, x.cond_effects[c].add);
      }
      while (member_begin.size() < op.size() + 1) member_begin.push_back(static_cast<uint32_t>(members.size()));
    }
    op_first[task.ops.size()] = static_cast<uint32_t>(op.size());
    const uint32_t n = static_cast<uint32_t>(op.size());
    pre_begin.push_back(static_cast<uint32_t>(pre.size()));
    add_begin.push_back(static_cast<uint32_t>(add.size()));
    // Inverted indices by counting sort: rops stay in increasing order per fact.
    auto invert = [&](const std::vector<uint32_t>& counts, const std::vector<uint32_t>& begin,
                      const std::vector<uint32_t>& items, std::vector<uint32_t>& out_begin,
                      std::vector<uint32_t>& out) {
      out_begin.assign(nf + 1, 0);
      for (size_t f = 0; f < nf; ++f) out_begin[f + 1] = out_begin[f] + counts[f];
      out.resize(out_begin[nf]);
      std::vector<uint32_t> fill(out_begin.begin(), out_begin.end() - 1);
      for (uint32_t r = 0; r < n; ++r) {
        for (uint32_t i = begin[r]; i < begin[r + 1]; ++i) out[fill[items[i]]++] = r;
      }
    };
    invert(pre_count, pre_begin, pre, pre_of_begin, pre_of);
    invert(add_count, add_begin, add, adders_begin, adders);
    {
      std::vector<uint32_t> member_facts(members.size());
      for (size_t i = 0; i < members.size(); ++i) member_facts[i] = members[i].first;
      invert(member_count, member_begin, member_facts, member_of_begin, member_of);
    }
    for (uint32_t r = 0; r < n; ++r) {
      if (count[r] == 0) no_pre.push_back(r);
    }
    if (!implied_effects) return;
    // Implied effects: within each operator, rop j is implied by rop i when cond(j) is a subset
    // of cond(i) (the unconditional part is implied by every conditional effect).
    implied_begin.assign(n + 1, 0);
    for (OpId o = 0; o < task.ops.size(); ++o) {
      const Operator& x = task.ops[o];
      for (uint32_t i = op_first[o]; i < op_first[o + 1]; ++i) {
        implied_begin[i] = static_cast<uint32_t>(implied.size());
        if (ce[i] < 0) continue;  // the unconditional part implies no conditional effect
        const auto& ci = x.cond_effects[static_cast<size_t>(ce[i])].cond;
        for (uint32_t j = op_first[o]; j < op_first[o + 1]; ++j) {
          if (j == i) continue;
          if (ce[j] < 0) {
            implied.push_back(j);
            continue;
          }
          const auto& cj = x.cond_effects[static_cast<size_t>(ce[j])].cond;
          if (std::includes(ci.begin(), ci.end(), cj.begin(), cj.end())) implied.push_back(j);
        }
      }
    }
    implied_begin[n] = static_cast<uint32_t>(implied.size());
  }

  /// Operators without conditional effects that share their adds and all preconditions but one
  /// (at least two of them): each operator joins the largest such group over its choices of the
  /// differing precondition (first on ties); groups that end with one operator are dropped.
  static void findGroups(const Task& task, std::vector<uint32_t>& group, std::vector<FactId>& varying,
                         std::vector<std::vector<OpId>>& groups) {
    // Key of (operator, index `skip` of the differing precondition): its adds and its other
    // preconditions, hashed without building it; equal hashes are checked against the key's
    // first (operator, skip) and a colliding key is not merged.
    auto hash = [](const Operator& x, size_t skip) {
      uint64_t h = 0x9E3779B97F4A7C15ULL;
      for (FactId f : x.add) h = (h ^ f) * 0x100000001B3ULL;
      h = (h ^ kNone) * 0x100000001B3ULL;
      for (size_t i = 0; i < x.pre.size(); ++i) {
        if (i != skip) h = (h ^ x.pre[i]) * 0x100000001B3ULL;
      }
      return h ^ (h >> 29);
    };
    auto same = [](const Operator& a, size_t sa, const Operator& b, size_t sb) {
      if (a.add != b.add || a.pre.size() != b.pre.size()) return false;
      for (size_t k = 0; k + 1 < a.pre.size(); ++k) {  // the preconditions but the skipped one
        if (a.pre[k + (k >= sa ? 1 : 0)] != b.pre[k + (k >= sb ? 1 : 0)]) return false;
      }
      return true;
    };
    auto eligible = [](const Operator& x) { return x.cond_effects.empty() && !x.add.empty() && !x.pre.empty(); };
    size_t num_keys = 0;  // one per (eligible operator, precondition): the map never grows
    for (const Operator& x : task.ops) num_keys += eligible(x) ? x.pre.size() : 0;
    U64IdMap key_id(num_keys);
    std::vector<uint32_t> key_count;
    std::vector<std::pair<OpId, uint32_t>> key_rep;  // key -> its first (operator, skip)
    std::vector<uint32_t> first_key(task.ops.size() + 1, 0), keys;  // per operator, its keys' ids
    for (OpId o = 0; o < task.ops.size(); ++o) {
      first_key[o] = static_cast<uint32_t>(keys.size());
      const Operator& x = task.ops[o];
      if (!eligible(x)) continue;
      for (size_t i = 0; i < x.pre.size(); ++i) {
        auto [id, inserted] = key_id.tryEmplace(hash(x, i), static_cast<uint32_t>(key_count.size()));
        if (inserted) {
          key_count.push_back(0);
          key_rep.push_back({o, static_cast<uint32_t>(i)});
        } else if (!same(task.ops[key_rep[id].first], key_rep[id].second, x, i)) {
          id = static_cast<uint32_t>(key_count.size());  // a hash collision: a key of its own
          key_count.push_back(0);
          key_rep.push_back({o, static_cast<uint32_t>(i)});
        }
        ++key_count[id];
        keys.push_back(id);
      }
    }
    first_key[task.ops.size()] = static_cast<uint32_t>(keys.size());
    std::vector<uint32_t> chosen, members_of_key, group_of_key(key_count.size(), kNone);
    chooseLargestKeys(first_key, keys, key_count, chosen, members_of_key);
    for (OpId o = 0; o < task.ops.size(); ++o) {
      if (chosen[o] == kNone) continue;
      const uint32_t kid = keys[chosen[o]];
      if (members_of_key[kid] < 2) continue;
      if (group_of_key[kid] == kNone) {
        group_of_key[kid] = static_cast<uint32_t>(groups.size());
        groups.emplace_back();
      }
      group[o] = group_of_key[kid];
      groups[group[o]].push_back(o);
      varying[o] = task.ops[o].pre[chosen[o] - first_key[o]];
    }
  }
};

/// Goal facts of the current goal: per fact, the conjuncts it belongs to (reset-free lookups).
class GoalIndex {
 public:
  void set(const Goal& goal, size_t num_facts) {
    if (first_.size() != num_facts) first_.assign(num_facts, kNone);
    for (const auto& [f, c] : pairs_) first_[f] = kNone;
    pairs_.clear();
    for (uint32_t c = 0; c < goal.conjuncts.size(); ++c) {
      for (FactId f : goal.conjuncts[c].pos) pairs_.push_back({f, c});
    }
    std::sort(pairs_.begin(), pairs_.end());
    pairs_.erase(std::unique(pairs_.begin(), pairs_.end()), pairs_.end());
    for (uint32_t i = static_cast<uint32_t>(pairs_.size()); i-- > 0;) first_[pairs_[i].first] = i;
    sizes_.assign(goal.conjuncts.size(), 0);
    for (const auto& [f, c] : pairs_) ++sizes_[c];
  }
  bool isGoal(FactId f) const { return first_[f] != kNone; }
  /// Calls fn(conjunct) for every conjunct that contains f.
  template <typename Fn>
  void forEach(FactId f, const Fn& fn) const {
    for (uint32_t i = first_[f]; i < pairs_.size() && pairs_[i].first == f; ++i) fn(pairs_[i].second);
  }
  const std::vector<uint32_t>& sizes() const { return sizes_; }

 private:
  std::vector<uint32_t> first_;
  std::vector<std::pair<FactId, uint32_t>> pairs_;
  std::vector<uint32_t> sizes_;
};

/// Calls fn(f) for every fact f < num_facts true in state `s` (`words` 64-bit words), in order.
template <typename Fn>
void forEachTrueFact(const uint64_t* s, size_t words, size_t num_facts, Fn&& fn) {
  for (size_t w = 0; w < words; ++w) {
    uint64_t word = s[w];
    while (word) {
      const FactId f = static_cast<FactId>(w * 64 + static_cast<size_t>(__builtin_ctzll(word)));
      word &= word - 1;
      if (f >= num_facts) return;
      fn(f);
    }
  }
}

bool holdsAll(const uint64_t* s, const std::vector<FactId>& facts) {
  for (FactId f : facts) {
    if (!testBit(s, f)) return false;
  }
  return true;
}

/// Relaxed dead ends remembered by their closure: the facts relaxed-reachable from them, closed under
/// every relaxed operator. A state whose true facts all lie in such a closure reaches no fact
/// outside it, so no goal conjunct either: it is a relaxed dead end too, known without exploring
/// (the same value and no helpful actions, as the exploration would give). Successive evaluations
/// are of neighbouring states: on trucks-18 most of the lazy search's evaluations are dead ends
/// next to one evaluated just before. Keeps the last `kSlots` closures; `clear()` when the goal
/// changes.
class DeadEndMemo {
 public:
  static constexpr size_t kSlots = 4;

  void clear(size_t words) {
    words_ = words;
    bits_.assign(kSlots * words, 0);
    used_ = next_ = 0;
  }
  /// Does a remembered closure contain every fact true in `s`?
  bool covers(const uint64_t* s) const {
    for (size_t k = 0; k < used_; ++k) {
      const uint64_t* c = &bits_[k * words_];
      size_t w = 0;
      while (w < words_ && (s[w] & ~c[w]) == 0) ++w;
      if (w == words_) return true;
    }
    return false;
  }
  /// Remembers a dead end's closure, given as the facts fact(0) .. fact(n - 1) (over the oldest
  /// one when every slot is taken).
  template <typename FactAt>
  void add(size_t n, const FactAt& fact) {
    uint64_t* c = &bits_[next_ * words_];
    std::fill(c, c + words_, 0);
    for (size_t i = 0; i < n; ++i) {
      const FactId f = fact(i);
      c[f >> 6] |= uint64_t{1} << (f & 63);
    }
    next_ = (next_ + 1) % kSlots;
    used_ = std::min(used_ + 1, kSlots);
  }

 private:
  size_t words_{0}, used_{0}, next_{0};
  std::vector<uint64_t> bits_;  ///< kSlots closures of words_ words each
};

// -------------------------------------------------------------------------------------------------
/// FF's own heuristic (Hoffmann & Nebel 2001, Sec. 4.3) for tasks in which every operator costs the
/// same (h = that cost times the number of operators in the relaxed plan): a layered relaxed planning graph built breadth-first only up to the first layer that contains
/// a goal conjunct, a relaxed plan extracted backwards layer by layer (achievers of the previous
/// layer with the least difficulty; the adds of a selected achiever count as true at its layer
/// and the one below; each operator counted once), and helpful actions: the applicable operators
/// that add a layer-1 sub-goal, the relaxed plan's own first-layer actions first, or in FF-v2.3's
/// order (`setFFStyle`). Every array is reset through the lists of what the last evaluation
/// touched (no per-evaluation pass over all facts or operators).
class LayeredFF : public Heuristic {
 public:
  /// `factor`: count shared preconditions through conjunction nodes (`RelaxedOps::factor`; the
  /// same values and helpful actions either way, fewer edges on tasks with such groups).
  LayeredFF(const Task& task, CostType ct, Cost unit, bool factor) : task_(task), unit_(unit) {
    R_.build(task, ct, /*implied=*/true, /*merge=*/true);
    if (factor) R_.factor();
    group_done_.assign(R_.size(), 0);
    const size_t nf = task.numFacts(), nr = R_.size();
    level_.assign(nf, kNone);
    ctr_.resize(nr);
    zero_pos_.assign(nr, kNone);
    for (uint32_t r = 0; r < nr; ++r) {
      const uint32_t c = factor ? R_.cnt_count[r] : R_.count[r];
      ctr_[r] = {c, c};
      if (c == 0) {  // the base state is the empty one: only the rops without preconditions
        zero_pos_[r] = static_cast<uint32_t>(zero_.size());
        zero_.push_back(r);
      }
    }
    member_true_.assign(nr, 0);
    base_.assign(task.numWords(), 0);
    if (!factor) {  // every rop counts its own preconditions
      R_.cnt_pre_of_begin = R_.pre_of_begin;
      R_.cnt_pre_of = R_.pre_of;
      R_.node_of_begin.assign(nf + 1, 0);
    }
    node_ctr_.resize(R_.numNodes());
    for (size_t x = 0; x < R_.numNodes(); ++x) node_ctr_[x] = {R_.node_count[x], R_.node_count[x]};
    node_touched_.resize(R_.numNodes() + 1);
    rop_level_.assign(nr, kNone);
    true_a_.assign(nf, 0);
    true_b_.assign(nf, 0);
    goal_mark_.assign(nf, 0);
    op_used_.assign(task.ops.size(), 0);
    op_mark_.assign(task.ops.size(), 0);
    // Each fact is reached once and each rop activated and touched once per evaluation; one
    // spare slot for the branch-free appends below.
    facts_.resize(nf);
    active_.resize(nr + 1);
    touched_.resize(nr + 1);
  }

  void setGoal(const Goal& goal) override {
    goal_ = goal;
    goals_.set(goal_, task_.numFacts());
    dead_ends_.clear(task_.numWords());
    several_conjuncts_ = goal_.conjuncts.size() > 1;
    // The order in which the first layer's rops activate decides which conjunct of a disjunctive
    // goal is taken; only the full count of layer 0 keeps it (see `buildGraph`).
    incremental_ = !several_conjuncts_;
  }
  bool computesPreferred() const override { return true; }
  const std::vector<OpId>& preferred() const override { return preferred_; }
  bool setFFStyle(bool on) override {
    ff_style_ = on;
    return true;
  }
  bool setRelaxedPlanPreferred(bool on) override {
    plan_preferred_ = on;
    return true;
  }

  Cost evaluate(const uint64_t* s) override {
    preferred_.clear();
    if (goal_.conjuncts.empty()) return kInf;
    if (task_.goalReached(s, goal_)) return 0;
    if (dead_ends_.covers(s)) return kInf;
    const int conj = buildGraph(s);
    if (conj < 0) {  // the facts reached are the closure of s
      dead_ends_.add(num_facts_, [this](size_t i) { return facts_[i]; });
      return kInf;
    }
    return extract(s, goal_.conjuncts[static_cast<size_t>(conj)]) * unit_;
  }

 private:
  void reset() {
    for (size_t i = 0; i < num_facts_; ++i) level_[facts_[i]] = kNone;
    for (size_t i = 0; i < num_active_; ++i) rop_level_[active_[i]] = kNone;
    for (size_t i = 0; i < num_touched_; ++i) {
      const uint32_t r = touched_[i];
      ctr_[r].unsat = ctr_[r].base;
      group_done_[r] = member_true_[r] != 0;
    }
    for (size_t i = 0; i < num_node_touched_; ++i) node_ctr_[node_touched_[i]].unsat = node_ctr_[node_touched_[i]].base;
    num_facts_ = num_active_ = num_touched_ = num_node_touched_ = 0;
  }

  // The base state (`base_`): the counters at rest (`Counter::base`, `group_done_`) count the
  // preconditions of every rop that hold in it, as layer 0 of a graph from it would, and `zero_`
  // lists the rops with none left (layer 0's active rops). Successive evaluations are of
  // neighbouring states (a parent's children, a path's next state), which differ in a few facts:
  // moving the base to the evaluated state through those facts' edges replaces layer 0's pass
  // over every true fact's edges (airport-30: 85 % of the graph's precondition edges). Called
  // between evaluations only (every counter at rest).
  void baseDec(uint32_t r) {
    --ctr_[r].unsat;
    if (--ctr_[r].base == 0) {
      zero_pos_[r] = static_cast<uint32_t>(zero_.size());
      zero_.push_back(r);
    }
  }
  void baseInc(uint32_t r) {
    if (ctr_[r].base++ == 0) {  // out of `zero_`: the last entry takes its place
      const uint32_t i = zero_pos_[r], last = zero_.back();
      zero_[i] = last;
      zero_pos_[last] = i;
      zero_.pop_back();
      zero_pos_[r] = kNone;
    }
    ++ctr_[r].unsat;
  }
  /// Fact f enters (`on`) or leaves the base state.
  void baseFlip(FactId f, bool on) {
    const RelaxedOps& R = R_;
    for (uint32_t k = R.cnt_pre_of_begin[f], e = R.cnt_pre_of_begin[f + 1]; k < e; ++k) {
      on ? baseDec(R.cnt_pre_of[k]) : baseInc(R.cnt_pre_of[k]);
    }
    for (uint32_t k = R.node_of_begin[f], e = R.node_of_begin[f + 1]; k < e; ++k) {
      const uint32_t x = R.node_of[k];
      const uint32_t before = node_ctr_[x].base;
      node_ctr_[x].base = on ? before - 1 : before + 1;
      node_ctr_[x].unsat = node_ctr_[x].base;
      if ((on ? node_ctr_[x].base : before) != 0) continue;  // completed (on) or no longer
      for (uint32_t j = R.node_rops_begin[x], je = R.node_rops_begin[x + 1]; j < je; ++j) {
        on ? baseDec(R.node_rops[j]) : baseInc(R.node_rops[j]);
      }
    }
    for (uint32_t k = R.member_of_begin[f], e = R.member_of_begin[f + 1]; k < e; ++k) {
      const uint32_t r = R.member_of[k];
      // The disjunction of members counts once, while any of their facts holds.
      if (on) {
        if (member_true_[r]++ == 0) baseDec(r);
      } else if (--member_true_[r] == 0) {
        baseInc(r);
      }
      group_done_[r] = member_true_[r] != 0;
    }
  }
  /// Moves the base state to `s` (nullptr: the empty state).
  void moveBase(const uint64_t* s) {
    const size_t words = base_.size();
    for (size_t w = 0; w < words; ++w) {
      const uint64_t next = s == nullptr ? 0 : s[w];
      uint64_t diff = base_[w] ^ next;
      if (diff == 0) continue;
      base_[w] = next;
      while (diff) {
        const FactId f = static_cast<FactId>(w * 64 + static_cast<size_t>(__builtin_ctzll(diff)));
        diff &= diff - 1;
        baseFlip(f, (next >> (f % 64)) & 1);
      }
    }
  }

  /// Builds the graph up to the first layer with a complete goal conjunct; returns the conjunct
  /// or -1 when the relaxed fixpoint is reached without one (a dead end). The lists are arrays
  /// sized for the whole task, appended to through local counters; the inner loop over
  /// precondition edges appends without branches (its two conditions are unpredictable).
  int buildGraph(const uint64_t* s) {
    reset();
    // Incremental: layer 0's counting is the base's, moved to s. Otherwise the base is the empty
    // state and layer 0 counts every true fact's edges in fact order (the rops' order matters).
    moveBase(incremental_ ? s : nullptr);
    remaining_ = goals_.sizes();
    int done = -1;
    const size_t nf = task_.numFacts();
    const size_t words = task_.numWords();
    FactId* const facts = facts_.data();
    uint32_t* const active = active_.data();
    uint32_t* const touched = touched_.data();
    uint32_t* const level = level_.data();
    uint32_t* const rop_level = rop_level_.data();
    Counter* const ctr = ctr_.data();
    const uint32_t* const pre_of = R_.cnt_pre_of.data();
    const uint32_t* const pre_of_begin = R_.cnt_pre_of_begin.data();
    const uint32_t* const node_of = R_.node_of.data();
    const uint32_t* const node_of_begin = R_.node_of_begin.data();
    const uint32_t* const node_rops = R_.node_rops.data();
    const uint32_t* const node_rops_begin = R_.node_rops_begin.data();
    Counter* const node_ctr = node_ctr_.data();
    uint32_t* const node_touched = node_touched_.data();
    const uint32_t* const add = R_.add.data();
    const uint32_t* const add_begin = R_.add_begin.data();
    const uint32_t* const member_of = R_.member_of.data();
    const uint32_t* const member_of_begin = R_.member_of_begin.data();
    uint8_t* const group_done = group_done_.data();
    size_t nfacts = 0, nactive = 0, ntouched = 0, nnode_touched = 0;
    auto reach = [&](FactId f, uint32_t lvl) {
      level[f] = lvl;
      facts[nfacts++] = f;
      if (goals_.isGoal(f)) {
        goals_.forEach(f, [&](uint32_t c) {
          if (--remaining_[c] == 0 && done < 0) done = static_cast<int>(c);
        });
      }
    };
    forEachTrueFact(s, words, nf, [&](FactId f) { reach(f, 0); });
    // Layer 0's facts are counted already when incremental (the base is s).
    size_t start_ft = incremental_ ? nfacts : 0, start_ef = 0;
    for (uint32_t time = 0;; ++time) {
      if (done >= 0) {
        max_level_ = time;
        break;
      }
      const size_t stop_ft = nfacts;
      for (size_t i = start_ft; i < stop_ft; ++i) {
        const FactId f = facts[i];
        const size_t first_active = nactive;
        for (uint32_t k = pre_of_begin[f], e = pre_of_begin[f + 1]; k < e; ++k) {
          const uint32_t r = pre_of[k];
          const uint32_t u = ctr[r].unsat;
          touched[ntouched] = r;
          ntouched += u == ctr[r].base;
          ctr[r].unsat = u - 1;
          active[nactive] = r;
          nactive += u == 1;
        }
        // Conjunction nodes: one completed by f counts as a reached precondition of its rops now.
        bool via_node = false;
        for (uint32_t k = node_of_begin[f], e = node_of_begin[f + 1]; k < e; ++k) {
          const uint32_t x = node_of[k];
          const uint32_t u = node_ctr[x].unsat;
          node_touched[nnode_touched] = x;
          nnode_touched += u == node_ctr[x].base;
          node_ctr[x].unsat = u - 1;
          if (u != 1) continue;
          via_node = true;
          for (uint32_t j = node_rops_begin[x], je = node_rops_begin[x + 1]; j < je; ++j) {
            const uint32_t r = node_rops[j];
            const uint32_t ur = ctr[r].unsat;
            touched[ntouched] = r;
            ntouched += ur == ctr[r].base;
            ctr[r].unsat = ur - 1;
            active[nactive] = r;
            nactive += ur == 1;
          }
        }
        // The rops f activates in rop order, as when every rop counts its own preconditions (the
        // order of the next layer's facts decides which conjunct of a disjunctive goal is taken).
        // Only the choice of a disjunctive goal's conjunct depends on that order (levels do not):
        // a goal of one conjunct skips the sort (15 % of an evaluation on hiking-16).
        if (via_node && several_conjuncts_ && nactive - first_active > 1) {
          std::sort(active + first_active, active + nactive);
        }
        // Merged rops: their disjunction of members counts once, when its first fact is reached.
        for (uint32_t k = member_of_begin[f], e = member_of_begin[f + 1]; k < e; ++k) {
          const uint32_t r = member_of[k];
          if (group_done[r]) continue;
          group_done[r] = 1;
          const uint32_t u = ctr[r].unsat;
          touched[ntouched] = r;
          ntouched += u == ctr[r].base;
          ctr[r].unsat = u - 1;
          active[nactive] = r;
          nactive += u == 1;
        }
      }
      if (time == 0) {  // the rops that need nothing beyond s (incremental: all of layer 0's)
        for (uint32_t r : incremental_ ? zero_ : R_.no_pre) active[nactive++] = r;
      }
      const size_t stop_ef = nactive;
      for (size_t i = start_ef; i < stop_ef; ++i) {
        const uint32_t r = active[i];
        rop_level[r] = time;
        for (uint32_t k = add_begin[r], e = add_begin[r + 1]; k < e; ++k) {
          const FactId g = add[k];
          if (level[g] == kNone) reach(g, time + 1);
        }
      }
      if (stop_ft == nfacts) break;  // fixpoint without the goals (done < 0)
      start_ft = stop_ft;
      start_ef = stop_ef;
    }
    num_facts_ = nfacts;
    num_active_ = nactive;
    num_touched_ = ntouched;
    num_node_touched_ = nnode_touched;
    return done;
  }

  void nextEpoch() {
    if (++epoch_ == 0) {
      std::fill(true_a_.begin(), true_a_.end(), 0);
      std::fill(true_b_.begin(), true_b_.end(), 0);
      std::fill(goal_mark_.begin(), goal_mark_.end(), 0);
      std::fill(op_used_.begin(), op_used_.end(), 0);
      std::fill(op_mark_.begin(), op_mark_.end(), 0);
      epoch_ = 1;
    }
  }
  uint64_t stamp(uint32_t t) const { return (static_cast<uint64_t>(epoch_) << 32) | t; }

  void addSubgoal(FactId f) {
    goal_mark_[f] = epoch_;
    goals_at_[level_[f]].push_back(f);
  }

  Cost extract(const uint64_t* s, const GoalConjunct& gc) {
    nextEpoch();
    const uint32_t max = max_level_;
    if (goals_at_.size() < max + 1) goals_at_.resize(max + 1);
    for (uint32_t t = 0; t <= max; ++t) goals_at_[t].clear();
    for (FactId f : gc.pos) {
      if (goal_mark_[f] != epoch_) addSubgoal(f);
    }
    Cost h = 0;
    plan_first_.clear();
    for (uint32_t time = max; time > 0; --time) {
      // goals_at_[time] does not grow while this layer is processed (sub-goals go below).
      for (size_t i = 0; i < goals_at_[time].size(); ++i) {
        const FactId g = goals_at_[time][i];
        if (isTrue(g, time)) continue;  // added by an achiever selected at this layer or above
        uint32_t best = kNone, best_member = kNone;
        OpId best_op = kNone;
        uint64_t best_d = UINT64_MAX;
        for (uint32_t k = R_.adders_begin[g]; k < R_.adders_begin[g + 1]; ++k) {
          const uint32_t r = R_.adders[k];
          if (rop_level_[r] != time - 1) continue;
          uint64_t d = 0;
          for (uint32_t p = R_.pre_begin[r]; p < R_.pre_begin[r + 1]; ++p) d += level_[R_.pre[p]];
          uint32_t m = kNone;
          if (R_.merged(r)) {  // the member (operator) whose differing fact is reached first
            m = easiestMember(r);
            d += level_[R_.members[m].first];
          }
          // Ties go to the lowest operator, as they would with the operators apart (adders are
          // in operator order; a merged rop stands at its first member's place).
          const OpId ro = m == kNone ? R_.op[r] : R_.members[m].second;
          if (d < best_d || (d == best_d && ro < best_op)) {
            best_d = d;
            best = r;
            best_member = m;
            best_op = ro;
          }
        }
        if (best == kNone) continue;  // cannot happen: g has level `time`
        const OpId o = best_member == kNone ? R_.op[best] : R_.members[best_member].second;
        if (op_used_[o] != epoch_) {  // an operator counts once per relaxed plan
          op_used_[o] = epoch_;
          ++h;
          if (time == 1) plan_first_.push_back(o);
        }
        // Sub-goals in precondition order (a merged rop: its concrete operator's, member included).
        const auto subgoal = [&](FactId q) {
          if (goal_mark_[q] != epoch_ && !isTrue(q, time - 1)) addSubgoal(q);
        };
        if (best_member == kNone) {
          for (uint32_t p = R_.pre_begin[best]; p < R_.pre_begin[best + 1]; ++p) subgoal(R_.pre[p]);
        } else {
          for (FactId q : task_.ops[o].pre) subgoal(q);
        }
        markTrue(best, time);
        for (uint32_t k = R_.implied_begin[best]; k < R_.implied_begin[best + 1]; ++k) markTrue(R_.implied[k], time);
      }
    }
    collectHelpful(s);
    return h;
  }

  /// Index (in R_.members) of the member of merged rop `r` whose fact has the lowest level
  /// (the first on ties; unreached facts have level kNone).
  uint32_t easiestMember(uint32_t r) const {
    uint32_t best = R_.member_begin[r];
    for (uint32_t i = best + 1; i < R_.member_begin[r + 1]; ++i) {
      if (level_[R_.members[i].first] < level_[R_.members[best].first]) best = i;
    }
    return best;
  }

  bool isTrue(FactId f, uint32_t t) const { return true_a_[f] == stamp(t) || true_b_[f] == stamp(t); }

  /// The add effects of an achiever selected at layer `time` count as true at `time` and
  /// `time - 1` (FF).
  void markTrue(uint32_t r, uint32_t time) {
    for (uint32_t k = R_.add_begin[r]; k < R_.add_begin[r + 1]; ++k) {
      true_a_[R_.add[k]] = stamp(time);
      true_b_[R_.add[k]] = stamp(time - 1);
    }
  }

  /// Helpful actions: first the relaxed plan's own layer-1 operators that are applicable (EHC
  /// tries helpful actions in order), then (unless `plan_preferred_`) every applicable operator
  /// that adds a layer-1 sub-goal (for a conditional effect: with its condition true).
  void collectHelpful(const uint64_t* s) {
    if (goals_at_.size() < 2) return;
    if (ff_style_ && !plan_preferred_) return collectHelpfulFF(s);
    for (OpId o : plan_first_) {
      if (op_mark_[o] == epoch_ || !task_.applicable(s, o)) continue;
      op_mark_[o] = epoch_;
      preferred_.push_back(o);
    }
    if (plan_preferred_) return;
    // The operators applicable in s that add g are those of g's adders at layer 0 (a merged
    // rop: its members whose own fact is true), taken in operator order as from
    // `task_.achievers[g]`, without testing each achiever's preconditions against s (hiking-16:
    // thousands of achievers per sub-goal, a few applicable).
    for (FactId g : goals_at_[1]) {
      layer0_.clear();
      for (uint32_t k = R_.adders_begin[g]; k < R_.adders_begin[g + 1]; ++k) {
        const uint32_t r = R_.adders[k];
        if (rop_level_[r] != 0) continue;
        if (!R_.merged(r)) {
          layer0_.push_back(R_.op[r]);
          continue;
        }
        for (uint32_t i = R_.member_begin[r]; i < R_.member_begin[r + 1]; ++i) {
          if (level_[R_.members[i].first] == 0) layer0_.push_back(R_.members[i].second);
        }
      }
      std::sort(layer0_.begin(), layer0_.end());
      for (OpId o : layer0_) {
        if (op_mark_[o] == epoch_) continue;
        op_mark_[o] = epoch_;
        preferred_.push_back(o);
      }
    }
  }

  /// FF-v2.3's helpful actions: operators with an effect at layer 0 (applicable, condition true)
  /// that adds a sub-goal of layer 1, ordered by the number of goals and sub-goals their layer-0
  /// effects delete (fewest first); among equals, those collected last come first.
  void collectHelpfulFF(const uint64_t* s) {
    cand_.clear();
    for (FactId g : goals_at_[1]) {
      // This sub-goal's candidates in operator order (as with the operators apart).
      const size_t batch = cand_.size();
      for (uint32_t k = R_.adders_begin[g]; k < R_.adders_begin[g + 1]; ++k) {
        const uint32_t r = R_.adders[k];
        if (rop_level_[r] != 0) continue;
        if (R_.merged(r)) {  // every member applicable in s
          for (uint32_t i = R_.member_begin[r]; i < R_.member_begin[r + 1]; ++i) {
            const OpId o = R_.members[i].second;
            if (level_[R_.members[i].first] != 0 || op_mark_[o] == epoch_) continue;
            op_mark_[o] = epoch_;
            cand_.push_back({0, o});
          }
          continue;
        }
        const OpId o = R_.op[r];
        if (op_mark_[o] == epoch_) continue;
        op_mark_[o] = epoch_;
        cand_.push_back({0, o});
      }
      std::sort(cand_.begin() + static_cast<std::ptrdiff_t>(batch), cand_.end(),
                [](const std::pair<uint32_t, OpId>& a, const std::pair<uint32_t, OpId>& b) { return a.second < b.second; });
    }
    for (auto& [d, o] : cand_) {
      const Operator& op = task_.ops[o];
      uint32_t n = 0;
      for (FactId f : op.del) n += goal_mark_[f] == epoch_ ? 1 : 0;
      for (const auto& ce : op.cond_effects) {
        if (ce.del.empty() || !holdsAll(s, ce.cond)) continue;
        for (FactId f : ce.del) n += goal_mark_[f] == epoch_ ? 1 : 0;
      }
      d = n;
    }
    std::reverse(cand_.begin(), cand_.end());
    std::stable_sort(cand_.begin(), cand_.end(),
                     [](const std::pair<uint32_t, OpId>& a, const std::pair<uint32_t, OpId>& b) { return a.first < b.first; });
    for (const auto& c : cand_) preferred_.push_back(c.second);
  }

  const Task& task_;
  Cost unit_;  ///< the cost every operator has (h counts operators)
  RelaxedOps R_;
  Goal goal_;
  GoalIndex goals_;
  std::vector<uint32_t> remaining_;
  uint32_t max_level_{0};
  // Graph (reset through the first num_* entries of facts_/active_/touched_).
  /// Unsatisfied preconditions of a rop next to their number in the base state (one cache line).
  struct Counter {
    uint32_t unsat, base;
  };
  std::vector<Counter> ctr_, node_ctr_;
  std::vector<uint8_t> group_done_;  ///< merged rop: a member fact was reached
  // The base state (see `moveBase`).
  bool incremental_{true};
  std::vector<uint64_t> base_;
  std::vector<uint32_t> zero_, zero_pos_;  ///< rops with base 0; rop -> its index there or kNone
  std::vector<uint32_t> member_true_;      ///< merged rop -> member facts true in the base state
  std::vector<uint32_t> level_, rop_level_;
  std::vector<FactId> facts_;
  std::vector<uint32_t> active_, touched_, node_touched_;
  size_t num_facts_{0}, num_active_{0}, num_touched_{0}, num_node_touched_{0};
  // Extraction (epoch-stamped).
  uint32_t epoch_{0};
  std::vector<uint64_t> true_a_, true_b_;
  std::vector<uint32_t> goal_mark_, op_mark_, op_used_;
  std::vector<std::pair<uint32_t, OpId>> cand_;
  bool ff_style_{false};
  bool plan_preferred_{false};  ///< setRelaxedPlanPreferred
  std::vector<OpId> plan_first_;
  std::vector<OpId> layer0_;       ///< collectHelpful(): a sub-goal's adders applicable in the state
  bool several_conjuncts_{false};  ///< the goal is a disjunction of conjuncts
  DeadEndMemo dead_ends_;
  std::vector<std::vector<FactId>> goals_at_;
  std::vector<OpId> preferred_;
};

// -------------------------------------------------------------------------------------------------
/// A min-heap of (cost, fact) with reused storage.
class FactHeap {
 public:
  void clear() { v_.clear(); }
  bool empty() const { return v_.empty(); }
  void push(Cost c, FactId f) {
    v_.push_back({c, f});
    std::push_heap(v_.begin(), v_.end(), cmp);
  }
  std::pair<Cost, FactId> pop() {
    std::pop_heap(v_.begin(), v_.end(), cmp);
    auto e = v_.back();
    v_.pop_back();
    return e;
  }

 private:
  static bool cmp(const std::pair<Cost, FactId>& a, const std::pair<Cost, FactId>& b) { return a.first > b.first; }
  std::vector<std::pair<Cost, FactId>> v_;
};

/// Cost-based relaxed exploration (generalised Dijkstra over facts, as Fast Downward's relaxation
/// heuristics): h_max, h_add, and h_FF with a relaxed plan through the h_add best supporters (for
/// tasks whose operators differ in cost).
class RelaxationHeuristic : public Heuristic {
 public:
  enum class Mode { kMax, kAdd, kFF };

  RelaxationHeuristic(const Task& task, CostType ct, Mode mode) : task_(task), mode_(mode) {
    const size_t nf = task.numFacts();
    R_.build(task, ct, /*implied=*/false);
    for (OpId o = 0; o < task.ops.size(); ++o) op_cost_.push_back(adjustedCost(task.ops[o], ct, task.unit_cost));
    fact_cost_.assign(nf, kInf);
    supporter_.assign(nf, UINT32_MAX);
    unsat_.resize(R_.size());
    rop_cost_.resize(R_.size());
    goal_stamp_.assign(nf, 0);
    fact_mark_.assign(nf, 0);
    op_mark_.assign(task.ops.size(), 0);
  }

  void setGoal(const Goal& goal) override {
    goal_ = goal;
    dead_ends_.clear(task_.numWords());
    // Goal facts: a counter per conjunct for early termination.
    goal_of_.assign(task_.numFacts(), {});
    for (uint32_t c = 0; c < goal_.conjuncts.size(); ++c) {
      for (FactId f : goal_.conjuncts[c].pos) goal_of_[f].push_back(c);
    }
  }

  bool computesPreferred() const override { return mode_ == Mode::kFF; }
  bool setRelaxedPlanPreferred(bool on) override {
    if (mode_ != Mode::kFF) return false;
    plan_preferred_ = on;
    return true;
  }
  const std::vector<OpId>& preferred() const override { return preferred_; }

  Cost evaluate(const uint64_t* s) override {
    preferred_.clear();
    if (goal_.conjuncts.empty()) return kInf;
    if (task_.goalReached(s, goal_)) return 0;
    if (dead_ends_.covers(s)) return kInf;
    explore(s);
    // Best conjunct.
    Cost best = kInf;
    int best_c = -1;
    for (uint32_t c = 0; c < goal_.conjuncts.size(); ++c) {
      Cost v = 0;
      for (FactId f : goal_.conjuncts[c].pos) {
        const Cost fc = fact_cost_[f];
        if (fc == kInf) {
          v = kInf;
          break;
        }
        v = mode_ == Mode::kMax ? std::max(v, fc) : v + fc;
      }
      if (v < best) {
        best = v;
        best_c = static_cast<int>(c);
      }
    }
    if (best == kInf) {  // the exploration ran to its fixpoint: the facts reached are the closure
      reached_.clear();
      for (FactId f = 0; f < fact_cost_.size(); ++f) {
        if (fact_cost_[f] != kInf) reached_.push_back(f);
      }
      dead_ends_.add(reached_.size(), [this](size_t i) { return reached_[i]; });
      return kInf;
    }
    if (mode_ != Mode::kFF) return best;
    return extract(s, goal_.conjuncts[static_cast<size_t>(best_c)]);
  }

 private:
  void explore(const uint64_t* s) {
    const size_t nf = task_.numFacts();
    std::fill(fact_cost_.begin(), fact_cost_.end(), kInf);
    std::copy(R_.count.begin(), R_.count.end(), unsat_.begin());
    std::fill(rop_cost_.begin(), rop_cost_.end(), 0);
    heap_.clear();
    ++stamp_;
    remaining_.assign(goal_.conjuncts.size(), 0);
    for (uint32_t c = 0; c < goal_.conjuncts.size(); ++c) remaining_[c] = static_cast<uint32_t>(goal_.conjuncts[c].pos.size());
    const size_t words = task_.numWords();
    forEachTrueFact(s, words, nf, [&](FactId f) {
      fact_cost_[f] = 0;
      supporter_[f] = UINT32_MAX;
      heap_.push(0, f);
    });
    for (uint32_t r : R_.no_pre) fire(r, 0);
    while (!heap_.empty()) {
      auto [c, f] = heap_.pop();
      if (c > fact_cost_[f]) continue;
      if (goal_stamp_[f] == stamp_) continue;  // already settled (duplicate entry, same cost)
      goal_stamp_[f] = stamp_;
      bool done = false;
      for (uint32_t gc : goal_of_[f]) {
        if (--remaining_[gc] == 0) done = true;
      }
      if (done) break;
      for (uint32_t i = R_.pre_of_begin[f]; i < R_.pre_of_begin[f + 1]; ++i) {
        const uint32_t r = R_.pre_of[i];
        if (mode_ == Mode::kMax) {
          rop_cost_[r] = std::max(rop_cost_[r], c);
        } else {
          rop_cost_[r] += c;
        }
        if (--unsat_[r] == 0) fire(r, rop_cost_[r]);
      }
    }
  }

  void fire(uint32_t r, Cost pre_cost) {
    const Cost nc = pre_cost + R_.cost[r];
    for (uint32_t i = R_.add_begin[r]; i < R_.add_begin[r + 1]; ++i) {
      const FactId g = R_.add[i];
      if (nc < fact_cost_[g]) {
        fact_cost_[g] = nc;
        supporter_[g] = r;
        heap_.push(nc, g);
      }
    }
  }

  Cost extract(const uint64_t* s, const GoalConjunct& gc) {
    ++mark_;
    if (mark_ == 0) {
      std::fill(fact_mark_.begin(), fact_mark_.end(), 0);
      std::fill(op_mark_.begin(), op_mark_.end(), 0);
      mark_ = 1;
    }
    Cost h = 0;
    stack_.clear();
    g1_.clear();
    for (FactId f : gc.pos) stack_.push_back(f);
    while (!stack_.empty()) {
      const FactId f = stack_.back();
      stack_.pop_back();
      if (fact_mark_[f] == mark_ || testBit(s, f)) continue;
      fact_mark_[f] = mark_;
      const uint32_t r = supporter_[f];
      if (r == UINT32_MAX) continue;  // cannot happen for reached facts
      const OpId o = R_.op[r];
      if (op_mark_[o] != mark_) {
        op_mark_[o] = mark_;
        h += op_cost_[o];
      }
      bool first_layer = true;
      for (uint32_t i = R_.pre_begin[r]; i < R_.pre_begin[r + 1]; ++i) {
        const FactId p = R_.pre[i];
        if (!testBit(s, p)) {
          first_layer = false;
          stack_.push_back(p);
        }
      }
      if (first_layer) g1_.push_back(f);
    }
    // Helpful actions (FF): applicable operators that add a first-layer sub-goal.
    collectHelpful(s);
    return h;
  }

  void collectHelpful(const uint64_t* s) {
    ++pref_mark_;
    if (pref_mark_ == 0 || pref_stamp_.size() != task_.ops.size()) {
      pref_stamp_.assign(task_.ops.size(), 0);
      pref_mark_ = 1;
    }
    if (plan_preferred_) return collectPlanOperators();
    for (FactId g : g1_) {
      for (OpId o : task_.achievers[g]) {
        if (pref_stamp_[o] == pref_mark_) continue;
        if (!task_.applicable(s, o) || !addsIn(s, o, g)) continue;
        pref_stamp_[o] = pref_mark_;
        preferred_.push_back(o);
      }
    }
  }

  /// The relaxed plan's first-layer operators: the best supporters of the first-layer sub-goals
  /// (their preconditions, a conditional effect's condition included, hold in the state).
  void collectPlanOperators() {
    for (FactId g : g1_) {
      const OpId o = R_.op[supporter_[g]];
      if (pref_stamp_[o] == pref_mark_) continue;
      pref_stamp_[o] = pref_mark_;
      preferred_.push_back(o);
    }
  }

  bool addsIn(const uint64_t* s, OpId o, FactId g) const {
    const Operator& op = task_.ops[o];
    if (std::binary_search(op.add.begin(), op.add.end(), g)) return true;
    for (const auto& ce : op.cond_effects) {
      if (!std::binary_search(ce.add.begin(), ce.add.end(), g)) continue;
      bool ok = true;
      for (FactId f : ce.cond) ok = ok && testBit(s, f);
      if (ok) return true;
    }
    return false;
  }

  const Task& task_;
  Mode mode_;
  Goal goal_;
  std::vector<std::vector<uint32_t>> goal_of_;
  std::vector<uint32_t> remaining_;
  RelaxedOps R_;
  std::vector<Cost> op_cost_;
  // Per evaluation.
  std::vector<Cost> fact_cost_, rop_cost_;
  std::vector<uint32_t> supporter_, unsat_;
  std::vector<uint32_t> goal_stamp_;
  uint32_t stamp_{0};
  FactHeap heap_;
  std::vector<uint32_t> fact_mark_, op_mark_, pref_stamp_;
  uint32_t mark_{0}, pref_mark_{0};
  std::vector<FactId> stack_, g1_;
  std::vector<OpId> preferred_;
  bool plan_preferred_{false};  ///< setRelaxedPlanPreferred
  DeadEndMemo dead_ends_;
  std::vector<FactId> reached_;
};

class BlindHeuristic : public Heuristic {
 public:
  explicit BlindHeuristic(const Task& task) : task_(task) {}
  void setGoal(const Goal& g) override { goal_ = g; }
  Cost evaluate(const uint64_t* s) override {
    if (goal_.conjuncts.empty()) return kDeadEnd;
    return task_.goalReached(s, goal_) ? 0 : 1;
  }

 private:
  const Task& task_;
  Goal goal_;
};

/// The cost every operator has under `ct` when they all have the same positive one, else 0.
Cost uniformCost(const Task& task, CostType ct) {
  if (ct == CostType::kUnit || task.unit_cost || task.ops.empty()) return 1;
  const Cost c = adjustedCost(task.ops[0], ct, task.unit_cost);
  for (const auto& op : task.ops) {
    if (adjustedCost(op, ct, task.unit_cost) != c) return 0;
  }
  return c;
}

}  // namespace

std::unique_ptr<Heuristic> makeHeuristic(HeuristicKind kind, const Task& task, CostType cost_type) {
  switch (kind) {
    case HeuristicKind::kFF: {
      // FF's layered graph when every operator costs the same (h scaled by that cost), the
      // cost-based relaxed plan otherwise.
      if (const Cost c = uniformCost(task, cost_type); c > 0) {
        return std::make_unique<LayeredFF>(task, cost_type, c, /*factor=*/true);
      }
      return std::make_unique<RelaxationHeuristic>(task, cost_type, RelaxationHeuristic::Mode::kFF);
    }
    case HeuristicKind::kFFHadd:
      return std::make_unique<RelaxationHeuristic>(task, cost_type, RelaxationHeuristic::Mode::kFF);
    case HeuristicKind::kAdd: return std::make_unique<RelaxationHeuristic>(task, cost_type, RelaxationHeuristic::Mode::kAdd);
    case HeuristicKind::kMax: return std::make_unique<RelaxationHeuristic>(task, cost_type, RelaxationHeuristic::Mode::kMax);
    case HeuristicKind::kBlind: return std::make_unique<BlindHeuristic>(task);
  }
  throw std::invalid_argument("makeHeuristic: unknown heuristic kind " + std::to_string(static_cast<int>(kind)));
}

namespace detail {
std::unique_ptr<Heuristic> makeLayeredFF(const Task& task, CostType cost_type, bool factor) {
  const Cost c = uniformCost(task, cost_type);
  if (c <= 0) throw std::invalid_argument("makeLayeredFF: the operators differ in cost under this cost type");
  return std::make_unique<LayeredFF>(task, cost_type, c, factor);
}
}  // namespace detail

}  // namespace tamp::symbolic_planner
