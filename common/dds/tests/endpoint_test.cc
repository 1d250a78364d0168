#include "tamp/dds/endpoint.h"

#include <atomic>
#include <memory>
#include <thread>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "test_util.h"
#include "tamp/dds/topics.h"

namespace tamp::dds {
namespace {

using testing::makeParticipant;

msg::WorldObject object(const std::string& id, double x) {
  msg::WorldObject o;
  o.id(id);
  o.label("box");
  o.kind(msg::OBJECT_MOVABLE);
  o.pose().position().x(x);
  o.pose().orientation().w(1.0);
  return o;
}

TEST(ParticipantTest, RejectsBadDomainAndProfileWithClearErrors) {
  auto bad_domain = Participant::create(ParticipantOptions{500, kProfileDefault, "", {}});
  ASSERT_FALSE(bad_domain.ok());
  EXPECT_THAT(bad_domain.error().message, ::testing::HasSubstr("[0, 232], got 500"));
  auto bad_profile = Participant::create(ParticipantOptions{testing::isolatedDomain(), "no_such_profile", "", {}});
  ASSERT_FALSE(bad_profile.ok());
  EXPECT_THAT(bad_profile.error().message, ::testing::HasSubstr("unknown DDS participant profile 'no_such_profile'"));
  auto no_file = Participant::create(ParticipantOptions{1, kProfileDefault, "", "/nonexistent/profiles.xml"});
  ASSERT_FALSE(no_file.ok());
  EXPECT_EQ(no_file.error().code, ErrorCode::kNotFound);
}

TEST(ParticipantTest, DomainFromEnvironment) {
  ::setenv("TAMP_DOMAIN_ID", "42", 1);
  EXPECT_EQ(*resolveDomainId(-1), 42);
  EXPECT_EQ(*resolveDomainId(7), 7);
  ::setenv("TAMP_DOMAIN_ID", "x42", 1);
  EXPECT_FALSE(resolveDomainId(-1).ok());
  ::unsetenv("TAMP_DOMAIN_ID");
  EXPECT_EQ(*resolveDomainId(-1), 0);
}

TEST(EndpointTest, DeliversSamplesToCallbackAndPolling) {
  auto p = makeParticipant();
  ASSERT_TRUE(p);
  std::mutex m;
  std::vector<std::string> got;
  Reader<msg::WorldObject> cb_reader(p, topics::kWorldObjects, [&](const msg::WorldObject& o, const SampleMeta& meta) {
    std::lock_guard lock(m);
    if (meta.alive) got.push_back(o.id());
  });
  Reader<msg::WorldObject> poll_reader(p, topics::kWorldObjects);
  Writer<msg::WorldObject> writer(p, topics::kWorldObjects);
  ASSERT_TRUE(writer.waitForReaders(Termination::after(5.0), 2));
  ASSERT_TRUE(writer.write(object("box_1", 1.0)).ok());
  ASSERT_TRUE(writer.write(object("box_2", 2.0)).ok());
  const Deadline d = Deadline::in(5.0);
  while (!d.expired()) {
    std::lock_guard lock(m);
    if (got.size() == 2) break;
  }
  {
    std::lock_guard lock(m);
    EXPECT_THAT(got, ::testing::UnorderedElementsAre("box_1", "box_2"));
  }
  std::optional<msg::WorldObject> s;
  const Deadline d2 = Deadline::in(5.0);
  while (!(s = poll_reader.takeNext()) && !d2.expired()) std::this_thread::sleep_for(std::chrono::milliseconds(5));
  ASSERT_TRUE(s.has_value());
  EXPECT_TRUE(s->id() == "box_1" || s->id() == "box_2");
}

TEST(EndpointTest, TransientLocalStateReachesLateJoinerAndDisposeIsReported) {
  auto p = makeParticipant();
  ASSERT_TRUE(p);
  Writer<msg::WorldObject> writer(p, topics::kWorldObjects);
  ASSERT_TRUE(writer.write(object("table", 0.0)).ok());
  ASSERT_TRUE(writer.write(object("can", 0.5)).ok());
  ASSERT_TRUE(writer.write(object("can", 0.7)).ok());  // KEEP_LAST 1 per instance: only 0.7 kept

  std::mutex m;
  std::map<std::string, double> alive;
  std::vector<std::string> disposed;
  Reader<msg::WorldObject> late(p, topics::kWorldObjects, [&](const msg::WorldObject& o, const SampleMeta& meta) {
    std::lock_guard lock(m);
    if (meta.alive) {
      alive[o.id()] = o.pose().position().x();
    } else {
      disposed.push_back(o.id());
      alive.erase(o.id());
    }
  });
  auto wait = [&](auto pred) {
    const Deadline d = Deadline::in(5.0);
    while (!d.expired()) {
      {
        std::lock_guard lock(m);
        if (pred()) return true;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
    }
    return false;
  };
  ASSERT_TRUE(wait([&] { return alive.size() == 2; }));
  {
    std::lock_guard lock(m);
    EXPECT_DOUBLE_EQ(alive["can"], 0.7);
  }
  ASSERT_TRUE(writer.dispose(object("can", 0.0)).ok());
  ASSERT_TRUE(wait([&] { return !disposed.empty(); }));
  std::lock_guard lock(m);
  EXPECT_EQ(disposed, std::vector<std::string>{"can"});
  EXPECT_EQ(alive.count("can"), 0u);
}

TEST(EndpointTest, KeyedCommandsAndEventsAreNotLimitedToTenInstances) {
  // One instance per command id: a mission sends far more than Fast DDS's default 10, and the
  // 11th write once blocked until TIMEOUT. Every class whose topics are keyed per command.
  auto p = makeParticipant();
  ASSERT_TRUE(p);
  Reader<msg::ExecuteCommand> commands(p, topics::kExecuteCommand);
  Reader<msg::ExecuteStatus> statuses(p, topics::kExecuteStatus);
  Writer<msg::ExecuteCommand> command_writer(p, topics::kExecuteCommand);
  Writer<msg::ExecuteStatus> status_writer(p, topics::kExecuteStatus);
  ASSERT_TRUE(command_writer.waitForReaders(Termination::after(5.0)));
  ASSERT_TRUE(status_writer.waitForReaders(Termination::after(5.0)));
  constexpr int kCommands = 40;
  for (int i = 0; i < kCommands; ++i) {
    msg::ExecuteCommand c;
    c.command_id("m" + std::to_string(i));
    ASSERT_TRUE(command_writer.write(c).ok()) << "command " << i;
    msg::ExecuteStatus st;
    st.command_id(c.command_id());
    ASSERT_TRUE(status_writer.write(st).ok()) << "status " << i;
  }
  int got_commands = 0, got_statuses = 0;
  const Deadline d = Deadline::in(10.0);
  while ((got_commands < kCommands || got_statuses < kCommands) && !d.expired()) {
    bool any = false;
    while (commands.takeNext()) ++got_commands, any = true;
    while (statuses.takeNext()) ++got_statuses, any = true;
    if (!any) std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  EXPECT_EQ(got_commands, kCommands);
  EXPECT_EQ(got_statuses, kCommands);
}

TEST(EndpointTest, AReaderThatComesBackCountsAsANewMatch) {
  // A restarted reader (a new participant) matches again: the writer's ever-matched count rises
  // while its current count returns to one, so a writer can tell that a reader may have missed
  // what it wrote (volatile commands).
  auto p = makeParticipant();
  ASSERT_TRUE(p);
  Writer<msg::ExecuteCommand> writer(p, topics::kExecuteCommand);
  auto first = makeParticipant();
  ASSERT_TRUE(first);
  auto reader = std::make_unique<Reader<msg::ExecuteCommand>>(first, topics::kExecuteCommand);
  ASSERT_TRUE(writer.waitForReaders(Termination::after(5.0)));
  EXPECT_EQ(writer.readersEverMatched(), 1);
  reader.reset();
  first.reset();
  const Deadline gone = Deadline::in(10.0);
  while (writer.matchedReaders() > 0 && !gone.expired()) std::this_thread::sleep_for(std::chrono::milliseconds(5));
  ASSERT_EQ(writer.matchedReaders(), 0);
  auto second = makeParticipant();
  ASSERT_TRUE(second);
  Reader<msg::ExecuteCommand> again(second, topics::kExecuteCommand);
  ASSERT_TRUE(writer.waitForReaders(Termination::after(5.0)));
  EXPECT_EQ(writer.matchedReaders(), 1);
  EXPECT_EQ(writer.readersEverMatched(), 2);
}

TEST(EndpointTest, ThrowingCallbackIsContainedAndCounted) {
  auto p = makeParticipant();
  ASSERT_TRUE(p);
  std::atomic<int> calls{0};
  Reader<msg::WorldEvent> reader(p, topics::kWorldEvents, [&](const msg::WorldEvent&, const SampleMeta&) {
    ++calls;
    throw std::runtime_error("boom");
  });
  Writer<msg::WorldEvent> writer(p, topics::kWorldEvents);
  ASSERT_TRUE(writer.waitForReaders(Termination::after(5.0)));
  msg::WorldEvent e;
  e.object_id("x");
  ASSERT_TRUE(writer.write(e).ok());
  ASSERT_TRUE(writer.write(e).ok());
  const Deadline d = Deadline::in(5.0);
  while (calls < 2 && !d.expired()) std::this_thread::sleep_for(std::chrono::milliseconds(5));
  EXPECT_EQ(calls.load(), 2);
  EXPECT_EQ(reader.callbackErrors(), 2u);
}

TEST(EndpointTest, TopicTypeConflictThrows) {
  auto p = makeParticipant();
  ASSERT_TRUE(p);
  Writer<msg::WorldEvent> ok(p, TopicSpec<msg::WorldEvent>{"tamp/test/conflict", QosClass::kEvent});
  EXPECT_THROW((Writer<msg::Heartbeat>(p, TopicSpec<msg::Heartbeat>{"tamp/test/conflict", QosClass::kEvent})),
               std::runtime_error);
}

}  // namespace
}  // namespace tamp::dds
