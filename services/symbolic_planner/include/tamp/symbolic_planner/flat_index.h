#pragma once
/// @file
/// Small flat containers for grounding and the construction of h_FF (issue 14, twelfth round).
///
/// The profile of `tamp plan` on small IPC tasks (grid, mprime, mystery, trucks: 5-100 ms per
/// run) spent a large share in node-based `std::unordered_map`s (allocation per node, rehashing)
/// and in per-call vectors. These replace them where the key space is dense or the map is
/// insert-only:
/// - `U64IdMap`: an insert-only open-addressing map from 64-bit keys to 32-bit ids (linear
///   probing, power-of-two table, load <= 1/2). Same answers as `std::unordered_map::try_emplace`
///   on the same sequence of calls.
/// - `ArgIndex`: per (predicate, argument position, object) the list of atom ids with that object
///   there, in insertion order, in one flat array of slots (no hashing: the key is dense).
/// Both are internal to the planner library; they are in a public header only for their tests.

#include <cstddef>
#include <cstdint>
#include <utility>
#include <vector>

namespace tamp::symbolic_planner {

/// Insert-only hash map uint64 -> uint32 with open addressing (linear probing).
class U64IdMap {
 public:
  /// `expected`: number of keys expected (sizes the table; it grows beyond that as needed).
  explicit U64IdMap(size_t expected = 0) { reserve(expected); }

  /// Reserves room for `n` keys without growing.
  void reserve(size_t n) {
    size_t cap = 16;
    while (cap < 2 * n) cap *= 2;
    if (cap > keys_.size()) rehash(cap);
  }

  /// Inserts (key, id) when `key` is absent; returns the stored id and whether it was inserted
  /// (as `std::unordered_map::try_emplace(key, id)`).
  std::pair<uint32_t, bool> tryEmplace(uint64_t key, uint32_t id) {
    if ((size_ + 1) * 2 > keys_.size()) rehash(keys_.size() * 2);
    size_t i = slot(key);
    while (used_[i]) {
      if (keys_[i] == key) return {ids_[i], false};
      i = (i + 1) & (keys_.size() - 1);
    }
    used_[i] = 1;
    keys_[i] = key;
    ids_[i] = id;
    ++size_;
    return {id, true};
  }

  /// The id of `key`, or `absent` when it is not in the map.
  uint32_t find(uint64_t key, uint32_t absent = UINT32_MAX) const {
    size_t i = slot(key);
    while (used_[i]) {
      if (keys_[i] == key) return ids_[i];
      i = (i + 1) & (keys_.size() - 1);
    }
    return absent;
  }

  size_t size() const { return size_; }
  size_t capacity() const { return keys_.size(); }

 private:
  size_t slot(uint64_t key) const {
    uint64_t h = key * 0x9E3779B97F4A7C15ULL;  // Fibonacci hashing: the high bits are mixed best
    h ^= h >> 32;
    return static_cast<size_t>(h) & (keys_.size() - 1);
  }
  void rehash(size_t cap) {
    std::vector<uint64_t> keys(cap);
    std::vector<uint32_t> ids(cap);
    std::vector<uint8_t> used(cap, 0);
    keys_.swap(keys);
    ids_.swap(ids);
    used_.swap(used);
    for (size_t j = 0; j < keys.size(); ++j) {
      if (!used[j]) continue;
      size_t i = slot(keys[j]);
      while (used_[i]) i = (i + 1) & (keys_.size() - 1);
      used_[i] = 1;
      keys_[i] = keys[j];
      ids_[i] = ids[j];
    }
  }
  std::vector<uint64_t> keys_;
  std::vector<uint32_t> ids_;
  std::vector<uint8_t> used_;
  size_t size_{0};
};

/// Atom ids by (predicate, argument position, object): per (predicate, position) a flat array
/// indexed by the object id, grown to the largest object added there (so memory follows the atoms,
/// not predicates x objects); no hashing, the key is dense.
class ArgIndex {
 public:
  ArgIndex() = default;
  /// `arity[p]`: arity of predicate p.
  explicit ArgIndex(const std::vector<uint32_t>& arity) {
    pred_first_.reserve(arity.size() + 1);
    size_t n = 0;
    for (uint32_t a : arity) {
      pred_first_.push_back(n);
      n += a;
    }
    pred_first_.push_back(n);
    columns_.resize(n);
  }

  /// Appends `atom` to the list of (pred, pos, obj). Precondition: pos < arity of pred.
  void add(uint32_t pred, uint32_t pos, uint32_t obj, uint32_t atom) {
    auto& col = columns_[pred_first_[pred] + pos];
    if (obj >= col.size()) col.resize(size_t{obj} + 1);
    col[obj].push_back(atom);
  }
  /// The atoms with `obj` at position `pos` of `pred`, in the order they were added (empty when
  /// there are none). Precondition: pos < arity of pred.
  const std::vector<uint32_t>& get(uint32_t pred, uint32_t pos, uint32_t obj) const {
    const auto& col = columns_[pred_first_[pred] + pos];
    return obj < col.size() ? col[obj] : empty_;
  }

 private:
  std::vector<size_t> pred_first_;
  std::vector<std::vector<std::vector<uint32_t>>> columns_;  // (pred, pos) -> object -> atoms
  std::vector<uint32_t> empty_;
};

/// Ground atom ids by their arguments, without hashing: for each predicate whose argument tuples
/// are few enough (num_objects ^ arity <= the caps), a flat array indexed by the tuple
/// (mixed radix over the object ids) holding the atom id or -1. Predicates over the caps are
/// "not dense": find() answers kNotDense and the caller looks the atom up in its hash table.
class DenseAtomIndex {
 public:
  static constexpr int64_t kNotDense = -2;

  DenseAtomIndex() = default;
  /// `arity[p]`: arity of predicate p; objects are 0 .. num_objects - 1. A predicate is dense when
  /// its tuples number at most `max_per_predicate` and all dense predicates together at most
  /// `max_total` (predicates in id order, first come first served).
  DenseAtomIndex(const std::vector<uint32_t>& arity, uint32_t num_objects, size_t max_per_predicate,
                 size_t max_total)
      : num_objects_(num_objects) {
    offset_.assign(arity.size(), kNone);
    size_t total = 0;
    for (size_t p = 0; p < arity.size(); ++p) {
      size_t n = 1;
      bool small = true;
      for (uint32_t i = 0; i < arity[p] && small; ++i) {
        small = num_objects == 0 || n <= max_per_predicate / num_objects;
        n *= num_objects;
      }
      if (!small || n > max_per_predicate || total + n > max_total) continue;
      offset_[p] = total;
      total += n;
    }
    slots_.assign(total, -1);
  }

  bool isDense(uint32_t pred) const { return pred < offset_.size() && offset_[pred] != kNone; }
  /// `key` = [pred, args...] with `n` - 1 = arity of pred and every arg < num_objects: the atom's
  /// id, -1 when it has none, kNotDense when pred is not dense.
  int64_t find(const uint32_t* key, uint32_t n) const {
    const size_t off = key[0] < offset_.size() ? offset_[key[0]] : kNone;
    if (off == kNone) return kNotDense;
    return slots_[off + tuple(key, n)];
  }
  /// Records `id` for `key` (ignored when pred is not dense). Same preconditions as find().
  void set(const uint32_t* key, uint32_t n, uint32_t id) {
    const size_t off = key[0] < offset_.size() ? offset_[key[0]] : kNone;
    if (off != kNone) slots_[off + tuple(key, n)] = static_cast<int32_t>(id);
  }
  size_t numSlots() const { return slots_.size(); }

 private:
  static constexpr size_t kNone = SIZE_MAX;
  size_t tuple(const uint32_t* key, uint32_t n) const {
    size_t t = 0;
    for (uint32_t i = 1; i < n; ++i) t = t * num_objects_ + key[i];
    return t;
  }
  uint32_t num_objects_{0};
  std::vector<size_t> offset_;
  std::vector<int32_t> slots_;
};

}  // namespace tamp::symbolic_planner
