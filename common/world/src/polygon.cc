#include "tamp/world/polygon.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <stdexcept>
#include <unordered_map>

namespace tamp::world {

namespace {

double cross(const Point2& o, const Point2& a, const Point2& b) {
  return (a.x() - o.x()) * (b.y() - o.y()) - (a.y() - o.y()) * (b.x() - o.x());
}

bool samePoint(const Point2& a, const Point2& b) { return a.x() == b.x() && a.y() == b.y(); }

// Inclusive point-in-triangle for a counter-clockwise triangle.
bool inTriangle(const Point2& a, const Point2& b, const Point2& c, const Point2& p) {
  return cross(a, b, p) >= 0 && cross(b, c, p) >= 0 && cross(c, a, p) >= 0;
}

}  // namespace

double signedArea(const Polygon2& poly) {
  const size_t n = poly.size();
  if (n < 3) return 0.0;
  double a = 0.0;
  for (size_t i = 0, j = n - 1; i < n; j = i++) {
    a += poly[j].x() * poly[i].y() - poly[i].x() * poly[j].y();
  }
  return 0.5 * a;
}

Point2 areaCentroid(const Polygon2& poly) {
  if (poly.empty()) throw std::invalid_argument("areaCentroid: empty polygon");
  const size_t n = poly.size();
  // Shift to the first vertex for numerical stability with large coordinates.
  const Point2 o = poly[0];
  double a2 = 0.0;
  Point2 c = Point2::Zero();
  for (size_t i = 0, j = n - 1; i < n; j = i++) {
    const Point2 p = poly[j] - o, q = poly[i] - o;
    const double w = p.x() * q.y() - q.x() * p.y();
    a2 += w;
    c += (p + q) * w;
  }
  if (std::abs(a2) < 1e-15) {
    Point2 m = Point2::Zero();
    for (const auto& p : poly) m += p;
    return m / static_cast<double>(n);
  }
  return o + c / (3.0 * a2);
}

bool isConvex(const Polygon2& poly) {
  const size_t n = poly.size();
  if (n < 3 || std::abs(signedArea(poly)) < 1e-15) return false;
  int sign = 0;
  for (size_t i = 0; i < n; ++i) {
    const double c = cross(poly[i], poly[(i + 1) % n], poly[(i + 2) % n]);
    const double scale =
        (poly[(i + 1) % n] - poly[i]).norm() * (poly[(i + 2) % n] - poly[(i + 1) % n]).norm();
    if (std::abs(c) <= 1e-12 * scale) continue;
    const int s = c > 0 ? 1 : -1;
    if (sign == 0)
      sign = s;
    else if (s != sign)
      return false;
  }
  // Turning in one direction is not enough for a star polygon: the total turn must be 2*pi.
  double turn = 0.0;
  for (size_t i = 0; i < n; ++i) {
    const Point2 d1 = poly[(i + 1) % n] - poly[i], d2 = poly[(i + 2) % n] - poly[(i + 1) % n];
    if (d1.squaredNorm() == 0.0 || d2.squaredNorm() == 0.0) continue;
    turn += std::atan2(d1.x() * d2.y() - d1.y() * d2.x(), d1.dot(d2));
  }
  return std::abs(std::abs(turn) - 2 * M_PI) < 1e-6;
}

bool containsPoint(const Polygon2& poly, const Point2& p) {
  bool inside = false;
  const size_t n = poly.size();
  for (size_t i = 0, j = n - 1; i < n; j = i++) {
    const Point2& a = poly[i];
    const Point2& b = poly[j];
    if ((a.y() > p.y()) != (b.y() > p.y()) &&
        p.x() < (b.x() - a.x()) * (p.y() - a.y()) / (b.y() - a.y()) + a.x()) {
      inside = !inside;
    }
  }
  return inside;
}

double segmentDistance(const Point2& p, const Point2& a, const Point2& b) {
  const Point2 ab = b - a;
  const double l2 = ab.squaredNorm();
  const double t = l2 > 0.0 ? std::clamp((p - a).dot(ab) / l2, 0.0, 1.0) : 0.0;
  return (a + t * ab - p).norm();
}

double polygonDistance(const Polygon2& poly, const Point2& p) {
  if (containsPoint(poly, p)) return 0.0;
  double d = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < poly.size(); ++i) d = std::min(d, segmentDistance(p, poly[i], poly[(i + 1) % poly.size()]));
  return d;
}

double circumradius(const Polygon2& poly, const Point2& centre) {
  double r = 0.0;
  for (const auto& p : poly) r = std::max(r, (p - centre).norm());
  return r;
}

Polygon2 cleanPolygon(const Polygon2& poly, double eps) {
  Polygon2 out;
  out.reserve(poly.size());
  for (const auto& p : poly) {
    if (!p.allFinite()) continue;
    if (out.empty() || (p - out.back()).norm() > eps) out.push_back(p);
  }
  while (out.size() > 1 && (out.front() - out.back()).norm() <= eps) out.pop_back();
  // Remove vertices lying on the segment between their neighbours (repeat: removal can expose
  // more).
  bool changed = true;
  while (changed && out.size() >= 3) {
    changed = false;
    for (size_t i = 0; i < out.size() && out.size() >= 3; ++i) {
      const size_t n = out.size();
      const Point2& a = out[(i + n - 1) % n];
      const Point2& b = out[i];
      const Point2& c = out[(i + 1) % n];
      const double len = (c - a).norm();
      const bool collinear = std::abs(cross(a, b, c)) <= eps * std::max(len, 1.0);
      const bool between = (b - a).dot(c - a) > 0 && (b - c).dot(a - c) > 0;
      if (collinear && between) {
        out.erase(out.begin() + static_cast<std::ptrdiff_t>(i));
        changed = true;
        --i;
      }
    }
  }
  if (signedArea(out) < 0) std::reverse(out.begin(), out.end());
  return out;
}

std::vector<std::array<int, 3>> triangulate(const Polygon2& poly) {
  std::vector<std::array<int, 3>> tris;
  const int n = static_cast<int>(poly.size());
  if (n < 3) return tris;
  tris.reserve(static_cast<size_t>(n - 2));
  // Work on a counter-clockwise ring; map back to the caller's indices.
  std::vector<int> order(static_cast<size_t>(n));
  for (int i = 0; i < n; ++i) order[static_cast<size_t>(i)] = i;
  if (signedArea(poly) < 0) std::reverse(order.begin(), order.end());
  std::vector<int> prev(static_cast<size_t>(n)), next(static_cast<size_t>(n));
  for (int i = 0; i < n; ++i) {
    prev[static_cast<size_t>(i)] = (i + n - 1) % n;
    next[static_cast<size_t>(i)] = (i + 1) % n;
  }
  auto P = [&](int k) -> const Point2& {
    return poly[static_cast<size_t>(order[static_cast<size_t>(k)])];
  };
  auto pv = [&](int k) { return prev[static_cast<size_t>(k)]; };
  auto nx = [&](int k) { return next[static_cast<size_t>(k)]; };
  auto remove = [&](int k) {
    next[static_cast<size_t>(pv(k))] = nx(k);
    prev[static_cast<size_t>(nx(k))] = pv(k);
  };
  auto isEar = [&](int k) {
    const int ia = pv(k), ic = nx(k);
    const Point2& a = P(ia);
    const Point2& b = P(k);
    const Point2& c = P(ic);
    if (cross(a, b, c) <= 0) return false;  // reflex or degenerate
    for (int p = nx(ic); p != ia; p = nx(p)) {
      const Point2& q = P(p);
      if (samePoint(q, a) || samePoint(q, b) || samePoint(q, c)) continue;
      // Only reflex (or flat) vertices can lie inside an ear of a simple polygon.
      if (cross(P(pv(p)), q, P(nx(p))) <= 0 && inTriangle(a, b, c, q)) return false;
    }
    return true;
  };

  int remaining = n;
  int cur = 0;
  int stall = 0;  // vertices examined since the last clip
  while (remaining > 3) {
    if (isEar(cur)) {
      tris.push_back({order[static_cast<size_t>(pv(cur))], order[static_cast<size_t>(cur)],
                      order[static_cast<size_t>(nx(cur))]});
      const int nxt = nx(cur);
      remove(cur);
      --remaining;
      cur = nxt;
      stall = 0;
      continue;
    }
    cur = nx(cur);
    if (++stall < remaining) continue;
    // A full turn without an ear: drop a flat vertex (collinear or a zero-width spike), else clip
    // the first convex vertex regardless of the containment test (input not simple).
    int pick = -1;
    int k = cur;
    for (int i = 0; i < remaining; ++i, k = nx(k)) {
      if (std::abs(cross(P(pv(k)), P(k), P(nx(k)))) <= 1e-18) {
        pick = k;
        break;
      }
    }
    if (pick >= 0) {
      tris.push_back({order[static_cast<size_t>(pv(pick))], order[static_cast<size_t>(pick)],
                      order[static_cast<size_t>(nx(pick))]});
    } else {
      k = cur;
      for (int i = 0; i < remaining; ++i, k = nx(k)) {
        if (cross(P(pv(k)), P(k), P(nx(k))) > 0) {
          pick = k;
          break;
        }
      }
      if (pick < 0) pick = cur;
      tris.push_back({order[static_cast<size_t>(pv(pick))], order[static_cast<size_t>(pick)],
                      order[static_cast<size_t>(nx(pick))]});
    }
    cur = nx(pick);
    remove(pick);
    --remaining;
    stall = 0;
  }
  tris.push_back({order[static_cast<size_t>(pv(cur))], order[static_cast<size_t>(cur)],
                  order[static_cast<size_t>(nx(cur))]});
  return tris;
}

std::vector<Polygon2> convexDecomposition(const Polygon2& input) {
  std::vector<Polygon2> out;
  const Polygon2 poly = cleanPolygon(input);
  if (poly.size() < 3) return out;
  if (isConvex(poly)) {
    out.push_back(poly);
    return out;
  }
  const auto tris = triangulate(poly);
  // Pieces as index rings; drop zero-area triangles (slits, flat vertices).
  std::vector<std::vector<int>> pieces;
  pieces.reserve(tris.size());
  for (const auto& t : tris) {
    const double a = cross(poly[static_cast<size_t>(t[0])], poly[static_cast<size_t>(t[1])],
                           poly[static_cast<size_t>(t[2])]);
    if (a > 1e-14) pieces.push_back({t[0], t[1], t[2]});
  }
  auto key = [](int u, int v) {
    return (static_cast<uint64_t>(static_cast<uint32_t>(u)) << 32) | static_cast<uint32_t>(v);
  };
  std::unordered_map<uint64_t, int> owner;  // directed edge -> piece
  for (int p = 0; p < static_cast<int>(pieces.size()); ++p) {
    const auto& r = pieces[static_cast<size_t>(p)];
    for (size_t i = 0; i < r.size(); ++i) owner[key(r[i], r[(i + 1) % r.size()])] = p;
  }
  std::vector<std::pair<int, int>> diagonals;
  for (const auto& [k, p] : owner) {
    const int u = static_cast<int>(k >> 32), v = static_cast<int>(k & 0xffffffffu);
    if (u < v && owner.count(key(v, u))) diagonals.emplace_back(u, v);
  }
  std::sort(diagonals.begin(), diagonals.end());  // deterministic result
  std::vector<bool> alive(pieces.size(), true);
  auto toPoly = [&](const std::vector<int>& r) {
    Polygon2 q;
    q.reserve(r.size());
    for (int i : r) q.push_back(poly[static_cast<size_t>(i)]);
    return q;
  };
  for (const auto& [u, v] : diagonals) {
    const auto pu = owner.find(key(u, v));
    const auto pv = owner.find(key(v, u));
    if (pu == owner.end() || pv == owner.end()) continue;
    const int a = pu->second, b = pv->second;
    if (a == b) continue;
    const auto& A = pieces[static_cast<size_t>(a)];
    const auto& B = pieces[static_cast<size_t>(b)];
    // A contains u->v: rotate to start at v (ends at u). B contains v->u: rotate to start at u.
    auto ia = std::find(A.begin(), A.end(), v);
    auto ib = std::find(B.begin(), B.end(), u);
    std::vector<int> merged;
    merged.reserve(A.size() + B.size() - 2);
    for (size_t i = 0; i < A.size(); ++i) {
      merged.push_back(A[(static_cast<size_t>(ia - A.begin()) + i) % A.size()]);
    }
    for (size_t i = 1; i + 1 < B.size(); ++i) {
      merged.push_back(B[(static_cast<size_t>(ib - B.begin()) + i) % B.size()]);
    }
    if (!isConvex(toPoly(merged))) continue;
    owner.erase(key(u, v));
    owner.erase(key(v, u));
    for (size_t i = 0; i < B.size(); ++i) {
      const auto it = owner.find(key(B[i], B[(i + 1) % B.size()]));
      if (it != owner.end() && it->second == b) it->second = a;
    }
    pieces[static_cast<size_t>(a)] = std::move(merged);
    pieces[static_cast<size_t>(b)].clear();
    alive[static_cast<size_t>(b)] = false;
  }
  for (size_t p = 0; p < pieces.size(); ++p) {
    if (!alive[p]) continue;
    Polygon2 q = cleanPolygon(toPoly(pieces[p]));
    if (q.size() >= 3) out.push_back(std::move(q));
  }
  return out;
}

std::optional<Polygon2> insetConvex(const Polygon2& convex, double by) {
  const size_t n = convex.size();
  if (n < 3) return std::nullopt;
  // The intersection of the half-planes at least `by` inside each edge (Sutherland-Hodgman: each
  // clip of a convex polygon by a half-plane is convex).
  Polygon2 out = convex;
  for (size_t i = 0; i < n && out.size() >= 3; ++i) {
    const Point2 a = convex[i], d = convex[(i + 1) % n] - a;
    if (d.norm() == 0.0) continue;
    const Point2 inward = Point2(-d.y(), d.x()) / d.norm();
    auto depth = [&](const Point2& p) { return inward.dot(p - a) - by; };
    Polygon2 clipped;
    for (size_t k = 0; k < out.size(); ++k) {
      const Point2& p = out[k];
      const Point2& q = out[(k + 1) % out.size()];
      const double dp = depth(p), dq = depth(q);
      if (dp >= 0.0) clipped.push_back(p);
      if ((dp >= 0.0) != (dq >= 0.0)) clipped.push_back(p + (q - p) * (dp / (dp - dq)));
    }
    out = std::move(clipped);
  }
  out = cleanPolygon(out);
  if (out.size() < 3 || signedArea(out) < 1e-12) return std::nullopt;
  return out;
}

}  // namespace tamp::world

