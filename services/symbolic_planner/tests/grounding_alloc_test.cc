// Issue 14, thirteenth round: task construction allocates a bounded number of times per ground
// operator (its name, precondition and effects once each), and the rewrite that made it so keeps
// the operators. A binary of its own: it replaces the global operator new to count allocations.
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <cstdio>
#include <cstdlib>
#include <new>
#include <string>

#include "tamp/symbolic_planner/grounding.h"

namespace {
std::atomic<uint64_t> g_allocations{0};

void* countedAlloc(std::size_t n) {
  g_allocations.fetch_add(1, std::memory_order_relaxed);
  if (void* p = std::malloc(n == 0 ? 1 : n)) return p;
  throw std::bad_alloc();
}
}  // namespace

void* operator new(std::size_t n) { return countedAlloc(n); }
void* operator new[](std::size_t n) { return countedAlloc(n); }
void* operator new(std::size_t n, const std::nothrow_t&) noexcept {
  g_allocations.fetch_add(1, std::memory_order_relaxed);
  return std::malloc(n == 0 ? 1 : n);
}
void* operator new[](std::size_t n, const std::nothrow_t&) noexcept {
  g_allocations.fetch_add(1, std::memory_order_relaxed);
  return std::malloc(n == 0 ? 1 : n);
}
void operator delete(void* p) noexcept { std::free(p); }
void operator delete[](void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t) noexcept { std::free(p); }
void operator delete(void* p, const std::nothrow_t&) noexcept { std::free(p); }
void operator delete[](void* p, const std::nothrow_t&) noexcept { std::free(p); }

namespace tamp::symbolic_planner {
namespace {

/// A STRIPS task whose operator names are longer than the short-string buffer: `kPlaces` places
/// with long names, every pair connected (static), one robot moving and marking places.
constexpr int kPlaces = 24;
std::string domain() {
  return R"((define (domain tour)
  (:requirements :strips :typing)
  (:types robot place)
  (:predicates (at ?r - robot ?p - place) (connected ?a ?b - place) (visited ?p - place)
               (clear ?p - place))
  (:action move
    :parameters (?r - robot ?from ?to - place)
    :precondition (and (at ?r ?from) (connected ?from ?to) (clear ?to))
    :effect (and (at ?r ?to) (visited ?to) (clear ?from) (not (at ?r ?from)) (not (clear ?to))
                 (not (visited ?to))))))";
}
std::string place(int i) { return "a-place-with-a-rather-long-name-" + std::to_string(i); }
std::string problem() {
  std::string objects, init;
  for (int i = 0; i < kPlaces; ++i) {
    objects += " " + place(i);
    if (i > 0) init += " (clear " + place(i) + ")";
    for (int j = 0; j < kPlaces; ++j) {
      if (i != j) init += " (connected " + place(i) + " " + place(j) + ")";
    }
  }
  return "(define (problem t) (:domain tour) (:objects the-robot-with-a-long-name - robot" +
         objects + " - place) (:init (at the-robot-with-a-long-name " + place(0) + ")" + init +
         ") (:goal (visited " + place(kPlaces - 1) + ")))";
}

TEST(GroundingAllocations, TaskConstructionAllocatesAFewTimesPerOperator) {
  auto d = pddl::parseDomain(domain());
  ASSERT_TRUE(d.ok()) << d.error().toString();
  auto p = pddl::parseProblem(problem(), *d);
  ASSERT_TRUE(p.ok()) << p.error().toString();
  auto g = Grounder::create(*d, *p);
  ASSERT_TRUE(g.ok()) << g.error().toString();
  std::vector<AtomId> init;
  for (const auto& a : p->init) init.push_back(*(*g)->atomId(a));
  ASSERT_TRUE((*g)->extend(init, Termination()).ok());
  auto neg = (*g)->negatedAtoms(p->goal);
  ASSERT_TRUE(neg.ok());

  const uint64_t before = g_allocations.load();
  auto t = (*g)->buildTask(init, *neg, false, Termination());
  const uint64_t allocations = g_allocations.load() - before;
  ASSERT_TRUE(t.ok()) << t.error().toString();
  const Task& task = **t;
  ASSERT_EQ(task.ops.size(), static_cast<size_t>(kPlaces * (kPlaces - 1)));

  // The operators themselves: add wins over delete ((visited ?to) is both), sorted facts.
  const auto fact = [&](const std::string& name) {
    for (FactId f = 0; f < task.numFacts(); ++f) {
      if (task.fact_names[f] == name) return static_cast<int64_t>(f);
    }
    return int64_t{-1};
  };
  const Operator& op = task.ops.front();
  EXPECT_EQ(op.name.rfind("(move the-robot-with-a-long-name " + place(0) + " ", 0), 0u) << op.name;
  ASSERT_EQ(op.add.size(), 3u);
  ASSERT_EQ(op.del.size(), 2u);
  EXPECT_TRUE(std::is_sorted(op.add.begin(), op.add.end()));
  EXPECT_TRUE(std::is_sorted(op.del.begin(), op.del.end()));
  EXPECT_TRUE(std::is_sorted(op.pre.begin(), op.pre.end()));
  const std::string to =
      op.name.substr(op.name.rfind(' ') + 1, op.name.size() - op.name.rfind(' ') - 2);
  const int64_t visited = fact("(visited " + to + ")");
  ASSERT_GE(visited, 0);
  EXPECT_TRUE(std::binary_search(op.add.begin(), op.add.end(), static_cast<FactId>(visited)));
  EXPECT_FALSE(std::binary_search(op.del.begin(), op.del.end(), static_cast<FactId>(visited)));

  // Name, precondition, adds, deletes: one allocation each, plus the tables of the task and a
  // few grown vectors (the operator list); before this round it was about 3 times as many.
  const double per_op = static_cast<double>(allocations) / static_cast<double>(task.ops.size());
  EXPECT_LE(per_op, 6.0) << allocations << " allocations for " << task.ops.size() << " operators";
  std::printf("[ info ] %.2f allocations per operator (%llu for %zu)\n", per_op,
              static_cast<unsigned long long>(allocations), task.ops.size());
}

}  // namespace
}  // namespace tamp::symbolic_planner
