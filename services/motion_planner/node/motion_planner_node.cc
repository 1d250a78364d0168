#include "motion_planner_node.h"

#include <cmath>

#include "motion_convert.h"
#include "tamp/config/yaml_reader.h"
#include "tamp/core/log.h"
#include "tamp/core/paths.h"

namespace tamp::motion_planner {
namespace {

std::shared_ptr<spdlog::logger> nodeLog() { return log::get("motion_planner"); }

/// Sets the reply header's code and message from an error (the RPC server keeps them).
template <typename Rep>
Rep errorReply(const Error& e) {
  Rep rep;
  rep.header().code(dds::toMsg(e.code));
  // Names the field when the error knows it (the shared validator's messages start with it).
  const bool named = !e.where.field.empty() && e.message.rfind(e.where.field, 0) == 0;
  rep.header().message(named ? e.message : e.toString());
  return rep;
}

}  // namespace

Result<NodeConfig> parseNodeConfig(const std::string& yaml_text, const std::string& name) {
  NodeConfig c;
  auto params = parseMotionPlannerParams(yaml_text, name, {"node"});
  if (!params) return params.error();
  c.params = *params;
  auto doc = config::parseYaml(yaml_text, name);
  if (!doc) return doc.error();
  if (doc->root.IsNull()) return c;
  config::FieldReader root(*doc);
  config::FieldReader r = root.child("node", false);
  if (!r.node().IsDefined() || r.node().IsNull()) return c;
  if (!r.isMap()) {
    root.fail("node", "expected a mapping");
    return root.status().error();
  }
  std::string urdf;
  r.optional("robot", c.robot);
  r.optional("urdf", urdf);
  r.optional("disc_radius", c.disc_radius);
  r.optional("disc_height", c.disc_height);
  r.optional("world_id", c.world_id);
  r.optional("default_budget_s", c.default_budget_s);
  r.optional("world_wait_s", c.world_wait_s);
  r.optional("prepare", c.prepare);
  r.optional("prepare_budget_s", c.prepare_budget_s);
  r.optional("planners", c.planners);
  r.check(c.robot == "mobile_manipulator" || c.robot == "disc", "robot",
          "must be 'mobile_manipulator' or 'disc', got '" + c.robot + "'");
  r.check(std::isfinite(c.disc_radius) && c.disc_radius > 0, "disc_radius", "must be positive");
  r.check(std::isfinite(c.disc_height) && c.disc_height > 0, "disc_height", "must be positive");
  r.check(!c.world_id.empty(), "world_id", "must not be empty");
  r.check(std::isfinite(c.default_budget_s) && c.default_budget_s > 0, "default_budget_s", "must be positive");
  r.check(std::isfinite(c.world_wait_s) && c.world_wait_s >= 0, "world_wait_s", "must be >= 0");
  r.check(std::isfinite(c.prepare_budget_s) && c.prepare_budget_s > 0, "prepare_budget_s", "must be positive");
  r.check(c.planners >= 1 && c.planners <= 16, "planners", "must be in [1, 16]");
  r.refuseUnknownKeys();
  if (!r.ok()) return r.status().error();
  if (!urdf.empty()) {
    const std::filesystem::path p(urdf);
    c.urdf = p.is_absolute() ? p : configDir() / p;
  }
  return c;
}

Result<NodeConfig> loadNodeConfig(const std::filesystem::path& file) {
  auto text = readTextFile(file);
  if (!text) return text.error();
  return parseNodeConfig(*text, file.string());
}

Result<std::unique_ptr<dds::ServiceNode>> MotionPlannerNode::create(const dds::ServiceArgs& args) {
  const std::filesystem::path file =
      args.config_file.empty() ? configDir() / "services" / "motion_planner.yaml" : std::filesystem::path(args.config_file);
  auto cfg = loadNodeConfig(file);
  if (!cfg) return cfg.error();
  auto node = create(args, std::move(*cfg));
  if (!node) return node.error();
  return std::unique_ptr<dds::ServiceNode>(std::move(*node));
}

Result<std::unique_ptr<MotionPlannerNode>> MotionPlannerNode::create(const dds::ServiceArgs& args, NodeConfig config) {
  if (config.planners < 1 || config.planners > 16) {
    return Error(ErrorCode::kInvalidArgument, "node.planners: must be in [1, 16], got " + std::to_string(config.planners));
  }
  seedRandomness(config.params.seed);
  std::vector<MotionPlanner> planners;
  if (config.robot == "disc") {
    for (int i = 0; i < config.planners; ++i) {
      planners.emplace_back(collision::RobotGeometry::disc(config.disc_radius, config.disc_height), config.params);
    }
  } else {
    auto model = config.urdf.empty() ? robot::RobotModel::loadDefault() : robot::RobotModel::loadFile(config.urdf);
    if (!model) return model.error();
    for (int i = 0; i < config.planners; ++i) planners.emplace_back(*model, config.params);
  }
  return std::unique_ptr<MotionPlannerNode>(new MotionPlannerNode(args, std::move(config), std::move(planners)));
}

MotionPlannerNode::MotionPlannerNode(const dds::ServiceArgs& args, NodeConfig config, std::vector<MotionPlanner> planners)
    : ServiceNode(args), config_(std::move(config)) {
  for (auto& p : planners) slots_.push_back(std::make_unique<Slot>(std::move(p)));
  mirror_ = std::make_unique<dds::WorldMirror>(participant(), config_.world_id);
  mirror_->onChange([this] {
    std::lock_guard g(pool_mutex_);
    for (auto& sl : slots_) sl->dirty = true;
  });
  if (slots_.front()->planner.robotModel()) {
    // Only for the preparation: a node that may not read the robot's state (permissions that
    // predate it) prepares for the default state, as it did before, and serves all the same.
    try {
      robot_reader_ = std::make_unique<dds::Reader<msg::RobotState>>(
          participant(), dds::topics::kRobotState, [this](const msg::RobotState& m, const dds::SampleMeta& meta) {
            if (meta.alive && msgv::accept(m, dds::topics::kRobotState.name, rejects_)) onRobotState(m);
          });
    } catch (const std::exception& e) {
      nodeLog()->warn("no robot state ({}): roadmaps are prepared for the default state", e.what());
    }
  }
  effort_reader_ = std::make_unique<dds::Reader<msg::EffortModelSnapshot>>(
      participant(), dds::topics::kEffortModel, [this](const msg::EffortModelSnapshot& m, const dds::SampleMeta& meta) {
        if (!meta.alive || !msgv::accept(m, dds::topics::kEffortModel.name, rejects_)) return;
        if (Status st = applyEffortModel(m); !st) {
          nodeLog()->warn("effort model v{} ignored: {}", m.version(), st.error().toString());
        }
      });
  // As many workers per service as planners: concurrent requests of one service run at once.
  dds::RpcServerOptions server;
  server.threads = static_cast<int>(slots_.size());
  motion_ = std::make_unique<dds::RpcServer<msg::MotionRequest, msg::MotionReply>>(
      participant(), dds::services::kMotion,
      [this](const msg::MotionRequest& r, const dds::RequestContext& c) { return handleMotion(r, c); }, server);
  placement_ = std::make_unique<dds::RpcServer<msg::PlacementRequest, msg::PlacementReply>>(
      participant(), dds::services::kPlacement,
      [this](const msg::PlacementRequest& r, const dds::RequestContext& c) { return handlePlacement(r, c); }, server);
  grasp_ = std::make_unique<dds::RpcServer<msg::GraspRequest, msg::GraspReply>>(
      participant(), dds::services::kGrasp,
      [this](const msg::GraspRequest& r, const dds::RequestContext& c) { return handleGrasp(r, c); }, server);
}

MotionPlannerNode::~MotionPlannerNode() {
  grasp_.reset();  // servers first: their workers use the planners and the mirror
  placement_.reset();
  motion_.reset();
  effort_reader_.reset();
  mirror_.reset();
}

std::string MotionPlannerNode::notReadyBecause() const {
  if (mirror_ != nullptr && mirror_->publishedVersion() > 0) return {};
  return std::string("no world model yet (") + dds::topics::kWorldMeta.name + " and its objects)";
}

std::pair<uint64_t, uint64_t> MotionPlannerNode::requestCounters() const {
  auto [served, failed] = ServiceNode::requestCounters();
  if (motion_) {
    served += motion_->served();
    failed += motion_->failed() + motion_->rejected();
  }
  if (placement_) {
    served += placement_->served();
    failed += placement_->failed() + placement_->rejected();
  }
  if (grasp_) {
    served += grasp_->served();
    failed += grasp_->failed() + grasp_->rejected();
  }
  return {served, failed};
}

void MotionPlannerNode::spinOnce() { (void)prepareIfWorldChanged(); }

Status MotionPlannerNode::applyEffortModel(const msg::EffortModelSnapshot& snapshot) {
  auto models = fromMsg(snapshot);
  if (!models) return models.error();
  // Every planner has the same cost parameters.
  auto fn = fittedObjectEffort(slots_.front()->planner.params().cost, *models);
  if (!fn) return fn.error();
  std::lock_guard g(pool_mutex_);
  effort_ = std::make_shared<const ObjectEffortFn>(std::move(*fn));
  ++effort_version_;
  effort_model_version_ = snapshot.version();
  nodeLog()->debug("object efforts from effort model v{}", snapshot.version());
  return Status::Ok();
}

uint64_t MotionPlannerNode::effortModelVersion() const {
  std::lock_guard g(pool_mutex_);
  return effort_model_version_;
}

MotionPlannerNode::Lease::~Lease() {
  if (!node_) return;
  {
    std::lock_guard g(node_->pool_mutex_);
    Slot& s = *node_->slots_[index_];
    s.busy = false;
    s.preparing = false;
  }
  node_->pool_cv_.notify_all();
}

std::optional<MotionPlannerNode::Lease> MotionPlannerNode::acquire(const Termination& term) {
  std::unique_lock lock(pool_mutex_);
  ++waiting_;
  while (true) {
    std::optional<std::size_t> clean, idle;
    bool preparing = false;
    for (std::size_t i = 0; i < slots_.size(); ++i) {
      const Slot& s = *slots_[i];
      preparing |= s.preparing;
      if (s.busy) continue;
      if (!idle) idle = i;
      if (!clean && !s.dirty) clean = i;
    }
    // A prepared idle planner; else stop the preparation (kept, resumed later) rather than
    // take an unprepared one; else any idle planner.
    std::optional<std::size_t> pick = clean ? clean : preparing ? std::nullopt : idle;
    if (pick) {
      --waiting_;
      slots_[*pick]->busy = true;
      return Lease(this, *pick);
    }
    for (auto& s : slots_) {
      if (s->preparing) s->prepare_stop.request_stop();
    }
    if (term()) {
      --waiting_;
      return std::nullopt;
    }
    pool_cv_.wait_for(lock, std::chrono::milliseconds(20));
  }
}

uint64_t MotionPlannerNode::syncPlanner(Slot& slot) {
  const uint64_t version = mirror_->publishedVersion();  // the snapshot holds at least this
  slot.planner.setWorld(mirror_->snapshot());
  std::shared_ptr<const ObjectEffortFn> effort;
  std::uint64_t effort_version = 0;
  {
    std::lock_guard g(pool_mutex_);
    effort = effort_;
    effort_version = effort_version_;
  }
  if (effort && slot.effort_version != effort_version) {
    slot.planner.setObjectEffort(*effort);
    slot.effort_version = effort_version;
  }
  return version;
}

void MotionPlannerNode::onRobotState(const msg::RobotState& m) {
  const robot::RobotModel* model = slots_.front()->planner.robotModel();
  auto base = dds::fromMsg(m.base(), "base");
  if (!model || !base) return;
  auto st = model->fromJointValues(std::vector<std::string>(m.joint_names().begin(), m.joint_names().end()),
                                   std::vector<double>(m.joint_positions().begin(), m.joint_positions().end()),
                                   model->defaultState(*base));
  if (!st) return;
  st->base = *base;
  std::lock_guard g(pool_mutex_);
  const bool first = !robot_now_;
  robot_now_ = *st;
  // Prepared before the robot was heard of: for the default state, which may not be its own.
  if (first)
    for (auto& sl : slots_) sl->dirty = true;
}

std::vector<std::optional<PrepareStats>> MotionPlannerNode::prepareIfWorldChanged() {
  std::vector<std::optional<PrepareStats>> out(slots_.size());
  if (!config_.prepare) return out;
  for (std::size_t i = 0; i < slots_.size(); ++i) {
    Slot& slot = *slots_[i];
    std::stop_token token;
    {
      std::lock_guard g(pool_mutex_);
      if (waiting_ > 0) break;  // requests first
      if (slot.busy || !slot.dirty) continue;
      slot.busy = true;
      slot.preparing = true;
      slot.dirty = false;  // a world change from now on sets it again
      slot.prepare_stop = std::stop_source();
      token = slot.prepare_stop.get_token();
    }
    Lease lease(this, i);
    (void)syncPlanner(slot);
    robot::RobotState state;
    if (slot.last_base_start) {
      state = *slot.last_base_start;
    } else if (std::lock_guard g(pool_mutex_); robot_now_) {
      state = *robot_now_;
    } else if (const auto* model = slot.planner.robotModel()) {
      state = model->defaultState();
    }
    auto r = slot.planner.prepare(PlanningGroup::kBase, state, {},
                                  Termination(Deadline::in(config_.prepare_budget_s), std::move(token)));
    if (!r) {
      nodeLog()->warn("roadmap preparation of planner {} failed: {}", i, r.error().toString());
      continue;
    }
    if (!r->completed) {  // interrupted: resume at the next spin
      std::lock_guard g(pool_mutex_);
      slot.dirty = true;
    }
    nodeLog()->debug("planner {}: roadmap prepared in {:.1f} ms ({}, {} nodes, {} edges evaluated{})", i, r->time_ms,
                     r->built ? "new" : "cached", r->roadmap_nodes, r->edges_evaluated,
                     r->completed ? "" : ", interrupted");
    out[i] = *r;
  }
  return out;
}

Result<Termination> MotionPlannerNode::termination(uint64_t world_version, const dds::RequestContext& ctx) {
  Termination term = ctx.termination;
  if (term.deadline().isNever()) term = term.tightened(Deadline::in(config_.default_budget_s));
  if (world_version > 0 && mirror_->publishedVersion() < world_version) {
    const Termination wait = term.tightened(Deadline::in(config_.world_wait_s));
    if (!mirror_->waitForPublishedVersion(world_version, wait)) {
      return Error(ErrorCode::kNotReady, "world_version: " + std::to_string(world_version) +
                                                " not received (latest " + std::to_string(mirror_->publishedVersion()) +
                                                ")");
    }
  }
  return term;
}

namespace {
Error busy() { return Error(ErrorCode::kTimeout, "every planner stayed busy until the deadline"); }
}  // namespace

msg::MotionReply MotionPlannerNode::handleMotion(const msg::MotionRequest& req, const dds::RequestContext& ctx) {
  if (Status bad = msgv::screen(req, dds::services::kMotion.name, rejects_); !bad.ok()) {
    msg::MotionReply rep;
    rep.status(msg::MOTION_INVALID_REQUEST);
    rep.reason(bad.error().message);
    rep.header().message(bad.error().message);
    return rep;
  }
  auto term = termination(req.world_version(), ctx);
  if (!term) return errorReply<msg::MotionReply>(term.error());
  auto lease = acquire(*term);
  if (!lease) return errorReply<msg::MotionReply>(busy());
  Slot& slot = lease->slot();
  const uint64_t world_version = syncPlanner(slot);
  auto request = fromMsg(req, slot.planner);
  if (!request) {
    msg::MotionReply rep;
    rep.status(msg::MOTION_INVALID_REQUEST);
    rep.reason(request.error().toString());
    rep.header().message(request.error().toString());
    rep.world_version(world_version);
    return rep;
  }
  if (request->group == PlanningGroup::kBase) slot.last_base_start = request->start;
  const MotionResult r = slot.planner.plan(*request, *term);
  const PlanningStats& st = r.stats;
  nodeLog()->debug(
      "motion {} on planner {}: {} {} {} in {:.1f} ms (goal {:.1f}, sampling {:.1f}, proof {:.1f} over {} cells, "
      "optimize {:.1f}, shortcut {:.1f}, analysis {:.1f}; {} checks, {} by the clearance grid), {} blocking{}{}{}",
      ctx.request_id, lease->index(), toString(request->group), toString(request->mode), toString(r.status),
      r.planning_time_s * 1e3, st.goal_ms, st.sampling_ms, st.proof_ms, st.proof_cells, st.optimize_ms, st.shortcut_ms,
      st.analysis_ms, st.validity_checks, st.grid_answers, r.blocking.size(), request->object_overrides.empty() ? "" : ", overrides",
      st.proof_trace.empty() ? "" : "; proof ", st.proof_trace);
  for (const auto& id : r.start_contacts) {
    nodeLog()->info("motion {}: the start touches '{}'; the path leaves it first", ctx.request_id, id);
  }
  msg::MotionReply rep = toMsg(r);
  rep.world_version(world_version);
  if (r.status != MotionStatus::kSolved) rep.header().message(r.reason);
  return rep;
}

msg::PlacementReply MotionPlannerNode::handlePlacement(const msg::PlacementRequest& req,
                                                      const dds::RequestContext& ctx) {
  if (Status bad = msgv::screen(req, dds::services::kPlacement.name, rejects_); !bad.ok())
    return errorReply<msg::PlacementReply>(bad.error());
  auto term = termination(req.world_version(), ctx);
  if (!term) return errorReply<msg::PlacementReply>(term.error());
  auto lease = acquire(*term);
  if (!lease) return errorReply<msg::PlacementReply>(busy());
  Slot& slot = lease->slot();
  (void)syncPlanner(slot);
  auto request = fromMsg(req);
  if (!request) return errorReply<msg::PlacementReply>(request.error());
  auto r = slot.planner.samplePlacements(*request, *term);
  if (!r) return errorReply<msg::PlacementReply>(r.error());
  return toMsg(*r);
}

msg::GraspReply MotionPlannerNode::handleGrasp(const msg::GraspRequest& req, const dds::RequestContext& ctx) {
  if (Status bad = msgv::screen(req, dds::services::kGrasp.name, rejects_); !bad.ok())
    return errorReply<msg::GraspReply>(bad.error());
  auto term = termination(req.world_version(), ctx);
  if (!term) return errorReply<msg::GraspReply>(term.error());
  auto lease = acquire(*term);
  if (!lease) return errorReply<msg::GraspReply>(busy());
  Slot& slot = lease->slot();
  (void)syncPlanner(slot);
  auto request = fromMsg(req);
  if (!request) return errorReply<msg::GraspReply>(request.error());
  auto r = slot.planner.generateGrasps(*request, *term);
  if (!r) return errorReply<msg::GraspReply>(r.error());
  return toMsg(*r);
}

}  // namespace tamp::motion_planner
