#include "svg.h"

#include <cctype>
#include <charconv>
#include <cmath>
#include <map>
#include <optional>

#include <tinyxml2.h>
#include <Eigen/Geometry>

#include "tamp/core/xml_error.h"

namespace tamp::world::svg {

namespace {

using Affine = Eigen::Affine2d;

std::string lower(std::string s) {
  for (char& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

std::string trim(const std::string& s) {
  size_t a = 0, b = s.size();
  while (a < b && std::isspace(static_cast<unsigned char>(s[a]))) ++a;
  while (b > a && std::isspace(static_cast<unsigned char>(s[b - 1]))) --b;
  return s.substr(a, b - a);
}

/// "#abc" -> "#aabbcc"; lower case.
std::string normaliseColour(const std::string& in) {
  std::string c = lower(trim(in));
  if (c.size() == 4 && c[0] == '#') c = std::string{'#', c[1], c[1], c[2], c[2], c[3], c[3]};
  return c;
}

/// Scanner over SVG number lists ("1.5e-3-2,.5"): SVG number grammar, no inf/nan/hex.
class Scanner {
 public:
  explicit Scanner(const std::string& s) : s_(s) {}
  void skipSeparators() {
    while (i_ < s_.size() && (std::isspace(static_cast<unsigned char>(s_[i_])) || s_[i_] == ','))
      ++i_;
  }
  bool atEnd() {
    skipSeparators();
    return i_ >= s_.size();
  }
  size_t pos() const { return i_; }
  char peek() {
    skipSeparators();
    return i_ < s_.size() ? s_[i_] : '\0';
  }
  char take() { return s_[i_++]; }
  bool nextIsNumber() {
    const char c = peek();
    return (c >= '0' && c <= '9') || c == '.' || c == '-' || c == '+';
  }
  bool number(double& out) {
    skipSeparators();
    const size_t start = i_;
    size_t j = i_;
    if (j < s_.size() && (s_[j] == '+' || s_[j] == '-')) ++j;
    size_t digits = 0;
    while (j < s_.size() && std::isdigit(static_cast<unsigned char>(s_[j]))) ++j, ++digits;
    if (j < s_.size() && s_[j] == '.') {
      ++j;
      while (j < s_.size() && std::isdigit(static_cast<unsigned char>(s_[j]))) ++j, ++digits;
    }
    if (digits == 0) return false;
    if (j < s_.size() && (s_[j] == 'e' || s_[j] == 'E')) {
      size_t k = j + 1;
      if (k < s_.size() && (s_[k] == '+' || s_[k] == '-')) ++k;
      size_t ed = 0;
      while (k < s_.size() && std::isdigit(static_cast<unsigned char>(s_[k]))) ++k, ++ed;
      if (ed > 0) j = k;
    }
    const char* b = s_.data() + start + (s_[start] == '+' ? 1 : 0);
    const auto r = std::from_chars(b, s_.data() + j, out);
    if (r.ec != std::errc() || !std::isfinite(out)) return false;
    i_ = j;
    return true;
  }

 private:
  const std::string& s_;
  size_t i_{0};
};

Result<Affine> parseTransform(const std::string& text) {
  Affine T = Affine::Identity();
  size_t i = 0;
  while (true) {
    while (i < text.size() && (std::isspace(static_cast<unsigned char>(text[i])) || text[i] == ','))
      ++i;
    if (i >= text.size()) break;
    size_t j = i;
    while (j < text.size() && std::isalpha(static_cast<unsigned char>(text[j]))) ++j;
    const std::string name = text.substr(i, j - i);
    while (j < text.size() && std::isspace(static_cast<unsigned char>(text[j]))) ++j;
    if (j >= text.size() || text[j] != '(')
      return Error(ErrorCode::kParseError, "bad transform '" + text + "'");
    const size_t close = text.find(')', j);
    if (close == std::string::npos)
      return Error(ErrorCode::kParseError, "bad transform '" + text + "': missing ')'");
    const std::string args_text = text.substr(j + 1, close - j - 1);
    Scanner sc(args_text);
    std::vector<double> a;
    double v = 0;
    while (!sc.atEnd()) {
      if (!sc.number(v) || a.size() > 6)
        return Error(ErrorCode::kParseError, "bad transform arguments '" + args_text + "'");
      a.push_back(v);
    }
    Affine M = Affine::Identity();
    const double deg = M_PI / 180.0;
    if (name == "matrix" && a.size() == 6) {
      M.matrix() << a[0], a[2], a[4], a[1], a[3], a[5], 0, 0, 1;
    } else if (name == "translate" && (a.size() == 1 || a.size() == 2)) {
      M.translation() = Eigen::Vector2d(a[0], a.size() == 2 ? a[1] : 0.0);
    } else if (name == "scale" && (a.size() == 1 || a.size() == 2)) {
      M.linear() = Eigen::Vector2d(a[0], a.size() == 2 ? a[1] : a[0]).asDiagonal();
    } else if (name == "rotate" && (a.size() == 1 || a.size() == 3)) {
      const Eigen::Vector2d c =
          a.size() == 3 ? Eigen::Vector2d(a[1], a[2]) : Eigen::Vector2d::Zero();
      M = Eigen::Translation2d(c) * Eigen::Rotation2Dd(a[0] * deg) * Eigen::Translation2d(-c);
    } else if (name == "skewX" && a.size() == 1) {
      M.linear() << 1, std::tan(a[0] * deg), 0, 1;
    } else if (name == "skewY" && a.size() == 1) {
      M.linear() << 1, 0, std::tan(a[0] * deg), 1;
    } else {
      return Error(ErrorCode::kParseError, "unsupported transform '" + name + "' with " +
                                               std::to_string(a.size()) + " arguments");
    }
    T = T * M;
    i = close + 1;
  }
  if (!T.matrix().allFinite())
    return Error(ErrorCode::kParseError, "transform '" + text + "' is not finite");
  return T;
}

struct Flattener {
  int segments;
  std::vector<Polygon2> subpaths;
  Polygon2 cur;
  void moveTo(const Eigen::Vector2d& p) {
    flush();
    cur.push_back(p);
  }
  void lineTo(const Eigen::Vector2d& p) { cur.push_back(p); }
  void cubic(const Eigen::Vector2d& p0, const Eigen::Vector2d& c1, const Eigen::Vector2d& c2,
             const Eigen::Vector2d& p3) {
    if (c1 == p0 && c2 == p3) {  // a straight segment written as a degenerate curve
      cur.push_back(p3);
      return;
    }
    for (int k = 1; k <= segments; ++k) {
      const double t = static_cast<double>(k) / segments, u = 1 - t;
      cur.push_back(u * u * u * p0 + 3 * u * u * t * c1 + 3 * u * t * t * c2 + t * t * t * p3);
    }
  }
  void quadratic(const Eigen::Vector2d& p0, const Eigen::Vector2d& c, const Eigen::Vector2d& p2) {
    for (int k = 1; k <= segments; ++k) {
      const double t = static_cast<double>(k) / segments, u = 1 - t;
      cur.push_back(u * u * p0 + 2 * u * t * c + t * t * p2);
    }
  }
  void flush() {
    if (!cur.empty()) subpaths.push_back(std::move(cur));
    cur.clear();
  }
};

/// Parses path data into subpaths (user units, untransformed). Arcs are refused.
Result<std::vector<Polygon2>> parsePathData(const std::string& d, int segments, size_t max_points) {
  Scanner sc(d);
  Flattener f{segments, {}, {}};
  Eigen::Vector2d p = Eigen::Vector2d::Zero(), start = p, last_ctrl = p;
  char cmd = 0, prev = 0;
  size_t total = 0;
  auto bad = [&](const std::string& why) {
    return Error(ErrorCode::kParseError,
                 "bad path data at character " + std::to_string(sc.pos()) + ": " + why);
  };
  while (!sc.atEnd()) {
    if (std::isalpha(static_cast<unsigned char>(sc.peek()))) {
      cmd = sc.take();
    } else if (cmd == 0) {
      return bad("expected a command letter");
    } else if (cmd == 'M') {
      cmd = 'L';  // implicit lineto after moveto
    } else if (cmd == 'm') {
      cmd = 'l';
    } else if (cmd == 'Z' || cmd == 'z') {
      return bad("numbers after a close-path command");
    }
    const bool rel = std::islower(static_cast<unsigned char>(cmd)) != 0;
    const char upper_cmd = static_cast<char>(std::toupper(static_cast<unsigned char>(cmd)));
    if (upper_cmd != 'M' && upper_cmd != 'Z' && f.cur.empty())
      f.cur.push_back(p);  // drawing after Z
    const Eigen::Vector2d base = rel ? p : Eigen::Vector2d::Zero();
    double v[6];
    auto read = [&](int n) {
      for (int k = 0; k < n; ++k) {
        if (!sc.number(v[k])) return false;
      }
      return true;
    };
    switch (std::toupper(static_cast<unsigned char>(cmd))) {
      case 'M':
        if (!read(2)) return bad("expected x y after moveto");
        p = base + Eigen::Vector2d(v[0], v[1]);
        start = p;
        f.moveTo(p);
        break;
      case 'L':
        if (!read(2)) return bad("expected x y after lineto");
        p = base + Eigen::Vector2d(v[0], v[1]);
        f.lineTo(p);
        break;
      case 'H':
        if (!read(1)) return bad("expected x after horizontal lineto");
        p.x() = (rel ? p.x() : 0.0) + v[0];
        f.lineTo(p);
        break;
      case 'V':
        if (!read(1)) return bad("expected y after vertical lineto");
        p.y() = (rel ? p.y() : 0.0) + v[0];
        f.lineTo(p);
        break;
      case 'C': {
        if (!read(6)) return bad("expected 6 numbers after curveto");
        const Eigen::Vector2d c1 = base + Eigen::Vector2d(v[0], v[1]),
                              c2 = base + Eigen::Vector2d(v[2], v[3]),
                              e = base + Eigen::Vector2d(v[4], v[5]);
        f.cubic(p, c1, c2, e);
        last_ctrl = c2;
        p = e;
        break;
      }
      case 'S': {
        if (!read(4)) return bad("expected 4 numbers after smooth curveto");
        const char up = static_cast<char>(std::toupper(static_cast<unsigned char>(prev)));
        const Eigen::Vector2d c1 =
            (up == 'C' || up == 'S') ? Eigen::Vector2d(2 * p - last_ctrl) : p;
        const Eigen::Vector2d c2 = base + Eigen::Vector2d(v[0], v[1]),
                              e = base + Eigen::Vector2d(v[2], v[3]);
        f.cubic(p, c1, c2, e);
        last_ctrl = c2;
        p = e;
        break;
      }
      case 'Q': {
        if (!read(4)) return bad("expected 4 numbers after quadratic curveto");
        const Eigen::Vector2d c = base + Eigen::Vector2d(v[0], v[1]),
                              e = base + Eigen::Vector2d(v[2], v[3]);
        f.quadratic(p, c, e);
        last_ctrl = c;
        p = e;
        break;
      }
      case 'T': {
        if (!read(2)) return bad("expected x y after smooth quadratic curveto");
        const char up = static_cast<char>(std::toupper(static_cast<unsigned char>(prev)));
        const Eigen::Vector2d c = (up == 'Q' || up == 'T') ? Eigen::Vector2d(2 * p - last_ctrl) : p;
        const Eigen::Vector2d e = base + Eigen::Vector2d(v[0], v[1]);
        f.quadratic(p, c, e);
        last_ctrl = c;
        p = e;
        break;
      }
      case 'Z':
        p = start;
        f.flush();
        break;
      case 'A':
        return Error(ErrorCode::kUnsupported, "elliptical arc commands (A/a) are not supported");
      default:
        return bad(std::string("unknown command '") + cmd + "'");
    }
    if (!p.allFinite()) return bad("coordinates overflow");
    prev = cmd;
    total = 0;
    for (const auto& s : f.subpaths) total += s.size();
    total += f.cur.size();
    if (total > max_points) return bad("more than " + std::to_string(max_points) + " vertices");
  }
  f.flush();
  return f.subpaths;
}

void removeDuplicates(Polygon2& pts) {
  Polygon2 out;
  out.reserve(pts.size());
  for (const auto& p : pts) {
    if (out.empty() || (p - out.back()).norm() > 1e-12) out.push_back(p);
  }
  while (out.size() > 2 && (out.front() - out.back()).norm() <= 1e-12) out.pop_back();
  pts = std::move(out);
}

std::map<std::string, std::string> parseStyle(const char* style) {
  std::map<std::string, std::string> out;
  if (style == nullptr) return out;
  const std::string s = style;
  size_t i = 0;
  while (i < s.size()) {
    size_t semi = s.find(';', i);
    if (semi == std::string::npos) semi = s.size();
    const std::string item = s.substr(i, semi - i);
    const size_t colon = item.find(':');
    if (colon != std::string::npos)
      out[lower(trim(item.substr(0, colon)))] = trim(item.substr(colon + 1));
    i = semi + 1;
  }
  return out;
}

struct Walker {
  const std::string& file;
  const Options& options;
  Document doc;
  std::vector<Error> errors;
  size_t points{0};
  int depth_limit{256};

  std::string errAt(const tinyxml2::XMLElement* e) const {
    const char* id = e->Attribute("id");
    return std::string("<") + e->Name() + (id ? std::string(" id='") + id + "'" : std::string()) +
           ">";
  }

  void fail(const tinyxml2::XMLElement* e, ErrorCode code, const std::string& msg) {
    errors.emplace_back(code, errAt(e) + ": " + msg, SourceLocation{file, e->GetLineNum(), 0, ""});
  }

  void walk(const tinyxml2::XMLElement* e, const Affine& parent, std::string fill,
            std::string stroke, int depth) {
    if (depth > depth_limit) {
      fail(e, ErrorCode::kUnsupported,
           "elements nested deeper than " + std::to_string(depth_limit) + " levels");
      return;
    }
    std::string tag = e->Name();
    const size_t colon = tag.find(':');
    if (colon != std::string::npos) {
      if (tag.compare(0, colon, "svg") != 0) return;  // inkscape:, sodipodi:, rdf: ... metadata
      tag = tag.substr(colon + 1);
    }
    if (tag == "defs" || tag == "metadata" || tag == "title" || tag == "desc" ||
        tag == "clipPath" || tag == "mask" || tag == "pattern" || tag == "symbol" ||
        tag == "style" || tag == "marker") {
      return;
    }
    const auto style = parseStyle(e->Attribute("style"));
    auto styleOr = [&](const char* key) -> std::optional<std::string> {
      auto it = style.find(key);
      if (it != style.end()) return it->second;
      if (const char* a = e->Attribute(key)) return std::string(a);
      return std::nullopt;
    };
    if (auto disp = styleOr("display"); disp && trim(*disp) == "none") return;
    if (auto v = styleOr("fill")) fill = normaliseColour(*v);
    if (auto v = styleOr("stroke")) stroke = normaliseColour(*v);
    Affine T = parent;
    if (const char* tr = e->Attribute("transform")) {
      auto m = parseTransform(tr);
      if (!m) {
        fail(e, ErrorCode::kParseError, m.error().message);
        return;
      }
      T = parent * *m;
    }
    if (tag == "path" || tag == "rect" || tag == "polygon") {
      Element el;
      el.id = e->Attribute("id") ? e->Attribute("id") : "";
      el.tag = tag;
      el.fill = fill;
      el.stroke = stroke;
      el.line = e->GetLineNum();
      std::vector<Polygon2> subs;
      if (tag == "path") {
        const char* d = e->Attribute("d");
        if (d == nullptr) {
          fail(e, ErrorCode::kParseError, "missing attribute 'd'");
          return;
        }
        auto parsed = parsePathData(d, options.curve_segments, options.max_points);
        if (!parsed) {
          fail(e, parsed.error().code, parsed.error().message);
          return;
        }
        subs = std::move(*parsed);
      } else if (tag == "rect") {
        double x = 0, y = 0, w = 0, h = 0;
        e->QueryDoubleAttribute("x", &x);
        e->QueryDoubleAttribute("y", &y);
        if (e->QueryDoubleAttribute("width", &w) != tinyxml2::XML_SUCCESS ||
            e->QueryDoubleAttribute("height", &h) != tinyxml2::XML_SUCCESS || !(w >= 0) ||
            !(h >= 0) || !std::isfinite(x + y + w + h)) {
          fail(e, ErrorCode::kParseError, "needs finite x, y and non-negative width, height");
          return;
        }
        subs.push_back({{x, y}, {x + w, y}, {x + w, y + h}, {x, y + h}});
      } else {
        const char* pts = e->Attribute("points");
        Scanner sc(pts ? std::string(pts) : std::string());
        Polygon2 poly;
        double a = 0, b = 0;
        while (!sc.atEnd()) {
          if (!sc.number(a) || !sc.number(b)) {
            fail(e, ErrorCode::kParseError, "bad 'points' list");
            return;
          }
          poly.emplace_back(a, b);
          if (poly.size() > options.max_points) {
            fail(e, ErrorCode::kParseError, "too many points");
            return;
          }
        }
        subs.push_back(std::move(poly));
      }
      el.subpaths = static_cast<int>(subs.size());
      if (subs.empty()) {
        doc.warnings.push_back(file + ":" + std::to_string(el.line) + ": " + errAt(e) +
                               " has no geometry; ignored");
        return;
      }
      // Keep the subpath of largest area (or the longest when all are lines).
      size_t best = 0;
      double best_area = -1;
      for (size_t k = 0; k < subs.size(); ++k) {
        const double a =
            std::abs(signedArea(subs[k])) + 1e-12 * static_cast<double>(subs[k].size());
        if (a > best_area) {
          best_area = a;
          best = k;
        }
      }
      if (subs.size() > 1) {
        doc.warnings.push_back(file + ":" + std::to_string(el.line) + ": " + errAt(e) + " has " +
                               std::to_string(subs.size()) + " subpaths; only the largest is used");
      }
      el.points = std::move(subs[best]);
      for (auto& pt : el.points) pt = T * pt;
      removeDuplicates(el.points);
      points += el.points.size();
      if (points > options.max_points) {
        fail(e, ErrorCode::kParseError,
             "document has more than " + std::to_string(options.max_points) + " vertices");
        return;
      }
      doc.elements.push_back(std::move(el));
      return;
    }
    for (const auto* c = e->FirstChildElement(); c != nullptr; c = c->NextSiblingElement()) {
      walk(c, T, fill, stroke, depth + 1);
      if (errors.size() > 100) return;
    }
  }
};

}  // namespace

Result<Document> parse(const std::string& text, const std::string& file, const Options& options) {
  tinyxml2::XMLDocument xml;
  if (xml.Parse(text.c_str(), text.size()) != tinyxml2::XML_SUCCESS) {
    return Error(ErrorCode::kParseError, "invalid XML: " + xmlErrorMessage(xml),
                 SourceLocation{file, xml.ErrorLineNum(), 0, ""});
  }
  const tinyxml2::XMLElement* root = xml.RootElement();
  if (root == nullptr ||
      (std::string_view(root->Name()) != "svg" && std::string_view(root->Name()) != "svg:svg")) {
    return Error(ErrorCode::kParseError, "the root element must be <svg>",
                 SourceLocation{file, root ? root->GetLineNum() : 1, 0, ""});
  }
  Walker w{file, options, {}, {}, 0};
  w.walk(root, Affine::Identity(), "#000000", "none", 0);
  if (w.errors.size() == 1) return w.errors.front();
  if (!w.errors.empty()) return Error(w.errors.front().code, joinErrors(w.errors));
  return std::move(w.doc);
}

}  // namespace tamp::world::svg
