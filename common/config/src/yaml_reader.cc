#include "tamp/config/yaml_reader.h"

#include <yaml-cpp/eventhandler.h>

#include <cmath>
#include <map>
#include <sstream>

#include "tamp/core/paths.h"

namespace tamp::config {

namespace {

/// Finds keys repeated within one mapping. yaml-cpp keeps both pairs and lookups return the first,
/// so a repeated key silently loses the second value. Works on parser events, so aliases are not
/// expanded (linear in the text, whatever the anchors).
class DuplicateKeyFinder : public YAML::EventHandler {
 public:
  std::vector<Error> errors;
  std::string file;

  void OnDocumentStart(const YAML::Mark&) override {}
  void OnDocumentEnd() override { done_ = true; }
  void OnNull(const YAML::Mark& m, YAML::anchor_t) override { node(m, nullptr); }
  void OnAlias(const YAML::Mark& m, YAML::anchor_t) override { node(m, nullptr); }
  void OnScalar(const YAML::Mark& m, const std::string&, YAML::anchor_t, const std::string& value) override {
    node(m, &value);
  }
  void OnSequenceStart(const YAML::Mark& m, const std::string&, YAML::anchor_t, YAML::EmitterStyle::value) override {
    node(m, nullptr);
    if (!done_) stack_.push_back(Frame{false, true, {}, "", 0});
  }
  void OnSequenceEnd() override { pop(); }
  void OnMapStart(const YAML::Mark& m, const std::string&, YAML::anchor_t, YAML::EmitterStyle::value) override {
    node(m, nullptr);
    if (!done_) stack_.push_back(Frame{true, true, {}, "", 0});
  }
  void OnMapEnd() override { pop(); }

 private:
  struct Frame {
    bool is_map;
    bool expect_key;
    std::map<std::string, YAML::Mark> keys;  // scalar keys seen, first occurrence
    std::string key;                         // map: the current key; sequence: unused
    size_t index;                            // sequence: the next element's index
  };

  std::string path() const {
    std::string out;
    for (const Frame& f : stack_) {
      if (f.is_map) {
        // Outer mappings are inside the value of their current key; the innermost one is at the
        // repeated key itself.
        out += (out.empty() ? "" : ".") + f.key;
      } else {
        out += "[" + std::to_string(f.index == 0 ? 0 : f.index - 1) + "]";
      }
    }
    return out;
  }

  /// Every node start (scalar, null, alias, container) passes here, in document order.
  void node(const YAML::Mark& m, const std::string* scalar) {
    if (done_ || stack_.empty()) return;
    Frame& f = stack_.back();
    if (!f.is_map) {
      ++f.index;
      return;
    }
    if (f.expect_key) {
      f.key = scalar ? *scalar : "?";
      if (scalar) {
        auto [it, inserted] = f.keys.emplace(*scalar, m);
        if (!inserted) {
          errors.emplace_back(ErrorCode::kParseError,
                              "duplicate key '" + *scalar + "' (first given at line " +
                                  std::to_string(it->second.line + 1) + ")",
                              SourceLocation{file, m.line + 1, m.column + 1, path()});
        }
      }
    }
    f.expect_key = !f.expect_key;
  }
  void pop() {
    if (!done_ && !stack_.empty()) stack_.pop_back();
  }

  std::vector<Frame> stack_;
  bool done_{false};
};

}  // namespace

std::optional<Error> findDuplicateKeys(const std::string& text, const std::string& name) {
  DuplicateKeyFinder finder;
  finder.file = name;
  try {
    std::istringstream in(text);
    YAML::Parser parser(in);
    (void)parser.HandleNextDocument(finder);
  } catch (const YAML::Exception&) {
    return std::nullopt;  // syntax errors are reported by YAML::Load
  }
  if (finder.errors.empty()) return std::nullopt;
  if (finder.errors.size() == 1) return finder.errors.front();
  Error e = finder.errors.front();
  e.message += " (and " + std::to_string(finder.errors.size() - 1) + " more):\n" + joinErrors(finder.errors);
  return e;
}

Result<YamlDocument> parseYaml(const std::string& text, const std::string& name) {
  try {
    YamlDocument doc{YAML::Load(text), name};
    if (auto dup = findDuplicateKeys(text, name)) return *dup;
    return doc;
  } catch (const YAML::Exception& e) {
    // e.mark is 0-based; e.msg is the bare message without the position prefix.
    return Error(ErrorCode::kParseError, "invalid YAML: " + e.msg,
                 SourceLocation{name, e.mark.line + 1, e.mark.column + 1, ""});
  }
}

Result<YamlDocument> loadYamlFile(const std::filesystem::path& file) {
  auto text = readTextFile(file);
  if (!text) return text.error();
  return parseYaml(*text, file.string());
}

FieldReader::FieldReader(YAML::Node node, std::string file, std::string path)
    : FieldReader(std::move(node), std::move(file), std::move(path),
                  std::make_shared<std::vector<Error>>()) {}

FieldReader::FieldReader(YAML::Node node, std::string file, std::string path,
                         std::shared_ptr<std::vector<Error>> errors)
    : node_(std::move(node)), file_(std::move(file)), path_(std::move(path)), errors_(std::move(errors)) {
  if (node_.IsDefined() && !node_.IsNull() && !node_.IsMap()) {
    errors_->emplace_back(ErrorCode::kInvalidArgument, "expected a mapping (key: value pairs)",
                          SourceLocation{file_, node_.Mark().line + 1, node_.Mark().column + 1, path_});
  }
}

std::string FieldReader::fieldPath(const std::string& key) const {
  if (path_.empty()) return key;
  if (key.empty()) return path_;
  return path_ + "." + key;
}

SourceLocation FieldReader::locationOf(const std::string& key) const {
  YAML::Mark m = node_.Mark();
  if (!key.empty() && node_.IsMap()) {
    const YAML::Node v = node_[key];
    if (v.IsDefined()) m = v.Mark();
  }
  if (m.is_null()) return SourceLocation{file_, 0, 0, fieldPath(key)};
  return SourceLocation{file_, m.line + 1, m.column + 1, fieldPath(key)};
}

bool FieldReader::has(const std::string& key) const {
  return node_.IsMap() && node_[key].IsDefined();
}

template <typename T>
bool FieldReader::read(const std::string& key, T& out, bool required) {
  used_.insert(key);
  if (!node_.IsMap()) {
    if (required && (node_.IsNull() || !node_.IsDefined())) {
      // The parent was missing or empty: its own error is already recorded when it mattered.
      if (node_.IsNull() && node_.IsDefined()) fail(key, "missing required field");
    }
    return false;
  }
  const YAML::Node v = node_[key];
  if (!v.IsDefined()) {
    if (required) fail(key, "missing required field");
    return false;
  }
  std::string why;
  T tmp{};
  if (!convert(v, tmp, why)) {
    errors_->emplace_back(ErrorCode::kInvalidArgument, why, locationOf(key));
    return false;
  }
  out = std::move(tmp);
  return true;
}

template <typename T>
bool FieldReader::required(const std::string& key, T& out) { return read(key, out, true); }
template <typename T>
bool FieldReader::optional(const std::string& key, T& out) { return read(key, out, false); }

FieldReader FieldReader::child(const std::string& key, bool required) {
  used_.insert(key);
  YAML::Node v = node_.IsMap() ? node_[key] : YAML::Node();
  if (!v.IsDefined()) {
    if (required) fail(key, "missing required section");
    return FieldReader(YAML::Node(YAML::NodeType::Undefined), file_, fieldPath(key), errors_);
  }
  return FieldReader(v, file_, fieldPath(key), errors_);
}

std::vector<FieldReader> FieldReader::sequence(const std::string& key, bool required) {
  used_.insert(key);
  std::vector<FieldReader> out;
  YAML::Node v = node_.IsMap() ? node_[key] : YAML::Node();
  if (!v.IsDefined() || v.IsNull()) {
    if (required) fail(key, "missing required list");
    return out;
  }
  if (!v.IsSequence()) {
    errors_->emplace_back(ErrorCode::kInvalidArgument, "expected a list", locationOf(key));
    return out;
  }
  for (size_t i = 0; i < v.size(); ++i) {
    out.push_back(FieldReader(v[i], file_, fieldPath(key) + "[" + std::to_string(i) + "]", errors_));
  }
  return out;
}

std::vector<std::pair<std::string, FieldReader>> FieldReader::entries(const std::string& key, bool required) {
  used_.insert(key);
  std::vector<std::pair<std::string, FieldReader>> out;
  YAML::Node v = node_.IsMap() ? node_[key] : YAML::Node();
  if (!v.IsDefined() || v.IsNull()) {
    if (required) fail(key, "missing required mapping");
    return out;
  }
  if (!v.IsMap()) {
    errors_->emplace_back(ErrorCode::kInvalidArgument, "expected a mapping", locationOf(key));
    return out;
  }
  for (auto it = v.begin(); it != v.end(); ++it) {
    const std::string name = it->first.as<std::string>();
    out.emplace_back(name, FieldReader(it->second, file_, fieldPath(key) + "." + name, errors_));
  }
  return out;
}

bool FieldReader::check(bool cond, const std::string& key, const std::string& message) {
  if (!cond) fail(key, message);
  return cond;
}

void FieldReader::fail(const std::string& key, const std::string& message, ErrorCode code) {
  errors_->emplace_back(code, message, locationOf(key));
}

void FieldReader::failAt(const std::string& key, size_t index, const std::string& message,
                         ErrorCode code) {
  const YAML::Node v = node_.IsMap() ? node_[key] : YAML::Node();
  if (!v.IsDefined() || !v.IsSequence() || index >= v.size() || v[index].Mark().is_null()) {
    fail(key, message, code);
    return;
  }
  const YAML::Mark m = v[index].Mark();
  errors_->emplace_back(code, message,
                        SourceLocation{file_, m.line + 1, m.column + 1,
                                       fieldPath(key) + "[" + std::to_string(index) + "]"});
}

void FieldReader::refuseUnknownKeys() {
  if (!node_.IsMap()) return;
  std::string expected;
  for (const auto& k : used_) expected += (expected.empty() ? "" : ", ") + k;
  for (auto it = node_.begin(); it != node_.end(); ++it) {
    const std::string key = it->first.as<std::string>();
    if (used_.count(key) != 0) continue;
    YAML::Mark m = it->first.Mark();
    errors_->emplace_back(ErrorCode::kInvalidArgument,
                          "unknown key '" + key + "' (expected one of: " + expected + ")",
                          SourceLocation{file_, m.line + 1, m.column + 1, fieldPath(key)});
  }
}

Status FieldReader::status() const {
  if (errors_->empty()) return Status::Ok();
  Error e(errors_->front().code, joinErrors(*errors_));
  return e;
}

// ---- conversions -------------------------------------------------------------------------------

namespace {
std::string describe(const YAML::Node& n) {
  if (n.IsNull()) return "null";
  if (n.IsSequence()) return "a list";
  if (n.IsMap()) return "a mapping";
  return "'" + n.Scalar() + "'";
}

bool parseDouble(const YAML::Node& n, double& out) {
  if (!n.IsScalar()) return false;
  const std::string& s = n.Scalar();
  if (s == ".inf" || s == "inf") { out = INFINITY; return true; }
  try {
    size_t pos = 0;
    out = std::stod(s, &pos);
    return pos == s.size();
  } catch (...) {
    return false;
  }
}
}  // namespace

template <>
bool convert<double>(const YAML::Node& n, double& out, std::string& why) {
  if (parseDouble(n, out) && !std::isnan(out)) return true;
  why = "expected a number, got " + describe(n);
  return false;
}

template <>
bool convert<int>(const YAML::Node& n, int& out, std::string& why) {
  if (n.IsScalar()) {
    try {
      size_t pos = 0;
      long v = std::stol(n.Scalar(), &pos, 10);
      if (pos == n.Scalar().size() && v >= INT32_MIN && v <= INT32_MAX) {
        out = static_cast<int>(v);
        return true;
      }
    } catch (...) {
    }
  }
  why = "expected an integer, got " + describe(n);
  return false;
}

template <>
bool convert<unsigned>(const YAML::Node& n, unsigned& out, std::string& why) {
  int v = 0;
  if (convert<int>(n, v, why) && v >= 0) {
    out = static_cast<unsigned>(v);
    return true;
  }
  why = "expected a non-negative integer, got " + describe(n);
  return false;
}

template <>
bool convert<bool>(const YAML::Node& n, bool& out, std::string& why) {
  if (n.IsScalar()) {
    const std::string& s = n.Scalar();
    if (s == "true" || s == "True" || s == "yes" || s == "on") { out = true; return true; }
    if (s == "false" || s == "False" || s == "no" || s == "off") { out = false; return true; }
  }
  why = "expected true or false, got " + describe(n);
  return false;
}

template <>
bool convert<std::string>(const YAML::Node& n, std::string& out, std::string& why) {
  if (n.IsScalar()) {
    out = n.Scalar();
    return true;
  }
  why = "expected a string, got " + describe(n);
  return false;
}

template <typename E>
static bool convertList(const YAML::Node& n, std::vector<E>& out, std::string& why, const char* what) {
  if (!n.IsSequence()) {
    why = std::string("expected a list of ") + what + ", got " + describe(n);
    return false;
  }
  out.clear();
  for (size_t i = 0; i < n.size(); ++i) {
    E e{};
    std::string inner;
    if (!convert<E>(n[i], e, inner)) {
      why = "element " + std::to_string(i) + ": " + inner;
      return false;
    }
    out.push_back(std::move(e));
  }
  return true;
}

template <>
bool convert<std::vector<double>>(const YAML::Node& n, std::vector<double>& out, std::string& why) {
  return convertList(n, out, why, "numbers");
}
template <>
bool convert<std::vector<int>>(const YAML::Node& n, std::vector<int>& out, std::string& why) {
  return convertList(n, out, why, "integers");
}
template <>
bool convert<std::vector<std::string>>(const YAML::Node& n, std::vector<std::string>& out, std::string& why) {
  return convertList(n, out, why, "strings");
}

template <>
bool convert<Eigen::Vector3d>(const YAML::Node& n, Eigen::Vector3d& out, std::string& why) {
  std::vector<double> v;
  if (!convert(n, v, why) || v.size() != 3) {
    if (why.empty()) why = "expected [x, y, z], got " + std::to_string(v.size()) + " numbers";
    return false;
  }
  out = Eigen::Vector3d(v[0], v[1], v[2]);
  return true;
}

template <>
bool convert<Pose2D>(const YAML::Node& n, Pose2D& out, std::string& why) {
  if (n.IsSequence()) {
    std::vector<double> v;
    if (!convert(n, v, why)) return false;
    if (v.size() != 2 && v.size() != 3) {
      why = "expected [x, y] or [x, y, theta], got " + std::to_string(v.size()) + " numbers";
      return false;
    }
    out = Pose2D{v[0], v[1], v.size() == 3 ? v[2] : 0.0};
    return true;
  }
  if (n.IsMap()) {
    Pose2D p;
    std::string inner;
    for (auto it = n.begin(); it != n.end(); ++it) {
      const std::string k = it->first.as<std::string>();
      double* dst = k == "x" ? &p.x : k == "y" ? &p.y : k == "theta" ? &p.theta : nullptr;
      if (dst == nullptr) {
        why = "unknown key '" + k + "' in pose (expected x, y, theta)";
        return false;
      }
      if (!convert<double>(it->second, *dst, inner)) {
        why = k + ": " + inner;
        return false;
      }
    }
    out = p;
    return true;
  }
  why = "expected a pose [x, y, theta] or {x:, y:, theta:}, got " + describe(n);
  return false;
}

#define TAMP_INSTANTIATE(T)                                             \
  template bool FieldReader::required<T>(const std::string&, T&);      \
  template bool FieldReader::optional<T>(const std::string&, T&);
TAMP_INSTANTIATE(double)
TAMP_INSTANTIATE(int)
TAMP_INSTANTIATE(unsigned)
TAMP_INSTANTIATE(bool)
TAMP_INSTANTIATE(std::string)
TAMP_INSTANTIATE(std::vector<double>)
TAMP_INSTANTIATE(std::vector<int>)
TAMP_INSTANTIATE(std::vector<std::string>)
TAMP_INSTANTIATE(Eigen::Vector3d)
TAMP_INSTANTIATE(Pose2D)
#undef TAMP_INSTANTIATE

}  // namespace tamp::config
