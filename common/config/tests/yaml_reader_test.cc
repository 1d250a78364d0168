#include "tamp/config/yaml_reader.h"

#include <filesystem>
#include <fstream>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

namespace tamp::config {
namespace {

using ::testing::HasSubstr;

struct Params {
  double speed{1.0};
  int retries{3};
  std::string name;
  Pose2D start;
  std::vector<double> limits;
};

Status readParams(const YamlDocument& doc, Params& p) {
  FieldReader r(doc);
  r.required("name", p.name);
  r.optional("speed", p.speed);
  r.optional("retries", p.retries);
  r.optional("start", p.start);
  r.optional("limits", p.limits);
  r.check(p.speed > 0, "speed", "must be positive, got " + std::to_string(p.speed));
  r.refuseUnknownKeys();
  return r.status();
}

TEST(YamlReaderTest, ReadsValidFile) {
  auto doc = parseYaml("name: r1\nspeed: 0.5\nstart: [1, 2, 0.5]\nlimits: [1, 2]\n", "p.yaml");
  ASSERT_TRUE(doc.ok());
  Params p;
  ASSERT_TRUE(readParams(*doc, p).ok());
  EXPECT_EQ(p.name, "r1");
  EXPECT_DOUBLE_EQ(p.speed, 0.5);
  EXPECT_EQ(p.retries, 3);
  EXPECT_DOUBLE_EQ(p.start.y, 2.0);
  EXPECT_EQ(p.limits.size(), 2u);
}

TEST(YamlReaderTest, SyntaxErrorNamesFileLineColumn) {
  auto doc = parseYaml("name: r1\nspeed: [1, 2\n", "bad.yaml");
  ASSERT_FALSE(doc.ok());
  EXPECT_EQ(doc.error().code, ErrorCode::kParseError);
  EXPECT_EQ(doc.error().where.file, "bad.yaml");
  EXPECT_GT(doc.error().where.line, 1);
}

TEST(YamlReaderTest, ReportsEveryErrorWithLineAndField) {
  auto doc = parseYaml("speed: fast\nretries: 2.5\nstrat: [0, 0]\n", "p.yaml");
  ASSERT_TRUE(doc.ok());
  Params p;
  Status s = readParams(*doc, p);
  ASSERT_FALSE(s.ok());
  const std::string msg = s.error().message;
  EXPECT_THAT(msg, HasSubstr("field 'name': missing required field"));
  EXPECT_THAT(msg, HasSubstr("p.yaml:1:8: field 'speed': expected a number, got 'fast'"));
  EXPECT_THAT(msg, HasSubstr("p.yaml:2:10: field 'retries': expected an integer, got '2.5'"));
  EXPECT_THAT(msg, HasSubstr("p.yaml:3:1: field 'strat': unknown key 'strat'"));
}

TEST(YamlReaderTest, NestedSectionsAndSequencesCarryDottedPaths) {
  auto doc = parseYaml("robot:\n  joints:\n    - {name: a, max: 1}\n    - {name: b, max: x}\n", "r.yaml");
  ASSERT_TRUE(doc.ok());
  FieldReader r(*doc);
  FieldReader robot = r.child("robot");
  for (FieldReader& j : robot.sequence("joints")) {
    std::string name;
    double max = 0;
    j.required("name", name);
    j.required("max", max);
    j.refuseUnknownKeys();
  }
  robot.refuseUnknownKeys();
  r.refuseUnknownKeys();
  ASSERT_EQ(r.errors().size(), 1u);
  EXPECT_EQ(r.errors()[0].where.field, "robot.joints[1].max");
  EXPECT_EQ(r.errors()[0].where.line, 4);
}

TEST(YamlReaderTest, MissingFileIsNotFound) {
  auto doc = loadYamlFile("/nonexistent/x.yaml");
  ASSERT_FALSE(doc.ok());
  EXPECT_EQ(doc.error().code, ErrorCode::kNotFound);
  EXPECT_THAT(doc.error().toString(), HasSubstr("/nonexistent/x.yaml"));
}


// yaml-cpp keeps both pairs of a repeated key and returns the first: the second value would be
// dropped without a word. Every loader goes through parseYaml(), so all of them refuse it.
TEST(YamlReaderTest, DuplicateKeyNamesFileLineAndField) {
  const std::string text =
      "name: a\n"
      "world:\n"
      "  objects:\n"
      "    - id: can\n"
      "      mass: 0.3\n"
      "      mass: 3.0\n";
  auto doc = parseYaml(text, "dup.yaml");
  ASSERT_FALSE(doc.ok());
  EXPECT_EQ(doc.error().code, ErrorCode::kParseError);
  EXPECT_EQ(doc.error().where.file, "dup.yaml");
  EXPECT_EQ(doc.error().where.line, 6);
  EXPECT_EQ(doc.error().where.field, "world.objects[0].mass");
  EXPECT_THAT(doc.error().message, HasSubstr("duplicate key 'mass' (first given at line 5)"));
}

TEST(YamlReaderTest, DuplicateTopLevelKeyAndEveryRepeatReported) {
  auto doc = parseYaml("a: 1\nb: {x: 1, y: 2, x: 3}\na: 2\n", "t.yaml");
  ASSERT_FALSE(doc.ok());
  EXPECT_EQ(doc.error().where.field, "b.x");
  EXPECT_EQ(doc.error().where.line, 2);
  EXPECT_THAT(doc.error().message, HasSubstr("and 1 more"));
  EXPECT_THAT(doc.error().message, HasSubstr("duplicate key 'a'"));
}

TEST(YamlReaderTest, SameKeyInDifferentMappingsIsFine) {
  const std::string text =
      "objects:\n  - {id: a, mass: 1}\n  - {id: b, mass: 2}\n"
      "base: &b {x: 1, y: 2}\nother: *b\nlist: [x, x, x]\n? [1, 2]\n: complex\n? [1, 2]\n: again\n";
  auto doc = parseYaml(text, "ok.yaml");
  EXPECT_TRUE(doc.ok()) << doc.error().toString();
  EXPECT_FALSE(findDuplicateKeys("a: [1, 2\n", "bad.yaml").has_value());  // syntax: parseYaml's job
  EXPECT_FALSE(parseYaml("a: [1, 2\n", "bad.yaml").ok());
}

TEST(YamlReaderTest, DuplicateKeyInFileOnDisk) {
  const auto path = std::filesystem::temp_directory_path() / "tamp_yaml_dup_test.yaml";
  {
    std::ofstream out(path);
    out << "service:\n  threads: 2\n  seed: 1\n  threads: 4\n";
  }
  auto doc = loadYamlFile(path);
  std::filesystem::remove(path);
  ASSERT_FALSE(doc.ok());
  EXPECT_THAT(doc.error().toString(), HasSubstr(path.string() + ":4:3"));
  EXPECT_THAT(doc.error().toString(), HasSubstr("service.threads"));
}

TEST(YamlReaderTest, EveryShippedYamlFileHasNoDuplicateKey) {
  // Scenarios, robot descriptions, service configs, deployments, seeds of the fuzz corpus aside.
  int n = 0;
  for (const auto& e : std::filesystem::recursive_directory_iterator(std::filesystem::path(TAMP_SOURCE_DIR) / "config")) {
    if (e.path().extension() != ".yaml") continue;
    auto doc = loadYamlFile(e.path());
    EXPECT_TRUE(doc.ok()) << doc.error().toString();
    ++n;
  }
  EXPECT_GE(n, 18);
}

}  // namespace
}  // namespace tamp::config
