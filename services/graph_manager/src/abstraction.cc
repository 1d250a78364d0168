#include <cstdio>
#include "tamp/graph_manager/abstraction.h"

#include <algorithm>
#include <cmath>
#include <future>
#include <sstream>

#include "tamp/world/polygon.h"
#include "tamp/world/scenario.h"

namespace tamp::graph_manager {

std::vector<std::string> atomTokens(const std::string& atom) {
  std::vector<std::string> out;
  std::string cur;
  for (char c : atom) {
    if (c == '(' || c == ')' || std::isspace(static_cast<unsigned char>(c))) {
      if (!cur.empty()) out.push_back(cur), cur.clear();
    } else {
      cur += static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    }
  }
  if (!cur.empty()) out.push_back(cur);
  return out;
}

namespace {
double angleDiff(double a, double b) { return std::abs(std::remainder(a - b, 2 * M_PI)); }

/// From this many (pose, region) pairs on, reachAll splits them between two threads.
constexpr std::size_t kParallelReachFrom = 4;

/// world::reachesRegion for each pair, in order. Each is an inverse-kinematics search (up to 24
/// restarts of 300 iterations when the region lies within the arm's reach sphere but is not
/// reached: most of the graph manager's own time in a replanning that adds push stands and
/// slots), independent of the others and deterministic (fixed seed and restarts), so the pairs
/// are split between this thread and one more (alternately: the costly ones cluster) and the
/// answers are those of the serial loop.
std::vector<char> reachAll(const robot::RobotModel& robot,
                           const std::vector<std::pair<const Pose2D*, const world::Region*>>& pairs) {
  std::vector<char> out(pairs.size(), 0);
  auto run = [&](std::size_t first, std::size_t step) {
    for (std::size_t i = first; i < pairs.size(); i += step)
      out[i] = world::reachesRegion(robot, *pairs[i].first, *pairs[i].second) ? 1 : 0;
  };
  if (pairs.size() < kParallelReachFrom) {
    run(0, 1);
    return out;
  }
  auto other = std::async(std::launch::async, run, std::size_t{1}, std::size_t{2});
  run(0, 2);
  other.get();
  return out;
}
}  // namespace

Abstraction::Abstraction(world::World world, robot::RobotModel robot, AbstractionParams params)
    : world_(std::move(world)), robot_(std::move(robot)), params_(params) {
  for (const auto& r : world_.regions()) regions_[r.id] = r;
  for (const auto& l : world_.locations()) {
    locations_[l.id] = l.pose;
    addReaches(l.id, l.pose);
  }
}

void Abstraction::setWorld(world::World world) { world_ = std::move(world); }

void Abstraction::addReaches(const std::string& location, const Pose2D& pose) {
  reaches_.insert("(reaches " + location + " stow)");
  std::vector<std::pair<const Pose2D*, const world::Region*>> pairs;
  std::vector<const std::string*> ids;
  for (const auto& [id, region] : regions_) {
    pairs.emplace_back(&pose, &region);
    ids.push_back(&id);
  }
  const std::vector<char> reached = reachAll(robot_, pairs);
  for (std::size_t i = 0; i < ids.size(); ++i)
    if (reached[i]) reaches_.insert("(reaches " + location + " " + armconfOver(*ids[i]) + ")");
}

void Abstraction::addRegionReaches(const std::string& region_symbol, const world::Region& region) {
  std::vector<std::pair<const Pose2D*, const world::Region*>> pairs;
  std::vector<const std::string*> ids;
  for (const auto& [id, pose] : locations_) {
    pairs.emplace_back(&pose, &region);
    ids.push_back(&id);
  }
  const std::vector<char> reached = reachAll(robot_, pairs);
  for (std::size_t i = 0; i < ids.size(); ++i)
    if (reached[i]) reaches_.insert("(reaches " + *ids[i] + " " + armconfOver(region_symbol) + ")");
}

std::string Abstraction::findLocation(const Pose2D& pose) const {
  return findLocation(pose, params_.location_tolerance_m);
}

std::string Abstraction::findLocation(const Pose2D& pose, double within_m) const {
  std::string best;
  double best_d = within_m;
  for (const auto& [id, p] : locations_) {
    const double d = std::hypot(p.x - pose.x, p.y - pose.y);
    if (d <= best_d && angleDiff(p.theta, pose.theta) <= params_.location_tolerance_rad) {
      best_d = d;
      best = id;
    }
  }
  return best;
}

std::optional<Pose2D> Abstraction::locationPose(const std::string& id) const {
  auto it = locations_.find(id);
  if (it == locations_.end()) return std::nullopt;
  return it->second;
}

std::string Abstraction::locationFor(const Pose2D& pose, const std::string& hint) {
  return locationFor(pose, hint, params_.location_tolerance_m);
}

std::string Abstraction::locationFor(const Pose2D& pose, const std::string& hint, double reuse_within_m) {
  if (auto existing = findLocation(pose, reuse_within_m); !existing.empty()) return existing;
  std::string id = hint;
  for (int k = 2; locations_.count(id) || regions_.count(id); ++k) id = hint + "_" + std::to_string(k);
  locations_[id] = pose;
  addReaches(id, pose);
  return id;
}

std::string Abstraction::slotAt(const std::string& object_id, const Eigen::Vector2d& xy,
                                const std::string& parent_region) const {
  std::string best;
  double best_d = params_.slot_tolerance_m;
  for (const auto& [id, s] : slots_) {
    if (s.object_id != object_id || (!parent_region.empty() && s.parent_region != parent_region)) continue;
    const double d = (s.pose.translation().head<2>() - xy).norm();
    if (d <= best_d) {
      best_d = d;
      best = id;
    }
  }
  return best;
}

world::Region Abstraction::slotRegion(const Slot& s) const {
  world::Region r;
  r.id = s.id;
  r.label = "slot for " + s.object_id;
  const world::Region* parent = nullptr;
  if (auto it = regions_.find(s.parent_region); it != regions_.end()) parent = &it->second;
  r.kind = parent ? parent->kind : world::RegionKind::kFloor;
  r.height = parent ? parent->height : 0.0;
  const double h = params_.slot_half_size_m;
  const Eigen::Vector2d c = s.pose.translation().head<2>();
  r.polygon = {c + Eigen::Vector2d(-h, -h), c + Eigen::Vector2d(h, -h), c + Eigen::Vector2d(h, h),
               c + Eigen::Vector2d(-h, h)};
  return r;
}

std::string Abstraction::addSlot(const std::string& object_id, const std::string& parent_region,
                                 const Eigen::Isometry3d& pose) {
  for (const auto& [id, s] : slots_) {
    if (s.object_id == object_id && (s.pose.translation() - pose.translation()).norm() < 1e-3) return id;
  }
  Slot s;
  s.id = "slot_" + object_id + "_" + std::to_string(++slot_counter_);
  s.object_id = object_id;
  s.parent_region = parent_region;
  s.pose = pose;
  const world::Region region = slotRegion(s);
  regions_[s.id] = region;
  slots_[s.id] = s;
  addRegionReaches(s.id, region);
  return s.id;
}

bool Abstraction::isReached(const std::string& armconf) const {
  const std::string tail = " " + armconf + ")";
  for (const auto& r : reaches_)
    if (r.size() > tail.size() && r.compare(r.size() - tail.size(), tail.size(), tail) == 0) return true;
  return false;
}

std::vector<std::string> Abstraction::refinedSupports(const std::vector<std::string>& atoms) const {
  std::vector<std::string> out;
  out.reserve(atoms.size());
  for (const auto& a : atoms) {
    const auto t = atomTokens(a);
    std::string replaced;
    if (t.size() == 3 && t[0] == "on" && slots_.count(t[2]) == 0) {
      if (const world::Object* o = world_.findObject(t[1])) {
        if (const std::string id = slotAt(t[1], o->pose.translation().head<2>(), t[2]); !id.empty())
          replaced = "(on " + t[1] + " " + id + ")";
      }
    }
    out.push_back(replaced.empty() ? a : replaced);
  }
  return out;
}

const Slot* Abstraction::slot(const std::string& id) const {
  auto it = slots_.find(id);
  return it == slots_.end() ? nullptr : &it->second;
}

void Abstraction::addReach(const std::string& location, const std::string& armconf) {
  if (locations_.count(location) && !regionOfArmconf(armconf).empty())
    reaches_.insert("(reaches " + location + " " + armconf + ")");
}

void Abstraction::addPush(const std::string& object, const std::string& support, const std::string& from,
                          const std::string& to, const std::string& slot) {
  if (locations_.count(from) && locations_.count(to) && regions_.count(support) && slots_.count(slot))
    pushes_.emplace("(push-to " + object + " " + support + " " + from + " " + to + " " + slot + ")", object);
}

bool Abstraction::isRegion(const std::string& id) const { return regions_.count(id) > 0; }

const world::Region* Abstraction::region(const std::string& id) const {
  auto it = regions_.find(id);
  return it == regions_.end() ? nullptr : &it->second;
}

namespace {
/// `hint`, or `hint_2`, ... the first that `taken` does not know.
template <typename Taken>
std::string freeName(const std::string& hint, Taken taken) {
  std::string id = hint;
  for (int k = 2; taken(id); ++k) id = hint + "_" + std::to_string(k);
  return id;
}
}  // namespace

std::string Abstraction::addPlaceholder(const std::string& hint) {
  const std::string id = freeName(hint, [&](const std::string& x) {
    return world_.findObject(x) != nullptr || locations_.count(x) || regions_.count(x) || placeholders_.count(x) ||
           observed_armconfs_.count(x);
  });
  placeholders_.insert(id);
  return id;
}

std::string Abstraction::addObservedArmconf(const std::string& hint) {
  const std::string id = freeName(hint, [&](const std::string& x) {
    return x == "stow" || world_.findObject(x) != nullptr || locations_.count(x) || regions_.count(x) ||
           placeholders_.count(x) || observed_armconfs_.count(x) || !regionOfArmconf(x).empty();
  });
  observed_armconfs_.insert(id);
  return id;
}

std::string Abstraction::regionOfArmconf(const std::string& armconf) const {
  if (armconf.rfind("over_", 0) != 0) return {};
  const std::string r = armconf.substr(5);
  return regions_.count(r) ? r : std::string{};
}

bool Abstraction::graspable(const world::Object& o) const { return whyNotGraspable(o).empty(); }

std::string Abstraction::whyNotGraspable(const world::Object& o) const {
  auto kg = [](double m) {
    char b[32];
    std::snprintf(b, sizeof(b), "%.1f kg", m);
    return std::string(b);
  };
  if (o.kind != world::ObjectKind::kMovable) return "'" + o.id + "' is static";
  if (o.mass > robot_.payload()) return "'" + o.id + "' (" + kg(o.mass) + ") exceeds the robot's payload of " + kg(robot_.payload());
  if (o.mass > params_.payload_cap_kg) return "'" + o.id + "' (" + kg(o.mass) + ") exceeds payload_cap_kg " + kg(params_.payload_cap_kg);
  if (!o.graspable) return "'" + o.id + "' is not graspable (its scenario or world file says so)";
  return "";
}

std::vector<std::string> Abstraction::objects() const {
  std::vector<std::string> out;
  for (const auto& [id, p] : locations_) out.push_back(id + " - location");
  for (const auto& [id, r] : regions_) {
    out.push_back(id + " - region");
    out.push_back(armconfOver(id) + " - armconf");
  }
  for (const auto& o : world_.objects()) {
    if (o.kind == world::ObjectKind::kMovable) out.push_back(o.id + " - item");
  }
  for (const auto& id : placeholders_)
    if (world_.findObject(id) == nullptr) out.push_back(id + " - item");
  for (const auto& id : observed_armconfs_) out.push_back(id + " - armconf");
  return out;
}

std::vector<std::string> Abstraction::staticAtoms() const {
  std::set<std::string> s(reaches_.begin(), reaches_.end());
  // Pushes of objects the world still has: perception may lose one (a pushed crate seen through
  // where its estimate lagged), and a fact about an object the problem does not declare makes
  // the whole problem invalid for the task planner.
  for (const auto& [fact, object] : pushes_)
    if (world_.findObject(object) != nullptr) s.insert(fact);
  for (const auto& [id, r] : regions_) s.insert("(conf-over " + armconfOver(id) + " " + id + ")");
  for (const auto& o : world_.objects()) {
    if (graspable(o)) s.insert("(graspable " + o.id + ")");
  }
  return {s.begin(), s.end()};
}

std::vector<std::string> Abstraction::dynamicAtoms(const world::World& w, const Pose2D& base,
                                                   const std::string& armconf, const std::string& held) {
  std::set<std::string> atoms;
  atoms.insert("(robot-at " + locationFor(base, "here") + ")");
  atoms.insert("(arm-at " + (armconf.empty() ? std::string("stow") : armconf) + ")");
  if (held.empty())
    atoms.insert("(hand-empty)");
  else
    atoms.insert("(holding " + held + ")");
  // on: a slot the object occupies, else its region, else the region below it, else a slot made
  // where it stands.
  std::map<std::string, std::string> support;
  for (const auto& o : w.objects()) {
    if (o.kind != world::ObjectKind::kMovable || o.id == held) continue;
    std::string where = slotAt(o.id, o.pose.translation().head<2>());
    if (where.empty() && !o.region.empty() && regions_.count(o.region)) where = o.region;
    if (where.empty()) {
      if (const world::Region* r = w.regionBelow(o.pose.translation() - Eigen::Vector3d(0, 0, o.shape.halfHeight())))
        where = r->id;
    }
    // On the floor but on no known region (an object perceived where the scenario named no
    // region): a slot of its own where it stands, so that it can be picked like any other. An
    // object off the floor on no region (in a hand the planner thinks empty, on an unknown
    // support) stays without an `on` fact.
    const double bottom = o.pose.translation().z() - o.shape.halfHeight();
    if (where.empty() && std::abs(bottom) <= kOnTheFloor_m) where = addSlot(o.id, "", o.pose);
    if (where.empty()) continue;
    atoms.insert("(on " + o.id + " " + where + ")");
    support[o.id] = slots_.count(where) ? slots_.at(where).parent_region : where;
  }
  // occludes: x in the corridor from the approach location of o's support to o (as seen by the
  // nearest location that reaches that support).
  for (const auto& o : w.objects()) {
    auto so = support.find(o.id);
    if (so == support.end()) continue;
    const auto region_it = regions_.find(so->second);
    if (region_it == regions_.end()) continue;
    const Eigen::Vector2d centroid = world::areaCentroid(region_it->second.polygon);
    const Pose2D* approach = nullptr;
    double best = std::numeric_limits<double>::infinity();
    for (const auto& [lid, lp] : locations_) {
      if (!reaches_.count("(reaches " + lid + " " + armconfOver(so->second) + ")")) continue;
      const double d = (centroid - Eigen::Vector2d(lp.x, lp.y)).norm();
      if (d < best) best = d, approach = &lp;
    }
    if (!approach) continue;
    const Eigen::Vector2d l(approach->x, approach->y);
    for (const auto& x : w.objects()) {
      if (x.id == o.id) continue;
      auto sx = support.find(x.id);
      if (sx == support.end() || sx->second != so->second) continue;
      if (world::occludes(x, o, l)) atoms.insert("(occludes " + x.id + " " + o.id + ")");
    }
  }
  return {atoms.begin(), atoms.end()};
}

Binding Abstraction::bind(const std::vector<std::string>& atoms) const {
  Binding b;
  b.armconf = "stow";
  for (const auto& a : atoms) {
    const auto t = atomTokens(a);
    if (t.size() == 2 && t[0] == "robot-at") {
      b.location = t[1];
      if (auto p = locationPose(t[1])) b.base = *p;
    } else if (t.size() == 2 && t[0] == "arm-at") {
      b.armconf = t[1];
    } else if (t.size() == 2 && t[0] == "holding") {
      b.held = t[1];
    } else if (t.size() == 3 && t[0] == "on") {
      if (const Slot* s = slot(t[2]); s && s->object_id == t[1]) b.object_poses[t[1]] = s->pose;
    }
  }
  return b;
}

}  // namespace tamp::graph_manager
