#include "tamp/collision/scene.h"

#include <algorithm>
#include <map>
#include <sstream>
#include <stdexcept>
#include <tuple>

#include <fcl/broadphase/broadphase_dynamic_AABB_tree.h>
#include <fcl/geometry/bvh/BVH_model.h>
#include <fcl/geometry/octree/octree.h>
#include <fcl/geometry/shape/box.h>
#include <fcl/geometry/shape/convex.h>
#include <fcl/geometry/shape/cylinder.h>
#include <fcl/geometry/shape/sphere.h>
#include <fcl/math/bv/OBBRSS.h>
#include <fcl/narrowphase/collision.h>
#include <fcl/narrowphase/collision_object.h>
#include <fcl/narrowphase/distance.h>
#include <octomap/OcTree.h>

#include "tamp/world/polygon.h"

namespace tamp::collision {

using world::Object;
using world::ObjectKind;
using world::Shape;
using world::ShapeKind;

// ---- geometry -----------------------------------------------------------------------------------

namespace {

using GeomPtr = std::shared_ptr<fcl::CollisionGeometryd>;

/// One FCL geometry of a shape and its placement in the shape's frame.
struct GeomPiece {
  GeomPtr geom;
  Eigen::Isometry3d offset{Eigen::Isometry3d::Identity()};
};

// A rectangle (4 vertices, right angles) as (centre, angle of the first edge, side lengths).
bool asRectangle(const world::Polygon2& p, Eigen::Vector2d& centre, double& angle, double& w,
                 double& h) {
  if (p.size() != 4) return false;
  for (size_t i = 0; i < 4; ++i) {
    const Eigen::Vector2d a = p[(i + 1) % 4] - p[i], b = p[(i + 2) % 4] - p[(i + 1) % 4];
    if (std::abs(a.dot(b)) > 1e-9 * a.norm() * b.norm()) return false;
  }
  const Eigen::Vector2d e0 = p[1] - p[0], e1 = p[2] - p[1];
  w = e0.norm();
  h = e1.norm();
  if (w <= 0 || h <= 0) return false;
  angle = std::atan2(e0.y(), e0.x());
  centre = 0.25 * (p[0] + p[1] + p[2] + p[3]);
  return true;
}

GeomPiece prismPiece(const world::Polygon2& poly, double height) {
  Eigen::Vector2d c;
  double angle = 0, w = 0, h = 0;
  if (asRectangle(poly, c, angle, w, h)) {
    GeomPiece g;
    g.geom = std::make_shared<fcl::Boxd>(w, h, height);
    g.offset.translation() = Eigen::Vector3d(c.x(), c.y(), 0.0);
    g.offset.linear() = Eigen::AngleAxisd(angle, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    return g;
  }
  const int n = static_cast<int>(poly.size());
  auto verts = std::make_shared<std::vector<Eigen::Vector3d>>();
  verts->reserve(static_cast<size_t>(2 * n));
  for (const auto& p : poly) verts->emplace_back(p.x(), p.y(), -0.5 * height);
  for (const auto& p : poly) verts->emplace_back(p.x(), p.y(), 0.5 * height);
  auto faces = std::make_shared<std::vector<int>>();
  faces->push_back(n);  // top, counter-clockwise seen from +z
  for (int i = 0; i < n; ++i) faces->push_back(n + i);
  faces->push_back(n);  // bottom, reversed
  for (int i = n - 1; i >= 0; --i) faces->push_back(i);
  for (int i = 0; i < n; ++i) {  // sides, outward normals
    const int j = (i + 1) % n;
    faces->insert(faces->end(), {4, i, j, n + j, n + i});
  }
  GeomPiece g;
  g.geom = std::make_shared<fcl::Convexd>(verts, n + 2, faces);
  return g;
}

GeomPiece prismMesh(const world::Polygon2& poly, double height) {
  const auto tris = world::triangulate(poly);
  const int n = static_cast<int>(poly.size());
  std::vector<Eigen::Vector3d> v;
  for (const auto& p : poly) v.emplace_back(p.x(), p.y(), -0.5 * height);
  for (const auto& p : poly) v.emplace_back(p.x(), p.y(), 0.5 * height);
  std::vector<fcl::Triangle> t;
  for (const auto& tri : tris) {
    t.emplace_back(n + tri[0], n + tri[1], n + tri[2]);
    t.emplace_back(tri[2], tri[1], tri[0]);
  }
  for (int i = 0; i < n; ++i) {
    const int j = (i + 1) % n;
    t.emplace_back(i, j, n + j);
    t.emplace_back(i, n + j, n + i);
  }
  auto model = std::make_shared<fcl::BVHModel<fcl::OBBRSSd>>();
  model->beginModel(static_cast<int>(t.size()), static_cast<int>(v.size()));
  model->addSubModel(v, t);
  model->endModel();
  GeomPiece g;
  g.geom = model;
  return g;
}

std::vector<GeomPiece> makeGeometry(const Shape& s, Scene::PrismMode mode) {
  std::vector<GeomPiece> out;
  switch (s.kind) {
    case ShapeKind::kBox:
      out.push_back({std::make_shared<fcl::Boxd>(s.size.x(), s.size.y(), s.size.z()),
                     Eigen::Isometry3d::Identity()});
      break;
    case ShapeKind::kCylinder:
      out.push_back(
          {std::make_shared<fcl::Cylinderd>(s.radius, s.height), Eigen::Isometry3d::Identity()});
      break;
    case ShapeKind::kSphere:
      out.push_back({std::make_shared<fcl::Sphered>(s.radius), Eigen::Isometry3d::Identity()});
      break;
    case ShapeKind::kPrism: {
      const world::Polygon2 poly = world::cleanPolygon(s.polygon);
      if (world::isConvex(poly)) {
        out.push_back(prismPiece(poly, s.height));
      } else if (mode == Scene::PrismMode::kMesh) {
        out.push_back(prismMesh(poly, s.height));
      } else {
        for (const auto& piece : world::convexDecomposition(poly))
          out.push_back(prismPiece(piece, s.height));
      }
      break;
    }
  }
  return out;
}

struct FclObject {
  std::unique_ptr<fcl::CollisionObjectd> obj;
  Eigen::Isometry3d offset{Eigen::Isometry3d::Identity()};  // piece in the owner's frame
};

std::vector<FclObject> makeObjects(const Shape& s, Scene::PrismMode mode, void* owner) {
  std::vector<FclObject> out;
  for (auto& g : makeGeometry(s, mode)) {
    FclObject o;
    o.obj = std::make_unique<fcl::CollisionObjectd>(g.geom);
    o.obj->setUserData(owner);
    o.offset = g.offset;
    out.push_back(std::move(o));
  }
  return out;
}

void placeAll(std::vector<FclObject>& objs, const Eigen::Isometry3d& pose) {
  for (auto& o : objs) {
    o.obj->setTransform(pose * o.offset);
    o.obj->computeAABB();
  }
}

}  // namespace

// ---- implementation state -----------------------------------------------------------------------

namespace {

/// A world object's FCL objects.
struct Body {
  std::string id;
  ObjectKind kind{ObjectKind::kStatic};
  std::vector<FclObject> pieces;
  bool attached{false};
  int link{-1};
  Eigen::Isometry3d link_T_object{Eigen::Isometry3d::Identity()};
};

/// A robot part's FCL objects (one per part; prisms may give several).
struct Part {
  int link{0};
  Eigen::Isometry3d link_T_shape{Eigen::Isometry3d::Identity()};
  std::vector<FclObject> pieces;
};

/// The resolved filter of one query.
struct Resolved {
  std::uint8_t groups{kAllGroups};
  bool has_only{false};
  std::vector<const Body*> only;    // sorted
  std::vector<const Body*> ignore;  // sorted
  bool allows(const Body* b) const {
    if (has_only && !std::binary_search(only.begin(), only.end(), b)) return false;
    return ignore.empty() || !std::binary_search(ignore.begin(), ignore.end(), b);
  }
};

/// The robot side of one narrow-phase callback: a query object and its name.
struct CollideData {
  const fcl::CollisionObjectd* query{nullptr};
  const Resolved* filter{nullptr};
  bool stop_at_first{false};
  bool done{false};
  std::vector<const Body*> hits;  // bodies hit by this query object
};

bool collideCallback(fcl::CollisionObjectd* o1, fcl::CollisionObjectd* o2, void* vd) {
  auto* d = static_cast<CollideData*>(vd);
  fcl::CollisionObjectd* other = (o1 == d->query) ? o2 : o1;
  const auto* b = static_cast<const Body*>(other->getUserData());
  if (b == nullptr || !d->filter->allows(b)) return false;
  if (std::find(d->hits.begin(), d->hits.end(), b) != d->hits.end()) return false;  // known hit
  fcl::CollisionRequestd req;
  fcl::CollisionResultd res;
  fcl::collide(o1, o2, req, res);
  if (!res.isCollision()) return false;
  d->hits.push_back(b);
  if (d->stop_at_first) d->done = true;
  return d->done;
}

struct DistanceData {
  const fcl::CollisionObjectd* query{nullptr};
  const Resolved* filter{nullptr};
  double best{std::numeric_limits<double>::infinity()};
  const Body* best_body{nullptr};
  Eigen::Vector3d p_query{Eigen::Vector3d::Zero()}, p_other{Eigen::Vector3d::Zero()};
};

void narrowDistance(const fcl::CollisionObjectd* q, const fcl::CollisionObjectd* other,
                    double& dist, Eigen::Vector3d& pq, Eigen::Vector3d& po) {
  fcl::DistanceRequestd req(true, true);
  fcl::DistanceResultd res;
  fcl::distance(q, other, req, res);
  dist = res.min_distance;
  // FCL 0.7 reports nearest points in the world frame; index 0 belongs to the first argument.
  pq = res.nearest_points[0];
  po = res.nearest_points[1];
  if (dist < 0) {
    // Signed distance is only reliable for primitive/convex pairs; confirm contact and clamp.
    fcl::CollisionRequestd creq;
    fcl::CollisionResultd cres;
    fcl::collide(q, other, creq, cres);
    if (!cres.isCollision()) dist = 0.0;
  }
}

bool distanceCallback(fcl::CollisionObjectd* o1, fcl::CollisionObjectd* o2, void* vd,
                      double& dist) {
  auto* d = static_cast<DistanceData*>(vd);
  fcl::CollisionObjectd* other = (o1 == d->query) ? o2 : o1;
  const auto* b = static_cast<const Body*>(other->getUserData());
  if (b != nullptr && d->filter->allows(b)) {
    double dd = 0;
    Eigen::Vector3d pq, po;
    narrowDistance(d->query, other, dd, pq, po);
    if (dd < d->best) {
      d->best = dd;
      d->best_body = b;
      d->p_query = pq;
      d->p_other = po;
    }
  }
  dist = std::max(d->best, 0.0);
  return d->best <= 0.0;
}

}  // namespace

struct Scene::Impl {
  Options options;
  world::World world;
  std::map<std::string, std::unique_ptr<Body>, std::less<>> bodies;
  /// The attached bodies, in id order: kept so that placing the robot and iterating its pieces
  /// (every query) does not walk the whole object map. Refreshed by every mutation of
  /// `bodies` or of an attachment (refreshAttached()).
  std::vector<Body*> attached_bodies;
  fcl::DynamicAABBTreeCollisionManagerd static_mgr;
  fcl::DynamicAABBTreeCollisionManagerd movable_mgr;
  std::size_t n_static{0}, n_movable{0};

  RobotGeometry robot;
  std::vector<Part> parts;
  std::vector<Eigen::Isometry3d> link_poses;

  std::shared_ptr<const octomap::OcTree> octomap;
  std::unique_ptr<fcl::CollisionObjectd> octree;

  fcl::DynamicAABBTreeCollisionManagerd& managerFor(ObjectKind k) {
    return k == ObjectKind::kStatic ? static_mgr : movable_mgr;
  }

  std::unique_ptr<Body> makeBody(const Object& o) {
    auto b = std::make_unique<Body>();
    b->id = o.id;
    b->kind = o.kind;
    b->pieces = makeObjects(o.shape, options.prism_mode, b.get());
    placeAll(b->pieces, o.pose);
    return b;
  }

  void registerBody(Body& b) {
    auto& m = managerFor(b.kind);
    for (auto& p : b.pieces) m.registerObject(p.obj.get());
    (b.kind == ObjectKind::kStatic ? n_static : n_movable)++;
  }

  void unregisterBody(Body& b) {
    auto& m = managerFor(b.kind);
    for (auto& p : b.pieces) m.unregisterObject(p.obj.get());
    (b.kind == ObjectKind::kStatic ? n_static : n_movable)--;
  }

  void rebuildAll() {
    static_mgr.clear();
    movable_mgr.clear();
    n_static = n_movable = 0;
    // Keep attachments whose objects survive.
    std::map<std::string, std::pair<int, Eigen::Isometry3d>> keep;
    for (const auto& [id, b] : bodies) {
      if (b->attached) keep[id] = {b->link, b->link_T_object};
    }
    bodies.clear();
    std::vector<fcl::CollisionObjectd*> st, mv;
    for (const Object& o : world.objects()) {
      auto b = makeBody(o);
      auto k = keep.find(o.id);
      if (k != keep.end() && o.kind == ObjectKind::kMovable) {
        b->attached = true;
        b->link = k->second.first;
        b->link_T_object = k->second.second;
        placeAttached(*b);
      } else {
        auto& v = o.kind == ObjectKind::kStatic ? st : mv;
        for (auto& p : b->pieces) v.push_back(p.obj.get());
        (o.kind == ObjectKind::kStatic ? n_static : n_movable)++;
      }
      bodies.emplace(o.id, std::move(b));
    }
    // Bulk registration builds a balanced tree at once.
    static_mgr.registerObjects(st);
    movable_mgr.registerObjects(mv);
    static_mgr.setup();
    movable_mgr.setup();
    refreshAttached();
  }

  void refreshAttached() {
    attached_bodies.clear();
    for (auto& [id, b] : bodies) {
      if (b->attached) attached_bodies.push_back(b.get());
    }
  }

  void placeAttached(Body& b) {
    const Eigen::Isometry3d& L = b.link >= 0 && b.link < static_cast<int>(link_poses.size())
                                     ? link_poses[static_cast<size_t>(b.link)]
                                     : Eigen::Isometry3d::Identity();
    placeAll(b.pieces, L * b.link_T_object);
  }

  void placeParts() {
    for (auto& p : parts)
      placeAll(p.pieces, link_poses[static_cast<size_t>(p.link)] * p.link_T_shape);
    for (Body* b : attached_bodies) placeAttached(*b);
  }

  Resolved resolve(const Filter& f) const {
    Resolved r;
    r.groups = f.groups;
    r.has_only = !f.only.empty();
    for (const auto& id : f.only) {
      auto it = bodies.find(id);
      if (it != bodies.end()) r.only.push_back(it->second.get());
    }
    for (const auto& id : f.ignore) {
      auto it = bodies.find(id);
      if (it != bodies.end()) r.ignore.push_back(it->second.get());
    }
    std::sort(r.only.begin(), r.only.end());
    std::sort(r.ignore.begin(), r.ignore.end());
    return r;
  }

  /// Runs a collision query for one FCL object against the enabled groups; returns true when
  /// the octree was hit. Hits go into d.hits.
  bool collideOne(fcl::CollisionObjectd* q, const Resolved& r, CollideData& d) const {
    d.query = q;
    d.filter = &r;
    if ((r.groups & kStaticObjects) && !d.done && n_static > 0)
      static_mgr.collide(q, &d, collideCallback);
    if ((r.groups & kMovableObjects) && !d.done && n_movable > 0)
      movable_mgr.collide(q, &d, collideCallback);
    if ((r.groups & kUnknownSpace) && !d.done && octree && !r.has_only) {
      fcl::CollisionRequestd req;
      fcl::CollisionResultd res;
      fcl::collide(q, octree.get(), req, res);
      if (res.isCollision()) {
        if (d.stop_at_first) d.done = true;
        return true;
      }
    }
    return false;
  }

  /// Calls fn(name, FclObject&) for every robot part piece and attached-object piece.
  template <typename Fn>
  void forEachRobotPiece(Fn&& fn) const {
    for (const auto& p : parts) {
      for (const auto& piece : p.pieces) {
        if (fn(robot.links[static_cast<size_t>(p.link)], *piece.obj)) return;
      }
    }
    for (const Body* b : attached_bodies) {
      for (const auto& piece : b->pieces) {
        if (fn(b->id, *piece.obj)) return;
      }
    }
  }

  void distanceOne(fcl::CollisionObjectd* q, const Resolved& r, DistanceResult& best,
                   const std::string& robot_name) const {
    DistanceData d;
    d.query = q;
    d.filter = &r;
    d.best = best.distance;
    if ((r.groups & kStaticObjects) && n_static > 0) static_mgr.distance(q, &d, distanceCallback);
    if ((r.groups & kMovableObjects) && n_movable > 0 && d.best > 0)
      movable_mgr.distance(q, &d, distanceCallback);
    if (d.best_body != nullptr && d.best < best.distance) {
      best.distance = d.best;
      best.object = d.best_body->id;
      best.robot = robot_name;
      best.point_on_robot = d.p_query;
      best.point_on_object = d.p_other;
    }
    if ((r.groups & kUnknownSpace) && octree && !r.has_only && best.distance > 0) {
      double dd = 0;
      Eigen::Vector3d pq, po;
      narrowDistance(q, octree.get(), dd, pq, po);
      if (dd < best.distance) {
        best.distance = dd;
        best.object = kUnknownSpaceId;
        best.robot = robot_name;
        best.point_on_robot = pq;
        best.point_on_object = po;
      }
    }
  }
};

// ---- RobotGeometry ------------------------------------------------------------------------------

RobotGeometry RobotGeometry::disc(double radius, double height) {
  RobotGeometry g;
  g.links = {"base"};
  RobotPart p;
  p.link = 0;
  p.shape = Shape::cylinder(radius, height);
  p.link_T_shape.translation() = Eigen::Vector3d(0, 0, 0.5 * height);
  g.parts.push_back(p);
  return g;
}

RobotGeometry RobotGeometry::box(double sx, double sy, double sz) {
  RobotGeometry g;
  g.links = {"base"};
  RobotPart p;
  p.link = 0;
  p.shape = Shape::box(sx, sy, sz);
  p.link_T_shape.translation() = Eigen::Vector3d(0, 0, 0.5 * sz);
  g.parts.push_back(p);
  return g;
}

// ---- Scene: lifecycle ---------------------------------------------------------------------------

Scene::Scene() : Scene(Options{}) {}
Scene::Scene(Options options) : impl_(std::make_unique<Impl>()) { impl_->options = options; }
Scene::Scene(const world::World& w, Options options) : Scene(options) { setWorld(w); }
Scene::~Scene() = default;
Scene::Scene(Scene&&) noexcept = default;
Scene& Scene::operator=(Scene&&) noexcept = default;

Scene::Scene(const Scene& other) : Scene(other.impl_->options) {
  const Impl& o = *other.impl_;
  impl_->world = o.world;
  impl_->rebuildAll();
  if (!o.robot.links.empty()) {
    setRobot(o.robot);
    setLinkPoses(o.link_poses);
  }
  for (const auto& [id, b] : o.bodies) {
    if (b->attached) {
      Body& mine = *impl_->bodies.at(id);
      impl_->unregisterBody(mine);
      mine.attached = true;
      mine.link = b->link;
      mine.link_T_object = b->link_T_object;
      impl_->placeAttached(mine);
    }
  }
  impl_->refreshAttached();
  if (o.octomap) {
    impl_->octomap = o.octomap;
    impl_->octree =
        std::make_unique<fcl::CollisionObjectd>(std::make_shared<fcl::OcTreed>(o.octomap));
    impl_->octree->computeAABB();
  }
}

Scene& Scene::operator=(const Scene& other) {
  if (this != &other) *this = Scene(other);
  return *this;
}

// ---- Scene: world -------------------------------------------------------------------------------

void Scene::setWorld(const world::World& w) {
  impl_->world = w;
  impl_->rebuildAll();
}

void Scene::syncWorld(const world::World& w) {
  Impl& m = *impl_;
  const world::WorldDiff d = world::diff(m.world, w);
  m.world = w;
  for (const auto& id : d.removed) {
    auto it = m.bodies.find(id);
    if (it == m.bodies.end()) continue;
    if (!it->second->attached) m.unregisterBody(*it->second);
    m.bodies.erase(it);
  }
  for (const auto& o : d.added) {
    auto b = m.makeBody(o);
    m.registerBody(*b);
    m.bodies[o.id] = std::move(b);
  }
  for (const auto& mv : d.moved) {
    auto it = m.bodies.find(mv.id);
    if (it == m.bodies.end()) continue;
    Body& b = *it->second;
    if (b.attached) continue;  // follows its link
    placeAll(b.pieces, mv.pose);
    auto& mgr = m.managerFor(b.kind);
    for (auto& p : b.pieces) mgr.update(p.obj.get());
  }
  for (const auto& o : d.changed) {
    auto it = m.bodies.find(o.id);
    bool attached = false;
    int link = -1;
    Eigen::Isometry3d lto = Eigen::Isometry3d::Identity();
    if (it != m.bodies.end()) {
      attached = it->second->attached;
      link = it->second->link;
      lto = it->second->link_T_object;
      if (!attached) m.unregisterBody(*it->second);
      m.bodies.erase(it);
    }
    auto b = m.makeBody(o);
    if (attached && o.kind == ObjectKind::kMovable) {
      b->attached = true;
      b->link = link;
      b->link_T_object = lto;
      m.placeAttached(*b);
    } else {
      m.registerBody(*b);
    }
    m.bodies[o.id] = std::move(b);
  }
  m.refreshAttached();
}

const world::World& Scene::world() const { return impl_->world; }
std::size_t Scene::staticCount() const { return impl_->n_static; }
std::size_t Scene::movableCount() const { return impl_->n_movable; }
std::size_t Scene::fclObjectCount() const {
  return impl_->static_mgr.size() + impl_->movable_mgr.size();
}

// ---- Scene: robot -------------------------------------------------------------------------------

void Scene::setRobot(RobotGeometry g) {
  const int nl = static_cast<int>(g.links.size());
  for (size_t i = 0; i < g.parts.size(); ++i) {
    const RobotPart& p = g.parts[i];
    if (p.link < 0 || p.link >= nl) {
      throw std::invalid_argument("Scene::setRobot: part " + std::to_string(i) +
                                  " names link index " + std::to_string(p.link) + ", robot has " +
                                  std::to_string(nl) + " links");
    }
    if (auto why = p.shape.invalidReason()) {
      throw std::invalid_argument("Scene::setRobot: part " + std::to_string(i) + " on link '" +
                                  g.links[static_cast<size_t>(p.link)] + "': " + *why);
    }
  }
  for (const auto& [a, b] : g.allowed_self_collisions) {
    if (a < 0 || a >= nl || b < 0 || b >= nl) {
      throw std::invalid_argument("Scene::setRobot: allowed self-collision pair (" +
                                  std::to_string(a) + ", " + std::to_string(b) + ") out of range");
    }
  }
  Impl& m = *impl_;
  m.parts.clear();
  for (const auto& p : g.parts) {
    Part part;
    part.link = p.link;
    part.link_T_shape = p.link_T_shape;
    part.pieces = makeObjects(p.shape, m.options.prism_mode, nullptr);
    m.parts.push_back(std::move(part));
  }
  // Attachments refer to link indices of the previous robot: drop them.
  for (auto& [id, b] : m.bodies) {
    if (b->attached) {
      b->attached = false;
      placeAll(b->pieces, m.world.object(id).pose);
      m.registerBody(*b);
    }
  }
  m.attached_bodies.clear();
  m.robot = std::move(g);
  m.link_poses.assign(m.robot.links.size(), Eigen::Isometry3d::Identity());
  m.placeParts();
}

const RobotGeometry& Scene::robot() const { return impl_->robot; }

void Scene::setLinkPoses(std::span<const Eigen::Isometry3d> poses) {
  Impl& m = *impl_;
  if (poses.size() != m.link_poses.size()) {
    throw std::invalid_argument("Scene::setLinkPoses: got " + std::to_string(poses.size()) +
                                " poses, robot has " + std::to_string(m.link_poses.size()) +
                                " links");
  }
  std::copy(poses.begin(), poses.end(), m.link_poses.begin());
  m.placeParts();
}

void Scene::setBasePose(const Pose2D& pose) {
  Impl& m = *impl_;
  if (m.link_poses.empty()) throw std::invalid_argument("Scene::setBasePose: no robot set");
  m.link_poses[0] = pose.toIsometry();
  m.placeParts();
}

Status Scene::attach(const std::string& object_id, const std::string& link,
                     const Eigen::Isometry3d& link_T_object) {
  Impl& m = *impl_;
  auto it = m.bodies.find(object_id);
  if (it == m.bodies.end())
    return Error(ErrorCode::kNotFound, "attach: no object '" + object_id + "'");
  Body& b = *it->second;
  if (b.kind != ObjectKind::kMovable) {
    return Error(ErrorCode::kInvalidArgument, "attach: object '" + object_id + "' is static");
  }
  if (b.attached)
    return Error(ErrorCode::kInvalidArgument,
                 "attach: object '" + object_id + "' is already attached");
  auto li = std::find(m.robot.links.begin(), m.robot.links.end(), link);
  if (li == m.robot.links.end())
    return Error(ErrorCode::kNotFound, "attach: robot has no link '" + link + "'");
  m.unregisterBody(b);
  b.attached = true;
  b.link = static_cast<int>(li - m.robot.links.begin());
  b.link_T_object = link_T_object;
  m.placeAttached(b);
  m.refreshAttached();
  return Status::Ok();
}

Status Scene::attachHeld() {
  const auto& h = impl_->world.held();
  if (!h) return Status::Ok();
  return attach(h->object_id, h->link, h->link_T_object);
}

Status Scene::detach(const std::string& object_id) {
  Impl& m = *impl_;
  auto it = m.bodies.find(object_id);
  if (it == m.bodies.end() || !it->second->attached) {
    return Error(ErrorCode::kNotFound, "detach: object '" + object_id + "' is not attached");
  }
  Body& b = *it->second;
  b.attached = false;
  placeAll(b.pieces, m.world.object(object_id).pose);
  m.registerBody(b);
  m.refreshAttached();
  return Status::Ok();
}

std::vector<std::string> Scene::attachedObjects() const {
  std::vector<std::string> out;
  for (const Body* b : impl_->attached_bodies) out.push_back(b->id);
  return out;
}

// ---- Scene: unknown space -----------------------------------------------------------------------

void Scene::setUnknownSpace(const std::vector<Eigen::Vector3d>& centres, double resolution) {
  if (!(resolution > 0) || !std::isfinite(resolution)) {
    throw std::invalid_argument("Scene::setUnknownSpace: resolution must be positive, got " +
                                std::to_string(resolution));
  }
  auto tree = std::make_shared<octomap::OcTree>(resolution);
  for (const auto& c : centres) {
    if (!c.allFinite()) continue;
    tree->updateNode(octomap::point3d(static_cast<float>(c.x()), static_cast<float>(c.y()),
                                      static_cast<float>(c.z())),
                     true);
  }
  impl_->octomap = tree;
  impl_->octree =
      std::make_unique<fcl::CollisionObjectd>(std::make_shared<fcl::OcTreed>(impl_->octomap));
  impl_->octree->computeAABB();
}

Status Scene::setUnknownSpaceFromOctomapBinary(const std::string& bytes) {
  auto tree = std::make_shared<octomap::OcTree>(0.1);
  std::istringstream in(bytes);
  if (!tree->readBinary(in)) {
    return Error(ErrorCode::kParseError, "unknown space: not an OctoMap binary stream");
  }
  impl_->octomap = tree;
  impl_->octree =
      std::make_unique<fcl::CollisionObjectd>(std::make_shared<fcl::OcTreed>(impl_->octomap));
  impl_->octree->computeAABB();
  return Status::Ok();
}

void Scene::clearUnknownSpace() {
  impl_->octree.reset();
  impl_->octomap.reset();
}

bool Scene::hasUnknownSpace() const { return impl_->octree != nullptr; }

// ---- Scene: queries -----------------------------------------------------------------------------

namespace {
std::vector<std::string> idsOf(std::vector<const Body*>& hits, bool unknown) {
  std::vector<std::string> out;
  out.reserve(hits.size() + (unknown ? 1 : 0));
  for (const Body* b : hits) out.push_back(b->id);
  if (unknown) out.emplace_back(kUnknownSpaceId);
  std::sort(out.begin(), out.end());
  out.erase(std::unique(out.begin(), out.end()), out.end());
  return out;
}
}  // namespace

bool Scene::robotInCollision(const Filter& filter) const {
  const Resolved r = impl_->resolve(filter);
  CollideData d;
  d.stop_at_first = true;
  impl_->forEachRobotPiece([&](const std::string&, fcl::CollisionObjectd& obj) {
    impl_->collideOne(&obj, r, d);
    return d.done;
  });
  return d.done;
}

std::vector<std::string> Scene::robotCollisions(const Filter& filter) const {
  const Resolved r = impl_->resolve(filter);
  std::vector<const Body*> all;
  bool unknown = false;
  impl_->forEachRobotPiece([&](const std::string&, fcl::CollisionObjectd& obj) {
    CollideData d;
    d.hits = all;  // skip narrow phase against bodies already known to collide
    unknown |= impl_->collideOne(&obj, r, d);
    all = std::move(d.hits);
    return false;
  });
  return idsOf(all, unknown);
}

std::vector<Contact> Scene::robotContacts(const Filter& filter) const {
  const Resolved r = impl_->resolve(filter);
  std::vector<Contact> out;
  impl_->forEachRobotPiece([&](const std::string& name, fcl::CollisionObjectd& obj) {
    CollideData d;
    const bool unknown = impl_->collideOne(&obj, r, d);
    for (const Body* b : d.hits) out.push_back(Contact{name, b->id});
    if (unknown) out.push_back(Contact{name, kUnknownSpaceId});
    return false;
  });
  std::sort(out.begin(), out.end(), [](const Contact& a, const Contact& b) {
    return std::tie(a.robot, a.object) < std::tie(b.robot, b.object);
  });
  out.erase(std::unique(out.begin(), out.end()), out.end());
  return out;
}

std::vector<std::pair<std::string, std::string>> Scene::selfCollisions() const {
  const Impl& m = *impl_;
  struct Item {
    std::string name;
    int link;
    bool attached;
    const fcl::CollisionObjectd* obj;
  };
  std::vector<Item> items;
  for (const auto& p : m.parts) {
    for (const auto& piece : p.pieces)
      items.push_back({m.robot.links[static_cast<size_t>(p.link)], p.link, false, piece.obj.get()});
  }
  for (const Body* b : m.attached_bodies) {
    for (const auto& piece : b->pieces) items.push_back({b->id, b->link, true, piece.obj.get()});
  }
  auto allowed = [&](int a, int b) {
    if (a == b) return true;
    for (const auto& [x, y] : m.robot.allowed_self_collisions) {
      if ((x == a && y == b) || (x == b && y == a)) return true;
    }
    return false;
  };
  std::vector<std::pair<std::string, std::string>> out;
  for (size_t i = 0; i < items.size(); ++i) {
    for (size_t j = i + 1; j < items.size(); ++j) {
      const Item& a = items[i];
      const Item& b = items[j];
      if (a.name == b.name) continue;
      if (!a.attached && !b.attached && allowed(a.link, b.link)) continue;
      // An attached object may touch the link holding it and that link's allowed neighbours.
      if (a.attached != b.attached && allowed(a.link, b.link)) continue;
      if (!a.obj->getAABB().overlap(b.obj->getAABB())) continue;
      fcl::CollisionRequestd req;
      fcl::CollisionResultd res;
      fcl::collide(a.obj, b.obj, req, res);
      if (res.isCollision()) out.emplace_back(std::min(a.name, b.name), std::max(a.name, b.name));
    }
  }
  std::sort(out.begin(), out.end());
  out.erase(std::unique(out.begin(), out.end()), out.end());
  return out;
}

DistanceResult Scene::robotDistance(const Filter& filter) const {
  const Resolved r = impl_->resolve(filter);
  DistanceResult best;
  impl_->forEachRobotPiece([&](const std::string& name, fcl::CollisionObjectd& obj) {
    impl_->distanceOne(&obj, r, best, name);
    return best.distance <= 0;
  });
  return best;
}

bool Scene::shapeInCollision(const Shape& shape, const Eigen::Isometry3d& pose,
                             const Filter& filter) const {
  if (auto why = shape.invalidReason())
    throw std::invalid_argument("Scene::shapeInCollision: " + *why);
  auto objs = makeObjects(shape, impl_->options.prism_mode, nullptr);
  placeAll(objs, pose);
  const Resolved r = impl_->resolve(filter);
  CollideData d;
  d.stop_at_first = true;
  for (auto& o : objs) {
    impl_->collideOne(o.obj.get(), r, d);
    if (d.done) break;
  }
  return d.done;
}

std::vector<std::string> Scene::shapeCollisions(const Shape& shape, const Eigen::Isometry3d& pose,
                                                const Filter& filter) const {
  if (auto why = shape.invalidReason())
    throw std::invalid_argument("Scene::shapeCollisions: " + *why);
  auto objs = makeObjects(shape, impl_->options.prism_mode, nullptr);
  placeAll(objs, pose);
  const Resolved r = impl_->resolve(filter);
  std::vector<const Body*> all;
  bool unknown = false;
  for (auto& o : objs) {
    CollideData d;
    d.hits = all;
    unknown |= impl_->collideOne(o.obj.get(), r, d);
    all = std::move(d.hits);
  }
  return idsOf(all, unknown);
}

DistanceResult Scene::shapeDistance(const Shape& shape, const Eigen::Isometry3d& pose,
                                    const Filter& filter) const {
  if (auto why = shape.invalidReason())
    throw std::invalid_argument("Scene::shapeDistance: " + *why);
  auto objs = makeObjects(shape, impl_->options.prism_mode, nullptr);
  placeAll(objs, pose);
  const Resolved r = impl_->resolve(filter);
  DistanceResult best;
  for (auto& o : objs) {
    impl_->distanceOne(o.obj.get(), r, best, "");
    if (best.distance <= 0) break;
  }
  return best;
}

}  // namespace tamp::collision
