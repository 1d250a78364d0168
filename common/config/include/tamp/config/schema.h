#pragma once
/// @file
/// A parameter struct's fields, declared once, drive both its YAML loader and its `validate()`.
/// Each field names its section, key, member and (optionally) a check; the schema then
///  - reads a file through FieldReader: type errors, failed checks and unknown keys of every
///    declared section, each with file:line:column and the dotted field ("lazy.roadmap_samples");
///  - validates a struct built in code: the same checks, errors naming the dotted field only.
///
///   const config::Schema<Params>& schema() {
///     static const config::Schema<Params> kSchema = [] {
///       config::Schema<Params> s;
///       s.root().field("seed", &Params::seed);
///       auto lazy = s.section("lazy", &Params::lazy);
///       lazy.field("roadmap_samples", &LazyParams::roadmap_samples, config::atLeast(0));
///       lazy.field("max_size", &LazyParams::max_size, config::positive());
///       lazy.rule("max_size", [](const LazyParams& l) -> std::optional<std::string> {
///         if (l.max_size >= l.min_size) return std::nullopt;   // cross-field check
///         return "must be >= min_size, got " + formatNumber(l.max_size);
///       });
///       return s;
///     }();
///     return kSchema;
///   }
///   // loader:   FieldReader r(doc); schema().read(r, p); <custom keys>; r.refuseUnknownKeys();
///   // validate: std::vector<Error> errors = schema().errors(p); <custom checks>
///
/// Escape hatches, for what a plain field does not fit: `convert<Raw>()` reads a YAML type and
/// converts it (enums from names with byName(), unsigned from int, a box from 6 numbers); `rule()`
/// checks anything computable from the section or the whole struct; keys the schema does not
/// declare (lists, maps, sections of other readers) are read by the caller from the same
/// FieldReader.

#include <cmath>
#include <functional>
#include <map>
#include <optional>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include "tamp/config/yaml_reader.h"
#include "tamp/core/error.h"
#include "tamp/core/format.h"

namespace tamp::config {

/// A check of one value: std::nullopt when valid, else the message ("must be positive, got 0").
template <typename T>
using Check = std::function<std::optional<std::string>(const T&)>;

/// `v` for a message: integers exactly, floating point as formatNumber() (0.5, 1e-09, inf).
template <typename T>
std::string formatValue(const T& v) {
  if constexpr (std::is_integral_v<T>) {
    return std::to_string(v);
  } else {
    return formatNumber(static_cast<double>(v));
  }
}

/// Valid when `ok(v)`; else "<message>, got <v>".
template <typename T, typename Pred>
Check<T> that(Pred ok, std::string message) {
  return
      [ok = std::move(ok), message = std::move(message)](const T& v) -> std::optional<std::string> {
        if (ok(v)) return std::nullopt;
        return message + ", got " + formatValue(v);
      };
}

/// Finite and > 0: "must be positive, got 0".
Check<double> positive();
/// Finite and >= 0: "must be >= 0[ <note>], got -1"; `note` names a unit or meaning ("s").
Check<double> nonNegative(const std::string& note = "");

/// >= lo (and finite, for floating point): "must be >= 2, got 1".
template <typename T>
Check<T> atLeast(T lo) {
  return that<T>(
      [lo](const T& v) {
        if constexpr (std::is_floating_point_v<T>) {
          return std::isfinite(v) && v >= lo;
        } else {
          return v >= lo;
        }
      },
      "must be >= " + formatValue(lo));
}

/// Which ends of a range are included.
enum class Ends {
  kOpen,        ///< (lo, hi)
  kClosed,      ///< [lo, hi]
  kOpenClosed,  ///< (lo, hi]
  kClosedOpen,  ///< [lo, hi)
};
/// lo < or <= v < or <= hi: "must be in (0, 1][ <note>], got 2"; `note` names a unit ("m").
Check<double> inRange(double lo, double hi, Ends ends, const std::string& note = "");

/// A `convert<std::string>()` function for an enum read by name: `from(name)` gives the value or
/// std::nullopt, refused as "unknown <what> 'x' (expected one of: <names>)".
template <typename E, typename From>
auto byName(From from, std::string what, std::string names) {
  return [from, what = std::move(what), names = std::move(names)](
             const std::string& name, E& out) -> std::optional<std::string> {
    if (std::optional<E> e = from(name)) {
      out = *e;
      return std::nullopt;
    }
    return "unknown " + what + " '" + name + "' (expected one of: " + names + ")";
  };
}

/// The declared fields and rules of the parameter struct `P`. Build once (e.g. a function-local
/// static); `read()` and `errors()` are const and thread-safe.
template <typename P>
class Schema {
 public:
  /// The fields of one section of the YAML file, stored in the sub-struct `S` of `P`
  /// (or in `P` itself for the top level). Refers to its schema: use it only while building.
  template <typename S>
  class Section {
   public:
    /// A field read with FieldReader::optional (absent keeps the default) and checked by `check`.
    template <typename T>
    Section& field(const std::string& key, T S::*member,
                   std::type_identity_t<Check<T>> check = {}) {
      const auto m = member;
      schema_->add(
          name_, key,
          [m, sm = section_](FieldReader& r, const std::string& k, P& p) {
            r.optional(k, of(p, sm).*m);
          },
          check ? wrap<T>(m, std::move(check)) : nullptr);
      return *this;
    }

    /// A field read as `Raw` and stored by `to(const Raw&, T&)`, which returns a message to
    /// refuse the value (recorded at the key; the member keeps its value). For enums by name,
    /// integers into unsigned types, composite values. `check` applies as for field().
    template <typename Raw, typename T, typename Convert>
    Section& convert(const std::string& key, T S::*member, Convert to,
                     std::type_identity_t<Check<T>> check = {}) {
      const auto m = member;
      schema_->add(
          name_, key,
          [m, sm = section_, to = std::move(to)](FieldReader& r, const std::string& k, P& p) {
            Raw raw{};
            if (!r.optional(k, raw)) return;
            T value = of(p, sm).*m;
            if (std::optional<std::string> why = to(raw, value)) {
              r.fail(k, *why);
            } else {
              of(p, sm).*m = std::move(value);
            }
          },
          check ? wrap<T>(m, std::move(check)) : nullptr);
      return *this;
    }

    /// A check of the whole section reported against `key`, for cross-field constraints
    /// ("base_distance_max >= base_distance_min"). Runs after every field has been read.
    template <typename Fn>
    Section& rule(const std::string& key, Fn check) {
      schema_->add(name_, key, nullptr,
                   [sm = section_, check = std::move(check)](
                       const P& p) -> std::optional<std::string> { return check(of(p, sm)); });
      return *this;
    }

   private:
    friend class Schema;
    Section(Schema* schema, std::string name, S P::*section)
        : schema_(schema), name_(std::move(name)), section_(section) {}

    /// The section's struct in `p` (const or not); `p` itself for the top level.
    template <typename Q>
    static auto& of(Q& p, S P::*section) {
      if constexpr (std::is_same_v<S, P>) {
        return p;
      } else {
        return p.*section;
      }
    }
    template <typename T>
    std::function<std::optional<std::string>(const P&)> wrap(T S::*m, Check<T> check) const {
      return
          [m, sm = section_, check = std::move(check)](const P& p) { return check(of(p, sm).*m); };
    }

    Schema* schema_;
    std::string name_;
    S P::*section_;  ///< unused (null) for the top level
  };

  /// The top-level keys (fields of `P` itself).
  Section<P> root() { return Section<P>(this, "", nullptr); }
  /// The section `name` (a mapping in YAML) stored in `p.*member`. An empty `name` reads the
  /// sub-struct's fields from the top level (a struct grouping some top-level keys).
  template <typename S>
  Section<S> section(const std::string& name, S P::*member) {
    return Section<S>(this, name, member);
  }

  /// A check of the whole struct reported against `section.key` ("" = top level), for
  /// constraints across sections ("clusters.tolerance > planes.voxel_size").
  template <typename Fn>
  void rule(const std::string& section, const std::string& key, Fn check) {
    add(section, key, nullptr, std::move(check));
  }

  /// Reads every declared field of `r` (a top-level reader) into `p`, then records every failed
  /// check and rule at its key (or its section, when the key is absent) and every unknown key of
  /// each declared section. A section that is not a mapping is an error; an absent one keeps
  /// its defaults. Unknown top-level keys are left to the caller (who may read more of them):
  /// call r.refuseUnknownKeys() after its own reads.
  void read(FieldReader& r, P& p) const {
    std::map<std::string, FieldReader> sections;
    auto reader = [&](const std::string& name) -> FieldReader& {
      if (name.empty()) return r;
      auto it = sections.find(name);
      if (it == sections.end()) it = sections.emplace(name, r.child(name, false)).first;
      return it->second;
    };
    for (const Entry& e : entries_) {
      if (e.read) e.read(reader(e.section), e.key, p);
    }
    for (const Entry& e : entries_) {
      if (!e.check) continue;
      if (std::optional<std::string> why = e.check(p)) reader(e.section).fail(e.key, *why);
    }
    for (auto& [name, s] : sections) s.refuseUnknownKeys();
  }

  /// Every failed check and rule of `p`, as kInvalidArgument errors naming the dotted field.
  std::vector<Error> errors(const P& p) const {
    std::vector<Error> out;
    for (const Entry& e : entries_) {
      if (!e.check) continue;
      if (std::optional<std::string> why = e.check(p)) {
        out.emplace_back(
            ErrorCode::kInvalidArgument, *why,
            SourceLocation{"", 0, 0, e.section.empty() ? e.key : e.section + "." + e.key});
      }
    }
    return out;
  }

 private:
  struct Entry {
    std::string section;  ///< "" = top level
    std::string key;
    std::function<void(FieldReader&, const std::string&, P&)> read;  ///< null for a rule
    std::function<std::optional<std::string>(const P&)> check;       ///< null = none
  };
  void add(std::string section, std::string key, decltype(Entry::read) read,
           decltype(Entry::check) check) {
    entries_.push_back(
        Entry{std::move(section), std::move(key), std::move(read), std::move(check)});
  }

  std::vector<Entry> entries_;
};

}  // namespace tamp::config
