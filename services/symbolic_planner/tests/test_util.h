#pragma once
// Shared helpers for the symbolic planner tests.
#include <gtest/gtest.h>

#include <filesystem>
#include <string>

#include "tamp/core/paths.h"
#include "tamp/symbolic_planner/planner.h"

namespace tamp::symbolic_planner::test {

inline std::string readFile(const std::filesystem::path& p) {
  auto t = readTextFile(p);
  if (!t) ADD_FAILURE() << t.error().toString();
  return t ? *t : std::string();
}

inline std::filesystem::path sourceDir() { return TAMP_SOURCE_DIR; }
/// tests/data/benchmarks of the source tree (IPC sets pddl/, pddl-adl/, ...).
inline std::filesystem::path benchmarksDir() { return TAMP_BENCHMARKS_DIR; }

/// A small ADL domain with every feature of the fragment: typing with either, constants,
/// negative preconditions, equality, disjunction, quantifiers, conditional effects, costs.
inline const char* kAdlDomain = R"(
(define (domain rooms)
  (:requirements :adl :action-costs)
  (:types room item - object box ball - item)
  (:constants hall - room)
  (:predicates (at-robot ?r - room) (at ?i - item ?r - room) (holding ?i - item)
               (connected ?a ?b - room) (locked ?r - room) (handempty) (lit ?r - room))
  (:functions (total-cost) - number (dist ?a ?b - room) - number)
  (:action move
    :parameters (?from ?to - room)
    :precondition (and (at-robot ?from) (or (connected ?from ?to) (connected ?to ?from))
                       (not (locked ?to)) (not (= ?from ?to)))
    :effect (and (not (at-robot ?from)) (at-robot ?to)
                 (forall (?i - item) (when (holding ?i) (and (not (at ?i ?from)) (at ?i ?to))))
                 (increase (total-cost) (dist ?from ?to))))
  (:action pick
    :parameters (?i - (either box ball) ?r - room)
    :precondition (and (at-robot ?r) (at ?i ?r) (handempty))
    :effect (and (holding ?i) (not (handempty)) (increase (total-cost) 1)))
  (:action drop
    :parameters (?i - item ?r - room)
    :precondition (and (at-robot ?r) (holding ?i))
    :effect (and (not (holding ?i)) (handempty) (increase (total-cost) 1)))
  (:action unlock
    :parameters (?r - room)
    :precondition (and (locked ?r) (exists (?x - room) (and (at-robot ?x) (connected ?x ?r)))
                       (forall (?i - item) (not (holding ?i))))
    :effect (and (not (locked ?r)) (increase (total-cost) 5)))
  (:action light-all
    :parameters ()
    :precondition (at-robot hall)
    :effect (forall (?r - room) (when (not (locked ?r)) (lit ?r)))))
)";

inline const char* kAdlProblem = R"(
(define (problem rooms-1)
  (:domain rooms)
  (:objects kitchen store - room b1 - box ball1 - ball)
  (:init (at-robot hall) (handempty) (at b1 hall) (at ball1 kitchen)
         (connected hall kitchen) (connected kitchen store) (locked store)
         (= (dist hall kitchen) 2) (= (dist kitchen hall) 2) (= (dist kitchen store) 3)
         (= (dist store kitchen) 3) (= (total-cost) 0))
  (:goal (and (at b1 store) (at ball1 hall) (handempty) (not (locked store))))
  (:metric minimize (total-cost)))
)";

/// Parses, plans and checks; returns the reply.
inline PlanReply planText(const std::string& domain, const std::string& problem, SearchAlgorithm alg,
                          double timeout = 60.0) {
  PlanRequest req;
  req.domain_text = domain;
  req.problem_text = problem;
  req.search.algorithm = alg;
  req.timeout_seconds = timeout;
  req.check_plan = true;
  return plan(req, Termination());
}

/// A vehicle on one-way roads that turn it round: from a it may enter b facing north, and from b
/// only c, where it faces south; the road b -> g needs it facing south at b, which it never is.
/// The delete relaxation sees a way to g from b; h^2 does not ((at b) and (facing south) never
/// hold together). The way is a -> d -> e -> f -> g.
inline const char* kOneWayDomain = R"(
(define (domain oneway)
  (:requirements :strips)
  (:predicates (at ?l) (facing ?d) (road ?from ?to ?d1 ?d2))
  (:action drive :parameters (?from ?to ?d1 ?d2)
    :precondition (and (at ?from) (facing ?d1) (road ?from ?to ?d1 ?d2))
    :effect (and (not (at ?from)) (at ?to) (not (facing ?d1)) (facing ?d2))))
)";
inline const char* kOneWayProblem = R"(
(define (problem trap) (:domain oneway)
  (:objects a b c d e f g north south)
  (:init (at a) (facing north)
         (road a b north north) (road b c north south) (road b g south south)
         (road a d north north) (road d e north north) (road e f north north) (road f g north north))
  (:goal (at g)))
)";

}  // namespace tamp::symbolic_planner::test
