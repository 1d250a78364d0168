#pragma once
/// @file
/// YAML files into validated parameter structs. Every error names the file, line, column and the
/// dotted field path, and a reader reports all errors of a file in one pass, not only the first:
///
///   tamp::config::FieldReader r = ...;          // from loadYamlFile()
///   r.required("max_speed", p.max_speed);       // type errors are recorded, not thrown
///   r.check(p.max_speed > 0, "max_speed", "must be positive");
///   r.refuseUnknownKeys();                      // typos become errors naming the unknown key
///   if (!r.ok()) return r.status();
///
/// Keys that are read (or explicitly ignored) are remembered per mapping; `refuseUnknownKeys()`
/// reports the rest with "unknown key 'x' (expected one of: a, b, c)".

#include <filesystem>
#include <memory>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include <yaml-cpp/yaml.h>

#include "tamp/core/error.h"
#include "tamp/core/geometry.h"

namespace tamp::config {

/// A parsed YAML document and the file it came from.
struct YamlDocument {
  YAML::Node root;
  std::string file;  ///< as given (used in messages)
};

/// Reads and parses a YAML file; syntax errors give kParseError with file:line:column.
/// A key given twice in one mapping is an error too (kParseError at the second occurrence,
/// naming the key, the mapping's dotted path and the line of the first): yaml-cpp would keep
/// the first value and drop the second silently.
Result<YamlDocument> loadYamlFile(const std::filesystem::path& file);
/// Parses YAML text; `name` is used as the file name in messages. Duplicate keys as above.
Result<YamlDocument> parseYaml(const std::string& text, const std::string& name);
/// The duplicate-key check alone: an error naming every repeated key, or nothing (also for text
/// that is not valid YAML; parseYaml() reports that).
std::optional<Error> findDuplicateKeys(const std::string& text, const std::string& name);

class FieldReader {
 public:
  /// A reader over `node` (normally a mapping). `path` is the dotted prefix of its fields.
  FieldReader(YAML::Node node, std::string file, std::string path = "");
  explicit FieldReader(const YamlDocument& doc) : FieldReader(doc.root, doc.file) {}

  bool has(const std::string& key) const;
  bool isMap() const { return node_.IsMap(); }
  /// Reads a required field into `out`; records an error (missing / wrong type) and returns false.
  template <typename T> bool required(const std::string& key, T& out);
  /// Reads an optional field; absent leaves `out` unchanged and returns false.
  template <typename T> bool optional(const std::string& key, T& out);
  /// Marks a key as known without reading it (e.g. handled elsewhere).
  void ignore(const std::string& key) { used_.insert(key); }

  /// A reader for a nested mapping. A missing required child records an error and returns a
  /// reader over an empty node (reads from it record nothing more).
  FieldReader child(const std::string& key, bool required = true);
  /// Readers for each element of a sequence field (elements must be mappings).
  std::vector<FieldReader> sequence(const std::string& key, bool required = true);
  /// Readers for each entry of a mapping field, with the entry's key.
  std::vector<std::pair<std::string, FieldReader>> entries(const std::string& key, bool required = true);

  /// Records `message` against `key` when `cond` is false. Returns cond.
  bool check(bool cond, const std::string& key, const std::string& message);
  /// Records an error against this mapping (or `key`) unconditionally.
  void fail(const std::string& key, const std::string& message, ErrorCode code = ErrorCode::kInvalidArgument);
  /// Records an error against element `index` of the sequence field `key` (its own line and
  /// column, field path "key[index]"); against `key` itself when that is not a long enough list.
  void failAt(const std::string& key, size_t index, const std::string& message,
              ErrorCode code = ErrorCode::kInvalidArgument);
  /// Records an error for every key of this mapping that was not read.
  void refuseUnknownKeys();

  bool ok() const { return errors_->empty(); }
  const std::vector<Error>& errors() const { return *errors_; }
  /// Ok, or one kInvalidArgument/kParseError error whose message lists every error found.
  Status status() const;

  const YAML::Node& node() const { return node_; }
  const std::string& file() const { return file_; }
  const std::string& path() const { return path_; }
  std::string fieldPath(const std::string& key) const;
  SourceLocation locationOf(const std::string& key) const;

 private:
  FieldReader(YAML::Node node, std::string file, std::string path,
              std::shared_ptr<std::vector<Error>> errors);
  template <typename T> bool read(const std::string& key, T& out, bool required);

  YAML::Node node_;
  std::string file_;
  std::string path_;
  std::set<std::string> used_;
  std::shared_ptr<std::vector<Error>> errors_;
};

/// Converts one scalar/sequence node; on failure fills `why` ("expected a number, got 'abc'").
/// Specialised in the .cc for: bool, int, unsigned, double, std::string, std::vector<double>,
/// std::vector<int>, std::vector<std::string>, Eigen::Vector3d, Pose2D ([x, y, theta] or
/// {x:, y:, theta:}).
template <typename T> bool convert(const YAML::Node& node, T& out, std::string& why);

}  // namespace tamp::config
