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
  rep.header().message(e.toString());  // names the field when the error knows it
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
  r.check(c.robot == "mobile_manipulator" || c.robot == "disc", "robot",
          "must be 'mobile_manipulator' or 'disc', got '" + c.robot + "'");
  r.check(std::isfinite(c.disc_radius) && c.disc_radius > 0, "disc_radius", "must be positive");
  r.check(std::isfinite(c.disc_height) && c.disc_height > 0, "disc_height", "must be positive");
  r.check(!c.world_id.empty(), "world_id", "must not be empty");
  r.check(std::isfinite(c.default_budget_s) && c.default_budget_s > 0, "default_budget_s", "must be positive");
  r.check(std::isfinite(c.world_wait_s) && c.world_wait_s >= 0, "world_wait_s", "must be >= 0");
  r.check(std::isfinite(c.prepare_budget_s) && c.prepare_budget_s > 0, "prepare_budget_s", "must be positive");
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
  seedRandomness(config.params.seed);
  if (config.robot == "disc") {
    MotionPlanner planner(collision::RobotGeometry::disc(config.disc_radius, config.disc_height), config.params);
    return std::unique_ptr<MotionPlannerNode>(new MotionPlannerNode(args, std::move(config), std::move(planner)));
  }
  auto model = config.urdf.empty() ? robot::RobotModel::loadDefault() : robot::RobotModel::loadFile(config.urdf);
  if (!model) return model.error();
  MotionPlanner planner(std::move(*model), config.params);
  return std::unique_ptr<MotionPlannerNode>(new MotionPlannerNode(args, std::move(config), std::move(planner)));
}

MotionPlannerNode::MotionPlannerNode(const dds::ServiceArgs& args, NodeConfig config, MotionPlanner planner)
    : ServiceNode(args), config_(std::move(config)), planner_(std::move(planner)) {
  mirror_ = std::make_unique<dds::WorldMirror>(participant(), config_.world_id);
  mirror_->onChange([this] { world_dirty_ = true; });
  motion_ = std::make_unique<dds::RpcServer<msg::MotionRequest, msg::MotionReply>>(
      participant(), dds::services::kMotion,
      [this](const msg::MotionRequest& r, const dds::RequestContext& c) { return handleMotion(r, c); });
  placement_ = std::make_unique<dds::RpcServer<msg::PlacementRequest, msg::PlacementReply>>(
      participant(), dds::services::kPlacement,
      [this](const msg::PlacementRequest& r, const dds::RequestContext& c) { return handlePlacement(r, c); });
  grasp_ = std::make_unique<dds::RpcServer<msg::GraspRequest, msg::GraspReply>>(
      participant(), dds::services::kGrasp,
      [this](const msg::GraspRequest& r, const dds::RequestContext& c) { return handleGrasp(r, c); });
}

MotionPlannerNode::~MotionPlannerNode() {
  grasp_.reset();  // servers first: their workers use the planner and the mirror
  placement_.reset();
  motion_.reset();
  mirror_.reset();
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

void MotionPlannerNode::interruptPreparation() {
  std::lock_guard g(stop_mutex_);
  prepare_stop_.request_stop();
}

std::optional<PrepareStats> MotionPlannerNode::prepareIfWorldChanged() {
  if (!config_.prepare || waiting_.load() > 0 || !world_dirty_.exchange(false)) return std::nullopt;
  std::unique_lock lock(mutex_, std::try_to_lock);
  if (!lock.owns_lock() || waiting_.load() > 0) {  // a request runs or waits: later
    world_dirty_ = true;
    return std::nullopt;
  }
  std::stop_token token;
  {
    std::lock_guard g(stop_mutex_);
    prepare_stop_ = std::stop_source();
    token = prepare_stop_.get_token();
  }
  planner_.setWorld(mirror_->snapshot());
  robot::RobotState state;
  if (last_base_start_) {
    state = *last_base_start_;
  } else if (const auto* model = planner_.robotModel()) {
    state = model->defaultState();
  }
  auto r = planner_.prepare(PlanningGroup::kBase, state, {},
                            Termination(Deadline::in(config_.prepare_budget_s), std::move(token)));
  if (!r) {
    nodeLog()->warn("roadmap preparation failed: {}", r.error().toString());
    return std::nullopt;
  }
  if (!r->completed) world_dirty_ = true;  // interrupted: resume at the next spin
  nodeLog()->debug("roadmap prepared in {:.1f} ms ({}, {} nodes, {} edges evaluated{})", r->time_ms,
                   r->built ? "new" : "cached", r->roadmap_nodes, r->edges_evaluated,
                   r->completed ? "" : ", interrupted");
  return *r;
}

Result<Termination> MotionPlannerNode::prepare(uint64_t world_version, const dds::RequestContext& ctx) {
  Termination term = ctx.termination;
  if (term.deadline().isNever()) term = term.tightened(Deadline::in(config_.default_budget_s));
  if (world_version > 0 && mirror_->publishedVersion() < world_version) {
    const Termination wait = term.tightened(Deadline::in(config_.world_wait_s));
    if (!mirror_->waitForPublishedVersion(world_version, wait)) {
      return Error(ErrorCode::kUnavailable, "world_version: " + std::to_string(world_version) +
                                                " not received (latest " + std::to_string(mirror_->publishedVersion()) +
                                                ")");
    }
  }
  planner_.setWorld(mirror_->snapshot());
  return term;
}

msg::MotionReply MotionPlannerNode::handleMotion(const msg::MotionRequest& req, const dds::RequestContext& ctx) {
  ++waiting_;
  interruptPreparation();
  std::unique_lock lock(mutex_);
  --waiting_;
  auto term = prepare(req.world_version(), ctx);
  if (!term) return errorReply<msg::MotionReply>(term.error());
  auto request = fromMsg(req, planner_);
  if (!request) {
    msg::MotionReply rep;
    rep.status(msg::MOTION_INVALID_REQUEST);
    rep.reason(request.error().toString());
    rep.header().message(request.error().toString());
    return rep;
  }
  if (request->group == PlanningGroup::kBase) last_base_start_ = request->start;
  const MotionResult r = planner_.plan(*request, *term);
  nodeLog()->debug("motion {} {} {}: {} in {:.1f} ms, {} blocking", ctx.request_id, toString(request->group),
                   toString(request->mode), toString(r.status), r.planning_time_s * 1e3, r.blocking.size());
  msg::MotionReply rep = toMsg(r);
  if (r.status != MotionStatus::kSolved) rep.header().message(r.reason);
  return rep;
}

msg::PlacementReply MotionPlannerNode::handlePlacement(const msg::PlacementRequest& req,
                                                      const dds::RequestContext& ctx) {
  ++waiting_;
  interruptPreparation();
  std::unique_lock lock(mutex_);
  --waiting_;
  auto term = prepare(0, ctx);
  if (!term) return errorReply<msg::PlacementReply>(term.error());
  auto request = fromMsg(req);
  if (!request) return errorReply<msg::PlacementReply>(request.error());
  auto r = planner_.samplePlacements(*request, *term);
  if (!r) return errorReply<msg::PlacementReply>(r.error());
  return toMsg(*r);
}

msg::GraspReply MotionPlannerNode::handleGrasp(const msg::GraspRequest& req, const dds::RequestContext& ctx) {
  ++waiting_;
  interruptPreparation();
  std::unique_lock lock(mutex_);
  --waiting_;
  auto term = prepare(0, ctx);
  if (!term) return errorReply<msg::GraspReply>(term.error());
  auto request = fromMsg(req);
  if (!request) return errorReply<msg::GraspReply>(request.error());
  auto r = planner_.generateGrasps(*request, *term);
  if (!r) return errorReply<msg::GraspReply>(r.error());
  return toMsg(*r);
}

}  // namespace tamp::motion_planner
