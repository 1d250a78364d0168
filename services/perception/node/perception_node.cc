#include "perception_node.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>

#include "checkpoint.h"
#include "cloud_convert.h"
#include "tamp/config/yaml_reader.h"
#include "tamp/core/log.h"
#include "tamp/core/paths.h"
#include "tamp/dds/convert.h"
#include "tamp/world/scenario.h"

namespace tamp::perception {

Result<PerceptionNodeOptions> parseNodeOptions(const std::string& yaml_text, const std::string& name) {
  auto params = parsePerceptionParams(yaml_text, name);
  if (!params) return params.error();
  PerceptionNodeOptions o;
  o.params = std::move(*params);
  auto doc = config::parseYaml(yaml_text, name);
  if (!doc) return doc.error();
  if (doc->root.IsMap() && doc->root["node"]) {
    config::FieldReader r(*doc);
    config::FieldReader n = r.child("node");
    n.optional("world_id", o.world_id);
    n.optional("occupancy_period_s", o.occupancy_period_s);
    n.optional("frame_budget_s", o.frame_budget_s);
    n.optional("robot_state_max_age_s", o.robot_state_max_age_s);
    n.optional("robot_state_wait_s", o.robot_state_wait_s);
    n.check(!o.world_id.empty(), "world_id", "must not be empty");
    n.check(std::isfinite(o.occupancy_period_s) && o.occupancy_period_s >= 0, "occupancy_period_s",
            "must be >= 0, got " + std::to_string(o.occupancy_period_s));
    n.check(std::isfinite(o.frame_budget_s) && o.frame_budget_s > 0, "frame_budget_s",
            "must be positive, got " + std::to_string(o.frame_budget_s));
    n.check(std::isfinite(o.robot_state_max_age_s) && o.robot_state_max_age_s >= 0,
            "robot_state_max_age_s", "must be >= 0, got " + std::to_string(o.robot_state_max_age_s));
    n.check(std::isfinite(o.robot_state_wait_s) && o.robot_state_wait_s >= 0 && o.robot_state_wait_s <= 5.0,
            "robot_state_wait_s", "must be in [0, 5], got " + std::to_string(o.robot_state_wait_s));
    n.refuseUnknownKeys();
    if (!r.ok()) return r.status().error();
  }
  return o;
}

Result<PerceptionNodeOptions> loadNodeOptions(const std::filesystem::path& file) {
  auto text = readTextFile(file);
  if (!text) return text.error();
  return parseNodeOptions(*text, file.string());
}

PerceptionNode::PerceptionNode(const dds::ServiceArgs& args, PerceptionNodeOptions options)
    : ServiceNode(args),
      options_(std::move(options)),
      perception_(std::make_unique<Perception>(options_.prior.plannerView(), options_.params)),
      world_pub_(participant(), options_.world_id),
      events_(participant(), dds::topics::kWorldEvents),
      occupancy_(participant(), dds::topics::kOccupancy) {
  if (options_.resume_grasp) {
    if (Status s = perception_->resumeGrasp(*options_.resume_grasp); !s.ok())
      log::get(name())->warn("checkpoint: the grasp not taken up: {}", s.error().toString());
  }
  checkpointed_grasp_ = perception_->heldGrasp();
  world_pub_.continueAbove(options_.resume_world_version);
  snapshot_ = perception_->world();
  if (Status s = world_pub_.publish(snapshot_); !s.ok()) {
    throw std::runtime_error("publishing the prior world: " + s.error().toString());
  }
  frame_watch_ = heartbeat().watchWorker("frames");
  worker_ = std::jthread([this](std::stop_token st) { work(st); });
  if (options_.robot) {
    robot_states_ = std::make_unique<dds::Reader<msg::RobotState>>(
        participant(), dds::topics::kRobotState,
        [this](const msg::RobotState& m, const dds::SampleMeta& meta) {
          if (meta.alive) onState(m);
        });
  }
  clouds_ = std::make_unique<dds::Reader<msg::PointCloudFrame>>(
      participant(), dds::topics::kPointCloud,
      [this](const msg::PointCloudFrame& m, const dds::SampleMeta& meta) {
        if (meta.alive) onCloud(m);
      });
}

PerceptionNode::~PerceptionNode() {
  clouds_.reset();  // no more callbacks
  robot_states_.reset();
  worker_.request_stop();
  cv_.notify_all();
  if (worker_.joinable()) worker_.join();
}

namespace {

/// A restarted perception (the checkpoint exists): `options.prior` restored, the grasp to take
/// up. A checkpoint that cannot be read or applied is logged and the prior used: perception must
/// come up, and it corrects its world model from what it sees.
void resumeFromCheckpoint(PerceptionNodeOptions& options, const std::string& node_name) {
  std::error_code ec;
  if (!std::filesystem::exists(options.checkpoint_file, ec)) return;
  const auto log = log::get(node_name);
  auto text = readTextFile(options.checkpoint_file);
  auto parsed = text ? parseCheckpoint(*text, options.checkpoint_file.string()) : Result<PerceptionCheckpoint>(text.error());
  if (!parsed) {
    log->error("checkpoint not used, starting from the scenario's prior: {}", parsed.error().toString());
    return;
  }
  auto restored = restoredPrior(options.prior, *parsed);
  if (!restored) {
    log->error("checkpoint {} not used, starting from the scenario's prior: {}", options.checkpoint_file.string(),
               restored.error().toString());
    return;
  }
  options.prior = std::move(*restored);
  options.resume_grasp = parsed->held;
  options.resume_world_version = parsed->world_version;
  log->info("resumed from checkpoint {}: {} movable object(s){}", options.checkpoint_file.string(),
            parsed->movables.size(), parsed->held ? ", holding '" + parsed->held->object_id + "'" : std::string());
}

}  // namespace

Result<std::unique_ptr<dds::ServiceNode>> PerceptionNode::create(const dds::ServiceArgs& args) {
  PerceptionNodeOptions options;
  if (!args.config_file.empty()) {
    auto o = loadNodeOptions(args.config_file);
    if (!o) return o.error();
    options = std::move(*o);
  }
  std::filesystem::path description = configDir() / "robots" / "mobile_manipulator.yaml";
  if (!args.scenario_file.empty()) {
    // The prior: the scenario's static map and declared objects (its planner view, no hidden ones).
    auto scenario = world::loadScenario(args.scenario_file);
    if (!scenario) return scenario.error();
    options.prior = scenario->plannerWorld();
    description = scenario->robot.description;
  }
  if (const char* run_dir = std::getenv("TAMP_RUN_DIR"); run_dir != nullptr && *run_dir != '\0') {
    options.checkpoint_file = std::filesystem::path(run_dir) / "perception.checkpoint";
    resumeFromCheckpoint(options, args.name);
  }
  // The robot whose body and held object the self filter removes.
  if (options.params.self_filter.enabled) {
    auto robot = robot::RobotModel::loadDescription(description);
    if (!robot) return robot.error();
    options.robot = std::make_shared<const robot::RobotModel>(std::move(robot).value());
  }
  try {
    return std::unique_ptr<dds::ServiceNode>(std::make_unique<PerceptionNode>(args, std::move(options)));
  } catch (const std::invalid_argument& e) {
    return Error(ErrorCode::kInvalidArgument, e.what());
  }
}

world::World PerceptionNode::worldSnapshot() const {
  std::lock_guard lock(mutex_);
  return snapshot_;
}

std::pair<uint64_t, uint64_t> PerceptionNode::requestCounters() const {
  return {processed_.load(), rejected_.load()};
}

void PerceptionNode::onCloud(const msg::PointCloudFrame& m) {
  if (!msgv::accept(m, dds::topics::kPointCloud.name, rejects_)) {  // logged once per kind
    ++rejected_;
    return;
  }
  auto frame = fromMsg(m, options_.params.max_points);
  if (!frame) {
    ++rejected_;
    log::get(name())->warn("rejected a point cloud from '{}': {}", m.sensor_id(), frame.error().toString());
    return;
  }
  {
    std::lock_guard lock(mutex_);
    if (pending_) ++skipped_;  // the worker is behind: the newer frame replaces it
    pending_ = std::move(*frame);
  }
  cv_.notify_one();
}

void PerceptionNode::onState(const msg::RobotState& m) {
  // Checked here (a malformed state must not reach forward kinematics); bad ones are counted.
  auto fail = [&](const std::string& why) {
    ++bad_states_;
    log::get(name())->warn("rejected a robot state of '{}': {}", m.robot_id(), why);
  };
  if (!msgv::accept(m, dds::topics::kRobotState.name, rejects_)) {  // logged once per kind
    ++bad_states_;
    return;
  }
  if (m.joint_names().size() != m.joint_positions().size()) {
    return fail("joint_positions: " + std::to_string(m.joint_positions().size()) + " values for " +
                std::to_string(m.joint_names().size()) + " joints");
  }
  for (double v : m.joint_positions()) {
    if (!std::isfinite(v)) return fail("joint_positions: not finite");
  }
  auto base = dds::fromMsg(m.base(), "base");
  if (!base) return fail(base.error().toString());
  auto s = options_.robot->fromJointValues(m.joint_names(), m.joint_positions(),
                                           options_.robot->defaultState(*base));
  if (!s) return fail(s.error().toString());
  if (s->arm.size() != options_.robot->armDof()) return fail("arm: wrong number of joints");
  ++states_;
  {
    std::lock_guard lock(state_mutex_);
    // Kept in stamp order (one writer delivers in order; a restarted one may not).
    StampedRobotState sample{m.header().stamp_ns(), std::move(s).value(), m.held_object_id()};
    const auto at = std::upper_bound(states_seen_.begin(), states_seen_.end(), sample.stamp_ns,
                                     [](std::int64_t t, const StampedRobotState& x) { return t < x.stamp_ns; });
    states_seen_.insert(at, std::move(sample));
    while (states_seen_.size() > 64) states_seen_.pop_front();
  }
  state_cv_.notify_all();
}

std::string PerceptionNode::notReadyBecause() const {
  if (!options_.robot || states_.load() > 0) return {};
  return std::string("no robot state yet (") + dds::topics::kRobotState.name + ")";
}

namespace {

/// The latest change, at or before `stamp_ns`, from a state holding an object to one with the
/// gripper empty: that first empty state and the object let go; nullopt without one.
std::optional<std::pair<StampedRobotState, std::string>> lastRelease(const std::deque<StampedRobotState>& states,
                                                                     std::int64_t stamp_ns) {
  for (std::size_t i = states.size(); i-- > 1;) {
    const StampedRobotState& s = states[i];
    if (s.stamp_ns > stamp_ns) continue;
    if (s.held_object_id.empty() && !states[i - 1].held_object_id.empty()) return std::pair{s, states[i - 1].held_object_id};
  }
  return std::nullopt;
}

}  // namespace

std::optional<RobotBody> PerceptionNode::bodyAt(std::int64_t stamp_ns, std::stop_token stop) const {
  if (!options_.robot) return std::nullopt;
  std::optional<StampedRobotState> at;
  std::optional<std::pair<StampedRobotState, std::string>> release;  // first empty state, object let go
  {
    std::unique_lock lock(state_mutex_);
    // The state of the frame's instant may still be on its way (another topic, another thread):
    // wait for one at or after the stamp, so that the body is interpolated, not extrapolated.
    const auto wait = std::chrono::duration<double>(options_.robot_state_wait_s);
    state_cv_.wait_for(lock, stop, wait,
                       [&] { return !states_seen_.empty() && states_seen_.back().stamp_ns >= stamp_ns; });
    at = robotStateAt(states_seen_, stamp_ns, options_.robot_state_max_age_s);
    if (at) release = lastRelease(states_seen_, stamp_ns);
  }
  if (!at) return std::nullopt;
  RobotBody body = robotBodyAt(*options_.robot, at->state, at->held_object_id, at->stamp_ns);
  if (release && at->held_object_id.empty()) {
    body.released_object_id = release->second;
    body.world_T_tool_at_release = robotBodyAt(*options_.robot, release->first.state, {}, release->first.stamp_ns).world_T_tool;
  }
  return body;
}

void PerceptionNode::work(std::stop_token stop) {
  while (!stop.stop_requested()) {
    std::optional<PointCloudFrame> frame;
    {
      std::unique_lock lock(mutex_);
      cv_.wait(lock, stop, [this] { return pending_.has_value(); });
      if (stop.stop_requested()) return;
      frame = std::move(pending_);
      pending_.reset();
    }
    const dds::WorkWatch::Scope busy(frame_watch_.get());
    try {
      process(*frame, stop);
    } catch (const std::exception& e) {
      ++rejected_;
      log::get(name())->error("processing a frame failed: {}", e.what());
    }
  }
}

void PerceptionNode::process(const PointCloudFrame& frame, std::stop_token stop) {
  const std::optional<RobotBody> body = bodyAt(frame.stamp_ns, stop);
  if (options_.robot && !body) ++without_state_;
  auto r = perception_->processFrame(frame, Termination::after(options_.frame_budget_s),
                                     body ? &*body : nullptr);
  if (!r) {
    ++rejected_;
    log::get(name())->warn("frame from '{}' not processed: {}", frame.sensor_id, r.error().toString());
    return;
  }
  ++processed_;
  // The checkpoint first: it records the version about to be published, above which a restarted
  // node publishes.
  checkpoint(r->world_changed);
  if (r->world_changed) {
    {
      std::lock_guard lock(mutex_);
      snapshot_ = perception_->world();
    }
    if (Status s = world_pub_.publish(perception_->world()); !s.ok()) {
      log::get(name())->error("publishing the world model failed: {}", s.error().toString());
    }
  }
  for (const WorldEvent& e : r->events) {
    log::get(name())->info("world event: {} {} ({})", toString(e.type), e.object_id, e.description);
    if (Status s = events_.write(toMsg(e, ++event_seq_)); !s.ok()) {
      log::get(name())->error("publishing a world event failed: {}", s.error().toString());
    }
  }
  const auto now = Clock::now();
  const bool due = !last_map_ || std::chrono::duration<double>(now - *last_map_).count() >= options_.occupancy_period_s;
  if (perception_->occupancy() != nullptr && due) {
    last_map_ = now;
    const msg::OccupancyMap m =
        occupancyToMsg(perception_->occupancyBinary(), perception_->occupancy()->resolution(), frame.stamp_ns, ++map_seq_);
    if (Status s = occupancy_.write(m); !s.ok()) {
      log::get(name())->error("publishing the occupancy map failed: {}", s.error().toString());
    }
  }
}

void PerceptionNode::checkpoint(bool world_changed) {
  if (options_.checkpoint_file.empty()) return;
  const auto grasp = perception_->heldGrasp();
  const bool grasp_changed = grasp.has_value() != checkpointed_grasp_.has_value() ||
                             (grasp && (grasp->object_id != checkpointed_grasp_->object_id ||
                                        !grasp->tool_T_object.isApprox(checkpointed_grasp_->tool_T_object)));
  if (!world_changed && !grasp_changed) return;
  const Status s = writeFileAtomically(options_.checkpoint_file, formatCheckpoint(perception_->world(), grasp, world_pub_.versionOf(perception_->world())),
                                       "perception's checkpoint");
  if (!s.ok()) {
    if (!checkpoint_failed_) log::get(name())->error("{} (a restart would start from the prior)", s.error().toString());
    checkpoint_failed_ = true;
    return;
  }
  checkpoint_failed_ = false;
  checkpointed_grasp_ = grasp;
}

}  // namespace tamp::perception
