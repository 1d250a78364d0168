#include "sim_node.h"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>

#include <nlohmann/json.hpp>
#include <filesystem>

#include "tamp/core/log.h"
#include "tamp/core/paths.h"
#include "tamp/dds/convert.h"
#include "tamp/dds/world_sync.h"
#include "checkpoint.h"

namespace tamp::sim {
namespace {

Error bad(const std::string& field, const std::string& message) {
  return Error(ErrorCode::kInvalidArgument, field + ": " + message, SourceLocation{"", 0, 0, field});
}

const std::shared_ptr<spdlog::logger>& logger() {
  static const auto l = tamp::log::get("sim");
  return l;
}

}  // namespace

Result<ActionCommand> fromMsg(const msg::TrajectoryCommand& m) {
  ActionCommand c;
  c.command_id = m.command_id();
  const int kind = static_cast<int>(m.kind());
  if (kind < 0 || kind > static_cast<int>(msg::ActionKind::ACTION_PLACE)) {
    return bad("kind", "unknown action kind " + std::to_string(kind));
  }
  c.kind = dds::fromMsg(m.kind());
  auto t = dds::fromMsg(m.trajectory(), "trajectory");
  if (!t) return t.error();
  c.trajectory = std::move(t).value();
  c.object_id = m.object_id();
  // object_target is meaningful for pick (where the object is believed to be) and place.
  if (c.kind == ActionKind::kPick || c.kind == ActionKind::kPlace) {
    const auto& q = m.object_target().orientation();
    const bool unset = q.x() == 0 && q.y() == 0 && q.z() == 0 && q.w() == 0;
    if (!(unset && c.kind == ActionKind::kPick)) {
      auto pose = dds::fromMsg(m.object_target(), "object_target");
      if (!pose) return pose.error();
      c.object_pose = *pose;
    }
  }
  return c;
}

msg::ActionResult toMsg(const ActionResult& r) {
  msg::ActionResult m;
  m.command_id(r.command_id);
  switch (r.outcome) {
    case Outcome::kSucceeded: m.outcome(msg::ActionOutcome::OUTCOME_SUCCEEDED); break;
    case Outcome::kBlocked: m.outcome(msg::ActionOutcome::OUTCOME_BLOCKED); break;
    case Outcome::kFailed: m.outcome(msg::ActionOutcome::OUTCOME_FAILED); break;
    case Outcome::kCancelled: m.outcome(msg::ActionOutcome::OUTCOME_CANCELLED); break;
  }
  m.duration_s(r.duration_s);
  m.progress(r.progress);
  m.blocking_object_id(r.blocking_object_id);
  m.reason(r.reason);
  return m;
}

msg::ExecutionRecord toMsg(const effort_model::ExecutionRecord& r) {
  msg::ExecutionRecord m;
  m.record_id(r.record_id);
  m.kind(dds::toMsg(r.action.kind));
  m.path(dds::toMsg(r.action.path));
  m.object_mass(r.action.object_mass_kg);
  m.duration_s(r.duration_s);
  m.success(r.success);
  m.stamp_ns(static_cast<std::int64_t>(r.timestamp_s * 1e9));
  m.source(r.source);
  m.approach_m(r.action.approach_m);
  m.retreat_m(r.action.retreat_m);
  return m;
}

Result<Fault> fromMsg(const msg::FaultInjection& m) {
  Fault f;
  f.id = m.fault_id().empty() ? "injected" : m.fault_id();
  f.reason = m.reason();
  switch (m.type()) {
    case msg::FaultType::FAULT_DROP_HELD_OBJECT: f.type = FaultType::kDropHeldObject; break;
    case msg::FaultType::FAULT_FAIL_NEXT_ACTION: f.type = FaultType::kFailAction; break;
    case msg::FaultType::FAULT_REMOVE_OBJECT:
      f.type = FaultType::kRemoveObject;
      f.object_id = m.object_id();
      break;
    case msg::FaultType::FAULT_SPAWN_OBJECT: {
      f.type = FaultType::kSpawnObject;
      auto shape = dds::fromMsg(m.shape(), "shape");
      if (!shape) return shape.error();
      auto pose = dds::fromMsg(m.pose(), "pose");
      if (!pose) return pose.error();
      f.object.id = m.object_id();
      f.object.label = m.reason().empty() ? "spawned" : m.reason();
      f.object.kind = world::ObjectKind::kStatic;
      f.object.shape = *shape;
      f.object.pose = *pose;
      break;
    }
    default:
      return bad("type", "unknown fault type " + std::to_string(static_cast<int>(m.type())));
  }
  if (Status s = f.validate(false); !s) return s.error();
  return f;
}

msg::RobotState toMsg(const RobotStateSample& s, const std::vector<std::string>& joint_names,
                      const std::string& robot_id, std::int64_t stamp_ns, std::uint64_t seq) {
  msg::RobotState m;
  m.header().stamp_ns(stamp_ns);
  m.header().frame_id("world");
  m.header().seq(seq);
  m.robot_id(robot_id);
  m.base(dds::toMsg(s.state.base));
  m.joint_names(joint_names);
  std::vector<double> q{s.state.base.x, s.state.base.y, s.state.base.theta};
  q.insert(q.end(), s.state.arm.begin(), s.state.arm.end());
  if (q.size() < joint_names.size()) q.push_back(s.state.gripper);
  m.joint_positions(q);
  m.joint_velocities(s.joint_velocities);
  m.held_object_id(s.held_object_id);
  m.moving(s.moving);
  return m;
}

namespace {
/// `tamp run --realtime-factor F` reaches the simulator as $TAMP_SIM_REALTIME_FACTOR: it overrides
/// the parameter file's realtime_factor for this run (0 = as fast as possible).
Status applyRealtimeFactorFromEnv(SimParams& params) {
  const char* v = std::getenv("TAMP_SIM_REALTIME_FACTOR");
  if (v == nullptr || *v == '\0') return Status::Ok();
  char* end = nullptr;
  const double f = std::strtod(v, &end);
  if (end == v || *end != '\0' || !std::isfinite(f) || f < 0) {
    return Error(ErrorCode::kInvalidArgument,
                 std::string("TAMP_SIM_REALTIME_FACTOR: expected a number >= 0 (0 = as fast as possible), got '") + v + "'");
  }
  params.realtime_factor = f;
  return Status::Ok();
}
}  // namespace

Result<std::unique_ptr<dds::ServiceNode>> SimNode::create(const dds::ServiceArgs& args) {
  std::filesystem::path file = args.config_file;
  if (file.empty() && std::filesystem::exists(configDir() / "services" / "sim.yaml")) {
    file = configDir() / "services" / "sim.yaml";
  }
  auto params = file.empty() ? Result<SimParams>(SimParams{}) : loadSimParams(file);
  if (!params) return params.error();
  if (!args.scenario_file.empty()) params->scenario = std::filesystem::absolute(args.scenario_file).string();
  if (Status s = applyRealtimeFactorFromEnv(*params); !s) return s.error();
  if (params->realtime_factor > 0) logger()->info("simulated time runs at {}x real time", params->realtime_factor);
  else logger()->info("simulated time runs as fast as the simulator can");
  auto setup = loadSetup(*params);
  if (!setup) return setup.error();
  // A restart within the run: the physical world stood where the checkpoint has it.
  std::filesystem::path checkpoint_file;
  std::optional<SimSnapshot> resume_from;
  if (const char* run_dir = std::getenv("TAMP_RUN_DIR"); run_dir != nullptr && *run_dir != '\0') {
    checkpoint_file = std::filesystem::path(run_dir) / kCheckpointFileName;
    std::error_code ec;
    if (std::filesystem::exists(checkpoint_file, ec)) {
      auto snapshot = readCheckpoint(checkpoint_file);
      if (!snapshot) return snapshot.error();
      resume_from = std::move(snapshot).value();
    }
  }
  try {
    return std::unique_ptr<dds::ServiceNode>(std::make_unique<SimNode>(
        args, std::move(setup).value(), std::move(params).value(), std::move(checkpoint_file), std::move(resume_from)));
  } catch (const std::invalid_argument& e) {
    return Error(ErrorCode::kInvalidArgument, e.what());
  }
}

SimNode::SimNode(const dds::ServiceArgs& args, SimSetup setup, SimParams params,
                 std::filesystem::path checkpoint_file, std::optional<SimSnapshot> resume_from)
    : ServiceNode(args), checkpoint_file_(std::move(checkpoint_file)), checkpoint_period_s_(params.checkpoint_period_s),
      checkpoint_idle_period_s_(params.checkpoint_idle_period_s) {
  robot_id_ = setup.robot.name();
  joint_names_ = setup.robot.fullJointNames();
  scripted_ = setup.faults;
  sim_ = std::make_unique<Simulator>(std::move(setup.world), std::move(setup.robot), setup.initial,
                                     std::move(params), std::move(setup.faults));
  if (resume_from) {
    if (Status s = sim_->resume(*resume_from); !s) {
      throw std::invalid_argument("checkpoint " + checkpoint_file_.string() + " does not fit the scenario: " +
                                  s.error().toString());
    }
    const RobotStateSample st = sim_->robotState();
    logger()->warn("resumed from checkpoint {}: simulated time {:.2f} s, robot at ({:.3f}, {:.3f}, {:.3f}){}, "
                   "{} command(s) in the action log",
                   checkpoint_file_.string(), sim_->time(), st.state.base.x, st.state.base.y, st.state.base.theta,
                   st.held_object_id.empty() ? std::string() : ", holding '" + st.held_object_id + "'",
                   sim_->actionLog().size());
  }
  const auto& p = participant();
  state_writer_ = std::make_unique<dds::Writer<msg::RobotState>>(p, dds::topics::kRobotState);
  cloud_writer_ = std::make_unique<dds::Writer<msg::PointCloudFrame>>(p, dds::topics::kPointCloud);
  result_writer_ = std::make_unique<dds::Writer<msg::ActionResult>>(p, dds::topics::kActionResult);
  // Raw measurements: the execution monitor adds the prediction and forwards them.
  record_writer_ = std::make_unique<dds::Writer<msg::ExecutionRecord>>(p, dds::topics::kRobotRecords);
  LoopCallbacks cb;
  cb.on_state = [this](const RobotStateSample& s, std::int64_t stamp) {
    if (Status st = state_writer_->write(toMsg(s, joint_names_, robot_id_, stamp, ++state_seq_)); !st) {
      logger()->warn("robot state not published: {}", st.error().toString());
    }
    checkpointPeriodically(s);
  };
  cb.on_cloud = [this](const PointCloudFrame& f) {
    if (Status st = cloud_writer_->write(dds::toMsg(f, ++cloud_seq_)); !st) {
      logger()->warn("point cloud not published: {}", st.error().toString());
    }
  };
  cb.on_result = [this](const ActionResult& r) {
    // On disk before it goes out: a restart after the result was seen finds the action ended.
    checkpoint("action end");
    if (Status st = result_writer_->write(toMsg(r)); !st) {
      logger()->error("result of '{}' not published: {}", r.command_id, st.error().toString());
    }
  };
  cb.on_record = [this](const effort_model::ExecutionRecord& r) {
    if (Status st = record_writer_->write(toMsg(r)); !st) {
      logger()->warn("execution record of '{}' not published: {}", r.record_id, st.error().toString());
    }
  };
  cb.on_fault = [this](const FaultEvent& e) {
    logger()->info("fault '{}' ({}): {}", e.fault_id, toString(e.type), e.description);
    checkpoint("fault");
  };
  loop_ = std::make_unique<SimulationLoop>(*sim_, std::move(cb));
  command_reader_ = std::make_unique<dds::Reader<msg::TrajectoryCommand>>(
      p, dds::topics::kTrajectoryCommand,
      [this](const msg::TrajectoryCommand& m, const dds::SampleMeta&) { onCommand(m); });
  fault_reader_ = std::make_unique<dds::Reader<msg::FaultInjection>>(
      p, dds::topics::kFaultInjection,
      [this](const msg::FaultInjection& m, const dds::SampleMeta&) { onFault(m); });
  if (oracleEnabled()) {
    logger()->warn("oracle enabled ($TAMP_ORACLE): serving the truth on {} (evaluation only)",
                   dds::services::kOracle.name);
    oracle_ = std::make_unique<dds::RpcServer<msg::OracleRequest, msg::OracleReply>>(
        p, dds::services::kOracle,
        [this](const msg::OracleRequest& req, const dds::RequestContext&) { return onOracle(req); });
  }
  checkpoint("start");
  loop_->start();
}

void SimNode::checkpoint(const char* why) {
  if (checkpoint_file_.empty() || !loop_) return;
  std::lock_guard lock(checkpoint_mutex_);
  const auto t0 = std::chrono::steady_clock::now();
  SimSnapshot snapshot;
  loop_->withSimulator([&](Simulator& sim) { snapshot = sim.snapshot(); });
  const std::string text = formatCheckpoint(snapshot);
  const Status s = writeFileAtomically(checkpoint_file_, text, "the simulator's checkpoint");
  const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  if (!s) {
    if (!checkpoint_failed_) logger()->error("{} ({}): a restart would not find this state", s.error().toString(), why);
    checkpoint_failed_ = true;
    return;
  }
  checkpoint_failed_ = false;
  last_checkpoint_s_ = snapshot.time_s;
  ++checkpoint_writes_;
  checkpoint_total_ms_ += ms;
  checkpoint_max_ms_ = std::max(checkpoint_max_ms_, ms);
  checkpoint_bytes_ = text.size();
  if (checkpoint_writes_ % 200 == 0) {
    logger()->info("checkpoint: {} writes, mean {:.2f} ms, max {:.2f} ms, {} bytes", checkpoint_writes_,
                   checkpoint_total_ms_ / static_cast<double>(checkpoint_writes_), checkpoint_max_ms_, checkpoint_bytes_);
  }
}

void SimNode::checkpointPeriodically(const RobotStateSample& s) {
  if (checkpoint_file_.empty()) return;
  // An action also runs while the robot stands still in it (the gripper closing, a settle pause).
  const bool busy = s.moving || loop_->busy();
  {
    std::lock_guard lock(checkpoint_mutex_);
    if (s.time_s - last_checkpoint_s_ < (busy ? checkpoint_period_s_ : checkpoint_idle_period_s_)) return;
  }
  checkpoint(busy ? "action" : "idle");
}

namespace {
/// The ground truth at the end, for tests and reports that judge a mission by the world it left
/// ($TAMP_SIM_FINAL_WORLD names the file; unset: nothing is written).
void writeFinalWorld(Simulator& sim) {
  const char* file = std::getenv("TAMP_SIM_FINAL_WORLD");
  if (!file || !*file) return;
  nlohmann::json j;
  const auto st = sim.robotState();
  j["robot"] = {{"x", st.state.base.x}, {"y", st.state.base.y}, {"theta", st.state.base.theta},
                {"held", st.held_object_id}};
  j["time_s"] = sim.time();
  j["actions"] = sim.actionCount();
  // The action log (what physically happened, one entry per accepted command id), so that a run
  // can be checked for an action executed twice.
  nlohmann::json log = nlohmann::json::array();
  for (const auto& e : sim.actionLog()) {
    log.push_back({{"command_id", e.command_id},
                   {"kind", std::string(toString(e.kind))},
                   {"outcome", e.result ? std::string(toString(e.result->outcome)) : std::string("running")}});
  }
  j["action_log"] = log;
  nlohmann::json objects = nlohmann::json::object();
  for (const auto& o : sim.world().objects()) {
    const Eigen::Vector3d t = o.pose.translation();
    objects[o.id] = {{"x", t.x()}, {"y", t.y()}, {"z", t.z()}, {"movable", o.kind == world::ObjectKind::kMovable},
                     {"hidden", o.hidden}};
  }
  j["objects"] = objects;
  const std::string tmp = std::string(file) + ".tmp";
  std::ofstream(tmp) << j.dump(2) << "\n";
  std::rename(tmp.c_str(), file);
}
}  // namespace

SimNode::~SimNode() {
  // Stop input first, then the loop (its callbacks use the writers).
  oracle_.reset();
  command_reader_.reset();
  fault_reader_.reset();
  if (loop_) loop_->stop();
  if (sim_ && loop_) {
    checkpoint("stop");
    std::lock_guard lock(checkpoint_mutex_);
    if (checkpoint_writes_ > 0) {
      logger()->info("checkpoint: {} writes, mean {:.2f} ms, max {:.2f} ms, {} bytes", checkpoint_writes_,
                     checkpoint_total_ms_ / static_cast<double>(checkpoint_writes_), checkpoint_max_ms_,
                     checkpoint_bytes_);
    }
  }
  if (sim_) {
    try {
      writeFinalWorld(*sim_);
    } catch (const std::exception& e) {
      logger()->warn("final world: {}", e.what());
    }
  }
}

void SimNode::onCommand(const msg::TrajectoryCommand& m) {
  try {
    ++commands_;
    if (Status bad = msgv::screen(m, dds::topics::kTrajectoryCommand.name, rejects_); !bad.ok()) {
      ++rejected_;
      // With a usable id the executor hears why (a FAILED result naming the field).
      if (!m.command_id().empty() && m.command_id().size() <= msgv::Limits{}.max_id_length) {
        ActionResult r;
        r.command_id = m.command_id();
        r.outcome = Outcome::kFailed;
        r.reason = "rejected: " + bad.error().message;
        (void)result_writer_->write(toMsg(r));
      }
      return;
    }
    if (m.cancel()) {
      if (Status s = loop_->cancel(m.command_id()); !s) {
        logger()->warn("cancel '{}': {}", m.command_id(), s.error().message);
      }
      return;
    }
    auto cmd = fromMsg(m);
    if (!cmd) {
      ++rejected_;
      ActionResult r;
      r.command_id = m.command_id();
      r.outcome = Outcome::kFailed;
      r.reason = "rejected: " + cmd.error().toString();  // names the field (convert.h errors)
      logger()->warn("command '{}' rejected: {}", m.command_id(), r.reason);
      (void)result_writer_->write(toMsg(r));
      return;
    }
    if (Status s = loop_->submit(*cmd); !s) {  // the loop reports the rejection as a result
      ++rejected_;
      logger()->warn("command '{}' rejected: {}", m.command_id(), s.error().message);
      return;
    }
    checkpoint("action start");  // the id is on disk as started: a restart never executes it again
  } catch (const std::exception& e) {
    logger()->error("command '{}': {}", m.command_id(), e.what());
  }
}

bool oracleEnabled() {
  const char* v = std::getenv("TAMP_ORACLE");
  return v != nullptr && (std::string(v) == "1" || std::string(v) == "true");
}

std::vector<msg::EffortEstimate> oracleDurations(const SimParams& params, const robot::RobotModel& robot,
                                                 const std::vector<msg::EffortQuery>& queries) {
  const auto speeds = armSpeedLimits(robot);
  std::vector<msg::EffortEstimate> out(queries.size());
  for (std::size_t i = 0; i < queries.size(); ++i) {
    const std::string field = "queries[" + std::to_string(i) + "]";
    if (Status bad = msgv::validateQuery(queries[i], i); !bad.ok()) {
      out[i].code(msg::STATUS_INVALID_ARGUMENT);
      out[i].message(bad.error().message);
      continue;
    }
    NominalQuery q;
    q.kind = dds::fromMsg(queries[i].kind());
    q.object_mass_kg = queries[i].object_mass();
    q.approach_m = queries[i].approach_m();
    q.retreat_m = queries[i].retreat_m();
    if (q.kind == ActionKind::kMoveBase || q.kind == ActionKind::kMoveArm) {
      auto path = dds::fromMsg(queries[i].path(), field + ".path");
      if (!path) {
        out[i].code(msg::STATUS_INVALID_ARGUMENT);
        out[i].message(path.error().toString());
        continue;
      }
      q.path = std::move(path).value();
    }
    auto t = nominalDuration(params.dynamics, speeds, q);
    if (!t) {
      out[i].code(dds::toMsg(t.error().code));
      out[i].message(field + ": " + t.error().message);
      continue;
    }
    out[i].mean_s(*t);
    out[i].stddev_s(params.duration_noise * *t);
    out[i].code(msg::STATUS_OK);
  }
  return out;
}

msg::OracleReply SimNode::onOracle(const msg::OracleRequest& req) {
  msg::OracleReply rep;
  try {
    if (Status bad = msgv::validateEnvelope(req); !bad.ok()) {
      rejects_.reject(dds::services::kOracle.name, bad.error());
      rep.header().code(msg::STATUS_INVALID_ARGUMENT);
      rep.header().message(bad.error().message);
      return rep;
    }
    // The dynamics and the robot never change after construction: no lock needed for them.
    rep.durations(oracleDurations(sim_->params(), sim_->robot(), req.queries()));
    loop_->withSimulator([&](Simulator& sim) {
      rep.action_count(sim.actionCount());
      rep.sim_time_s(sim.time());
      if (!req.want_truth()) return;
      for (const auto& o : sim.world().objects()) {
        if (!o.hidden) continue;
        world::Object told = o;  // its kind (movable or static) on the wire: the list says it is hidden
        told.hidden = false;
        rep.hidden_objects().push_back(dds::toMsg(told, 0));
      }
      // An object a scripted fault puts down is known where it will appear (or, once it has,
      // where it is): the planner's view learns of it only when perception sees it.
      for (const Fault& f : scripted_) {
        if (f.type != FaultType::kSpawnObject) continue;
        const world::Object* now = sim.world().findObject(f.object.id);
        if (now && now->hidden) continue;  // listed above
        world::Object told = now ? *now : f.object;
        told.hidden = false;
        rep.hidden_objects().push_back(dds::toMsg(told, 0));
      }
    });
    if (req.want_truth()) {
      for (const Fault& f : scripted_) {
        msg::OracleFault m;
        m.fault_id(f.id);
        switch (f.type) {
          case FaultType::kDropHeldObject: m.type(msg::FaultType::FAULT_DROP_HELD_OBJECT); break;
          case FaultType::kSpawnObject: m.type(msg::FaultType::FAULT_SPAWN_OBJECT); break;
          case FaultType::kFailAction: m.type(msg::FaultType::FAULT_FAIL_NEXT_ACTION); break;
          case FaultType::kRemoveObject: m.type(msg::FaultType::FAULT_REMOVE_OBJECT); break;
        }
        m.at_time(f.trigger.time_s.has_value());
        m.time_s(f.trigger.time_s.value_or(0.0));
        m.step(f.trigger.step.value_or(-1));
        m.fraction(f.trigger.fraction);
        m.any_action(!f.action.has_value());
        m.action(dds::toMsg(f.action.value_or(ActionKind::kMoveBase)));
        m.object_id(f.type == FaultType::kSpawnObject ? f.object.id : f.object_id);
        rep.faults().push_back(m);
      }
    }
    rep.header().code(msg::STATUS_OK);
  } catch (const std::exception& e) {
    rep = msg::OracleReply{};
    rep.header().code(msg::STATUS_INTERNAL);
    rep.header().message(std::string("oracle: ") + e.what());
  }
  return rep;
}

void SimNode::onFault(const msg::FaultInjection& m) {
  try {
    if (!msgv::accept(m, dds::topics::kFaultInjection.name, rejects_)) return;
    auto f = fromMsg(m);
    if (!f) {
      logger()->warn("fault '{}' rejected: {}", m.fault_id(), f.error().toString());
      return;
    }
    if (Status s = loop_->inject(std::move(f).value()); !s) {
      logger()->warn("fault '{}' rejected: {}", m.fault_id(), s.error().message);
    }
  } catch (const std::exception& e) {
    logger()->error("fault '{}': {}", m.fault_id(), e.what());
  }
}

}  // namespace tamp::sim
