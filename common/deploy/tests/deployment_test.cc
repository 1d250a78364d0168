// Deployment files: the shipped ones load, and every kind of mistake is an error naming the file,
// the line and the field.
#include "tamp/deploy/deployment.h"

#include <unistd.h>

#include <fstream>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "tamp/core/paths.h"

namespace tamp::deploy {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;

class DeploymentTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("tamp_deploy_test_" + std::to_string(::getpid()));
    fs::create_directories(dir_ / "bin");
    for (const char* exe : {"svc_a", "svc_b"}) {
      const fs::path p = dir_ / "bin" / exe;
      std::ofstream(p) << "#!/bin/sh\n";
      fs::permissions(p, fs::perms::owner_all);
    }
  }
  void TearDown() override { fs::remove_all(dir_); }

  fs::path write(const std::string& text) {
    const fs::path p = dir_ / ("d" + std::to_string(n_++) + ".yaml");
    std::ofstream(p) << text;
    return p;
  }
  /// The error of loading `text` (fails the test when it loads).
  std::string errorOf(const std::string& text) {
    auto d = loadDeployment(write(text));
    if (d.ok()) {
      ADD_FAILURE() << "loaded:\n" << text;
      return {};
    }
    return d.error().toString();
  }

  fs::path dir_;
  int n_{0};
};

TEST_F(DeploymentTest, ShippedLocalDeploymentIsOneHost) {
  auto d = loadDeployment(configDir() / "deploy" / "local.yaml");
  ASSERT_TRUE(d.ok()) << d.error().toString();
  ASSERT_EQ(d->hosts.size(), 1u);
  EXPECT_EQ(d->hosts[0].name, kLocalHost);
  EXPECT_EQ(d->servicesOn(kLocalHost).size(), d->services.size());
  EXPECT_GE(d->services.size(), 7u);
}

TEST_F(DeploymentTest, ShippedTwoHostDeploymentSplitsRobotAndWorkstation) {
  auto d = loadDeployment(configDir() / "deploy" / "two_hosts.yaml");
  ASSERT_TRUE(d.ok()) << d.error().toString();
  auto names = [&](const std::string& host) {
    std::vector<std::string> out;
    for (const auto* s : d->servicesOn(host)) out.push_back(s->name);
    return out;
  };
  EXPECT_THAT(names("robot"),
              ::testing::UnorderedElementsAre("sim", "perception", "execution_monitor"));
  EXPECT_THAT(names("workstation"),
              ::testing::IsSupersetOf(
                  {"graph_manager", "symbolic_planner", "motion_planner", "effort_estimator"}));
  EXPECT_EQ(d->servicesOn("").size(), d->services.size());
  EXPECT_EQ(d->host("nowhere"), nullptr);
}

TEST_F(DeploymentTest, FieldsAndDefaults) {
  auto d = loadDeployment(write(R"(heartbeat_period_s: 0.2
liveness_periods: 3
orphan_timeout_s: 0
restart: {max_restarts: 2, backoff_s: 0.1, backoff_max_s: 1}
hosts:
  robot: {env: ["A=1"]}
  desk:
services:
  - {name: a, host: robot, executable: svc_a, args: [--x, "{run_id}/{host}"], env: ["B=2"]}
  - {name: b, host: desk, executable: svc_b, optional: true, restart: false}
)"));
  ASSERT_TRUE(d.ok()) << d.error().toString();
  EXPECT_DOUBLE_EQ(d->livenessTimeout(), 0.6);
  EXPECT_EQ(d->restart.max_restarts, 2);
  EXPECT_DOUBLE_EQ(d->restart.stable_after_s, 30.0);
  EXPECT_DOUBLE_EQ(d->stall_timeout_s, 20.0);
  EXPECT_DOUBLE_EQ(d->ready_timeout_s, 20.0);
  EXPECT_EQ(d->ready_restarts, 2);
  // The first heartbeat, then two readiness restarts (each after 20 s and at most the 8 s
  // back-off cap), then 20 s for the last process: 30 + 2 * 28 + 20.
  EXPECT_DOUBLE_EQ(d->readyWait(), 30.0 + 2 * (20.0 + d->restart.backoff_max_s) + 20.0);
  EXPECT_EQ(d->host("robot")->env, std::vector<std::string>{"A=1"});
  EXPECT_TRUE(d->services[1].optional);
  EXPECT_FALSE(d->services[1].restart);
  EXPECT_EQ(expandArgs(d->services[0], Placeholders{"", "/c", "/r", "r42", "robot"}),
            (std::vector<std::string>{"--x", "r42/robot"}));
  EXPECT_TRUE(checkExecutables(*d, dir_ / "bin").ok());
}

TEST_F(DeploymentTest, ScenarioPairIsDroppedWithoutAScenario) {
  ServiceSpec s;
  s.args = {"--config", "{config}/x.yaml", "--scenario", "{scenario}", "--v"};
  EXPECT_EQ(expandArgs(s, Placeholders{"", "/cfg", "", "", ""}),
            (std::vector<std::string>{"--config", "/cfg/x.yaml", "--v"}));
  EXPECT_EQ(expandArgs(s, Placeholders{"/s.yaml", "/cfg", "", "", ""}),
            (std::vector<std::string>{"--config", "/cfg/x.yaml", "--scenario", "/s.yaml", "--v"}));
}

TEST_F(DeploymentTest, MissingExecutableNamesFileLineAndField) {
  const fs::path f = write(
      "services:\n  - name: a\n    executable: svc_a\n  - name: b\n    executable: svc_typo\n");
  auto d = loadDeployment(f);
  ASSERT_TRUE(d.ok()) << d.error().toString();
  Status s = checkExecutables(*d, dir_ / "bin");
  ASSERT_FALSE(s.ok());
  EXPECT_EQ(s.error().code, ErrorCode::kNotFound);
  const std::string msg = s.error().toString();
  EXPECT_THAT(msg, HasSubstr(f.string() + ":5:17: field 'services[1].executable'"));
  EXPECT_THAT(msg, HasSubstr((dir_ / "bin" / "svc_typo").string()));
  EXPECT_THAT(msg, ::testing::Not(HasSubstr("svc_a")));
  // An optional service is no excuse for a missing executable.
  auto opt =
      loadDeployment(write("services:\n  - {name: b, executable: /no/such/svc, optional: true}\n"));
  ASSERT_TRUE(opt.ok());
  EXPECT_THAT(checkExecutables(*opt, dir_ / "bin").error().toString(), HasSubstr("/no/such/svc"));
}

TEST_F(DeploymentTest, ExecutablesAreCheckedForTheLaunchedHostOnly) {
  auto d = loadDeployment(write(R"(hosts: {robot: , desk: }
services:
  - {name: a, host: robot, executable: svc_a}
  - {name: b, host: desk, executable: not_installed_here}
)"));
  ASSERT_TRUE(d.ok()) << d.error().toString();
  EXPECT_TRUE(checkExecutables(*d, dir_ / "bin", "robot").ok());
  EXPECT_FALSE(checkExecutables(*d, dir_ / "bin", "desk").ok());
  EXPECT_FALSE(checkExecutables(*d, dir_ / "bin").ok());
}

TEST_F(DeploymentTest, BadFilesNameTheFieldAndLine) {
  EXPECT_THAT(errorOf("services:\n  - name: a\n"),
              HasSubstr(":2:5: field 'services[0].executable': missing required field"));
  EXPECT_THAT(errorOf("services:\n  - {name: a, executable: x}\n  - {name: a, executable: y}\n"),
              HasSubstr(":3:12: field 'services[1].name': duplicate service name 'a'"));
  EXPECT_THAT(errorOf("hosts: {robot: }\nservices:\n  - {name: a, executable: x}\n"),
              HasSubstr("field 'services[0].host': missing required field"));
  EXPECT_THAT(errorOf("hosts: {robot: }\nservices:\n  - {name: a, host: robto, executable: x}\n"),
              HasSubstr(":3:21: field 'services[0].host': unknown host 'robto' (hosts: robot)"));
  EXPECT_THAT(errorOf("services:\n  - {name: a, host: robot, executable: x}\n"),
              HasSubstr("field 'services[0].host': host 'robot' is not declared"));
  EXPECT_THAT(errorOf("services:\n  - {name: a, executable: x, arg: [1]}\n"),
              HasSubstr("field 'services[0].arg': unknown key 'arg'"));
  EXPECT_THAT(errorOf("heartbeat_period_s: 0\nservices:\n  - {name: a, executable: x}\n"),
              HasSubstr(":1:21: field 'heartbeat_period_s': must be in (0, 10]"));
  EXPECT_THAT(errorOf("liveness_periods: 1\nservices:\n  - {name: a, executable: x}\n"),
              HasSubstr("field 'liveness_periods': must be at least 2"));
  EXPECT_THAT(errorOf("stall_timeout_s: -1\nservices:\n  - {name: a, executable: x}\n"),
              HasSubstr(":1:18: field 'stall_timeout_s': must be finite and not negative"));
  EXPECT_THAT(errorOf("ready_timeout_s: 0\nservices:\n  - {name: a, executable: x}\n"),
              HasSubstr(":1:18: field 'ready_timeout_s': must be finite and positive"));
  EXPECT_THAT(errorOf("ready_restarts: -1\nservices:\n  - {name: a, executable: x}\n"),
              HasSubstr(":1:17: field 'ready_restarts': must not be negative"));
  EXPECT_THAT(
      errorOf(
          "restart: {backoff_s: 2, backoff_max_s: 1}\nservices:\n  - {name: a, executable: x}\n"),
      HasSubstr("field 'restart.backoff_max_s': must be at least backoff_s"));
  EXPECT_THAT(errorOf("services:\n  - {name: a, executable: x, env: [NOEQUALS]}\n"),
              HasSubstr("field 'services[0].env': entry 0 must be KEY=value, got 'NOEQUALS'"));
  EXPECT_THAT(errorOf("services:\n  - {name: a/b, executable: x}\n"),
              HasSubstr("field 'services[0].name': must be"));
  EXPECT_THAT(errorOf("services: []\n"),
              HasSubstr("field 'services': must list at least one service"));
  EXPECT_THAT(errorOf("services:\n  - {name: a, executable: x, optional: maybe}\n"),
              HasSubstr("field 'services[0].optional'"));
  EXPECT_THAT(errorOf("just a string\n"), HasSubstr(":1: a deployment must be a mapping"));
  EXPECT_THAT(errorOf("services: [\n"), HasSubstr(".yaml:"));
  // Every error of a file at once, not only the first.
  const std::string both = errorOf("liveness_periods: 0\nservices:\n  - {name: a}\n");
  EXPECT_THAT(both, HasSubstr("liveness_periods"));
  EXPECT_THAT(both, HasSubstr("services[0].executable"));
}

TEST_F(DeploymentTest, DiscoveryIsMulticastUnlessTheFileAsksForServers) {
  // The shipped deployments say nothing: multicast, and no server list for the services.
  for (const char* file : {"local.yaml", "two_hosts.yaml"}) {
    auto d = loadDeployment(configDir() / "deploy" / file);
    ASSERT_TRUE(d.ok()) << d.error().toString();
    EXPECT_EQ(d->discovery.mode, DiscoverySpec::Mode::kMulticast) << file;
    EXPECT_EQ(d->discovery.serversEnv(), "") << file;
  }
  auto d = loadDeployment(write(R"(hosts: {robot: , desk: }
discovery: {mode: server, servers: ["10.0.0.1:11811", "10.0.0.3:11900"], server_host: desk}
services:
  - {name: a, host: robot, executable: svc_a}
)"));
  ASSERT_TRUE(d.ok()) << d.error().toString();
  EXPECT_EQ(d->discovery.mode, DiscoverySpec::Mode::kServer);
  EXPECT_EQ(d->discovery.server_hosts, (std::vector<std::string>{"desk", "desk"}));
  EXPECT_EQ(d->discovery.serversOn("desk"), (std::vector<std::size_t>{0, 1}));
  EXPECT_TRUE(d->discovery.serversOn("robot").empty());
  EXPECT_EQ(d->discovery.serversEnv(), "10.0.0.1:11811;10.0.0.3:11900");
}

// One server per host: either host's launcher runs its own, every client lists both, so no host
// is the only one that makes new participants discoverable.
TEST_F(DeploymentTest, EachDiscoveryServerMayRunOnAHostOfItsOwn) {
  auto d = loadDeployment(write(R"(hosts: {robot: , desk: }
discovery: {mode: server, servers: ["10.0.0.1:11811", "10.0.0.2:11811"], server_hosts: [desk, robot]}
services:
  - {name: a, host: robot, executable: svc_a}
)"));
  ASSERT_TRUE(d.ok()) << d.error().toString();
  EXPECT_EQ(d->discovery.serversOn("desk"), (std::vector<std::size_t>{0}));
  EXPECT_EQ(d->discovery.serversOn("robot"), (std::vector<std::size_t>{1}));
  EXPECT_EQ(d->discovery.serversEnv(), "10.0.0.1:11811;10.0.0.2:11811");
}

TEST_F(DeploymentTest, BadDiscoveryNamesTheField) {
  const std::string hosts = "hosts: {robot: , desk: }\n";
  const std::string services = "services:\n  - {name: a, host: robot, executable: x}\n";
  EXPECT_THAT(errorOf(hosts + "discovery: {mode: mesh}\n" + services),
              HasSubstr(":2:19: field 'discovery.mode': must be 'multicast' or 'server', got 'mesh'"));
  EXPECT_THAT(errorOf(hosts + "discovery: {mode: server, server_host: desk}\n" + services),
              HasSubstr("field 'discovery.servers': mode 'server' needs at least one server"));
  EXPECT_THAT(
      errorOf(hosts + "discovery: {mode: server, servers: [\"10.0.0.1\"], server_host: desk}\n" +
              services),
      HasSubstr("field 'discovery.servers': entry 0: '10.0.0.1' must be IPv4:PORT"));
  EXPECT_THAT(
      errorOf(hosts + "discovery: {mode: server, servers: [\"desk:11811\"], server_host: desk}\n" +
              services),
      HasSubstr("entry 0: 'desk' is not an IPv4 address"));
  EXPECT_THAT(
      errorOf(hosts + "discovery: {mode: server, servers: [\"10.0.0.1:0\"], server_host: desk}\n" +
              services),
      HasSubstr("entry 0: port must be in [1, 65535], got '0'"));
  EXPECT_THAT(
      errorOf(hosts + "discovery: {mode: server, servers: [\"10.0.0.1:11811\"], server_host: lab}\n" +
              services),
      HasSubstr("field 'discovery.server_host': must name a declared host that runs the discovery "
                "servers (hosts: robot, desk), got 'lab'"));
  EXPECT_THAT(errorOf(hosts + "discovery: {mode: server, servers: [\"10.0.0.1:11811\"]}\n" + services),
              HasSubstr("field 'discovery.server_host': give either server_host"));
  EXPECT_THAT(errorOf(hosts +
                      "discovery: {mode: server, servers: [\"10.0.0.1:11811\"], server_host: desk, "
                      "server_hosts: [desk]}\n" + services),
              HasSubstr("field 'discovery.server_hosts': give either server_host"));
  EXPECT_THAT(errorOf(hosts +
                      "discovery: {mode: server, servers: [\"10.0.0.1:11811\", \"10.0.0.2:11811\"], "
                      "server_hosts: [desk]}\n" + services),
              HasSubstr("field 'discovery.server_hosts': one host per server: 2 servers, 1 hosts"));
  EXPECT_THAT(errorOf(hosts +
                      "discovery: {mode: server, servers: [\"10.0.0.1:11811\", \"10.0.0.2:11811\"], "
                      "server_hosts: [desk, lab]}\n" + services),
              HasSubstr("field 'discovery.server_hosts': entry 1: must name a declared host (hosts: robot, "
                        "desk), got 'lab'"));
  EXPECT_THAT(errorOf(hosts + "discovery: {mode: multicast, servers: [\"10.0.0.1:11811\"]}\n" +
                      services),
              HasSubstr("field 'discovery.servers': only with mode 'server'"));
  EXPECT_THAT(errorOf(hosts + "discovery: {mode: multicast, server_hosts: [desk]}\n" + services),
              HasSubstr("field 'discovery.server_hosts': only with mode 'server'"));
  EXPECT_THAT(errorOf(hosts + "discovery: {mode: multicast, port: 3}\n" + services),
              HasSubstr("field 'discovery.port': unknown key 'port'"));
}

TEST_F(DeploymentTest, MissingFileIsNamed) {
  auto d = loadDeployment(dir_ / "nope.yaml");
  ASSERT_FALSE(d.ok());
  EXPECT_EQ(d.error().code, ErrorCode::kNotFound);
  EXPECT_THAT(d.error().toString(), HasSubstr("nope.yaml"));
}

}  // namespace
}  // namespace tamp::deploy
