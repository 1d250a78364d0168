// Segment evaluation, effort-aware shortcutting, the blocking report and path conversions.
#include <algorithm>
#include <cmath>
#include <deque>
#include <map>

#include <ompl/base/spaces/SE2StateSpace.h>
#include <ompl/geometric/PathSimplifier.h>

#include "internal.h"

namespace tamp::motion_planner::detail {
namespace {

/// An OMPL state freed on scope exit.
class ScopedState {
 public:
  explicit ScopedState(const ob::StateSpacePtr& space) : space_(space), s_(space->allocState()) {}
  ~ScopedState() { space_->freeState(s_); }
  ScopedState(const ScopedState&) = delete;
  ScopedState& operator=(const ScopedState&) = delete;
  ob::State* get() const { return s_; }

 private:
  const ob::StateSpacePtr& space_;
  ob::State* s_;
};

bool contains(const std::vector<int>& sorted, int v) {
  return std::binary_search(sorted.begin(), sorted.end(), v);
}

void mergeInto(std::vector<int>& acc, const std::vector<int>& add) {
  if (add.empty()) return;
  std::vector<int> out;
  out.reserve(acc.size() + add.size());
  std::set_union(acc.begin(), acc.end(), add.begin(), add.end(), std::back_inserter(out));
  acc.swap(out);
}

}  // namespace

SegmentInfo evaluateSegment(Oracle& oracle, const ob::State* a, const ob::State* b, double resolution,
                            bool static_known_valid, const std::vector<int>* already, double cost_cap) {
  const auto& space = oracle.group().space();
  SegmentInfo info;
  info.length = space->distance(a, b);
  const int n = std::max(1, static_cast<int>(std::ceil(info.length / resolution)));
  ScopedState tmp(space);
  const std::vector<double> corners = turnCorners(*space, a, b);
  if (!static_known_valid) {
    for (double f : corners) {
      space->interpolate(a, b, f, tmp.get());
      if (!oracle.staticFree(tmp.get())) {
        info.valid = false;
        return info;
      }
    }
  }
  if (!static_known_valid && n > 1) {
    // Interior samples in bisection order (collisions tend to be found early).
    std::deque<std::pair<int, int>> q{{1, n - 1}};
    while (!q.empty()) {
      const auto [lo, hi] = q.front();
      q.pop_front();
      if (lo > hi) continue;
      const int mid = (lo + hi) / 2;
      space->interpolate(a, b, static_cast<double>(mid) / n, tmp.get());
      if (!oracle.staticFree(tmp.get())) {
        info.valid = false;
        return info;
      }
      q.emplace_back(lo, mid - 1);
      q.emplace_back(mid + 1, hi);
    }
  }
  std::vector<int> cand;
  oracle.candidates(a, b, cand);
  if (cand.empty()) return info;
  std::vector<int> t;
  double new_cost = 0.0;
  const int samples = n + 1 + static_cast<int>(corners.size());
  for (int i = 0; i < samples; ++i) {
    const ob::State* s = a;
    if (i > n) {
      space->interpolate(a, b, corners[static_cast<std::size_t>(i - n - 1)], tmp.get());  // the corners last
      s = tmp.get();
    } else if (i == n) {
      s = b;
    } else if (i > 0) {
      space->interpolate(a, b, static_cast<double>(i) / n, tmp.get());
      s = tmp.get();
    }
    oracle.touched(s, t);
    for (int o : t) {
      if (contains(info.touched, o)) continue;
      if (already && !contains(*already, o)) new_cost += oracle.movables()[static_cast<std::size_t>(o)].cost_s;
      info.touched.insert(std::lower_bound(info.touched.begin(), info.touched.end(), o), o);
    }
    if (cost_cap > 0 && new_cost >= cost_cap) {
      info.valid = false;  // too expensive for the caller: stop early
      return info;
    }
  }
  return info;
}

double objectsCost(const Oracle& oracle, const std::vector<int>& ids) {
  double c = 0.0;
  for (int i : ids) c += oracle.movables()[static_cast<std::size_t>(i)].cost_s;
  return c;
}

PathCost EvaluatedPath::cost(const Oracle& oracle, double seconds_per_unit) const {
  PathCost c;
  for (const auto& s : segments) {
    c.length += s.length;
    mergeInto(c.objects, s.touched);
  }
  c.cost = c.length * seconds_per_unit + objectsCost(oracle, c.objects);
  return c;
}

EvaluatedPath evaluatePath(Oracle& oracle, const og::PathGeometric& path, double resolution,
                           double max_segment) {
  const auto& si = path.getSpaceInformation();
  EvaluatedPath ep(si);
  ep.path = path;
  if (max_segment > 0 && ep.path.getStateCount() >= 2) {
    // Cut long segments so that shortcuts can start and end inside them.
    og::PathGeometric cut(si);
    const auto& space = si->getStateSpace();
    cut.append(ep.path.getState(0));
    ScopedState tmp(space);
    for (std::size_t i = 0; i + 1 < ep.path.getStateCount(); ++i) {
      const ob::State* a = ep.path.getState(i);
      const ob::State* b = ep.path.getState(i + 1);
      const int pieces = std::max(1, static_cast<int>(std::ceil(space->distance(a, b) / max_segment)));
      for (int k = 1; k < pieces; ++k) {
        space->interpolate(a, b, static_cast<double>(k) / pieces, tmp.get());
        cut.append(tmp.get());
      }
      cut.append(b);
    }
    ep.path = cut;
  }
  for (std::size_t i = 0; i + 1 < ep.path.getStateCount(); ++i) {
    ep.segments.push_back(evaluateSegment(oracle, ep.path.getState(i), ep.path.getState(i + 1), resolution, true));
  }
  return ep;
}

void effortShortcut(Oracle& oracle, EvaluatedPath& ep, int attempts, double resolution, double seconds_per_unit,
                    std::mt19937& rng, const Termination& termination) {
  const auto& movables = oracle.movables();
  std::vector<int> count(movables.size(), 0);
  for (const auto& s : ep.segments)
    for (int o : s.touched) ++count[static_cast<std::size_t>(o)];
  std::vector<int> dec(movables.size(), 0);
  std::vector<int> remaining, removed_objects;
  auto& states = ep.path.getStates();
  for (int attempt = 0; attempt < attempts && !termination(); ++attempt) {
    const int n = static_cast<int>(states.size());
    if (n < 3) break;
    std::uniform_int_distribution<int> pick_i(0, n - 3);
    const int i = pick_i(rng);
    std::uniform_int_distribution<int> pick_j(i + 2, n - 1);
    const int j = pick_j(rng);
    double old_len = 0.0;
    removed_objects.clear();
    for (int k = i; k < j; ++k) {
      old_len += ep.segments[static_cast<std::size_t>(k)].length;
      for (int o : ep.segments[static_cast<std::size_t>(k)].touched) {
        if (dec[static_cast<std::size_t>(o)]++ == 0) removed_objects.push_back(o);
      }
    }
    double savings = 0.0;
    remaining.clear();
    for (std::size_t o = 0; o < movables.size(); ++o) {
      if (count[o] - dec[o] > 0) remaining.push_back(static_cast<int>(o));
    }
    for (int o : removed_objects) {
      if (count[static_cast<std::size_t>(o)] - dec[static_cast<std::size_t>(o)] == 0)
        savings += movables[static_cast<std::size_t>(o)].cost_s;
    }
    for (int o : removed_objects) dec[static_cast<std::size_t>(o)] = 0;
    const double new_len = oracle.group().space()->distance(states[static_cast<std::size_t>(i)],
                                                           states[static_cast<std::size_t>(j)]);
    const double gain_max = (old_len - new_len) * seconds_per_unit + savings;
    if (gain_max <= 1e-9) continue;
    SegmentInfo info = evaluateSegment(oracle, states[static_cast<std::size_t>(i)], states[static_cast<std::size_t>(j)],
                                       resolution, false, &remaining, gain_max);
    if (!info.valid) continue;
    double new_cost = 0.0;
    for (int o : info.touched) {
      if (!contains(remaining, o)) new_cost += movables[static_cast<std::size_t>(o)].cost_s;
    }
    const double delta = (new_len - old_len) * seconds_per_unit + new_cost - savings;
    if (delta >= -1e-9) continue;
    // Apply: drop states i+1 .. j-1 and segments i .. j-1, insert the new segment.
    for (int k = i; k < j; ++k)
      for (int o : ep.segments[static_cast<std::size_t>(k)].touched) --count[static_cast<std::size_t>(o)];
    for (int o : info.touched) ++count[static_cast<std::size_t>(o)];
    const auto& si = ep.path.getSpaceInformation();
    for (int k = i + 1; k < j; ++k) si->freeState(states[static_cast<std::size_t>(k)]);
    states.erase(states.begin() + i + 1, states.begin() + j);
    ep.segments.erase(ep.segments.begin() + i, ep.segments.begin() + j);
    ep.segments.insert(ep.segments.begin() + i, std::move(info));
  }
}

std::vector<BlockingObject> blockingReport(Oracle& oracle, const og::PathGeometric& path, double resolution,
                                           double swept_spacing) {
  const auto& gs = oracle.group();
  const auto& space = gs.space();
  const auto& movables = oracle.movables();
  std::vector<BlockingObject> out;
  if (movables.empty() || path.getStateCount() == 0) return out;
  const std::size_t ns = path.getStateCount();
  std::vector<double> cum(ns, 0.0);
  for (std::size_t i = 1; i < ns; ++i) cum[i] = cum[i - 1] + space->distance(path.getState(i - 1), path.getState(i));
  const double total = cum.back();
  const auto frac = [&](double along) { return total > 0 ? std::clamp(along / total, 0.0, 1.0) : 0.0; };

  struct Track {
    bool in{false};
    double enter{0}, last_swept{-1e300};
    BlockingObject obj;
  };
  std::map<int, Track> tracks;
  ScopedState cur(space), prev(space), probe(space);
  std::vector<int> t_prev, t_cur;

  // Contact boundary between prev (along a) and cur (along b): bisection on `index`.
  auto refine = [&](int index, bool entering, double a_along, double b_along) {
    double lo = 0.0, hi = 1.0;  // lo: state like prev, hi: state like cur
    for (int it = 0; it < 6; ++it) {
      const double mid = 0.5 * (lo + hi);
      space->interpolate(prev.get(), cur.get(), mid, probe.get());
      const bool touching = oracle.touches(probe.get(), index);
      if (touching == entering) {
        hi = mid;
      } else {
        lo = mid;
      }
    }
    const double t = entering ? hi : lo;
    return a_along + t * (b_along - a_along);
  };
  auto addSwept = [&](Track& tr, const ob::State* s, double along, bool force) {
    if (!force && along - tr.last_swept < swept_spacing) return;
    tr.last_swept = along;
    tr.obj.swept_base.push_back(gs.basePose(s));
    tr.obj.swept_configurations.push_back(gs.values(s));
  };

  double prev_along = 0.0;
  bool have_prev = false;
  std::vector<int> cand;
  for (std::size_t k = 0; k + 1 < std::max<std::size_t>(ns, 2); ++k) {
    const ob::State* a = path.getState(k);
    const ob::State* b = ns > 1 ? path.getState(k + 1) : a;
    const double len = ns > 1 ? space->distance(a, b) : 0.0;
    // Sampled along what the robot sweeps: a base segment that turns away and back has a small
    // SE(2) distance and a long sweep (a turn in place a few cm from an object touched it
    // between samples, and the execution monitor refused the path).
    const double swept = ns > 1 ? std::max(len, sweptLength(*space, a, b)) : 0.0;
    const int n = std::max(1, static_cast<int>(std::ceil(swept / resolution)));
    oracle.candidates(a, b, cand);
    for (int i = (k == 0 ? 0 : 1); i <= n; ++i) {
      space->interpolate(a, b, static_cast<double>(i) / n, cur.get());
      const double along = cum[k] + (ns > 1 ? len * i / n : 0.0);
      if (cand.empty()) {
        t_cur.clear();
      } else {
        oracle.touched(cur.get(), t_cur);
      }
      for (int o : t_cur) {
        Track& tr = tracks[o];
        if (!tr.in) {
          tr.in = true;
          const double enter_along = have_prev ? refine(o, true, prev_along, along) : along;
          if (tr.obj.intervals.empty()) {
            tr.obj.enter_fraction = frac(enter_along);
            tr.obj.enter_waypoint = k;  // prev and cur both lie on segment k
          }
          tr.enter = frac(enter_along);
          addSwept(tr, cur.get(), along, true);
        } else {
          addSwept(tr, cur.get(), along, false);
        }
      }
      for (int o : t_prev) {
        if (contains(t_cur, o)) continue;
        Track& tr = tracks[o];
        tr.in = false;
        const double exit_along = refine(o, false, prev_along, along);
        tr.obj.intervals.emplace_back(tr.enter, frac(exit_along));
        tr.obj.exit_fraction = frac(exit_along);
        tr.obj.exit_waypoint = std::min(ns - 1, k + 1);
      }
      space->copyState(prev.get(), cur.get());
      t_prev.swap(t_cur);
      prev_along = along;
      have_prev = true;
    }
  }
  for (int o : t_prev) {  // still in contact at the end
    Track& tr = tracks[o];
    tr.obj.intervals.emplace_back(tr.enter, 1.0);
    tr.obj.exit_fraction = 1.0;
    tr.obj.exit_waypoint = ns - 1;
  }
  for (auto& [o, tr] : tracks) {
    const MovableInfo& m = movables[static_cast<std::size_t>(o)];
    tr.obj.object_id = m.id;
    tr.obj.mass = m.mass;
    tr.obj.effort_s = m.effort_s;
    out.push_back(std::move(tr.obj));
  }
  std::sort(out.begin(), out.end(), [](const BlockingObject& x, const BlockingObject& y) {
    return std::tie(x.enter_fraction, x.object_id) < std::tie(y.enter_fraction, y.object_id);
  });
  return out;
}

int repairSegments(const ob::SpaceInformationPtr& fine_si, og::PathGeometric& path,
                   const std::function<ob::PlannerPtr(const ob::SpaceInformationPtr&)>& make,
                   const Termination& termination) {
  if (path.getStateCount() < 2) return 0;
  og::PathGeometric out(fine_si);
  out.append(path.getState(0));
  int repaired = 0;
  for (std::size_t i = 0; i + 1 < path.getStateCount(); ++i) {
    const ob::State* a = path.getState(i);
    const ob::State* b = path.getState(i + 1);
    if (fine_si->checkMotion(a, b)) {
      out.append(b);
      continue;
    }
    auto pdef = std::make_shared<ob::ProblemDefinition>(fine_si);
    pdef->setStartAndGoalStates(a, b, 1e-9);
    const ob::PlannerPtr planner = make(fine_si);
    planner->setProblemDefinition(pdef);
    planner->setup();
    for (double slice = 0.05; !pdef->hasExactSolution() && !termination(); slice *= 2) {
      const Termination t = termination.tightened(Deadline::in(slice));
      planner->solve(ob::PlannerTerminationCondition([&t] { return t(); }));
    }
    if (!pdef->hasExactSolution()) return -1;
    og::PathGeometric sub = *pdef->getSolutionPath()->as<og::PathGeometric>();
    og::PathSimplifier simplifier(fine_si);
    simplifier.shortcutPath(sub, 0, 0, 0.33, 0.005);
    simplifier.reduceVertices(sub);
    for (std::size_t k = 1; k < sub.getStateCount(); ++k) out.append(sub.getState(k));
    ++repaired;
  }
  if (repaired > 0) path = out;
  return repaired;
}

double reportedLength(const GroupSpace& gs, const og::PathGeometric& path) {
  double len = 0.0;
  for (std::size_t i = 1; i < path.getStateCount(); ++i) {
    if (gs.group() == PlanningGroup::kBase) {
      const Pose2D a = gs.basePose(path.getState(i - 1)), b = gs.basePose(path.getState(i));
      len += std::hypot(b.x - a.x, b.y - a.y);
    } else {
      len += gs.space()->distance(path.getState(i - 1), path.getState(i));
    }
  }
  return len;
}

JointPath toJointPath(const GroupSpace& gs, const og::PathGeometric& path) {
  JointPath jp;
  jp.joint_names = gs.jointNames();
  for (std::size_t i = 0; i < path.getStateCount(); ++i) {
    std::vector<double> v = gs.values(path.getState(i));
    if (gs.hasBase() && !jp.waypoints.empty()) v[2] = jp.waypoints.back()[2] + angleDiff(v[2], jp.waypoints.back()[2]);
    jp.waypoints.push_back(std::move(v));
  }
  return jp;
}

bool alignBaseHeadings(const ob::SpaceInformationPtr& si, og::PathGeometric& path) {
  if (path.getStateCount() < 3) return false;
  auto wrap = [](double a) { return std::remainder(a, 2.0 * M_PI); };
  og::PathGeometric aligned(path);
  auto* first = aligned.getState(0)->as<ob::SE2StateSpace::StateType>();
  double heading = first->getYaw();
  bool changed = false;
  for (std::size_t i = 1; i + 1 < aligned.getStateCount(); ++i) {
    auto* s = aligned.getState(i)->as<ob::SE2StateSpace::StateType>();
    const auto* n = aligned.getState(i + 1)->as<ob::SE2StateSpace::StateType>();
    const double dx = n->getX() - s->getX(), dy = n->getY() - s->getY();
    if (std::hypot(dx, dy) < 1e-6) {
      heading = s->getYaw();  // a turn in place is its own heading
      continue;
    }
    double h = std::atan2(dy, dx);
    if (std::abs(wrap(h + M_PI - heading)) < std::abs(wrap(h - heading))) h = wrap(h + M_PI);
    if (std::abs(wrap(h - s->getYaw())) > 1e-9) {
      s->setYaw(h);
      changed = true;
    }
    heading = h;
  }
  if (!changed) return false;
  for (std::size_t i = 0; i + 1 < aligned.getStateCount(); ++i) {
    if (!si->checkMotion(aligned.getState(i), aligned.getState(i + 1))) return false;
  }
  path = aligned;
  return true;
}

void explicitBaseTurns(const ob::SpaceInformationPtr& si, og::PathGeometric& path) {
  const ob::StateSpacePtr& space = si->getStateSpace();
  if (!isStopAndTurn(*space) || path.getStateCount() < 2) return;
  og::PathGeometric out(si);
  out.append(path.getState(0));
  ScopedState corner(space);
  for (std::size_t i = 0; i + 1 < path.getStateCount(); ++i) {
    const ob::State* a = path.getState(i);
    const ob::State* b = path.getState(i + 1);
    for (double f : turnCorners(*space, a, b)) {
      if (f <= 1e-9 || f >= 1.0 - 1e-9) continue;
      space->interpolate(a, b, f, corner.get());
      if (space->distance(corner.get(), out.getState(out.getStateCount() - 1)) > 1e-9) out.append(corner.get());
    }
    if (space->distance(b, out.getState(out.getStateCount() - 1)) > 1e-12) out.append(b);
  }
  path = out;
}

}  // namespace tamp::motion_planner::detail
