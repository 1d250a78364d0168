// Malformed messages on real Fast DDS topics at running services (issue 13, part 6): each service
// rejects them with an answer naming the field where the protocol has one (an RPC reply's status,
// a FAILED result for a command with an id), logs each kind once, and keeps serving the valid
// request that follows.
//   - symbolic planner: PlanRequest with an empty goal atom, a NaN weight, an unknown search enum;
//   - effort estimator: an EffortRequest with 150000 queries (huge sequence), a NaN query;
//   - simulator: a TrajectoryCommand with NaN positions and one with an unknown action kind.
#include <cmath>
#include <limits>

#include <gtest/gtest.h>

#include "integration_util.h"
#include "tamp/core/paths.h"
#include "tamp/dds/participant.h"
#include "tamp/dds/rpc.h"
#include "tamp/dds/topics.h"

namespace tamp::integration {
namespace {

using dds::testing::Inbox;

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

size_t count(const std::string& text, const std::string& what) {
  size_t n = 0;
  for (size_t at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) ++n;
  return n;
}

class MalformedInputTest : public ::testing::Test {
 protected:
  void SetUp() override {
    domain_ = isolatedDomain();
    const std::string scenario = (configDir() / "scenarios" / "occluded_can.yaml").string();
    sup_.add(serviceSpec("tamp_symbolic_planner_service", "symbolic_planner", domain_,
                         {"--config", (configDir() / "services" / "symbolic_planner.yaml").string()}));
    store_ = tempFile("tamp_it_malformed_store");
    config_ = tempFile("tamp_it_malformed_effort.yaml");
    std::ofstream(config_) << "store_directory: " << store_.string() << "\n";
    sup_.add(serviceSpec("tamp_effort_estimator_service", "effort_estimator", domain_, {"--config", config_.string()}));
    sup_.add(serviceSpec("tamp_sim_service", "sim", domain_,
                         {"--config", (configDir() / "services" / "sim.yaml").string(), "--scenario", scenario}));
    ASSERT_TRUE(sup_.startAll().ok());
    auto p = dds::Participant::create({domain_, dds::kProfileDefault, "tamp/malformed_input_test", {}});
    ASSERT_TRUE(p) << p.error().toString();
    participant_ = *p;
  }

  void TearDown() override {
    sup_.poll();
    for (const auto& st : sup_.status()) {
      EXPECT_EQ(st.phase, process::ProcessPhase::kRunning) << st.name << " died (" << st.last_exit << "):\n"
                                                            << log(st.name);
    }
    sup_.stopAll(5.0);
    std::filesystem::remove_all(store_);
    std::filesystem::remove(config_);
  }

  std::string log(const std::string& name) { return readFile(tempFile("tamp_it_" + name + ".log")); }

  int domain_{0};
  std::filesystem::path store_, config_;
  process::Supervisor sup_;
  std::shared_ptr<dds::Participant> participant_;
};

msg::PlanRequest validPlan() {
  msg::PlanRequest r;
  r.domain_pddl(*readTextFile(configDir() / "pddl" / "mobile_manipulation.pddl"));
  r.problem_pddl(*readTextFile(configDir() / "pddl" / "problems" / "occluded_can.pddl"));
  return r;
}

TEST_F(MalformedInputTest, ServicesRejectMalformedMessagesNamingTheFieldAndKeepServing) {
  // ---- symbolic planner (request/reply): the reply's status names the field.
  dds::RpcClient<msg::PlanRequest, msg::PlanReply> planner(participant_, dds::services::kPlan);
  for (int i = 0; i < 5; ++i) {  // five of one kind: logged once
    msg::PlanRequest bad = validPlan();
    bad.goal({"(holding can)", ""});
    auto rep = planner.call(bad, dds::CallOptions{30.0, {}});
    ASSERT_FALSE(rep.ok());
    EXPECT_EQ(rep.error().code, ErrorCode::kInvalidArgument);
    EXPECT_NE(rep.error().message.find("PlanRequest.goal[1]: empty string"), std::string::npos)
        << rep.error().message;
  }
  msg::PlanRequest nan_weight = validPlan();
  nan_weight.weight(kNaN);
  auto rep = planner.call(nan_weight, dds::CallOptions{30.0, {}});
  ASSERT_FALSE(rep.ok());
  EXPECT_NE(rep.error().message.find("PlanRequest.weight: NaN"), std::string::npos) << rep.error().message;
  msg::PlanRequest bad_enum = validPlan();
  bad_enum.search(static_cast<msg::SearchKind>(1234567));
  rep = planner.call(bad_enum, dds::CallOptions{30.0, {}});
  ASSERT_FALSE(rep.ok());
  EXPECT_NE(rep.error().message.find("PlanRequest.search: unknown value 1234567"), std::string::npos)
      << rep.error().message;
  rep = planner.call(validPlan(), dds::CallOptions{60.0, {}});
  ASSERT_TRUE(rep.ok()) << rep.error().toString();
  EXPECT_EQ(rep->status(), msg::PLAN_SOLVED) << rep->header().message();
  EXPECT_FALSE(rep->actions().empty());

  // ---- effort estimator: a huge sequence is refused whole; a NaN query is refused alone.
  dds::RpcClient<msg::EffortRequest, msg::EffortReply> effort(participant_, dds::services::kEffort);
  msg::EffortRequest huge;
  huge.queries().resize(150000);
  auto erep = effort.call(huge, dds::CallOptions{30.0, {}});
  ASSERT_FALSE(erep.ok());
  EXPECT_NE(erep.error().message.find("EffortRequest.queries: 150000 elements (limit 100000)"), std::string::npos)
      << erep.error().message;
  msg::EffortRequest mixed;
  msg::EffortQuery pick;
  pick.kind(msg::ACTION_PICK);
  pick.object_mass(0.3);
  pick.approach_m(0.1);
  pick.retreat_m(0.1);
  msg::EffortQuery nan = pick;
  nan.object_mass(kNaN);
  mixed.queries({pick, nan});
  erep = effort.call(mixed, dds::CallOptions{30.0, {}});
  ASSERT_TRUE(erep.ok()) << erep.error().toString();
  ASSERT_EQ(erep->estimates().size(), 2U);
  EXPECT_EQ(erep->estimates()[0].code(), msg::STATUS_OK) << erep->estimates()[0].message();
  EXPECT_GT(erep->estimates()[0].mean_s(), 0.0);
  EXPECT_EQ(erep->estimates()[1].code(), msg::STATUS_INVALID_ARGUMENT);
  EXPECT_EQ(erep->estimates()[1].message(), "EffortRequest.queries[1].object_mass: NaN");

  // ---- simulator (topic): a command with an id gets a FAILED result naming the field.
  Inbox<msg::ActionResult> results;
  dds::Reader<msg::ActionResult> result_reader(
      participant_, dds::topics::kActionResult, [&](const msg::ActionResult& m, const dds::SampleMeta&) { results.push(m); });
  dds::Writer<msg::TrajectoryCommand> commands(participant_, dds::topics::kTrajectoryCommand);
  ASSERT_TRUE(commands.waitForReaders(Termination::after(30.0))) << "the simulator did not subscribe";
  msg::TrajectoryCommand c;
  c.command_id("it_nan");
  c.kind(msg::ACTION_MOVE_BASE);
  c.trajectory().joint_names({"x", "y", "theta"});
  c.trajectory().times({0.0, 1.0});
  c.trajectory().positions({0, 0, 0, kNaN, 0, 0});
  ASSERT_TRUE(commands.write(c));
  msg::TrajectoryCommand k = c;
  k.command_id("it_kind");
  k.trajectory().positions({0, 0, 0, 0.1, 0, 0});
  k.kind(static_cast<msg::ActionKind>(77));
  ASSERT_TRUE(commands.write(k));
  auto r1 = results.waitFor([](const msg::ActionResult& r) { return r.command_id() == "it_nan"; }, 30.0);
  ASSERT_TRUE(r1) << "no result for the malformed command";
  EXPECT_EQ(r1->outcome(), msg::OUTCOME_FAILED);
  EXPECT_NE(r1->reason().find("TrajectoryCommand.trajectory.positions[3]: NaN"), std::string::npos) << r1->reason();
  auto r2 = results.waitFor([](const msg::ActionResult& r) { return r.command_id() == "it_kind"; }, 30.0);
  ASSERT_TRUE(r2);
  EXPECT_NE(r2->reason().find("TrajectoryCommand.kind: unknown value 77"), std::string::npos) << r2->reason();

  // Logged once per kind: five empty goal atoms, one line.
  sup_.poll();
  const std::string planner_log = log("symbolic_planner");
  EXPECT_EQ(count(planner_log, "PlanRequest.goal[1]: empty string"), 1U) << planner_log;
  EXPECT_EQ(count(planner_log, "PlanRequest.weight: NaN"), 1U) << planner_log;
  EXPECT_NE(log("sim").find("TrajectoryCommand.trajectory.positions[3]: NaN"), std::string::npos) << log("sim");
}

}  // namespace
}  // namespace tamp::integration
