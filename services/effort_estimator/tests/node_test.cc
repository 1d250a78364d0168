// The effort estimator service in-process on an isolated DDS domain: estimates through the real
// RPC path, execution records and model snapshots through real topics (a second participant plays
// the graph manager / executive).
#include "effort_estimator_node.h"

#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <limits>
#include <optional>
#include <random>
#include <thread>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "synthetic.h"
#include "test_dir.h"

namespace tamp::effort_estimator {
namespace {

using ::testing::HasSubstr;
using Client = dds::RpcClient<msg::EffortRequest, msg::EffortReply>;

int testDomain() { return 20 + static_cast<int>(::getpid() % 200); }

/// Polls `done` every 10 ms for at most `seconds`.
template <typename F>
bool eventually(F done, double seconds = 30.0) {
  const Deadline deadline = Deadline::in(seconds);
  while (!done()) {
    if (deadline.expired()) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  return true;
}

/// Every model snapshot a reader received. Polls (no callback), like a process that reads the
/// current model when it needs it.
class SnapshotLog {
 public:
  explicit SnapshotLog(std::shared_ptr<dds::Participant> p)
      : reader_(std::move(p), dds::topics::kEffortModel) {}

  /// The first received snapshot with version >= `version`, waiting up to 30 s.
  std::optional<msg::EffortModelSnapshot> waitForVersion(std::uint64_t version) {
    std::optional<msg::EffortModelSnapshot> found;
    eventually([&] {
      poll();
      for (const auto& s : got_) {
        if (s.version() >= version) {
          found = s;
          return true;
        }
      }
      return false;
    });
    return found;
  }
  int matchedWriters() const { return reader_.matchedWriters(); }
  std::vector<msg::EffortModelSnapshot> all() {
    poll();
    return got_;
  }

 private:
  void poll() {
    while (auto s = reader_.takeNext()) got_.push_back(std::move(*s));
  }

  dds::Reader<msg::EffortModelSnapshot> reader_;
  std::vector<msg::EffortModelSnapshot> got_;
};

const msg::ActionTimeModel& kindModel(const msg::EffortModelSnapshot& s, msg::ActionKind kind) {
  for (const auto& m : s.models()) {
    if (m.kind() == kind) return m;
  }
  throw std::invalid_argument("snapshot without that kind");
}

class EffortNodeTest : public ::testing::Test {
 protected:
  static EstimatorParams testParams() {
    EstimatorParams p;
    p.store_directory = "";  // in memory
    p.refit_batch_size = 5;  // refits triggered by the batch only: the period is long
    p.refit_period_s = 600.0;
    return p;
  }

  void SetUp() override {
    args_.name = "effort_estimator_test";
    args_.domain_id = testDomain();
    node_ = std::make_unique<EffortEstimatorNode>(args_, testParams());
    // The caller's side lives in its own participant, like another process.
    auto p = dds::Participant::create(
        dds::ParticipantOptions{args_.domain_id, dds::kProfileDefault, "test_client", {}});
    ASSERT_TRUE(p.ok()) << p.error().toString();
    peer_ = *p;
    client_ = std::make_unique<Client>(peer_, dds::services::kEffort);
  }

  void TearDown() override {
    client_.reset();
    node_.reset();
  }

  /// Publishes `records` on tamp/execution/record from the peer participant.
  void publish(const std::vector<ExecutionRecord>& records) {
    if (!record_writer_) {
      record_writer_ = std::make_unique<dds::Writer<msg::ExecutionRecord>>(
          peer_, dds::topics::kExecutionRecords);
      ASSERT_TRUE(record_writer_->waitForReaders(Termination::after(20.0)));
    }
    for (const auto& r : records) ASSERT_TRUE(record_writer_->write(toMsg(r)).ok());
  }

  std::vector<ExecutionRecord> moveBaseRecords(int n, std::uint64_t seed) {
    std::mt19937_64 rng(seed);
    auto recs = synthetic::records(ActionKind::kMoveBase, n, rng);
    for (size_t i = 0; i < recs.size(); ++i)
      recs[i].record_id = "rec-" + std::to_string(seed) + "-" + std::to_string(i);
    return recs;
  }

  dds::ServiceArgs args_;
  std::unique_ptr<EffortEstimatorNode> node_;
  std::shared_ptr<dds::Participant> peer_;
  std::unique_ptr<Client> client_;
  std::unique_ptr<dds::Writer<msg::ExecutionRecord>> record_writer_;
};

TEST_F(EffortNodeTest, EstimateRoundTripMatchesTheLibrary) {
  std::mt19937_64 rng(11);
  std::vector<ActionDescription> actions;
  for (ActionKind k : kAllActionKinds) {
    for (int i = 0; i < 3; ++i) actions.push_back(synthetic::randomAction(k, rng));
  }
  msg::EffortRequest req;
  std::vector<msg::EffortQuery> queries;
  for (const auto& a : actions) queries.push_back(toMsg(a));
  req.queries(queries);
  auto rep = client_->call(req, dds::CallOptions{30.0, {}});
  ASSERT_TRUE(rep.ok()) << rep.error().toString();
  ASSERT_EQ(rep->estimates().size(), actions.size());
  EXPECT_EQ(rep->model_version(), 0u);

  // An independent estimator with the same parameters and no records: the priors.
  EffortEstimator reference(testParams(), /*start_worker=*/false);
  for (size_t i = 0; i < actions.size(); ++i) {
    const auto& e = rep->estimates()[i];
    ASSERT_EQ(e.code(), msg::STATUS_OK) << i << ": " << e.message();
    auto want = reference.estimate(actions[i]);
    ASSERT_TRUE(want.ok()) << want.error().toString();
    EXPECT_DOUBLE_EQ(e.mean_s(), want->mean_s) << i << " " << toString(actions[i].kind);
    EXPECT_DOUBLE_EQ(e.stddev_s(), want->stddev_s) << i;
    EXPECT_GT(e.mean_s(), 0.0);
    EXPECT_GT(e.stddev_s(), 0.0);
  }
  // Pick/place prices depend on the distances the query carries.
  auto pick = actions[6];
  ASSERT_EQ(pick.kind, ActionKind::kPick);
  pick.approach_m += 0.2;
  msg::EffortRequest longer;
  longer.queries({toMsg(pick)});
  auto rep2 = client_->call(longer, dds::CallOptions{30.0, {}});
  ASSERT_TRUE(rep2.ok()) << rep2.error().toString();
  EXPECT_GT(rep2->estimates()[0].mean_s(), rep->estimates()[6].mean_s() + 1.0);
}

TEST_F(EffortNodeTest, MalformedQueriesGetAnErrorNamingTheField) {
  std::mt19937_64 rng(3);
  const ActionDescription base = synthetic::randomAction(ActionKind::kMoveBase, rng);
  std::vector<msg::EffortQuery> q(7, toMsg(base));
  msg::JointPath ragged = q[1].path();
  ragged.values().pop_back();  // not a multiple of the 3 base joints
  q[1].path(ragged);
  q[2].kind(static_cast<msg::ActionKind>(17));
  q[3] = toMsg(synthetic::randomAction(ActionKind::kPick, rng));
  q[3].object_mass(-1.0);
  q[4] = toMsg(synthetic::randomAction(ActionKind::kPlace, rng));
  q[4].path(q[0].path());  // place takes distances, not a path
  q[5] = toMsg(synthetic::randomAction(ActionKind::kPick, rng));
  q[5].approach_m(std::numeric_limits<double>::quiet_NaN());
  q[6].path(msg::JointPath());  // move_base without a path
  msg::EffortRequest req;
  req.queries(q);
  auto rep = client_->call(req, dds::CallOptions{30.0, {}});
  ASSERT_TRUE(rep.ok())
      << rep.error().toString();  // the batch is answered; each query has its status
  ASSERT_EQ(rep->estimates().size(), q.size());
  const auto& e = rep->estimates();
  EXPECT_EQ(e[0].code(), msg::STATUS_OK) << e[0].message();
  EXPECT_GT(e[0].mean_s(), 0.0);
  const std::vector<std::string> fields{"",
                                        "queries[1].path.values",
                                        "queries[2].kind",
                                        "queries[3].object_mass",
                                        "queries[4].path",
                                        "queries[5].approach_m",
                                        "queries[6].path"};
  for (size_t i = 1; i < q.size(); ++i) {
    EXPECT_EQ(e[i].code(), msg::STATUS_INVALID_ARGUMENT) << i;
    // The shared validator names "EffortRequest.queries[i].<field>", the node's conversion
    // "field 'queries[i].<field>'": either names the field.
    EXPECT_THAT(e[i].message(), HasSubstr(fields[i])) << i << ": " << e[i].message();
    EXPECT_EQ(e[i].mean_s(), 0.0) << i;
  }
  // The node is still serving.
  msg::EffortRequest good;
  good.queries({toMsg(base)});
  auto again = client_->call(good, dds::CallOptions{30.0, {}});
  ASSERT_TRUE(again.ok()) << again.error().toString();
  EXPECT_DOUBLE_EQ(again->estimates()[0].mean_s(), e[0].mean_s());
}

TEST_F(EffortNodeTest, PublishesTheStartupSnapshot) {
  SnapshotLog log(peer_);
  auto s = log.waitForVersion(0);
  ASSERT_TRUE(s.has_value()) << "no start-up snapshot; matched writers " << log.matchedWriters();
  EXPECT_EQ(s->model_id(), args_.name);
  EXPECT_EQ(s->version(), 0u);
  ASSERT_EQ(s->models().size(), kAllActionKinds.size());
  for (const auto& m : s->models()) {
    EXPECT_EQ(m.version(), 0u);
    const size_t n = m.parameter_names().size();
    EXPECT_EQ(m.values().size(), n);
    EXPECT_EQ(m.log_covariance().size(), n * n);
    EXPECT_EQ(m.values(), modelSpec(dds::fromMsg(m.kind())).defaults());
  }
}

TEST_F(EffortNodeTest, RecordsOnTheTopicLeadToARefitAndANewSnapshot) {
  SnapshotLog log(peer_);
  ASSERT_TRUE(log.waitForVersion(0).has_value()) << "matched writers " << log.matchedWriters();
  std::mt19937_64 rng(5);
  const ActionDescription probe = synthetic::randomAction(ActionKind::kMoveBase, rng);
  msg::EffortRequest req;
  req.queries({toMsg(probe)});
  auto before = client_->call(req, dds::CallOptions{30.0, {}});
  ASSERT_TRUE(before.ok()) << before.error().toString();

  // A bad record first: rejected with its reason, counted, and not fitted.
  ExecutionRecord bad = moveBaseRecords(1, 99)[0];
  bad.duration_s = std::numeric_limits<double>::quiet_NaN();
  publish({bad});
  publish(moveBaseRecords(5, 1));  // refit_batch_size records of one kind

  auto s = log.waitForVersion(1);
  ASSERT_TRUE(s.has_value()) << "no snapshot after the refit";
  EXPECT_EQ(s->version(), 1u);
  const auto& mb = kindModel(*s, msg::ACTION_MOVE_BASE);
  EXPECT_EQ(mb.version(), 1u);
  EXPECT_EQ(mb.record_count(), 5u);
  EXPECT_NE(mb.values(), modelSpec(ActionKind::kMoveBase).defaults());
  EXPECT_EQ(kindModel(*s, msg::ACTION_PICK).version(), 0u);
  EXPECT_TRUE(eventually([&] { return node_->recordsRejected() == 1; }));
  EXPECT_EQ(node_->estimator().counters().records_accepted, 5u);

  // Estimates now come from the refitted model, as the library computes them.
  auto after = client_->call(req, dds::CallOptions{30.0, {}});
  ASSERT_TRUE(after.ok()) << after.error().toString();
  EXPECT_EQ(after->model_version(), 1u);
  auto want = node_->estimator().estimate(probe);
  ASSERT_TRUE(want.ok());
  EXPECT_DOUBLE_EQ(after->estimates()[0].mean_s(), want->mean_s);
  EXPECT_NE(after->estimates()[0].mean_s(), before->estimates()[0].mean_s());
  // A re-delivered record (same id) is not counted again.
  publish(moveBaseRecords(5, 1));
  publish(moveBaseRecords(1, 2));
  EXPECT_TRUE(eventually([&] { return node_->estimator().counters().records_accepted == 6; }));
  EXPECT_EQ(node_->estimator().counters().records_duplicate, 5u);
}

TEST_F(EffortNodeTest, LateJoiningReaderReceivesTheCurrentSnapshot) {
  publish(moveBaseRecords(5, 7));
  ASSERT_TRUE(node_->estimator().waitForVersion(ActionKind::kMoveBase, 1, Deadline::in(30.0)));
  EXPECT_EQ(node_->publishedVersion(), 1u);
  // A process that starts now (own participant) gets the current model, not the start-up one.
  auto p = dds::Participant::create(
      dds::ParticipantOptions{args_.domain_id, dds::kProfileDefault, "late", {}});
  ASSERT_TRUE(p.ok()) << p.error().toString();
  SnapshotLog late(*p);
  auto s = late.waitForVersion(1);
  ASSERT_TRUE(s.has_value()) << "late joiner got no snapshot";
  EXPECT_EQ(kindModel(*s, msg::ACTION_MOVE_BASE).record_count(), 5u);
  // KEEP_LAST 1 per instance: the start-up snapshot is not replayed.
  std::this_thread::sleep_for(std::chrono::milliseconds(200));
  for (const auto& got : late.all()) EXPECT_EQ(got.version(), 1u);
}

TEST(EffortNodeRecords, BadRecordsAreRejectedNamingTheIdlField) {
  dds::ServiceArgs args;
  args.name = "effort_estimator_records";
  args.domain_id = testDomain();
  EstimatorParams params;
  params.store_directory = "";
  EffortEstimatorNode node(args, params);
  std::mt19937_64 rng(8);
  const msg::ExecutionRecord good = toMsg(synthetic::records(ActionKind::kPick, 1, rng)[0]);
  EXPECT_TRUE(node.handleRecord(good).ok());

  auto expectField = [&](msg::ExecutionRecord r, const std::string& field) {
    Status s = node.handleRecord(r);
    ASSERT_FALSE(s.ok()) << field;
    EXPECT_EQ(s.error().code, ErrorCode::kInvalidArgument);
    // "record.<field>" from the node's conversion, "ExecutionRecord.<field>" from the shared
    // validator that runs first: the same field either way.
    const std::string tail = field.substr(field.find('.'));
    const std::string& got = s.error().where.field;
    EXPECT_EQ(got.substr(got.find('.')).rfind(tail, 0), 0u) << s.error().toString();
  };
  msg::ExecutionRecord r = good;
  r.duration_s(-2.0);
  expectField(r, "record.duration_s");
  r = good;
  r.stamp_ns(-5);
  expectField(r, "record.stamp_ns");
  r = good;
  r.object_mass(std::numeric_limits<double>::infinity());
  expectField(r, "record.object_mass");
  r = good;
  r.kind(static_cast<msg::ActionKind>(9));
  expectField(r, "record.kind");
  r = good;
  r.success(false);
  expectField(r, "record.success");
  r = good;
  r.kind(msg::ACTION_MOVE_ARM);  // a motion without its path
  r.approach_m(0.0);
  r.retreat_m(0.0);
  expectField(r, "record.path");
  EXPECT_EQ(node.recordsRejected(), 6u);
  EXPECT_EQ(node.estimator().counters().records_accepted, 1u);
}

TEST(EffortNodeStore, ModelsFromTheStoreDirectorySurviveARestart) {
  testing_support::TempDir dir;
  dds::ServiceArgs args;
  args.name = "effort_estimator_store";
  args.domain_id = testDomain();
  EstimatorParams params;
  params.store_directory = dir.path().string();
  params.refit_batch_size = 5;
  params.refit_period_s = 600.0;
  std::mt19937_64 rng(21);
  const auto recs = synthetic::records(ActionKind::kMoveArm, 5, rng);
  std::uint64_t fitted_version = 0;
  {
    EffortEstimatorNode node(args, params);
    EXPECT_TRUE(node.estimator().persistent());
    for (const auto& r : recs) ASSERT_TRUE(node.handleRecord(toMsg(r)).ok());
    ASSERT_TRUE(node.estimator().waitForVersion(ActionKind::kMoveArm, 1, Deadline::in(30.0)));
    fitted_version = node.estimator().snapshot().version;
  }
  EffortEstimatorNode restarted(args, params);
  EXPECT_EQ(restarted.estimator().snapshot().version, fitted_version);
  EXPECT_EQ(restarted.publishedVersion(), fitted_version);
  EXPECT_EQ(restarted.estimator().recordCount(ActionKind::kMoveArm), 5u);
}

TEST(EffortNodeConfig, CreateReadsTheServiceYaml) {
  testing_support::TempDir dir;
  ::setenv("TAMP_DATA_DIR", dir.path().c_str(), 1);  // the YAML's relative store_directory
  dds::ServiceArgs args;
  args.name = "effort_estimator_config";
  args.domain_id = testDomain();
  args.config_file = std::string(TAMP_SOURCE_DIR) + "/config/services/effort_estimator.yaml";
  auto node = EffortEstimatorNode::create(args);
  ASSERT_TRUE(node.ok()) << node.error().toString();
  auto* effort = dynamic_cast<EffortEstimatorNode*>(node->get());
  ASSERT_NE(effort, nullptr);
  EXPECT_EQ(effort->estimator().params().refit_batch_size, 10);
  EXPECT_TRUE(effort->estimator().persistent());
  EXPECT_TRUE(std::filesystem::exists(dir.path() / "effort_estimator"));
  node->reset();

  const auto bad = dir.path() / "bad.yaml";
  std::ofstream(bad) << "refit_batch_size: 0\nstore_directory: \"\"\n";
  args.config_file = bad.string();
  auto refused = EffortEstimatorNode::create(args);
  ASSERT_FALSE(refused.ok());
  EXPECT_THAT(refused.error().toString(), HasSubstr("refit_batch_size"));
  ::unsetenv("TAMP_DATA_DIR");
}

TEST(EffortNodeConvert, IdlFieldNames) {
  EXPECT_EQ(idlField("action.object_mass_kg", "record"), "record.object_mass");
  EXPECT_EQ(idlField("timestamp_s", "record"), "record.stamp_ns");
  EXPECT_EQ(idlField("path.waypoints[3]", "queries[2]"), "queries[2].path.waypoints[3]");
  EXPECT_EQ(idlField("", "queries[0]"), "queries[0]");
  EXPECT_EQ(idlField("queries[1].path.values", "queries[1]"), "queries[1].path.values");
}

}  // namespace
}  // namespace tamp::effort_estimator
