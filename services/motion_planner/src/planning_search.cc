// Planning (planning.h): the search (the cached roadmap, the direct motion, the sampler with the
// `no path` proof in turns) and the path's refinement.
#include <algorithm>
#include <cmath>
#include <random>

#include <ompl/geometric/PathSimplifier.h>
#include <ompl/geometric/planners/kpiece/KPIECE1.h>
#include <ompl/geometric/planners/kpiece/LBKPIECE1.h>
#include <ompl/geometric/planners/rrt/RRTConnect.h>

#include "planning.h"
#include "tamp/core/format.h"
#include "tamp/core/log.h"

namespace tamp::motion_planner {
namespace {

ob::PlannerPtr makePlanner(PlannerKind kind, const ob::SpaceInformationPtr& si, double range) {
  switch (kind) {
    case PlannerKind::kLbkpiece: {
      auto p = std::make_shared<og::LBKPIECE1>(si);
      if (range > 0) p->setRange(range);
      return p;
    }
    case PlannerKind::kKpiece: {
      auto p = std::make_shared<og::KPIECE1>(si);
      if (range > 0) p->setRange(range);
      return p;
    }
    case PlannerKind::kRrtConnect: {
      auto p = std::make_shared<og::RRTConnect>(si);
      if (range > 0) p->setRange(range);
      return p;
    }
  }
  return nullptr;
}

ob::PlannerTerminationCondition ptcOf(const Termination& t) {
  return ob::PlannerTerminationCondition([t] { return t(); });
}

}  // namespace

// ---- lazy: the cached roadmap of the static free space ----

void Planning::searchRoadmapFirst() {
  if (!lazy || !P.lazy.optimize) return;
  Stopwatch rw;
  roadmap = impl.roadmapFor(staticWorldKey(impl, req.group, req.start, held, held_link, link_T_held, ignored), space,
                            res.stats.roadmap_reused, uncached);
  if (!res.stats.roadmap_reused && req.group == PlanningGroup::kBase && oracle.rigid()) deriveRoadmap();
  // A roadmap new in this request knows no edge yet: lazy KPIECE goes first and seeds it.
  if (req.group == PlanningGroup::kBase && P.lazy.roadmap_first && res.stats.roadmap_reused && !goal_states.empty()) {
    ensureSampled();
    res.stats.roadmap_pruned = roadmap->pruneRequestNodes(static_cast<std::size_t>(P.lazy.roadmap_max_request_nodes));
    const std::uint64_t request = ++impl.requests;
    const int s = roadmap->addRequestState(escaped ? escaped.get() : start.get(), request);
    std::vector<int> goals;
    for (const auto* g : goal_states) goals.push_back(roadmap->addRequestState(g, request));
    std::vector<int> crossed;
    from_roadmap = roadmap->search(oracle, si, s, goals, P.lazy, res_check, spu, termination, res.stats,
                                   P.lazy.roadmap_max_new_invalid, &crossed);
    if (from_roadmap) densify(*from_roadmap, s, goals, crossed);
  }
  res.stats.optimize_ms += rw.millis();
}

// The fixed objects of a request (obstacles for its lazy path) make a static world of their own,
// whose roadmap would be new: lazy KPIECE then ran in it, 1-3.3 s per request in
// namo_moghaddam_07. The cached roadmap of the world without them already knows that space but
// for the boxes the fixed objects occupy: it is copied, and only what is near them is checked.
void Planning::deriveRoadmap() {
  std::vector<std::shared_ptr<const world::Object>> added;
  for (const auto& cached : impl.roadmaps) {
    if (cached.get() == roadmap || cached->uniformSamples() == 0 || cached->samplingInterrupted()) continue;
    if (!roadmap->key().extends(cached->key(), added)) continue;
    std::vector<Aabb> boxes;
    for (const auto& o : added) boxes.push_back(o->aabb());
    const std::size_t dropped = roadmap->deriveFrom(*cached, oracle, boxes);
    res.stats.roadmap_reused = true;
    res.stats.roadmap_derived = true;
    log::get("motion_planner")
        ->debug("roadmap derived from a cached one ({} nodes, {} edges; {} nodes dropped) for {} more obstacle(s)",
                roadmap->nodeCount(), roadmap->edgeCount(), dropped, added.size());
    return;
  }
}

// A new roadmap draws its samples when it is first searched (arm requests whose lazy path
// crosses nothing never need it). Bridge-test samples for the base group only (narrow
// passages of the floor plan; in joint space they would cost many attempts, unmeasured).
void Planning::ensureSampled() {
  if (roadmap->uniformSamples() == 0 && P.lazy.roadmap_samples > 0) {
    roadmap->addSamples(oracle, gs, P.lazy.roadmap_samples, termination,
                        req.group == PlanningGroup::kBase ? P.lazy.roadmap_bridge_samples : 0,
                        P.lazy.roadmap_bridge_distance);
  }
}

// When the roadmap's best path crosses movables: samples around them, and the roadmap searched
// again (the result can only get cheaper: the old path is still in the roadmap).
// `objects`: those `path` crosses, as the search reported them.
void Planning::densify(og::PathGeometric& path, int s, const std::vector<int>& goals,
                       const std::vector<int>& objects) {
  if (objects.empty() || P.lazy.object_ring_samples <= 0 || req.group != PlanningGroup::kBase ||
      roadmap->nodeCount() >= static_cast<std::size_t>(P.lazy.roadmap_max_nodes)) {
    return;
  }
  if (roadmap->addObjectRingSamples(oracle, gs, objects, P.lazy.object_ring_samples, termination) == 0) return;
  auto again = roadmap->search(oracle, si, s, goals, P.lazy, res_check, spu, termination, res.stats);
  auto cost = [&](const og::PathGeometric& p) {
    return detail::evaluatePath(oracle, p, res_check, 0.0).cost(oracle, spu).cost;
  };
  if (again && cost(*again) < cost(path)) path = *again;
}

// ---- search (+ infeasibility proof, interleaved) ----

Outcome Planning::search() {
  if (req.straight_only) return straightOnly();
  Stopwatch phase;
  const PlannerKind kind = req.group != PlanningGroup::kBase ? (lazy ? P.sampling.arm_planner : P.sampling.arm_full_planner)
                           : lazy                            ? P.sampling.lazy_planner
                                                             : P.sampling.full_planner;
  planner = makePlanner(kind, si, P.sampling.range);
  planner->setProblemDefinition(pdef);
  planner->setup();
  if (P.sampling.direct_first) tryDirect(true);
  const bool solved = from_roadmap.has_value() || direct.has_value();
  res.stats.lazy_planner_used = !solved;
  return sample(phase, solved);
}

/// Full mode: the direct motion to a goal state when it is free (and keeps the base clearance,
/// when `keep_clearance`).
void Planning::tryDirect(bool keep_clearance) {
  if (lazy || termination()) return;
  const ob::State* from = escaped ? escaped.get() : start.get();
  for (const ob::State* g : goal_states) {
    if (!si->checkMotion(from, g) || (keep_clearance && !directKeepsClear(from, g))) continue;
    direct.emplace(si, from, g);
    res.stats.direct = true;
    res.stats.clearance_relaxed = !keep_clearance;
    break;
  }
}

/// MotionRequest::straight_only: the direct motion (one that keeps the base clearance first, else
/// any free one), or `no path` at once; nothing is sampled.
Outcome Planning::straightOnly() {
  Stopwatch phase;
  tryDirect(true);
  if (!direct) tryDirect(false);
  res.stats.sampling_ms = phase.millis();
  if (direct) return std::nullopt;
  const ob::State* from = escaped ? escaped.get() : start.get();
  // What it touches: just past the last free state along it.
  std::pair<ob::State*, double> last_valid{space->allocState(), 0.0};
  ob::State* past = space->allocState();
  std::string who;
  if (!goal_states.empty()) {
    (void)si->checkMotion(from, goal_states.front(), last_valid);
    for (const double f : {0.002, 0.01, 0.05, 0.2, 1.0}) {
      space->interpolate(last_valid.first, goal_states.front(), f, past);
      if (!(who = oracle.collidingObject(past, true)).empty()) break;
    }
  }
  space->freeState(past);
  space->freeState(last_valid.first);
  return finish(MotionStatus::kNoPath,
                "straight_only: the straight motion to the goal is not free" +
                    (who.empty() ? std::string() : " (it touches '" + who + "' near " +
                                                       formatNumber(std::round(last_valid.second * 100.0)) + " % of it)"),
                who);
}

/// An arm's direct motion is taken only when the robot grown by `direct_clearance` sweeps it
/// free: a straight joint-space motion runs as close to what it passes as the check allows, and
/// objects are where perception saw them to within centimetres (right after a place, the fingers
/// swept past the object just put down and the robot was stopped before it). Sampled paths are
/// shortcut too, but from a tree grown through free space.
bool Planning::directKeepsClear(const ob::State* from, const ob::State* to) {
  if (!gs.movesArm() || !(P.sampling.direct_clearance > 0.0)) return true;
  if (!direct_si) {
    direct_scene = std::make_unique<collision::Scene>(impl.world);
    direct_scene->setRobot(grownGeometry(impl.robot.geometry(), P.sampling.direct_clearance));
    if (!held.empty()) (void)direct_scene->attach(held, held_link, link_T_held);
    direct_oracle = std::make_unique<detail::Oracle>(*direct_scene, gs, ignored, oracle.movables(), oracle.reachRadius());
    // Contacts of the robot with itself as modelled: grown, its links touch one another.
    direct_oracle->setSelfScene(held_shape ? &plainScene() : &impl.scene);
    direct_si = sweptSi(*direct_oracle);
  }
  const bool clear = direct_si->checkMotion(from, to);
  gs.placeRobot(start.get(), impl.scene);
  return clear;
}

/// Unless `solved`: the sampling planner in doubling time slices until it finds a path, the
/// proof shows there is none, or the time is up; the base clearance is dropped when no path kept
/// it in time. The proof (full mode: a first turn before sampling) gets a turn after each slice,
/// of ProofParams::time_share times the slice, and goes on from where its last turn stopped,
/// refining its grid each time one is too coarse to decide. Sampling time is reported either way.
/// The held object where it rides on the base for this request (the arm still), modelled
/// without its margin; nothing when nothing is held or the arm moves.
std::optional<detail::DisconnectionProof::Carried> Planning::carriedByBase() const {
  if (held.empty() || gs.movesArm()) return std::nullopt;
  const world::Object* o = impl.scene.world().findObject(held);
  const auto world_T_link = impl.linkPose(req.start, held_link);
  if (o == nullptr || !world_T_link) return std::nullopt;
  return detail::DisconnectionProof::Carried{held_shape ? *held_shape : o->shape,
                                             req.start.base.toIsometry().inverse() * *world_T_link * link_T_held};
}

Outcome Planning::sample(const Stopwatch& phase, bool solved) {
  // Proof levels: (xy cell, yaw cells); the disc on finer and finer cells, then the oriented base.
  std::vector<std::pair<double, int>> proof_cells;
  if (P.proof.enabled && gs.hasBase() && base_goal) {
    for (double c = P.proof.cell_size; c >= P.proof.min_cell_size - 1e-12; c *= 0.5) proof_cells.emplace_back(c, 1);
    if (P.proof.yaw_cells > 1) {
      proof_cells.emplace_back(P.proof.oriented_cell_size, P.proof.yaw_cells);
      // Full mode only: there a passage the sampler cannot find is a run to the deadline; a lazy
      // request (movables free) is answered by sampling, and finer grids only cost it time.
      for (int k = 1; !lazy && k <= P.proof.oriented_refinements; ++k) {
        proof_cells.emplace_back(P.proof.oriented_cell_size / (1 << k), P.proof.yaw_cells << k);
      }
    }
  }
  const collision::Filter proof_filter = requestFilter();
  const std::shared_ptr<const collision::ClearanceGrid> statics = proof_cells.empty() ? nullptr : impl.clearanceGrid();
  std::size_t level = 0;
  std::unique_ptr<detail::DisconnectionProof> proof;
  // From where the sampler starts: a start touching movables is left first (the proof's cells
  // beside a touching start could all touch them too).
  const Pose2D proof_start = proof_cells.empty() ? req.start.base : gs.basePose(escaped ? escaped.get() : start.get());
  const auto carried = proof_cells.empty() ? std::nullopt : carriedByBase();
  auto traceProof = [&](const detail::DisconnectionProof& p, detail::ProofOutcome outcome) {
    static constexpr const char* kNames[] = {"disconnected", "connected", "skipped", "undecided"};
    std::string& t = res.stats.proof_trace;
    if (!t.empty()) t += ", ";
    t += formatNumber(p.cell()) + " m" + (p.yawCells() > 1 ? " x " + std::to_string(p.yawCells()) : std::string()) +
         ": " + kNames[static_cast<int>(outcome)] + " (" + std::to_string(p.tested()) + ")";
  };
  // One turn of the proof: true when it proved that there is no path.
  auto proofTurn = [&](double seconds) {
    Stopwatch pw;
    const Termination turn = termination.tightened(Deadline::in(seconds));
    bool proven = false;
    while (level < proof_cells.size() && !proven && !turn()) {
      if (!proof) {
        proof = std::make_unique<detail::DisconnectionProof>(
            impl.scene, proof_filter, statics.get(), impl.robot, bounds, proof_start, *base_goal,
            P.sampling.goal_position_tolerance, proof_cells[level].first, proof_cells[level].second,
            proof_cells[level].second > 1 ? P.proof.oriented_max_cells : P.proof.max_cells, carried);
      }
      const detail::ProofOutcome outcome = proof->advance(turn);
      if (outcome == detail::ProofOutcome::kStopped) break;
      proven = outcome == detail::ProofOutcome::kDisconnected;
      res.stats.proof_cells += proof->tested();
      res.stats.proof_grid_answers += proof->gridAnswers();
      traceProof(*proof, outcome);
      if (!proven) {
        // A finer (x, y, yaw) grid tests about eight times the cells: only where that fits.
        const bool refinement_next = level + 1 < proof_cells.size() && proof->yawCells() > 1;
        const bool small = outcome == detail::ProofOutcome::kConnected &&
                           8 * proof->tested() <= static_cast<std::size_t>(P.proof.oriented_max_cells);
        proof.reset();
        level = refinement_next && !small ? proof_cells.size() : level + 1;
      }
    }
    res.stats.proof_ms += pw.millis();
    return proven;
  };
  auto noPath = [&] {
    res.stats.sampling_ms = phase.millis() - res.stats.proof_ms;
    res.stats.validity_checks = oracle.checks();
    res.stats.grid_answers = oracle.gridAnswers();
    return finish(MotionStatus::kNoPath, std::string("no path: start and goal are in different components of the ") +
                                             (lazy ? "static " : "") + "free space of the base (proven on a " +
                                             formatNumber(proof->cell()) + " m grid" +
                                             (proof->yawCells() > 1 ? " with " + std::to_string(proof->yawCells()) +
                                                                          " yaw cells"
                                                                    : std::string()) +
                                             ")");
  };
  // A first turn before sampling: a goal walled off (by statics, or objects the request fixes)
  // is answered in milliseconds, before the first slice (lazy: 0.25 s) of a search that cannot
  // succeed. Requests the roadmap or the direct motion answered never get here.
  double slice = lazy ? 0.25 : 0.02;
  if (!solved && proofTurn(P.proof.first_turn_s)) return noPath();
  while (!solved) {
    if (termination()) break;
    // No path kept the clearance in time: on without it (every state and motion of the tree so
    // far passed the stronger check, so the tree stays valid).
    if (clearance && !clearance->relaxed() && phase.seconds() - res.stats.proof_ms / 1000.0 >= P.sampling.base_clearance_time_s) {
      clearance->relax();
      res.stats.clearance_relaxed = true;
    }
    const Termination slice_term = termination.tightened(Deadline::in(
        clearance && !clearance->relaxed() ? std::min(slice, P.sampling.base_clearance_time_s) : slice));
    planner->solve(ptcOf(slice_term));
    ++res.stats.sampling_slices;
    solved = pdef->hasExactSolution();
    if (!solved && proofTurn(slice * (lazy ? P.proof.lazy_time_share : P.proof.time_share))) return noPath();
    slice *= 2;
  }
  res.stats.sampling_ms = phase.millis() - res.stats.proof_ms;
  if (proof) traceProof(*proof, detail::ProofOutcome::kStopped);
  if (!solved) {
    res.stats.validity_checks = oracle.checks();
    res.stats.grid_answers = oracle.gridAnswers();
    const bool stop = termination.reason() == StopReason::kStopRequested;
    return finish(MotionStatus::kTimeout,
                  std::string(stop ? "stop requested" : "the deadline passed") + " before a " + (lazy ? "lazy " : "") +
                      "path was found" +
                      (proof_cells.empty() ? std::string(" (no infeasibility proof for this group)")
                                           : " (infeasibility not proven: " + res.stats.proof_trace + ")"));
  }
  return std::nullopt;
}

og::PathGeometric Planning::rawPath() {
  og::PathGeometric raw = from_roadmap ? *from_roadmap
                          : direct     ? *direct
                                       : *pdef->getSolutionPath()->as<og::PathGeometric>();
  res.stats.raw_path_length = detail::reportedLength(gs, raw);
  return raw;
}

// ---- lazy: roadmap improvement, effort shortcut, blocking report ----

og::PathGeometric Planning::improveLazyPath(const og::PathGeometric& raw) {
  Stopwatch phase;
  detail::EvaluatedPath raw_eval = detail::evaluatePath(oracle, raw, res_check, 0.0);
  const detail::PathCost raw_cost = raw_eval.cost(oracle, spu);
  res.stats.raw_cost_s = raw_cost.cost;
  for (int o : raw_cost.objects) res.stats.raw_blocking.push_back(oracle.movables()[static_cast<std::size_t>(o)].id);
  const og::PathGeometric best = improveByRoadmap(raw, raw_cost);
  res.stats.optimize_ms += phase.millis();
  phase.reset();
  detail::EvaluatedPath ep = detail::evaluatePath(oracle, best, res_check, P.lazy.path_node_spacing * 0.5);
  std::mt19937 rng(P.seed);
  detail::effortShortcut(oracle, ep, P.lazy.shortcut_attempts, res_check, spu, rng, termination);
  res.cost_s = ep.cost(oracle, spu).cost;
  og::PathGeometric final_path = ep.path;
  prependEscapeAndAlign(final_path);
  res.stats.shortcut_ms = phase.millis();
  phase.reset();
  res.blocking = detail::blockingReport(oracle, final_path, P.lazy.contact_resolution, P.lazy.swept_spacing);
  res.stats.analysis_ms = phase.millis();
  return final_path;
}

/// `raw`, or the roadmap's path between its ends when that is cheaper (base group, or a request
/// that gives the objects `raw` crosses a cost).
og::PathGeometric Planning::improveByRoadmap(const og::PathGeometric& raw, const detail::PathCost& raw_cost) {
  og::PathGeometric best = raw;
  const bool improve = req.group == PlanningGroup::kBase || (req.object_cost_scale > 0 && !raw_cost.objects.empty());
  if (roadmap && !from_roadmap && improve) {
    // Lazy KPIECE's path (statically valid) joins the roadmap, which also grows where it is.
    ensureSampled();
    const auto [s, g] = roadmap->addPath(raw, P.lazy.path_node_spacing);
    if (roadmap->nodeCount() < static_cast<std::size_t>(P.lazy.roadmap_max_nodes)) {
      roadmap->addSamples(oracle, gs, P.lazy.roadmap_growth_samples, termination);
    }
    std::vector<int> crossed;
    auto rm = roadmap->search(oracle, si, s, {g}, P.lazy, res_check, spu, termination, res.stats, 0, &crossed);
    if (rm) densify(*rm, s, {g}, crossed);
    if (rm) {
      detail::EvaluatedPath rm_eval = detail::evaluatePath(oracle, *rm, res_check, 0.0);
      if (rm_eval.cost(oracle, spu).cost < raw_cost.cost) best = *rm;
    }
  }
  return best;
}

// ---- full: simplification, swept-arm repair ----

Outcome Planning::refineFullPath(og::PathGeometric& path) {
  Stopwatch phase;
  simplify(path);
  if (auto done = repairSwept(path)) return done;
  prependEscapeAndAlign(path);
  res.stats.shortcut_ms = phase.millis();
  return std::nullopt;
}

void Planning::simplify(og::PathGeometric& path) {
  og::PathSimplifier simplifier(si);
  const Termination simp = termination.tightened(Deadline::in(0.05));
  for (int round = 0; round < 4 && !direct && !simp(); ++round) {
    bool better = simplifier.shortcutPath(path, 0, 0, 0.33, 0.005);
    better |= simplifier.reduceVertices(path);
    if (!better) break;
  }
  simplifier.collapseCloseVertices(path);
}

// The path as the robot sweeps it: segments that touch something between two states checked
// at validity_resolution are planned again at the swept resolution.
Outcome Planning::repairSwept(og::PathGeometric& path) {
  if (!(req.group == PlanningGroup::kArm && P.sampling.arm_swept_step > 0.0 && !sweep_radii.empty())) {
    return std::nullopt;
  }
  auto fine_si = std::make_shared<ob::SpaceInformation>(space);
  fine_si->setStateValidityChecker(si->getStateValidityChecker());
  fine_si->setStateValidityCheckingResolution(si->getStateValidityCheckingResolution());
  fine_si->setMotionValidator(
      std::make_shared<detail::SweptArmMotionValidator>(fine_si, gs, sweep_radii, P.sampling.arm_swept_step));
  fine_si->setup();
  const PlannerKind arm_kind = P.sampling.arm_full_planner;  // full mode only
  res.stats.swept_repairs = detail::repairSegments(
      fine_si, path, [&](const ob::SpaceInformationPtr& s) { return makePlanner(arm_kind, s, P.sampling.range); },
      termination);
  if (res.stats.swept_repairs < 0) {
    return finish(MotionStatus::kTimeout,
                  "a segment of the path touches an object between two checked states and could not be planned "
                  "again at the swept resolution (arm_swept_step " + formatNumber(P.sampling.arm_swept_step) +
                      " m) in time");
  }
  return std::nullopt;
}

/// The escape from the start prepended; a stop-and-turn base's headings along its drives.
void Planning::prependEscapeAndAlign(og::PathGeometric& path) {
  if (escaped) path.prepend(start.get());
  if (req.group == PlanningGroup::kBase && P.sampling.base_turn_in_place) {
    detail::alignBaseHeadings(si, path);
    detail::explicitBaseTurns(si, path);
  }
}

// ---- finish ----

MotionResult Planning::finishSolved(const og::PathGeometric& path) {
  res.stats.validity_checks = oracle.checks();
  res.stats.grid_answers = oracle.gridAnswers();
  res.path = detail::toJointPath(gs, path);
  res.path_length = detail::reportedLength(gs, path);
  auto traj = timeParameterize(res.path, impl.timingLimits());
  if (!traj) return out.finish(MotionStatus::kInvalidRequest, "time parameterization: " + traj.error().message);
  res.trajectory = std::move(*traj);
  return out.finish(MotionStatus::kSolved, {});
}

}  // namespace tamp::motion_planner
