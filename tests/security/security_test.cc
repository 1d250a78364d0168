// The DDS Security profile over real processes: a secured graph manager and simulator (each with
// its own certificate and permissions from deploy/security/make_certs.sh, made at test time into
// the build directory) and, in this process, participants with genuine, foreign, forged or no
// credentials.
//
// "Not received" is judged only after a positive control: the genuine participant's message on
// the same topic went through the secured service and came back, and the rogue's messages were
// written before and between the genuine ones; then a bounded grace period.
#include <unistd.h>

#include <atomic>
#include <condition_variable>
#include <functional>
#include <filesystem>
#include <fstream>
#include <thread>

#include <fastrtps/config.h>
#include <gtest/gtest.h>

#include "../integration/integration_util.h"
#include "tamp/core/paths.h"
#include "tamp/dds/rpc.h"
#include "tamp/dds/topics.h"

namespace tamp::integration {
namespace {

namespace fs = std::filesystem;
using dds::testing::Inbox;

fs::path pkiRoot() { return fs::path(TAMP_BIN_DIR).parent_path() / "test-pki" / std::to_string(::getpid()); }
fs::path genuineDir() { return pkiRoot() / "genuine"; }
fs::path rogueDir() { return pkiRoot() / "rogue"; }

int makeCerts(const fs::path& out, const std::vector<std::string>& extra = {}) {
  std::string cmd = std::string("bash ") + TAMP_SOURCE_DIR + "/deploy/security/make_certs.sh '" + out.string() + "'";
  for (const auto& e : extra) cmd += " '" + e + "'";
  cmd += " > '" + (out.string() + ".log") + "' 2>&1";
  fs::create_directories(out.parent_path());
  return std::system(cmd.c_str());
}

std::shared_ptr<dds::Participant> participant(int domain, dds::ParticipantOptions o, const std::string& name) {
  o.domain_id = domain;
  o.name = "test/" + name;
  auto p = dds::Participant::create(o);
  if (!p) {
    ADD_FAILURE() << name << ": " << p.error().toString();
    return nullptr;
  }
  return *p;
}

dds::ParticipantOptions secured(const fs::path& dir, const std::string& identity) {
  dds::ParticipantOptions o;
  o.security_dir = dir.string();
  o.security_identity = identity;
  return o;
}

dds::ParticipantOptions plain() {
  dds::ParticipantOptions o;
  o.security_dir = "none";  // whatever $TAMP_DDS_SECURITY says
  return o;
}

class SecurityTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    fs::remove_all(pkiRoot());
    ASSERT_EQ(makeCerts(genuineDir()), 0) << readFile(genuineDir().string() + ".log");
    // Another CA that grants its holders everything these tests try.
    fs::create_directories(pkiRoot());
    std::ofstream(pkiRoot() / "rogue_access.txt") << "execution_monitor pub tamp/mission/command\n"
                                                     "execution_monitor sub tamp/mission/status\n"
                                                     "execution_monitor pub tamp/robot/trajectory\n"
                                                     "execution_monitor sub tamp/robot/result\n"
                                                     "perception pub tamp/robot/trajectory\n"
                                                     "perception sub tamp/robot/result\n"
                                                     "perception pub tamp/mission/command\n"
                                                     "perception sub tamp/mission/status\n";
    ASSERT_EQ(makeCerts(rogueDir(), {"--table", (pkiRoot() / "rogue_access.txt").string(), "--ca-name", "Rogue CA"}),
              0)
        << readFile(rogueDir().string() + ".log");

    domain_ = isolatedDomain();
    sup_ = std::make_unique<process::Supervisor>();
    const std::string security = genuineDir().string();
    sup_->add(serviceSpec("tamp_graph_manager_service", "graph_manager", domain_,
                          {"--config", (configDir() / "services" / "graph_manager.yaml").string(), "--security",
                           security}));
    sup_->add(serviceSpec("tamp_sim_service", "sim", domain_,
                          {"--config", (configDir() / "services" / "sim.yaml").string(), "--scenario",
                           (configDir() / "scenarios" / "namo_corridor.yaml").string(), "--security", security}));
    ASSERT_TRUE(sup_->startAll().ok());
  }
  static void TearDownTestSuite() {
    if (sup_) sup_->stopAll(5.0);
    sup_.reset();
    fs::remove_all(pkiRoot());
  }
  void TearDown() override {
    if (HasFailure() && sup_) {
      for (const char* n : {"graph_manager", "sim"})
        std::cerr << "---- " << n << " log:\n" << readFile(tempFile(std::string("tamp_it_") + n + ".log")) << "\n";
    }
  }

  /// A participant with perception's genuine certificate and key, but permissions signed by the
  /// rogue CA that grant it the robot's command topic.
  static dds::ParticipantOptions forgedPerception() {
    dds::ParticipantOptions o;
    dds::ParticipantOptions::SecurityFiles f = dds::securityFiles(genuineDir(), "perception");
    f.permissions_ca = rogueDir() / "ca.pem";
    f.governance = rogueDir() / "governance.p7s";
    f.permissions = rogueDir() / "perception" / "permissions.p7s";
    o.security = f;
    return o;
  }

  static int domain_;
  static std::unique_ptr<process::Supervisor> sup_;
};
int SecurityTest::domain_ = 0;
std::unique_ptr<process::Supervisor> SecurityTest::sup_;

// A rogue endpoint pair: from its creation on it writes on `W`'s topic every 50 ms (ids
// "rogue-<name>-<n>"), and counts what its reader of `R` receives.
template <typename W, typename R>
struct Rogue {
  std::string name;
  std::shared_ptr<dds::Participant> p;
  std::unique_ptr<dds::Writer<W>> writer;
  std::unique_ptr<dds::Reader<R>> reader;
  std::atomic<int> received{0}, written{0};
  std::jthread flood;
  Rogue(std::string n, std::shared_ptr<dds::Participant> part, const dds::TopicSpec<W>& w, const dds::TopicSpec<R>& r,
        std::function<W(const std::string&)> make)
      : name(std::move(n)), p(std::move(part)) {
    writer = std::make_unique<dds::Writer<W>>(p, w);
    reader = std::make_unique<dds::Reader<R>>(p, r, [this](const R&, const dds::SampleMeta&) { ++received; });
    flood = std::jthread([this, make](std::stop_token st) {
      std::mutex m;
      std::condition_variable_any cv;
      while (!st.stop_requested()) {
        if (writer->write(make("rogue-" + name + "-" + std::to_string(written.load())))) ++written;
        std::unique_lock l(m);
        cv.wait_for(l, st, std::chrono::milliseconds(50), [] { return false; });
      }
    });
  }
  ~Rogue() {
    flood.request_stop();
    flood.join();
  }
};

// The genuine end of a test: a participant, its reader of `R` into an inbox and its writer of
// `W`, renewed (a new participant: a new GUID, matched anew) when its writer is not matched within
// 15 s, at most 3 times. Under load Debian's Fast DDS 2.9.1 sometimes never matches a secured pair
// (docs/reliability.md, sessions 25-26; the CI of 2026-12-07 lost the simulator's pair once), which
// the services (restarted when not ready) and `tamp mission` (a new participant) cure the same way.
template <typename W, typename R>
struct Genuine {
  std::shared_ptr<dds::Participant> p;
  std::unique_ptr<dds::Reader<R>> reader;
  std::unique_ptr<dds::Writer<W>> writer;
  int renewals{0};
  /// Whether the writer matched; `inbox` gets what the reader receives.
  bool connect(const std::function<std::shared_ptr<dds::Participant>()>& make, const dds::TopicSpec<W>& w,
               const dds::TopicSpec<R>& r, Inbox<R>& inbox) {
    for (int attempt = 0; attempt < 3; ++attempt) {
      writer.reset();
      reader.reset();
      p.reset();
      p = make();
      if (!p) return false;
      reader = std::make_unique<dds::Reader<R>>(p, r, [&inbox](const R& m, const dds::SampleMeta&) { inbox.push(m); });
      writer = std::make_unique<dds::Writer<W>>(p, w);
      if (writer->waitForReaders(Termination::after(15.0))) return true;
      ++renewals;
    }
    return false;
  }
};

msg::MissionCommand missionCommand(const std::string& id) {
  msg::MissionCommand c;
  c.mission_id(id);
  c.scenario_path("/nonexistent/scenario.yaml");  // the graph manager fails it at once, naming it
  return c;
}

TEST_F(SecurityTest, ParticipantsWithoutValidCredentialsNeitherReadTheMissionNorCommandIt) {
  using MissionRogue = Rogue<msg::MissionCommand, msg::MissionStatus>;
  std::vector<std::unique_ptr<MissionRogue>> rogues;
  // No security at all, and a certificate of another CA; both start writing before the genuine
  // participant exists, so they had every chance to be matched before the positive control.
  rogues.push_back(std::make_unique<MissionRogue>("plain", participant(domain_, plain(), "plain"),
                                                  dds::topics::kMissionCommand, dds::topics::kMissionStatus,
                                                  missionCommand));
  rogues.push_back(std::make_unique<MissionRogue>(
      "foreign_ca", participant(domain_, secured(rogueDir(), "execution_monitor"), "foreign"),
      dds::topics::kMissionCommand, dds::topics::kMissionStatus, missionCommand));

  Inbox<msg::MissionStatus> statuses;
  Genuine<msg::MissionCommand, msg::MissionStatus> tamp;
  ASSERT_TRUE(tamp.connect([] { return participant(domain_, secured(genuineDir(), "tamp"), "tamp"); },
                           dds::topics::kMissionCommand, dds::topics::kMissionStatus, statuses))
      << "the secured graph manager never matched (" << tamp.renewals << " renewals)";
  dds::Writer<msg::MissionCommand>& commands = *tamp.writer;
  ASSERT_TRUE(commands.write(missionCommand("genuine-1")));
  auto first = statuses.waitFor([](const msg::MissionStatus& s) {
    return s.mission_id() == "genuine-1" && s.state() == msg::MissionState::MISSION_FAILED;
  });
  ASSERT_TRUE(first) << "positive control: the genuine command was not answered";
  EXPECT_NE(first->message().find("/nonexistent/scenario.yaml"), std::string::npos) << first->message();
  // Grace period after the positive control, the rogues still writing: none of theirs may turn up.
  EXPECT_FALSE(statuses.waitFor([](const msg::MissionStatus& s) { return s.mission_id().rfind("rogue-", 0) == 0; }, 2.0))
      << "the graph manager ran a rogue's mission";
  ASSERT_TRUE(commands.write(missionCommand("genuine-2")));
  ASSERT_TRUE(statuses.waitFor([](const msg::MissionStatus& s) { return s.mission_id() == "genuine-2"; }));
  for (auto& r : rogues) {
    EXPECT_GE(r->written.load(), 5) << r->name << " hardly wrote";
    EXPECT_EQ(r->received.load(), 0) << r->name << " read the mission status";
    EXPECT_EQ(r->writer->matchedReaders(), 0) << r->name;
    EXPECT_EQ(r->reader->matchedWriters(), 0) << r->name;
  }
  EXPECT_FALSE(statuses.waitFor([](const msg::MissionStatus& s) { return s.mission_id().rfind("rogue-", 0) == 0; }, 0.0));
}

msg::TrajectoryCommand trajectory(const std::string& id) {
  msg::TrajectoryCommand c;
  c.command_id(id);  // no points: the simulator rejects it, and says so on tamp/robot/result
  return c;
}

TEST_F(SecurityTest, ParticipantsWithoutValidCredentialsOrWithForgedPermissionsCannotCommandTheRobot) {
  using RobotRogue = Rogue<msg::TrajectoryCommand, msg::ActionResult>;
  std::vector<std::unique_ptr<RobotRogue>> rogues;
  rogues.push_back(std::make_unique<RobotRogue>("plain", participant(domain_, plain(), "plain"),
                                                dds::topics::kTrajectoryCommand, dds::topics::kActionResult, trajectory));
  rogues.push_back(std::make_unique<RobotRogue>(
      "foreign_ca", participant(domain_, secured(rogueDir(), "execution_monitor"), "foreign"),
      dds::topics::kTrajectoryCommand, dds::topics::kActionResult, trajectory));
  // A genuine identity whose permissions were signed by another CA: it authenticates, but the
  // simulator does not accept its permissions.
  rogues.push_back(std::make_unique<RobotRogue>("forged_permissions", participant(domain_, forgedPerception(), "forged"),
                                                dds::topics::kTrajectoryCommand, dds::topics::kActionResult, trajectory));

  Inbox<msg::ActionResult> results;
  Genuine<msg::TrajectoryCommand, msg::ActionResult> monitor;
  ASSERT_TRUE(monitor.connect(
      [] { return participant(domain_, secured(genuineDir(), "execution_monitor"), "execution_monitor"); },
      dds::topics::kTrajectoryCommand, dds::topics::kActionResult, results))
      << "the secured simulator never matched (" << monitor.renewals << " renewals)";
  dds::Writer<msg::TrajectoryCommand>& commands = *monitor.writer;
  ASSERT_TRUE(commands.write(trajectory("genuine-1")));
  auto first = results.waitFor([](const msg::ActionResult& r) { return r.command_id() == "genuine-1"; });
  ASSERT_TRUE(first) << "positive control: the simulator did not answer the genuine command";
  EXPECT_EQ(first->outcome(), msg::OUTCOME_FAILED);
  EXPECT_FALSE(results.waitFor([](const msg::ActionResult& r) { return r.command_id().rfind("rogue-", 0) == 0; }, 2.0))
      << "the simulator took a rogue's command";
  ASSERT_TRUE(commands.write(trajectory("genuine-2")));
  ASSERT_TRUE(results.waitFor([](const msg::ActionResult& r) { return r.command_id() == "genuine-2"; }));
  for (auto& r : rogues) {
    EXPECT_GE(r->written.load(), 5) << r->name << " hardly wrote";
    EXPECT_EQ(r->received.load(), 0) << r->name << " read the robot's results";
    EXPECT_EQ(r->writer->matchedReaders(), 0) << r->name;
  }
  EXPECT_FALSE(results.waitFor([](const msg::ActionResult& r) { return r.command_id().rfind("rogue-", 0) == 0; }, 0.0));
}

TEST_F(SecurityTest, OneServicesCredentialsCannotWriteAnotherServicesTopics) {
  auto perception = participant(domain_, secured(genuineDir(), "perception"), "perception");
  ASSERT_TRUE(perception);
  // Its own topics: allowed.
  EXPECT_NO_THROW(dds::Writer<msg::WorldEvent>(perception, dds::topics::kWorldEvents));
  EXPECT_NO_THROW(dds::Reader<msg::PointCloudFrame>(perception, dds::topics::kPointCloud,
                                                    [](const msg::PointCloudFrame&, const dds::SampleMeta&) {}));
  // The execution monitor's, the tools' and the graph manager's: refused when created.
  EXPECT_THROW(dds::Writer<msg::TrajectoryCommand>(perception, dds::topics::kTrajectoryCommand), std::runtime_error);
  EXPECT_THROW(dds::Writer<msg::MissionCommand>(perception, dds::topics::kMissionCommand), std::runtime_error);
  EXPECT_THROW(dds::Writer<msg::MissionStatus>(perception, dds::topics::kMissionStatus), std::runtime_error);
  EXPECT_THROW(dds::Writer<msg::RobotState>(perception, dds::topics::kRobotState), std::runtime_error);
  EXPECT_THROW(dds::Reader<msg::MissionCommand>(perception, dds::topics::kMissionCommand,
                                                [](const msg::MissionCommand&, const dds::SampleMeta&) {}),
               std::runtime_error);
  // Nor may it serve another service's requests.
  EXPECT_THROW((dds::RpcServer<msg::PlanRequest, msg::PlanReply>(perception, dds::services::kPlan,
                                                                  [](const msg::PlanRequest&, const dds::RequestContext&) {
                                                                    return msg::PlanReply{};
                                                                  })),
               std::runtime_error);
}

TEST_F(SecurityTest, SecuredServicesAndToolsTalkRequestReply) {
  const std::string dom = std::to_string(domain_), security = genuineDir().string();
  for (const char* service : {"graph_manager", "sim"}) {
    auto [code, out] =
        runCommand(binDir() / "tamp-ping", {service, "--domain", dom, "--security", security, "-c", "3", "--timeout", "20"}, 60.0);
    EXPECT_EQ(code, 0) << out;
    EXPECT_NE(out.find("3 round trips"), std::string::npos) << out;
  }
  auto [code, out] = runCommand(binDir() / "tamp-status", {"--domain", dom, "--security", security, "--expect",
                                                           "graph_manager", "--expect", "sim", "--wait", "30"},
                                60.0);
  EXPECT_EQ(code, 0) << out;
  // Without credentials the same services are invisible.
  auto [plain_code, plain_out] =
      runCommand(binDir() / "tamp-ping", {"sim", "--domain", dom, "--security", "none", "-c", "1", "--timeout", "2"}, 30.0);
  EXPECT_NE(plain_code, 0) << plain_out;
}

TEST_F(SecurityTest, TheRobotStateReachesEverySubscriberTheTableGrantsIt) {
  for (const char* identity : {"graph_manager", "perception", "execution_monitor"}) {
    auto p = participant(domain_, secured(genuineDir(), identity), identity);
    ASSERT_TRUE(p);
    Inbox<msg::RobotState> states;
    dds::Reader<msg::RobotState> reader(p, dds::topics::kRobotState,
                                        [&](const msg::RobotState& s, const dds::SampleMeta&) { states.push(s); });
    EXPECT_TRUE(states.waitFor([](const msg::RobotState&) { return true; }, 15.0))
        << identity << ": no robot state from the secured simulator (matched writers: " << reader.matchedWriters() << ")";
  }
}

TEST_F(SecurityTest, MissingCredentialsAreAClearErrorNamingTheFile) {
  auto p = dds::Participant::create([] {
    auto o = secured(genuineDir(), "no_such_service");
    o.domain_id = domain_;
    return o;
  }());
  ASSERT_FALSE(p);
  EXPECT_EQ(p.error().code, ErrorCode::kNotFound);
  EXPECT_NE(p.error().toString().find("no_such_service/cert.pem"), std::string::npos) << p.error().toString();
}

// Fast DDS 2.9 has no secure discovery server: a secured client of one never authenticates it
// (the `tamp mission` tool aborted on an assertion inside Fast DDS in a secured two-host run).
// Refused by name instead, with what works (multicast discovery); from 2.10 on it is allowed.
TEST_F(SecurityTest, ASecuredParticipantWithADiscoveryServerIsRefusedWhereFastDdsCannotSecureIt) {
  auto p = dds::Participant::create([] {
    auto o = secured(genuineDir(), "sim");
    o.domain_id = domain_;
    o.discovery_servers = {"127.0.0.1:11811"};
    return o;
  }());
#if FASTRTPS_VERSION_MAJOR == 2 && FASTRTPS_VERSION_MINOR < 10
  ASSERT_FALSE(p);
  EXPECT_EQ(p.error().code, ErrorCode::kUnsupported);
  EXPECT_NE(p.error().message.find("discovery server"), std::string::npos) << p.error().toString();
  EXPECT_NE(p.error().message.find("multicast"), std::string::npos) << p.error().toString();
#else
  EXPECT_TRUE(p) << p.error().toString();
#endif
}

TEST_F(SecurityTest, MakeCertsIsIdempotent) {
  const auto before = fs::last_write_time(genuineDir() / "sim" / "cert.pem");
  const std::string key = readFile(genuineDir() / "sim" / "key.pem");
  const std::string perms = readFile(genuineDir() / "sim" / "permissions.p7s");
  ASSERT_EQ(makeCerts(genuineDir()), 0) << readFile(genuineDir().string() + ".log");
  EXPECT_EQ(fs::last_write_time(genuineDir() / "sim" / "cert.pem"), before);
  EXPECT_EQ(readFile(genuineDir() / "sim" / "key.pem"), key);
  EXPECT_EQ(readFile(genuineDir() / "sim" / "permissions.p7s"), perms) << "unchanged permissions are not re-signed";
  // Private keys are readable by their owner only.
  const auto perm = fs::status(genuineDir() / "sim" / "key.pem").permissions();
  EXPECT_EQ(perm & (fs::perms::group_all | fs::perms::others_all), fs::perms::none);
}

}  // namespace
}  // namespace tamp::integration
