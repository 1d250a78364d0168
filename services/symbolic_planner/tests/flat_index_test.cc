// The flat containers of grounding and h_FF's construction (flat_index.h): the same answers as
// the standard containers they replace, on fixed-seed random sequences and adversarial keys.
#include "tamp/symbolic_planner/flat_index.h"

#include <gtest/gtest.h>

#include <map>
#include <random>
#include <tuple>
#include <unordered_map>
#include <vector>

namespace tamp::symbolic_planner {
namespace {

TEST(U64IdMap, AgreesWithUnorderedMapTryEmplace) {
  std::mt19937_64 rng(14);
  for (size_t expected : {size_t{0}, size_t{1}, size_t{1000}}) {
    U64IdMap m(expected);
    std::unordered_map<uint64_t, uint32_t> ref;
    for (uint32_t i = 0; i < 20000; ++i) {
      // Few distinct keys in a narrow range (many repeats), some spread over 64 bits.
      const uint64_t key = (i % 3 == 0) ? rng() : rng() % 5000;
      const auto [id, inserted] = m.tryEmplace(key, i);
      const auto [it, ref_inserted] = ref.try_emplace(key, i);
      ASSERT_EQ(inserted, ref_inserted) << "key " << key;
      ASSERT_EQ(id, it->second) << "key " << key;
    }
    EXPECT_EQ(m.size(), ref.size());
    EXPECT_LE(2 * m.size(), m.capacity());  // load at most 1/2
    for (const auto& [k, v] : ref) EXPECT_EQ(m.find(k), v);
    EXPECT_EQ(m.find(uint64_t{1} << 63, 7U), 7U);  // absent (not drawn from rng % 5000)
  }
}

TEST(U64IdMap, KeysThatShareTheirLowOrHighBitsAndTheExtremes) {
  U64IdMap m;
  std::vector<uint64_t> keys = {0, UINT64_MAX, UINT64_MAX - 1, uint64_t{1} << 63};
  for (uint64_t i = 1; i < 512; ++i) keys.push_back(i << 40);      // equal low bits
  for (uint64_t i = 1; i < 512; ++i) keys.push_back(i);            // equal high bits
  for (uint64_t i = 1; i < 512; ++i) keys.push_back(i * 0x10000);  // strided
  std::map<uint64_t, uint32_t> ref;
  for (uint32_t i = 0; i < keys.size(); ++i) {
    const auto [id, inserted] = m.tryEmplace(keys[i], i);
    const auto [it, ref_inserted] = ref.try_emplace(keys[i], i);
    EXPECT_EQ(inserted, ref_inserted);
    EXPECT_EQ(id, it->second);
  }
  EXPECT_EQ(m.size(), ref.size());
  for (const auto& [k, v] : ref) EXPECT_EQ(m.find(k), v) << k;
  // A second insertion of every key finds the first id.
  for (const auto& [k, v] : ref) EXPECT_EQ(m.tryEmplace(k, 999999).first, v);
  EXPECT_EQ(m.size(), ref.size());
}

TEST(ArgIndex, ListsInInsertionOrderAndEmptyBeyondTheObjectsSeen) {
  const std::vector<uint32_t> arity = {0, 2, 3, 1};
  ArgIndex idx(arity);
  std::map<std::tuple<uint32_t, uint32_t, uint32_t>, std::vector<uint32_t>> ref;
  std::mt19937 rng(14);
  for (uint32_t atom = 0; atom < 5000; ++atom) {
    uint32_t pred = 1 + rng() % 3;
    const uint32_t pos = rng() % arity[pred];
    const uint32_t obj =
        (atom % 7 == 0) ? 1000 + rng() % 100 : rng() % 20;  // sparse and dense objects
    idx.add(pred, pos, obj, atom);
    ref[{pred, pos, obj}].push_back(atom);
  }
  for (uint32_t pred = 1; pred < arity.size(); ++pred) {
    for (uint32_t pos = 0; pos < arity[pred]; ++pos) {
      for (uint32_t obj = 0; obj < 1200; ++obj) {
        auto it = ref.find({pred, pos, obj});
        const std::vector<uint32_t> want = it == ref.end() ? std::vector<uint32_t>{} : it->second;
        ASSERT_EQ(idx.get(pred, pos, obj), want) << pred << " " << pos << " " << obj;
      }
    }
  }
  EXPECT_TRUE(idx.get(3, 0, UINT32_MAX).empty());  // never seen: empty, not out of bounds
}

TEST(DenseAtomIndex, FindsWhatWasSetAndSaysWhichPredicatesItDoesNotHold) {
  // Predicates: arity 0, 1, 2, 3 over 10 objects (1, 10, 100, 1000 tuples). Caps: 100 per
  // predicate, 105 in all: p0 (1) and p1 (10) fit, p2 (100) does not fit beside them (111 > 105),
  // p3 is over the per-predicate cap.
  DenseAtomIndex idx({0, 1, 2, 3}, 10, 100, 105);
  EXPECT_TRUE(idx.isDense(0));
  EXPECT_TRUE(idx.isDense(1));
  EXPECT_FALSE(idx.isDense(2));
  EXPECT_FALSE(idx.isDense(3));
  EXPECT_FALSE(idx.isDense(4));  // no such predicate
  EXPECT_EQ(idx.numSlots(), 11U);
  const uint32_t k0[] = {0};
  const uint32_t k1a[] = {1, 0}, k1b[] = {1, 9};
  const uint32_t k2[] = {2, 3, 4}, k3[] = {3, 1, 2, 3};
  EXPECT_EQ(idx.find(k0, 1), -1);
  EXPECT_EQ(idx.find(k1b, 2), -1);
  idx.set(k0, 1, 7);
  idx.set(k1b, 2, 12345);
  idx.set(k2, 3, 5);  // not dense: ignored
  EXPECT_EQ(idx.find(k0, 1), 7);
  EXPECT_EQ(idx.find(k1a, 2), -1);
  EXPECT_EQ(idx.find(k1b, 2), 12345);
  EXPECT_EQ(idx.find(k2, 3), DenseAtomIndex::kNotDense);
  EXPECT_EQ(idx.find(k3, 4), DenseAtomIndex::kNotDense);

  // Every tuple of a dense binary predicate maps to its own slot.
  DenseAtomIndex all({2}, 37, 1 << 20, 1 << 20);
  ASSERT_TRUE(all.isDense(0));
  uint32_t id = 0;
  for (uint32_t a = 0; a < 37; ++a) {
    for (uint32_t b = 0; b < 37; ++b) {
      const uint32_t k[] = {0, a, b};
      all.set(k, 3, id++);
    }
  }
  id = 0;
  for (uint32_t a = 0; a < 37; ++a) {
    for (uint32_t b = 0; b < 37; ++b) {
      const uint32_t k[] = {0, a, b};
      ASSERT_EQ(all.find(k, 3), id++) << a << " " << b;
    }
  }
  // No objects: only arity 0 has a tuple.
  DenseAtomIndex none({0, 2}, 0, 100, 100);
  EXPECT_TRUE(none.isDense(0));
  EXPECT_EQ(none.numSlots(), 1U);
}

}  // namespace
}  // namespace tamp::symbolic_planner
