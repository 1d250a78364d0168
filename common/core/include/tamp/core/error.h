#pragma once
/// @file
/// Errors as values. Expected failures (bad input, timeout, no plan) come back as `Result<T>`;
/// programming errors (a violated precondition) throw `std::invalid_argument`/`std::logic_error`.
///
/// An `Error` can carry the location of bad input (file, line, column, field) so that every
/// message a user sees names where the problem is, e.g.
/// `config/scenarios/x.yaml:12:5: field 'world.objects[2].mass': must be positive, got -1`.

#include <cassert>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <utility>
#include <variant>
#include <vector>

namespace tamp {

/// Broad classes of failure; services map them to status codes in replies.
enum class ErrorCode {
  kInvalidArgument,  ///< a request or parameter is outside its contract
  kParseError,       ///< malformed input text (PDDL, YAML, URDF, SVG, ...)
  kUnsupported,      ///< well-formed input using a feature we refuse by name
  kNotFound,         ///< a named file, object, service or entity does not exist
  kIo,               ///< reading or writing a file or device failed
  kTimeout,          ///< a deadline passed
  kCancelled,        ///< a stop was requested
  kUnavailable,      ///< a peer (service) is absent or not answering
  kInfeasible,       ///< the request is well-formed but has no solution
  kInternal,         ///< a bug or an unexpected library failure
  kNotReady,         ///< the peer has not yet received the state the request names (a world
                     ///< version): well-formed, worth asking again shortly
};

std::string_view toString(ErrorCode code);

/// Where in an input the problem is. Any member may be empty/zero when unknown.
struct SourceLocation {
  std::string file;
  int line{0};    ///< 1-based; 0 = unknown
  int column{0};  ///< 1-based; 0 = unknown
  std::string field;  ///< dotted path inside a structured file, e.g. "world.objects[2].mass"

  SourceLocation() = default;
  SourceLocation(std::string file_, int line_ = 0, int column_ = 0, std::string field_ = {})  // NOLINT
      : file(std::move(file_)), line(line_), column(column_), field(std::move(field_)) {}
};

struct Error {
  ErrorCode code{ErrorCode::kInternal};
  std::string message;
  SourceLocation where;

  Error() = default;
  Error(ErrorCode c, std::string msg) : code(c), message(std::move(msg)) {}
  Error(ErrorCode c, std::string msg, SourceLocation loc)
      : code(c), message(std::move(msg)), where(std::move(loc)) {}

  /// "file:line:col: field 'x': message" with the known parts only.
  std::string toString() const;
};

/// Several errors found in one pass over an input (loaders report all, not just the first).
std::string joinErrors(const std::vector<Error>& errors);

/// The value or the error. A small stand-in for C++23 `std::expected<T, Error>`.
template <typename T>
class [[nodiscard]] Result {
 public:
  Result(T value) : v_(std::move(value)) {}          // NOLINT(google-explicit-constructor)
  Result(Error error) : v_(std::move(error)) {}      // NOLINT(google-explicit-constructor)

  bool ok() const { return v_.index() == 0; }
  explicit operator bool() const { return ok(); }

  /// @throws std::logic_error when called on an error (misuse).
  T& value() & { check(); return std::get<0>(v_); }
  const T& value() const& { check(); return std::get<0>(v_); }
  T&& value() && { check(); return std::get<0>(std::move(v_)); }
  T& operator*() & { return value(); }
  const T& operator*() const& { return value(); }
  T* operator->() { return &value(); }
  const T* operator->() const { return &value(); }

  /// @throws std::logic_error when called on a value (misuse).
  const Error& error() const {
    if (ok()) throw std::logic_error("Result::error() called on a value");
    return std::get<1>(v_);
  }
  T valueOr(T fallback) const& { return ok() ? std::get<0>(v_) : std::move(fallback); }

 private:
  void check() const {
    if (!ok()) throw std::logic_error("Result::value() on error: " + std::get<1>(v_).toString());
  }
  std::variant<T, Error> v_;
};

/// Success or an error, for operations without a value.
class [[nodiscard]] Status {
 public:
  Status() = default;
  Status(Error error) : e_(std::move(error)) {}  // NOLINT(google-explicit-constructor)
  static Status Ok() { return {}; }

  bool ok() const { return !e_.has_value(); }
  explicit operator bool() const { return ok(); }
  const Error& error() const {
    if (ok()) throw std::logic_error("Status::error() called on success");
    return *e_;
  }

 private:
  std::optional<Error> e_;
};

/// Throws std::invalid_argument with `what` when `cond` is false. For preconditions of an API
/// (misuse), not for bad user input, which gets an Error value.
inline void require(bool cond, const std::string& what) {
  if (!cond) throw std::invalid_argument(what);
}

}  // namespace tamp
