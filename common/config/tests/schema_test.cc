// Contract of config::Schema: one declaration per field gives the loader and validate() the same
// checks and messages; the loader adds file:line:column and refuses unknown keys per section.
#include "tamp/config/schema.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

namespace tamp::config {
namespace {

using ::testing::HasSubstr;

enum class Mode { kFast, kSafe };
std::optional<Mode> modeFromString(std::string_view name) {
  if (name == "fast") return Mode::kFast;
  if (name == "safe") return Mode::kSafe;
  return std::nullopt;
}

struct Limits {
  double min{0.5};
  double max{1.0};  // >= min
  double fraction{0.5};
};

struct Params {
  unsigned seed{1};
  std::string name{"x"};
  int samples{10};
  double speed{1.0};
  Mode mode{Mode::kFast};
  std::size_t max_points{100};  // >= 1; read as an int
  Limits limits;
};

const Schema<Params>& schema() {
  static const Schema<Params> kSchema = [] {
    Schema<Params> s;
    s.root()
        .field("seed", &Params::seed)
        .field("name", &Params::name)
        .field("samples", &Params::samples, atLeast(0))
        .field("speed", &Params::speed, positive())
        .convert<std::string>("mode", &Params::mode,
                              byName<Mode>(modeFromString, "mode", "fast, safe"))
        .convert<int>(
            "max_points", &Params::max_points,
            [](int v, std::size_t& out) -> std::optional<std::string> {
              if (v < 0) return "expected a count, got " + std::to_string(v);
              out = static_cast<std::size_t>(v);
              return std::nullopt;
            },
            atLeast<std::size_t>(1));
    s.section("limits", &Params::limits)
        .field("min", &Limits::min, nonNegative("m"))
        .field("max", &Limits::max)
        .field("fraction", &Limits::fraction, inRange(0, 1, Ends::kOpenClosed))
        .rule("max", [](const Limits& l) -> std::optional<std::string> {
          if (l.max >= l.min) return std::nullopt;
          return "must be >= min, got " + formatNumber(l.max);
        });
    return s;
  }();
  return kSchema;
}

/// The loader of a service: schema fields, then the caller's own keys, then unknown keys.
Result<Params> parse(const std::string& text) {
  auto doc = parseYaml(text, "p.yaml");
  if (!doc) return doc.error();
  Params p;
  FieldReader r(*doc);
  schema().read(r, p);
  r.ignore("node");  // a section read by someone else
  r.refuseUnknownKeys();
  if (!r.ok()) return r.status().error();
  return p;
}

std::string messages(const std::vector<Error>& errors) { return joinErrors(errors); }

TEST(SchemaTest, CheckMessages) {
  EXPECT_EQ(positive()(0.0), "must be positive, got 0");
  EXPECT_EQ(positive()(INFINITY), "must be positive, got inf");
  EXPECT_EQ(positive()(0.5), std::nullopt);
  EXPECT_EQ(nonNegative()(-1.0), "must be >= 0, got -1");
  EXPECT_EQ(nonNegative("s")(-1.0), "must be >= 0 s, got -1");
  EXPECT_EQ(nonNegative()(0.0), std::nullopt);
  EXPECT_EQ(atLeast(2)(1), "must be >= 2, got 1");
  EXPECT_EQ(atLeast(2)(2), std::nullopt);
  EXPECT_EQ(atLeast(1.0)(NAN), "must be >= 1, got nan");
  EXPECT_EQ(inRange(0, 1, Ends::kOpenClosed)(0.0), "must be in (0, 1], got 0");
  EXPECT_EQ(inRange(0, 1, Ends::kOpenClosed)(1.0), std::nullopt);
  EXPECT_EQ(inRange(0, 1, Ends::kClosedOpen)(0.0), std::nullopt);
  EXPECT_EQ(inRange(0, 1, Ends::kClosedOpen)(1.0), "must be in [0, 1), got 1");
  EXPECT_EQ(inRange(0, 0.5, Ends::kOpen, "m")(0.5), "must be in (0, 0.5) m, got 0.5");
  EXPECT_EQ(inRange(0, 1, Ends::kClosed)(NAN), "must be in [0, 1], got nan");
  EXPECT_EQ((that<double>([](double v) { return std::isfinite(v); }, "must be finite")(INFINITY)),
            "must be finite, got inf");
}

TEST(SchemaTest, DefaultsAreValidAndAnEmptyFileKeepsThem) {
  EXPECT_TRUE(schema().errors(Params{}).empty());
  auto p = parse("");
  ASSERT_TRUE(p.ok()) << p.error().toString();
  EXPECT_EQ(p->samples, 10);
  EXPECT_DOUBLE_EQ(p->limits.max, 1.0);
}

TEST(SchemaTest, ReadsEveryDeclaredField) {
  auto p = parse(
      "seed: 7\nname: y\nsamples: 0\nspeed: 2\nmode: safe\nmax_points: 5\nlimits:\n  min: 0\n  "
      "max: 3\n"
      "  fraction: 1\nnode: {anything: 1}\n");
  ASSERT_TRUE(p.ok()) << p.error().toString();
  EXPECT_EQ(p->seed, 7u);
  EXPECT_EQ(p->name, "y");
  EXPECT_EQ(p->samples, 0);
  EXPECT_DOUBLE_EQ(p->speed, 2.0);
  EXPECT_EQ(p->mode, Mode::kSafe);
  EXPECT_EQ(p->max_points, 5u);
  EXPECT_DOUBLE_EQ(p->limits.min, 0.0);
  EXPECT_DOUBLE_EQ(p->limits.max, 3.0);
  EXPECT_DOUBLE_EQ(p->limits.fraction, 1.0);
}

TEST(SchemaTest, FileErrorsNameFileLineColumnAndDottedField) {
  auto p = parse(
      "samples: -1\nspeed: fast\nmode: slow\nlimits:\n  min: 2\n  fraction: 0\n  typo: 1\n"
      "other: 1\nmax_points: -2\n");
  ASSERT_FALSE(p.ok());
  EXPECT_EQ(p.error().code, ErrorCode::kInvalidArgument);
  const std::string m = p.error().message;
  EXPECT_THAT(m, HasSubstr("p.yaml:1:10: field 'samples': must be >= 0, got -1"));
  EXPECT_THAT(m, HasSubstr("p.yaml:2:8: field 'speed': expected a number, got 'fast'"));
  EXPECT_THAT(
      m, HasSubstr("p.yaml:3:7: field 'mode': unknown mode 'slow' (expected one of: fast, safe)"));
  EXPECT_THAT(m, HasSubstr("p.yaml:6:13: field 'limits.fraction': must be in (0, 1], got 0"));
  // A rule about a key absent from the file is located at its section.
  EXPECT_THAT(m, HasSubstr("p.yaml:5:3: field 'limits.max': must be >= min, got 1"));
  EXPECT_THAT(m, HasSubstr("p.yaml:7:3: field 'limits.typo': unknown key 'typo'"));
  EXPECT_THAT(m, HasSubstr("p.yaml:8:1: field 'other': unknown key 'other'"));
  // A refused conversion keeps the default, which then passes its check: one error, not two.
  EXPECT_THAT(m, HasSubstr("p.yaml:9:13: field 'max_points': expected a count, got -2"));
  EXPECT_EQ(m.find("max_points': must be"), std::string::npos) << m;
}

TEST(SchemaTest, ASectionThatIsNotAMappingIsAnError) {
  auto p = parse("limits: 3\n");
  ASSERT_FALSE(p.ok());
  EXPECT_THAT(p.error().message, HasSubstr("field 'limits': expected a mapping"));
}

// The contract: a bad value gives the same messages and fields whether loaded or built in code.
TEST(SchemaTest, LoaderAndValidateReportTheSameErrors) {
  Params bad;
  bad.samples = -3;
  bad.speed = 0;
  bad.limits.min = 2;
  bad.limits.fraction = 1.5;
  bad.max_points = 0;
  const std::vector<Error> in_code = schema().errors(bad);
  ASSERT_EQ(in_code.size(), 5u);
  EXPECT_EQ(messages(in_code),
            "field 'samples': must be >= 0, got -3\nfield 'speed': must be positive, got 0\n"
            "field 'max_points': must be >= 1, got 0\n"
            "field 'limits.fraction': must be in (0, 1], got 1.5\nfield 'limits.max': must be >= "
            "min, got 1");

  auto doc = parseYaml("samples: -3\nspeed: 0\nmax_points: 0\nlimits: {min: 2, fraction: 1.5}\n",
                       "p.yaml");
  ASSERT_TRUE(doc.ok());
  Params p;
  FieldReader r(*doc);
  schema().read(r, p);
  ASSERT_EQ(r.errors().size(), in_code.size());
  for (std::size_t i = 0; i < in_code.size(); ++i) {
    EXPECT_EQ(r.errors()[i].message, in_code[i].message);
    EXPECT_EQ(r.errors()[i].where.field, in_code[i].where.field);
    EXPECT_EQ(r.errors()[i].where.file, "p.yaml");
    EXPECT_GT(r.errors()[i].where.line, 0);
  }
}

}  // namespace
}  // namespace tamp::config
