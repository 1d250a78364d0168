#pragma once
// Internal: a small SVG geometry reader for the NAMO worlds (not a general SVG renderer).
// Reads <path>, <rect> and <polygon> elements outside <defs>, composes every ancestor's
// `transform`, flattens cubic and quadratic Bezier segments, and resolves the (inherited) fill.

#include <string>
#include <vector>

#include <Eigen/Core>

#include "tamp/core/error.h"
#include "tamp/world/polygon.h"

namespace tamp::world::svg {

struct Element {
  std::string id;      ///< may be empty
  std::string tag;     ///< "path", "rect", "polygon"
  std::string fill;    ///< lower-case "#rrggbb", "none", or a colour name; "#000000" by default
  std::string stroke;  ///< same, "none" by default
  int line{0};         ///< line of the element in the file
  Polygon2 points;     ///< user units, transforms applied, y down; consecutive duplicates removed
  int subpaths{1};     ///< how many subpaths `d` had (the largest is kept)
};

struct Document {
  std::vector<Element> elements;  ///< document order
  std::vector<std::string> warnings;
};

struct Options {
  int curve_segments{8};              ///< line segments per Bezier curve
  std::size_t max_points{2'000'000};  ///< refuse documents with more vertices (hostile input)
};

/// Parses SVG text. Errors name `file`, the line and the element (kParseError / kUnsupported).
Result<Document> parse(const std::string& text, const std::string& file,
                       const Options& options = {});

}  // namespace tamp::world::svg
