// Discovery servers: address parsing, the environment fallback, and participants that find each
// other only through a server (real Fast DDS, one process).
#include "tamp/dds/discovery.h"

#include <unistd.h>

#include <cstdlib>
#include <memory>
#include <string>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "tamp/dds/endpoint.h"
#include "tamp/dds/topics.h"
#include "test_util.h"

namespace tamp::dds {
namespace {

using ::testing::HasSubstr;

/// A participant on this test's domain that discovers the others only through `servers`; null
/// (and a test failure) when it cannot be made.
std::shared_ptr<Participant> serverClient(const std::string& name,
                                          const std::vector<DiscoveryServerAddress>& servers) {
  ParticipantOptions o{testing::isolatedDomain(), kProfileUdp, name, {}};
  for (const auto& s : servers) o.discovery_servers.push_back(s.toString());
  auto p = Participant::create(o);
  if (!p) ADD_FAILURE() << p.error().toString();
  return p ? *p : nullptr;
}

/// A reader callback that pushes the id of every alive world object into `inbox`.
auto pushAliveIds(testing::Inbox<std::string>& inbox) {
  return [&inbox](const msg::WorldObject& o, const SampleMeta& meta) {
    if (meta.alive) inbox.push(o.id());
  };
}

/// A movable object `id` at the origin.
msg::WorldObject movableObject(const std::string& id) {
  msg::WorldObject o;
  o.id(id);
  o.kind(msg::OBJECT_MOVABLE);
  o.pose().orientation().w(1.0);
  return o;
}

TEST(DiscoveryServerAddressTest, ParsesIpv4AndPortAndNamesWhatIsWrong) {
  auto a = parseDiscoveryServer("10.0.0.1:11811");
  ASSERT_TRUE(a.ok()) << a.error().toString();
  EXPECT_EQ(a->ip, "10.0.0.1");
  EXPECT_EQ(a->port, 11811);
  EXPECT_EQ(a->toString(), "10.0.0.1:11811");
  EXPECT_THAT(parseDiscoveryServer("10.0.0.1").error().message, HasSubstr("must be IPv4:PORT"));
  EXPECT_THAT(parseDiscoveryServer("host:11811").error().message,
              HasSubstr("'host' is not an IPv4 address"));
  EXPECT_THAT(parseDiscoveryServer("10.0.0.1:70000").error().message,
              HasSubstr("port must be in [1, 65535], got '70000'"));
  EXPECT_THAT(parseDiscoveryServer("10.0.0.1:").error().message, HasSubstr("got ''"));
  auto list = parseDiscoveryServers("10.0.0.1:1;10.0.0.2:2");
  ASSERT_TRUE(list.ok());
  ASSERT_EQ(list->size(), 2u);
  EXPECT_EQ((*list)[1].toString(), "10.0.0.2:2");
  EXPECT_TRUE(parseDiscoveryServers("")->empty());
  EXPECT_THAT(parseDiscoveryServers("10.0.0.1:1;nope").error().message, HasSubstr("'nope'"));
}

TEST(DiscoveryServerAddressTest, ExplicitListElseEnvironmentElseMulticast) {
  ::setenv("TAMP_DDS_DISCOVERY_SERVERS", "10.0.0.9:5000", 1);
  EXPECT_EQ((*resolveDiscoveryServers({}))[0].toString(), "10.0.0.9:5000");
  EXPECT_EQ((*resolveDiscoveryServers({"127.0.0.1:7"}))[0].toString(), "127.0.0.1:7");
  ::setenv("TAMP_DDS_DISCOVERY_SERVERS", "bad", 1);
  EXPECT_THAT(resolveDiscoveryServers({}).error().message, HasSubstr("TAMP_DDS_DISCOVERY_SERVERS"));
  ::setenv("TAMP_DDS_DISCOVERY_SERVERS", "", 1);  // what tamp launch sets for multicast
  EXPECT_TRUE(resolveDiscoveryServers({})->empty());
  ::unsetenv("TAMP_DDS_DISCOVERY_SERVERS");
  EXPECT_TRUE(resolveDiscoveryServers({})->empty());
  auto multicast = testing::makeParticipant();
  ASSERT_TRUE(multicast);
  EXPECT_FALSE(multicast->usesDiscoveryServer());
}

TEST(DiscoveryServerTest, ClientsOfAServerExchangeSamples) {
  const DiscoveryServerAddress address{"127.0.0.1",
                                       static_cast<uint16_t>(30000 + ::getpid() % 20000)};
  auto server = DiscoveryServer::start(address);
  ASSERT_TRUE(server.ok()) << server.error().toString();
  auto a = serverClient("client_a", {address});
  auto b = serverClient("client_b", {address});
  ASSERT_TRUE(a && b);
  EXPECT_TRUE(a->usesDiscoveryServer());
  testing::Inbox<std::string> inbox;
  Reader<msg::WorldObject> reader(b, topics::kWorldObjects, pushAliveIds(inbox));
  Writer<msg::WorldObject> writer(a, topics::kWorldObjects);
  ASSERT_TRUE(writer.waitForReaders(Termination::after(10.0), 1));
  ASSERT_TRUE(writer.write(movableObject("box_1")).ok());
  EXPECT_TRUE(inbox.waitFor([](const std::string& id) { return id == "box_1"; }, 10.0).has_value());
}

// Two servers, every client a client of both (a deployment with a server on each host): when
// one server is gone, a participant that starts afterwards still finds the others through the
// other server, and samples flow.
TEST(DiscoveryServerTest, WithTwoServersANewParticipantIsFoundWhenOneServerIsGone) {
  const uint16_t port = static_cast<uint16_t>(30000 + ::getpid() % 20000 + 2);
  const DiscoveryServerAddress first{"127.0.0.1", port};
  const DiscoveryServerAddress second{"127.0.0.1", static_cast<uint16_t>(port + 1)};
  auto server0 = DiscoveryServer::start(first, 0);
  ASSERT_TRUE(server0.ok()) << server0.error().toString();
  auto server1 = DiscoveryServer::start(second, 1);
  ASSERT_TRUE(server1.ok()) << server1.error().toString();
  auto a = serverClient("client_a", {first, second});
  ASSERT_TRUE(a);
  Writer<msg::WorldObject> writer(a, topics::kWorldObjects);
  server0->reset();  // the first host's server goes (its launcher died)
  auto b = serverClient("client_b", {first, second});
  ASSERT_TRUE(b);
  testing::Inbox<std::string> inbox;
  Reader<msg::WorldObject> reader(b, topics::kWorldObjects, pushAliveIds(inbox));
  ASSERT_TRUE(writer.waitForReaders(Termination::after(20.0), 1)) << "not found through the second server";
  ASSERT_TRUE(writer.write(movableObject("box_2")).ok());
  EXPECT_TRUE(inbox.waitFor([](const std::string& id) { return id == "box_2"; }, 10.0).has_value());
}

TEST(DiscoveryServerTest, RefusesAnAddressThatIsNotLocalOrABadId) {
  EXPECT_EQ(DiscoveryServer::start({"127.0.0.1", 11811}, 300).error().code,
            ErrorCode::kInvalidArgument);
  // 192.0.2.0/24 is TEST-NET-1: never an address of this host.
  auto foreign = DiscoveryServer::start({"192.0.2.1", 11811});
  ASSERT_FALSE(foreign.ok());
  EXPECT_EQ(foreign.error().code, ErrorCode::kInvalidArgument);
  EXPECT_THAT(foreign.error().message,
              HasSubstr("192.0.2.1:11811: the address is not one of this host's"));
  const DiscoveryServerAddress address{"127.0.0.1",
                                       static_cast<uint16_t>(30000 + ::getpid() % 20000 + 1)};
  auto first = DiscoveryServer::start(address);
  ASSERT_TRUE(first.ok()) << first.error().toString();
  auto second = DiscoveryServer::start(address);
  ASSERT_FALSE(second.ok());
  EXPECT_EQ(second.error().code, ErrorCode::kUnavailable);
  EXPECT_THAT(second.error().message, HasSubstr("port is in use"));
}

}  // namespace
}  // namespace tamp::dds
