#pragma once
/// @file
/// tinyxml2's parse error as a message: "mismatched element: XMLElement name=link", without its
/// own "Line number=N" prefix (callers put the line in the error's location). Header-only:
/// include it only from code that links tinyxml2 (the URDF and SVG loaders).

#include <cctype>
#include <string>

#include <tinyxml2.h>

namespace tamp {

inline std::string xmlErrorMessage(const tinyxml2::XMLDocument& doc) {
  std::string name = tinyxml2::XMLDocument::ErrorIDToName(doc.ErrorID());
  if (name.rfind("XML_ERROR_", 0) == 0) name = name.substr(10);
  for (char& c : name) c = c == '_' ? ' ' : static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  std::string detail = doc.ErrorStr() ? doc.ErrorStr() : "";
  const auto pos = detail.find("Line number=");
  if (pos != std::string::npos) {
    const auto colon = detail.find(": ", pos);
    detail = colon == std::string::npos ? "" : detail.substr(colon + 2);
  } else {
    detail.clear();
  }
  return detail.empty() ? name : name + ": " + detail;
}

}  // namespace tamp
