#include "tamp/render/render.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <memory>

#include <cairo-svg.h>
#include <cairo.h>
#include <fontconfig/fontconfig.h>

namespace tamp::render {

std::optional<Rgba> Rgba::fromHex(const std::string& hex) {
  if ((hex.size() != 7 && hex.size() != 9) || hex[0] != '#') return std::nullopt;
  unsigned v[4] = {0, 0, 0, 255};
  for (size_t i = 0; i < (hex.size() - 1) / 2; ++i) {
    unsigned x = 0;
    for (size_t k = 0; k < 2; ++k) {
      const char c = hex[1 + 2 * i + k];
      x *= 16;
      if (c >= '0' && c <= '9')
        x += static_cast<unsigned>(c - '0');
      else if (c >= 'a' && c <= 'f')
        x += static_cast<unsigned>(c - 'a' + 10);
      else if (c >= 'A' && c <= 'F')
        x += static_cast<unsigned>(c - 'A' + 10);
      else
        return std::nullopt;
    }
    v[i] = x;
  }
  return Rgba{v[0] / 255.0, v[1] / 255.0, v[2] / 255.0, v[3] / 255.0};
}

std::optional<std::string> RenderOptions::invalidReason() const {
  if (!(pixels_per_metre > 0) || !std::isfinite(pixels_per_metre))
    return "pixels_per_metre must be positive";
  if (max_pixels < 16 || max_pixels > 20000) return "max_pixels must be in [16, 20000]";
  if (!(margin_m >= 0) || !std::isfinite(margin_m)) return "margin_m must be >= 0";
  return std::nullopt;
}

void releaseFontCaches() {
  cairo_debug_reset_static_data();
  FcFini();
}

world::Polygon2 objectOutline(const world::Object& o) {
  const Eigen::Vector3d z = o.pose.linear().col(2);
  world::Polygon2 out;
  if (std::abs(z.z()) > 0.999) {  // upright (or upside down): the footprint at the pose
    const Pose2D p = Pose2D::fromIsometry(o.pose);
    const double c = std::cos(p.theta), s = std::sin(p.theta);
    const double flip = z.z() < 0 ? -1.0 : 1.0;  // upside down mirrors y
    for (const auto& v : o.shape.footprint(32)) {
      const double vx = v.x(), vy = flip * v.y();
      out.emplace_back(p.x + c * vx - s * vy, p.y + s * vx + c * vy);
    }
    return out;
  }
  const Aabb b = o.aabb();
  return {{b.min.x(), b.min.y()},
          {b.max.x(), b.min.y()},
          {b.max.x(), b.max.y()},
          {b.min.x(), b.max.y()}};
}

namespace {

world::Polygon2 placed(const world::Polygon2& poly, const Pose2D& p) {
  world::Polygon2 out;
  const double c = std::cos(p.theta), s = std::sin(p.theta);
  for (const auto& v : poly)
    out.emplace_back(p.x + c * v.x() - s * v.y(), p.y + s * v.x() + c * v.y());
  return out;
}

struct Painter {
  cairo_t* cr;
  double ppm;
  double x0, y1;  // world coordinates of the top-left corner of the view
  double margin_px;

  double px(double x) const { return margin_px + (x - x0) * ppm; }
  double py(double y) const { return margin_px + (y1 - y) * ppm; }

  void colour(const Rgba& c) { cairo_set_source_rgba(cr, c.r, c.g, c.b, c.a); }
  void polygonPath(const world::Polygon2& poly) {
    cairo_new_path(cr);
    for (size_t i = 0; i < poly.size(); ++i) {
      if (i == 0)
        cairo_move_to(cr, px(poly[i].x()), py(poly[i].y()));
      else
        cairo_line_to(cr, px(poly[i].x()), py(poly[i].y()));
    }
    cairo_close_path(cr);
  }
  void dash(bool on, double len = 6.0) {
    if (on) {
      const double d[] = {len, len * 0.6};
      cairo_set_dash(cr, d, 2, 0);
    } else {
      cairo_set_dash(cr, nullptr, 0, 0);
    }
  }
  void fillStroke(const world::Polygon2& poly, const std::optional<Rgba>& fill, const Rgba& line,
                  double width, bool dashed = false) {
    if (poly.size() < 2) return;
    polygonPath(poly);
    if (fill) {
      colour(*fill);
      cairo_fill_preserve(cr);
    }
    colour(line);
    cairo_set_line_width(cr, width);
    dash(dashed);
    cairo_stroke(cr);
    dash(false);
  }
  struct Box {
    double x0, y0, x1, y1;
    bool overlaps(const Box& o) const { return x0 < o.x1 && o.x0 < x1 && y0 < o.y1 && o.y0 < y1; }
  };
  std::vector<Box> placed_labels;

  /// A label centred at world (x, y), moved down/up in steps of its height when it would overlap
  /// an earlier label (crowded table tops).
  void text(double x, double y, const std::string& s, double size, const Rgba& c) {
    if (s.empty()) return;
    cairo_select_font_face(cr, "sans-serif", CAIRO_FONT_SLANT_NORMAL, CAIRO_FONT_WEIGHT_NORMAL);
    cairo_set_font_size(cr, size);
    cairo_text_extents_t e;
    cairo_text_extents(cr, s.c_str(), &e);
    double tx = px(x) - e.width / 2 - e.x_bearing;
    double ty = py(y) - e.height / 2 - e.y_bearing;
    const double step = e.height + 3;
    for (int k = 0; k < 9; ++k) {
      const double dy = (k % 2 == 1 ? 1 : -1) * ((k + 1) / 2) * step;
      const Box b{tx + e.x_bearing - 1, ty + dy + e.y_bearing - 1, tx + e.x_bearing + e.width + 1,
                  ty + dy + e.y_bearing + e.height + 1};
      const bool free = std::none_of(placed_labels.begin(), placed_labels.end(),
                                     [&](const Box& o) { return o.overlaps(b); });
      if (free || k == 8) {
        ty += dy;
        placed_labels.push_back(b);
        break;
      }
    }
    // A light halo keeps labels readable over dark shapes.
    cairo_move_to(cr, tx, ty);
    cairo_text_path(cr, s.c_str());
    cairo_set_source_rgba(cr, 1, 1, 1, 0.8);
    cairo_set_line_width(cr, 2.5);
    cairo_stroke(cr);
    cairo_move_to(cr, tx, ty);
    colour(c);
    cairo_show_text(cr, s.c_str());
  }
  void arrow(const Pose2D& p, double len_m, const Rgba& c, double width) {
    const double ex = p.x + len_m * std::cos(p.theta), ey = p.y + len_m * std::sin(p.theta);
    colour(c);
    cairo_set_line_width(cr, width);
    cairo_move_to(cr, px(p.x), py(p.y));
    cairo_line_to(cr, px(ex), py(ey));
    cairo_stroke(cr);
    const double h = 0.35 * len_m;
    for (double s : {+1.0, -1.0}) {
      const double a = p.theta + M_PI + s * 0.45;
      cairo_move_to(cr, px(ex), py(ey));
      cairo_line_to(cr, px(ex + h * std::cos(a)), py(ey + h * std::sin(a)));
    }
    cairo_stroke(cr);
  }
};

struct View {
  Aabb box;
  double ppm{0};
  int width{0}, height{0};
  double margin_px{0};
};

Result<View> computeView(const Drawing& d, const RenderOptions& o) {
  if (auto why = o.invalidReason())
    return Error(ErrorCode::kInvalidArgument, "render options: " + *why);
  Aabb b;
  if (o.view) {
    b = *o.view;
  } else {
    b = d.world.bounds();
    for (const auto& r : d.robots) {
      for (const auto& v : placed(r.polygon, r.pose)) b.extend(Eigen::Vector3d(v.x(), v.y(), 0));
    }
    for (const auto& p : d.paths) {
      for (const auto& q : p.poses) b.extend(Eigen::Vector3d(q.x, q.y, 0));
    }
    for (const auto& l : d.world.locations()) b.extend(Eigen::Vector3d(l.pose.x, l.pose.y, 0));
  }
  if (b.empty() || !b.min.allFinite() || !b.max.allFinite()) {
    return Error(ErrorCode::kInvalidArgument, "nothing to draw (empty view)");
  }
  View v;
  v.box = b;
  const double w = std::max(b.max.x() - b.min.x(), 0.5) + 2 * o.margin_m;
  const double h = std::max(b.max.y() - b.min.y(), 0.5) + 2 * o.margin_m;
  v.ppm = std::min(o.pixels_per_metre, (o.max_pixels - 1) / std::max(w, h));
  v.margin_px = o.margin_m * v.ppm;
  v.width = static_cast<int>(std::ceil(w * v.ppm));
  v.height = static_cast<int>(std::ceil(h * v.ppm)) + 28;  // room for the title / scale bar
  return v;
}

const Rgba kStaticFill{0.30, 0.30, 0.32, 1.0}, kStaticLine{0.10, 0.10, 0.10, 1.0};
const Rgba kMovableFill{0.96, 0.62, 0.18, 0.90}, kMovableLine{0.55, 0.30, 0.02, 1.0};
const Rgba kHiddenLine{0.85, 0.10, 0.10, 1.0}, kHiddenFill{0.85, 0.10, 0.10, 0.10};
const Rgba kTableFill{0.80, 0.66, 0.45, 0.45}, kTableLine{0.55, 0.40, 0.20, 1.0};
const Rgba kFloorFill{0.55, 0.80, 0.50, 0.20}, kFloorLine{0.30, 0.55, 0.25, 1.0};
const Rgba kText{0.08, 0.08, 0.08, 1.0}, kGrid{0.85, 0.85, 0.85, 1.0};

void paint(cairo_t* cr, const Drawing& d, const RenderOptions& o, const View& v) {
  Painter p{cr, v.ppm, v.box.min.x() - o.margin_m, v.box.max.y() + o.margin_m, 0.0, {}};
  const double font = std::clamp(v.ppm * 0.14, 8.0, 15.0);
  // Background and grid.
  cairo_set_source_rgb(cr, 1, 1, 1);
  cairo_paint(cr);
  if (o.show_grid) {
    cairo_set_line_width(cr, 1.0);
    p.colour(kGrid);
    const double xa = std::floor(p.x0), xb = p.x0 + v.width / v.ppm;
    const double ya = p.y1 - v.height / v.ppm, yb = p.y1;
    for (double x = xa; x <= xb; x += 1.0) {
      cairo_move_to(cr, p.px(x), 0);
      cairo_line_to(cr, p.px(x), v.height);
    }
    for (double y = std::floor(ya); y <= yb; y += 1.0) {
      cairo_move_to(cr, 0, p.py(y));
      cairo_line_to(cr, v.width, p.py(y));
    }
    cairo_stroke(cr);
  }
  // Floor regions under everything; table tops over the static bodies, under the items on them.
  auto drawRegions = [&](world::RegionKind kind) {
    if (!o.show_regions) return;
    for (const auto& r : d.world.regions()) {
      if (r.kind != kind) continue;
      const bool table = kind == world::RegionKind::kTable;
      p.fillStroke(r.polygon, table ? kTableFill : kFloorFill, table ? kTableLine : kFloorLine, 1.2,
                   !table);
    }
  };
  drawRegions(world::RegionKind::kFloor);
  // Objects, lowest top first; held object in the robot's colour.
  std::vector<const world::Object*> objs;
  for (const auto& ob : d.world.objects()) {
    if (ob.hidden && !o.show_hidden) continue;
    objs.push_back(&ob);
  }
  std::stable_sort(objs.begin(), objs.end(), [](const world::Object* a, const world::Object* b) {
    if (a->kind != b->kind) return a->kind == world::ObjectKind::kStatic;
    return a->aabb().max.z() < b->aabb().max.z();
  });
  const std::string held = d.world.held() ? d.world.held()->object_id : "";
  const Rgba robot_colour =
      d.robots.empty() ? Rgba{0.10, 0.35, 0.85, 1.0} : d.robots.front().colour;
  bool tables_drawn = false;
  for (const world::Object* ob : objs) {
    if (!tables_drawn && ob->kind == world::ObjectKind::kMovable) {
      drawRegions(world::RegionKind::kTable);
      tables_drawn = true;
    }
    const world::Polygon2 outline = objectOutline(*ob);
    if (ob->hidden) {
      p.fillStroke(outline, kHiddenFill, kHiddenLine, 2.0, true);
    } else if (ob->id == held) {
      p.fillStroke(outline, Rgba{robot_colour.r, robot_colour.g, robot_colour.b, 0.55},
                   robot_colour, 1.5);
    } else if (ob->kind == world::ObjectKind::kStatic) {
      p.fillStroke(outline, kStaticFill, kStaticLine, 1.0);
    } else {
      p.fillStroke(outline, kMovableFill, kMovableLine, 1.2);
    }
  }
  if (!tables_drawn) drawRegions(world::RegionKind::kTable);
  // Locations.
  if (o.show_locations) {
    for (const auto& l : d.world.locations()) {
      p.arrow(l.pose, 0.25, Rgba{0.35, 0.20, 0.60, 1.0}, 1.8);
      cairo_arc(cr, p.px(l.pose.x), p.py(l.pose.y), 2.5, 0, 2 * M_PI);
      cairo_fill(cr);
    }
  }
  // Paths.
  for (const auto& path : d.paths) {
    if (path.poses.empty()) continue;
    if (path.footprint_every_m > 0 && !path.footprint.empty()) {
      double acc = path.footprint_every_m;
      for (size_t i = 0; i < path.poses.size(); ++i) {
        if (i > 0) acc += path.poses[i].distanceTo(path.poses[i - 1]);
        if (acc >= path.footprint_every_m || i + 1 == path.poses.size()) {
          p.fillStroke(placed(path.footprint, path.poses[i]), std::nullopt,
                       Rgba{path.colour.r, path.colour.g, path.colour.b, 0.35}, 1.0);
          acc = 0;
        }
      }
    }
    p.colour(path.colour);
    cairo_set_line_width(cr, path.width_px);
    cairo_set_line_join(cr, CAIRO_LINE_JOIN_ROUND);
    p.dash(path.dashed, 8.0);
    cairo_new_path(cr);
    for (size_t i = 0; i < path.poses.size(); ++i) {
      if (i == 0)
        cairo_move_to(cr, p.px(path.poses[i].x), p.py(path.poses[i].y));
      else
        cairo_line_to(cr, p.px(path.poses[i].x), p.py(path.poses[i].y));
    }
    cairo_stroke(cr);
    p.dash(false);
  }
  // Robots.
  for (const auto& r : d.robots) {
    p.fillStroke(placed(r.polygon, r.pose), Rgba{r.colour.r, r.colour.g, r.colour.b, 0.12},
                 r.colour, 2.0, r.dashed);
    p.arrow(r.pose, 0.3, r.colour, 2.0);
  }
  // Labels last so that nothing covers them.
  if (o.show_labels) {
    for (const world::Object* ob : objs) {
      if (ob->kind == world::ObjectKind::kStatic && objs.size() > 40)
        continue;  // crowded NAMO maps
      const Eigen::Vector2d c = world::areaCentroid(objectOutline(*ob));
      std::string s = ob->id;
      if (ob->hidden)
        s += " (hidden)";
      else if (ob->kind == world::ObjectKind::kMovable) {
        char buf[32];
        std::snprintf(buf, sizeof buf, " %.1f kg", ob->mass);
        s += buf;
      }
      p.text(c.x(), c.y(), s, font * 0.85, ob->hidden ? kHiddenLine : kText);
    }
    if (o.show_regions) {
      for (const auto& r : d.world.regions()) {
        const Eigen::Vector2d c = world::areaCentroid(r.polygon);
        double ymax = -1e18;
        for (const auto& q : r.polygon) ymax = std::max(ymax, q.y());
        p.text(c.x(), ymax - 0.12, r.id, font * 0.8,
               r.kind == world::RegionKind::kTable ? kTableLine : kFloorLine);
      }
    }
    if (o.show_locations) {
      for (const auto& l : d.world.locations()) {
        p.text(l.pose.x, l.pose.y - 0.18, l.id, font * 0.85, Rgba{0.35, 0.20, 0.60, 1.0});
      }
    }
    for (const auto& path : d.paths) {
      if (!path.poses.empty())
        p.text(path.poses.back().x, path.poses.back().y + 0.2, path.label, font, path.colour);
    }
    for (const auto& r : d.robots) p.text(r.pose.x, r.pose.y + 0.45, r.label, font, r.colour);
  }
  // Title and a 1 m scale bar along the bottom.
  cairo_set_source_rgb(cr, 1, 1, 1);
  cairo_rectangle(cr, 0, v.height - 24, v.width, 24);
  cairo_fill(cr);
  cairo_set_source_rgb(cr, 0, 0, 0);
  cairo_set_line_width(cr, 2.0);
  cairo_move_to(cr, 10, v.height - 8);
  cairo_line_to(cr, 10 + v.ppm, v.height - 8);
  cairo_stroke(cr);
  cairo_select_font_face(cr, "sans-serif", CAIRO_FONT_SLANT_NORMAL, CAIRO_FONT_WEIGHT_NORMAL);
  cairo_set_font_size(cr, 11);
  cairo_move_to(cr, 14 + v.ppm, v.height - 5);
  cairo_show_text(cr, "1 m");
  if (!d.title.empty()) {
    // Shrink the title to fit the width (down to 8 pt), then cut it.
    const double room = v.width - (70 + v.ppm);
    std::string title = d.title;
    double size = 13;
    cairo_text_extents_t e;
    for (;;) {
      cairo_set_font_size(cr, size);
      cairo_text_extents(cr, title.c_str(), &e);
      if (e.x_advance <= room || title.size() <= 4) break;
      if (size > 8)
        size -= 0.5;
      else
        title = title.substr(0, title.size() - 4) + "...";
    }
    cairo_move_to(cr, 60 + v.ppm, v.height - 5);
    cairo_show_text(cr, title.c_str());
  }
}

Status checkCairo(cairo_status_t s, const std::filesystem::path& file) {
  if (s == CAIRO_STATUS_SUCCESS) return Status::Ok();
  return Error(ErrorCode::kIo, std::string("cannot write: ") + cairo_status_to_string(s),
               SourceLocation{file.string()});
}

}  // namespace

Status renderPng(const Drawing& d, const std::filesystem::path& file, const RenderOptions& o) {
  auto v = computeView(d, o);
  if (!v) return v.error();
  std::unique_ptr<cairo_surface_t, decltype(&cairo_surface_destroy)> surf(
      cairo_image_surface_create(CAIRO_FORMAT_ARGB32, v->width, v->height), &cairo_surface_destroy);
  if (Status s = checkCairo(cairo_surface_status(surf.get()), file); !s) return s;
  std::unique_ptr<cairo_t, decltype(&cairo_destroy)> cr(cairo_create(surf.get()), &cairo_destroy);
  paint(cr.get(), d, o, *v);
  cairo_surface_flush(surf.get());
  return checkCairo(cairo_surface_write_to_png(surf.get(), file.c_str()), file);
}

Status renderSvg(const Drawing& d, const std::filesystem::path& file, const RenderOptions& o) {
  auto v = computeView(d, o);
  if (!v) return v.error();
  std::unique_ptr<cairo_surface_t, decltype(&cairo_surface_destroy)> surf(
      cairo_svg_surface_create(file.c_str(), v->width, v->height), &cairo_surface_destroy);
  if (Status s = checkCairo(cairo_surface_status(surf.get()), file); !s) return s;
  {
    std::unique_ptr<cairo_t, decltype(&cairo_destroy)> cr(cairo_create(surf.get()), &cairo_destroy);
    paint(cr.get(), d, o, *v);
    if (Status s = checkCairo(cairo_status(cr.get()), file); !s) return s;
  }
  cairo_surface_finish(surf.get());
  return checkCairo(cairo_surface_status(surf.get()), file);
}

Status render(const Drawing& d, const std::filesystem::path& file, const RenderOptions& o) {
  const std::string ext = file.extension().string();
  if (ext == ".png") return renderPng(d, file, o);
  if (ext == ".svg") return renderSvg(d, file, o);
  return Error(ErrorCode::kInvalidArgument,
               "unknown picture format '" + ext + "' (expected .png or .svg)",
               SourceLocation{file.string()});
}

}  // namespace tamp::render
