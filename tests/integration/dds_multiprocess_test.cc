// Real processes talking over real Fast DDS transports, each test on its own domain:
// request/reply between processes, a server killed and restarted mid-run, `tamp status` from
// heartbeats, and malformed/oversized messages that neither side may crash on.
#include <signal.h>

#include <random>

#include <fastdds/dds/topic/TopicDataType.hpp>
#include <fastrtps/rtps/common/SerializedPayload.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "integration_util.h"
#include "tamp/dds/service_node.h"

namespace tamp::integration {
namespace {

using ::testing::HasSubstr;
using EchoClient = dds::RpcClient<msg::EchoRequest, msg::EchoReply>;

class DdsMultiProcessTest : public ::testing::Test {
 protected:
  void SetUp() override {
    domain_ = isolatedDomain();
    auto p = dds::Participant::create(dds::ParticipantOptions{domain_, dds::kProfileDefault, "it-client", {}});
    ASSERT_TRUE(p.ok()) << p.error().toString();
    participant_ = *p;
  }
  void TearDown() override {
    sup_.stopAll(3.0);
    if (HasFailure()) {
      for (const auto& st : sup_.status()) {
        std::cerr << "---- log of " << st.name << " (" << st.last_exit << ") ----\n"
                  << readFile(tempFile("tamp_it_" + st.name + ".log")) << "\n";
      }
    }
    if (!std::getenv("TAMP_KEEP_LOGS")) {
      for (const auto& st : sup_.status()) std::filesystem::remove(tempFile("tamp_it_" + st.name + ".log"));
    }
  }
  void startEcho(const std::string& name) {
    auto spec = serviceSpec("tamp_echo_node", name, domain_);
    std::filesystem::remove(spec.log_file);
    sup_.add(spec);
    ASSERT_TRUE(sup_.startAll().ok());
  }
  static msg::EchoRequest request(size_t bytes, uint8_t fill) {
    msg::EchoRequest r;
    r.payload(std::vector<uint8_t>(bytes, fill));
    return r;
  }

  int domain_{0};
  std::shared_ptr<dds::Participant> participant_;
  process::Supervisor sup_;
};

TEST_F(DdsMultiProcessTest, TwoProcessesExchangeRequests) {
  startEcho("echo_a");
  EchoClient client(participant_, dds::echoService("echo_a"));
  const pid_t server_pid = sup_.status("echo_a")->pid;
  for (int i = 0; i < 20; ++i) {
    auto rep = client.call(request(100 + static_cast<size_t>(i), static_cast<uint8_t>(i)), dds::CallOptions{15.0, {}});
    ASSERT_TRUE(rep.ok()) << rep.error().toString();
    EXPECT_EQ(rep->payload(), std::vector<uint8_t>(100 + static_cast<size_t>(i), static_cast<uint8_t>(i)));
    EXPECT_EQ(static_cast<pid_t>(rep->pid()), server_pid);  // answered by the other process
  }
}

TEST_F(DdsMultiProcessTest, ServerKilledAndRestartedClientRetriesSucceed) {
  startEcho("echo_k");
  EchoClient client(participant_, dds::echoService("echo_k"), dds::RpcClientOptions{0.5, 100, 0});
  auto first = client.call(request(10, 1), dds::CallOptions{15.0, {}});
  ASSERT_TRUE(first.ok()) << first.error().toString();
  const pid_t old_pid = sup_.status("echo_k")->pid;

  ASSERT_TRUE(sup_.signal("echo_k", SIGKILL));
  const Deadline reaped = Deadline::in(5.0);
  while (sup_.status("echo_k")->phase == process::ProcessPhase::kRunning && !reaped.expired()) {
    sup_.poll();
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  // A call made while the server is dead: its retries must reach the restarted server.
  std::optional<Result<msg::EchoReply>> during;
  std::thread caller([&] { during = client.call(request(20, 2), dds::CallOptions{30.0, {}}); });
  std::this_thread::sleep_for(std::chrono::milliseconds(700));
  auto spec = serviceSpec("tamp_echo_node", "echo_k", domain_);
  auto pid = process::spawn(spec);
  ASSERT_TRUE(pid.ok());
  caller.join();
  ASSERT_TRUE(during.has_value());
  ASSERT_TRUE(during->ok()) << during->error().toString();
  EXPECT_EQ(static_cast<pid_t>((*during)->pid()), *pid);
  EXPECT_NE(*pid, old_pid);
  EXPECT_EQ((*during)->payload(), std::vector<uint8_t>(20, 2));
  kill(*pid, SIGTERM);
  int wstatus = 0;
  waitpid(*pid, &wstatus, 0);
  EXPECT_TRUE(WIFEXITED(wstatus) && WEXITSTATUS(wstatus) == 0) << process::describeExit(wstatus);
}

TEST_F(DdsMultiProcessTest, StatusListsLiveServicesFromHeartbeats) {
  startEcho("svc_one");
  startEcho("svc_two");
  auto [rc, out] = runCommand(binDir() / "tamp-status", {"--domain", std::to_string(domain_), "--json", "--wait", "10",
                                                         "--expect", "svc_one", "--expect", "svc_two"});
  ASSERT_EQ(rc, 0) << out;
  auto j = nlohmann::json::parse(out.substr(out.find('{')));
  std::map<std::string, int> pids;
  for (const auto& s : j["services"]) {
    if (s["name"] == "svc_one" || s["name"] == "svc_two") {
      EXPECT_EQ(s["state"], "ready");
      EXPECT_TRUE(s["alive"].get<bool>());
      pids[s["name"]] = s["pid"].get<int>();
    }
  }
  EXPECT_EQ(pids["svc_one"], sup_.status("svc_one")->pid);
  EXPECT_EQ(pids["svc_two"], sup_.status("svc_two")->pid);

  auto [rc2, out2] = runCommand(binDir() / "tamp-status",
                                {"--domain", std::to_string(domain_), "--wait", "0.5", "--expect", "svc_three"});
  EXPECT_EQ(rc2, 40) << out2;
  EXPECT_THAT(out2, HasSubstr("MISSING: svc_three"));
}

// A type that claims to be EchoRequest but sends bytes that are not a valid EchoRequest.
class GarbageType : public eprosima::fastdds::dds::TopicDataType {
 public:
  explicit GarbageType(size_t bytes) : bytes_(bytes) {
    setName("tamp::msg::EchoRequest");
    m_typeSize = static_cast<uint32_t>(bytes + 4);
    m_isGetKeyDefined = false;
    auto_fill_type_object(false);
    auto_fill_type_information(false);
  }
  bool serialize(void*, eprosima::fastrtps::rtps::SerializedPayload_t* payload) override {
    std::mt19937 rng(7);
    payload->data[0] = 0;
    payload->data[1] = 1;  // CDR little endian
    payload->data[2] = payload->data[3] = 0;
    for (size_t i = 0; i < bytes_; ++i) payload->data[4 + i] = static_cast<uint8_t>(rng() | 0x80);
    payload->length = static_cast<uint32_t>(bytes_ + 4);
    return true;
  }
  bool deserialize(eprosima::fastrtps::rtps::SerializedPayload_t*, void*) override { return false; }
  std::function<uint32_t()> getSerializedSizeProvider(void*) override {
    return [this] { return static_cast<uint32_t>(bytes_ + 4); };
  }
  void* createData() override { return new char[1]; }
  void deleteData(void* d) override { delete[] static_cast<char*>(d); }
  bool getKey(void*, eprosima::fastrtps::rtps::InstanceHandle_t*, bool) override { return false; }

 private:
  size_t bytes_;
};

}  // namespace
}  // namespace tamp::integration

namespace tamp::dds {
struct GarbageSample {};
template <>
struct TypeSupport<GarbageSample> {
  struct type : integration::GarbageType {
    type() : integration::GarbageType(64) {}
  };
};
}  // namespace tamp::dds

namespace tamp::integration {
namespace {

TEST_F(DdsMultiProcessTest, MalformedAndOversizedMessagesAreRejectedWithoutCrashing) {
  startEcho("echo_m");
  EchoClient client(participant_, dds::echoService("echo_m"), dds::RpcClientOptions{1.0, 5, 64u << 20});
  ASSERT_TRUE(client.call(request(8, 1), dds::CallOptions{15.0, {}}).ok());

  // 1. Undecodable bytes on the request topic, from a second participant (a type mismatch cannot
  //    share one participant). Fast DDS matches the writer (by type name) and discards samples it
  //    cannot deserialize when the server takes them; the server must simply survive.
  auto rogue = dds::Participant::create(dds::ParticipantOptions{domain_, dds::kProfileDefault, "rogue", {}});
  ASSERT_TRUE(rogue.ok());
  {
    dds::Writer<dds::GarbageSample> garbage(*rogue, dds::TopicSpec<dds::GarbageSample>{
                                                        "tamp/echo_m/echo/request", dds::QosClass::kRpc});
    ASSERT_TRUE(garbage.waitForReaders(Termination::after(10.0))) << "the rogue writer never matched the server";
    dds::GarbageSample g;
    for (int i = 0; i < 20; ++i) ASSERT_TRUE(garbage.write(g).ok());
    std::this_thread::sleep_for(std::chrono::milliseconds(300));
  }

  // 2. A well-formed request without correlation ids cannot be answered: the server drops it,
  //    counts it, and reports the count in its heartbeat.
  {
    // (A fresh participant: `rogue` registered the garbage type under EchoRequest's name.)
    auto sender = dds::Participant::create(dds::ParticipantOptions{domain_, dds::kProfileDefault, "raw", {}});
    ASSERT_TRUE(sender.ok());
    dds::Writer<msg::EchoRequest> raw(*sender, dds::TopicSpec<msg::EchoRequest>{"tamp/echo_m/echo/request",
                                                                               dds::QosClass::kRpc});
    ASSERT_TRUE(raw.waitForReaders(Termination::after(10.0)));
    ASSERT_TRUE(raw.write(request(4, 4)).ok());
    dds::HeartbeatMonitor monitor(participant_);
    const Deadline d = Deadline::in(10.0);
    uint64_t failed = 0;
    while (!d.expired() && failed == 0) {
      for (const auto& s : monitor.services()) {
        if (s.name == "echo_m") failed = s.failed;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
    EXPECT_EQ(failed, 1u) << "the server should count the request without ids as failed";
  }

  // 3. A payload over the service's 16 MiB limit: refused by the server with a clear reply.
  auto big = client.call(request(20u << 20, 3), dds::CallOptions{30.0, {}});
  ASSERT_FALSE(big.ok());
  EXPECT_EQ(big.error().code, ErrorCode::kInvalidArgument);
  EXPECT_THAT(big.error().message, HasSubstr("exceeds the limit of 16777216 bytes"));

  // 4. A client with the default limit refuses to send it at all.
  EchoClient strict(participant_, dds::echoService("echo_m"));
  auto refused = strict.call(request(20u << 20, 3), dds::CallOptions{5.0, {}});
  ASSERT_FALSE(refused.ok());
  EXPECT_THAT(refused.error().message, HasSubstr("exceeds the limit"));

  // The server is alive and still answers; the process did not crash.
  auto after = client.call(request(1000, 9), dds::CallOptions{15.0, {}});
  ASSERT_TRUE(after.ok()) << after.error().toString();
  EXPECT_EQ(after->payload(), std::vector<uint8_t>(1000, 9));
  sup_.poll();
  EXPECT_EQ(sup_.status("echo_m")->phase, process::ProcessPhase::kRunning);
}

TEST_F(DdsMultiProcessTest, ServiceStopsCleanlyOnSigterm) {
  startEcho("echo_t");
  EchoClient client(participant_, dds::echoService("echo_t"));
  ASSERT_TRUE(client.call(request(1, 1), dds::CallOptions{15.0, {}}).ok());
  sup_.stopAll(5.0);
  EXPECT_EQ(sup_.status("echo_t")->last_exit, "exit 0");
}

}  // namespace
}  // namespace tamp::integration
