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
  for (uint64_t i = 1; i < 512; ++i) keys.push_back(i << 40);     // equal low bits
  for (uint64_t i = 1; i < 512; ++i) keys.push_back(i);           // equal high bits
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
    const uint32_t obj = (atom % 7 == 0) ? 1000 + rng() % 100 : rng() % 20;  // sparse and dense objects
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

}  // namespace
}  // namespace tamp::symbolic_planner
