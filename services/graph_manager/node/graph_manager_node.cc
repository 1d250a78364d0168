#include "graph_manager_node.h"

#include <chrono>
#include <cstdlib>
#include <filesystem>

#include "tamp/core/log.h"
#include "tamp/core/paths.h"
#include "tamp/dds/convert.h"
#include "tamp/graph_manager/report.h"
#include "tamp/world/scenario.h"

namespace tamp::graph_manager {
namespace {

const std::shared_ptr<spdlog::logger>& logger() {
  static const auto l = tamp::log::get("graph_manager");
  return l;
}

Policy fromMsg(msg::EffortPolicy p, Policy fallback) {
  switch (p) {
    case msg::EffortPolicy::POLICY_EFFORT_BASED: return Policy::kEffort;
    case msg::EffortPolicy::POLICY_INFEASIBILITY_ONLY: return Policy::kInfeasible;
    case msg::EffortPolicy::POLICY_ORACLE: return Policy::kOracle;
    default: return fallback;
  }
}

msg::MissionState stateOf(const std::string& s) {
  if (s == "planning") return msg::MissionState::MISSION_PLANNING;
  if (s == "executing") return msg::MissionState::MISSION_EXECUTING;
  if (s == "replanning") return msg::MissionState::MISSION_REPLANNING;
  if (s == "succeeded") return msg::MissionState::MISSION_SUCCEEDED;
  if (s == "aborted") return msg::MissionState::MISSION_ABORTED;
  return msg::MissionState::MISSION_FAILED;
}

/// The mission goal as atoms: the scenario's PDDL goal, object-in-region goals and the base goal
/// (a location; a bare pose becomes one).
Result<MissionGoal> goalOf(const world::Scenario& sc, const robot::RobotModel& robot, Abstraction& abs) {
  auto problem = world::toPddlProblem(sc, robot);
  if (!problem) return problem.error();
  MissionGoal g;
  g.atoms = problem->goal;
  if (sc.goal.base && sc.goal.base_location.empty())
    g.atoms.push_back("(robot-at " + abs.locationFor(*sc.goal.base, "goal") + ")");
  if (g.atoms.empty()) return Error(ErrorCode::kInvalidArgument, sc.file.string() + ": goal: the scenario has no goal");
  return g;
}

}  // namespace

Result<std::unique_ptr<dds::ServiceNode>> GraphManagerNode::create(const dds::ServiceArgs& args) {
  const std::filesystem::path file =
      args.config_file.empty() ? configDir() / "services" / "graph_manager.yaml" : std::filesystem::path(args.config_file);
  auto params = loadParams(file);
  if (!params) return params.error();
  // Each mission sets its scenario's robot; until then, the default one.
  auto robot = robot::RobotModel::loadDefault();
  if (!robot) return robot.error();
  return std::unique_ptr<dds::ServiceNode>(new GraphManagerNode(args, *params, *robot));
}

GraphManagerNode::GraphManagerNode(const dds::ServiceArgs& args, GraphManagerParams params,
                                   const robot::RobotModel& robot)
    : dds::ServiceNode(args),
      args_(args),
      params_(params),
      status_(participant(), dds::topics::kMissionStatus),
      graph_(participant(), dds::topics::kGraph),
      clients_(participant(), robot),
      oracle_clients_(participant(), clients_),
      executor_(participant(), ""),
      source_(participant(), robot) {
  openJournal();
  mission_watch_ = heartbeat().watchWorker("mission");
  clients_.watchedBy(mission_watch_.get());
  executor_.watchedBy(mission_watch_.get());
  source_.watchedBy(mission_watch_.get());
  thread_ = std::jthread([this](std::stop_token st) { worker(st); });
  commands_ = std::make_unique<dds::Reader<msg::MissionCommand>>(
      participant(), dds::topics::kMissionCommand,
      [this](const msg::MissionCommand& c, const dds::SampleMeta&) { onCommand(c); });
}

std::string GraphManagerNode::notReadyBecause() const {
  std::string missing = source_.missingInputs();
  auto add = [&missing](const std::string& what) {
    if (what.empty()) return;
    missing += missing.empty() ? "" : "; ";
    missing += what;
  };
  add(clients_.missingServers());
  add(executor_.monitorPresent() ? std::string()
                                 : std::string("no execution monitor matched (") + dds::topics::kExecuteCommand.name + ")");
  return missing;
}

GraphManagerNode::~GraphManagerNode() {
  commands_.reset();
  abort_ = true;
  thread_.request_stop();
  cv_.notify_all();
}

void GraphManagerNode::onCommand(const msg::MissionCommand& c) {
  if (Status bad = msgv::screen(c, dds::topics::kMissionCommand.name, rejects_); !bad.ok()) {
    // With a usable mission id the sender hears why: that mission FAILED, naming the field. Its
    // own status instance (keyed by mission id), so a running mission's status is untouched.
    if (!c.mission_id().empty() && c.mission_id().size() <= msgv::Limits{}.max_id_length && !c.abort()) {
      msg::MissionStatus st;
      st.mission_id(c.mission_id());
      st.state(msg::MissionState::MISSION_FAILED);
      st.message("rejected: " + bad.error().message);
      st.stamp_ns(dds::nowNs());
      if (Status s = status_.write(st); !s) logger()->warn("mission status: {}", s.error().message);
    }
    return;
  }
  std::unique_lock g(mutex_);
  if (c.abort()) {
    if (c.mission_id() != running_) return;
    abort_ = true;
    g.unlock();
    executor_.cancelInFlight();  // the robot stops now, not at the end of its action
    return;
  }
  if (c.mission_id().empty() || seen_.count(c.mission_id())) return;  // idempotent on mission id
  seen_.insert(c.mission_id());
  queue_.push_back(c);
  cv_.notify_all();
}

void GraphManagerNode::openJournal() {
  const char* run_dir = std::getenv("TAMP_RUN_DIR");
  if (run_dir == nullptr || *run_dir == '\0') return;
  journal_.emplace(std::filesystem::path(run_dir) / "graph_manager.journal.json");
  auto record = journal_->read();
  if (!record) {
    // Not taken up, and kept for a person to read: the next mission's record goes beside it.
    logger()->error("mission journal unreadable, no mission resumed: {}", record.error().toString());
    std::error_code ec;
    std::filesystem::rename(journal_->file(), journal_->file().string() + ".unreadable", ec);
    return;
  }
  if (!record->has_value()) return;
  seen_.insert((*record)->mission_id);
  if ((*record)->finished) return;
  std::error_code ec;
  const auto written = std::filesystem::last_write_time(journal_->file(), ec);
  const double age = ec ? 0.0 : std::chrono::duration<double>(std::filesystem::file_time_type::clock::now() - written).count();
  if (age > params_.resume_max_age_s) {
    (*record)->finished = true;
    (*record)->outcome = "aborted";
    (*record)->reason = "not resumed: the journal was written " + std::to_string(static_cast<long>(age)) +
                        " s ago (resume_max_age_s " + std::to_string(params_.resume_max_age_s) + ")";
    logger()->warn("mission {}: {}", (*record)->mission_id, (*record)->reason);
    journal(**record);
    return;
  }
  logger()->warn("mission {} was running when this graph manager stopped ({} actions done{}): resuming it",
                 (*record)->mission_id, (*record)->actions.size(),
                 (*record)->in_flight.empty() ? "" : ", " + (*record)->in_flight + " in flight");
  resume_ = std::move(**record);
}

void GraphManagerNode::journal(const MissionRecord& record) {
  if (!journal_) return;
  if (Status s = journal_->write(record); !s) logger()->warn("mission journal: {}", s.error().toString());
}

namespace {

/// The command a journal's unfinished mission was started with.
msg::MissionCommand commandOf(const MissionRecord& r) {
  msg::MissionCommand c;
  c.mission_id(r.mission_id);
  c.scenario_path(r.scenario_path);
  c.policy(r.policy == "infeasible" ? msg::EffortPolicy::POLICY_INFEASIBILITY_ONLY
           : r.policy == "oracle"   ? msg::EffortPolicy::POLICY_ORACLE
                                    : msg::EffortPolicy::POLICY_EFFORT_BASED);
  c.seed(r.seed);
  c.max_replans(static_cast<uint32_t>(std::max(0, r.max_replans)));
  c.goal(std::vector<std::string>(r.goal.begin(), r.goal.end()));
  return c;
}

}  // namespace

void GraphManagerNode::worker(std::stop_token stop) {
  if (resume_) {
    runGuarded(commandOf(*resume_), &*resume_);
    resume_.reset();
  }
  while (!stop.stop_requested()) {
    msg::MissionCommand c;
    {
      std::unique_lock lock(mutex_);
      cv_.wait(lock, stop, [&] { return !queue_.empty(); });
      if (stop.stop_requested()) return;
      c = queue_.front();
      queue_.pop_front();
      running_ = c.mission_id();  // with the dequeue: an abort from now on reaches it
      abort_ = false;
    }
    runGuarded(c, nullptr);
  }
}

void GraphManagerNode::runGuarded(const msg::MissionCommand& c, const MissionRecord* resumed) {
  if (resumed) {
    std::lock_guard g(mutex_);
    running_ = c.mission_id();
    abort_ = false;
  }
  const dds::WorkWatch::Scope busy(mission_watch_.get());
  try {
    runOne(c, resumed);
  } catch (const std::exception& e) {
    logger()->error("mission {}: {}", c.mission_id(), e.what());
    publish(c.mission_id(), msg::MissionState::MISSION_FAILED, std::string("internal error: ") + e.what());
  }
}

void GraphManagerNode::publish(const std::string& mission, msg::MissionState state, const std::string& message) {
  current_.mission_id(mission);
  current_.state(state);
  current_.message(message);
  current_.stamp_ns(dds::nowNs());
  if (Status s = status_.write(current_); !s) logger()->warn("mission status: {}", s.error().message);
}

namespace {

using Clock = std::chrono::steady_clock;
double since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

/// The journal's record of a mission: a new one from the command, or the resumed one taken up
/// once more.
MissionRecord recordOf(const msg::MissionCommand& c, Policy fallback, const MissionRecord* resumed) {
  MissionRecord record;
  if (resumed) {
    record = *resumed;
    ++record.resumptions;
    return record;
  }
  record.mission_id = c.mission_id();
  record.scenario_path = c.scenario_path();
  record.policy = std::string(toString(fromMsg(c.policy(), fallback)));
  record.seed = c.seed();
  record.max_replans = static_cast<int>(c.max_replans());
  record.goal.assign(c.goal().begin(), c.goal().end());
  return record;
}

/// What a mission is planned from: its scenario, the robot it names, the PDDL domain.
struct MissionInputs {
  std::string scenario_path;
  world::Scenario scenario;
  robot::RobotModel robot;
  std::string domain;
};

/// The command's scenario (else the node's); each failure names what was bad.
Result<MissionInputs> loadInputs(const msg::MissionCommand& c, const std::string& node_scenario) {
  const std::string path = c.scenario_path().empty() ? node_scenario : c.scenario_path();
  auto sc = world::loadScenario(path);
  if (!sc) return Error(sc.error().code, "bad scenario: " + sc.error().toString());
  auto robot = robot::RobotModel::loadDescription(sc->robot.description);
  if (!robot) return Error(robot.error().code, "bad robot description: " + robot.error().toString());
  auto domain = readTextFile(sc->domain);
  if (!domain) return Error(domain.error().code, "bad PDDL domain: " + domain.error().toString());
  return MissionInputs{path, std::move(*sc), std::move(*robot), std::move(*domain)};
}

/// The node's parameters with the command's policy, seed and replanning bound.
GraphManagerParams paramsFor(const msg::MissionCommand& c, GraphManagerParams p) {
  p.policy = fromMsg(c.policy(), p.policy);
  if (c.seed() != 0) p.seed = c.seed();
  if (c.max_replans() > 0) p.max_replans = static_cast<int>(c.max_replans());
  return p;
}

/// The command's own goal replaces the scenario's (atoms over the world's ids; the planner
/// refuses unknown names, which fails the mission as an input error).
Status applyCommandGoal(const msg::MissionCommand& c, MissionGoal& goal) {
  if (c.goal().empty()) return Status::Ok();
  goal.atoms.clear();
  for (std::size_t i = 0; i < c.goal().size(); ++i) {
    const std::string& a = c.goal()[i];
    if (atomTokens(a).empty() || a.find('(') == std::string::npos)
      return Error(ErrorCode::kInvalidArgument, "goal[" + std::to_string(i) + "]: not a PDDL atom: '" + a + "'");
    goal.atoms.push_back(a);
  }
  return Status::Ok();
}

/// What the planner is told: the scenario's planner view (a hidden object in the gripper is not
/// in it); the robot's own report of the hand selects the conditional branch. A resumed mission
/// believes what the robot reports.
Belief beliefOf(const world::Scenario& sc, bool resumed) {
  const world::World told = sc.world.plannerView();
  std::set<std::string> told_ids;
  for (const auto& o : told.objects()) told_ids.insert(o.id);
  if (resumed) return Belief{std::nullopt, told_ids};
  return Belief{told.held() ? told.held()->object_id : std::string(), told_ids};
}

/// The graph as published after every Traverse, with the best branch and its cost.
msg::GraphSnapshot snapshotOf(const std::string& mission, const ReachabilityGraph& g, const std::vector<EdgeId>& best,
                              NodeId node) {
  msg::GraphSnapshot s;
  s.mission_id(mission);
  s.version(g.version());
  s.current_node("n" + std::to_string(node));
  for (const Node& n : g.nodes()) {
    msg::GraphNode m;
    m.id("n" + std::to_string(n.id));
    m.atoms(n.atoms);
    m.healthy(n.healthy);
    s.nodes().push_back(m);
  }
  for (const Edge& e : g.edges()) {
    msg::GraphEdge m;
    m.id("e" + std::to_string(e.id));
    m.from_node("n" + std::to_string(e.from));
    m.to_node("n" + std::to_string(e.to));
    m.action(e.action);
    m.kind(dds::toMsg(e.kind));
    m.state(static_cast<msg::EdgeState>(static_cast<int>(e.state)));
    m.effort_mean_s(std::isfinite(e.effort_mean_s) ? e.effort_mean_s : -1.0);
    m.effort_stddev_s(e.effort_stddev_s);
    if (e.motion) m.blocking_objects(e.motion->blocking);
    s.edges().push_back(m);
  }
  double cost = 0.0;
  for (EdgeId e : best) {
    s.best_branch().push_back("e" + std::to_string(e));
    cost += std::isfinite(g.edge(e).effort_mean_s) ? g.edge(e).effort_mean_s : 0.0;
  }
  s.best_cost_s(cost);
  return s;
}

ResumePoint resumePointOf(const MissionRecord& record, const MissionRecord& resumed) {
  ResumePoint at;
  at.resumptions = record.resumptions;
  at.actions = resumed.actions;
  at.in_flight = resumed.in_flight;
  at.in_flight_action = resumed.in_flight_action;
  at.in_flight_budget_s = resumed.in_flight_budget_s;
  return at;
}

msg::MissionState finalStateOf(MissionOutcome o) {
  return o == MissionOutcome::kSucceeded ? msg::MissionState::MISSION_SUCCEEDED
         : o == MissionOutcome::kAborted ? msg::MissionState::MISSION_ABORTED
                                         : msg::MissionState::MISSION_FAILED;
}

}  // namespace

void GraphManagerNode::failMission(const msg::MissionCommand& c, MissionRecord& record, MissionOutcome o,
                                   const std::string& why) {
  MissionReport r;
  r.status = o;
  r.reason = why;
  r.resumptions = record.resumptions;
  current_.report_json(reportJson(r, c.scenario_path(), "", c.seed()));
  record.finished = true;
  record.outcome = std::string(toString(o));
  record.reason = why;
  journal(record);
  publish(c.mission_id(), msg::MissionState::MISSION_FAILED, why);
}

Result<GraphManagerNode::Backends> GraphManagerNode::backendsFor(const std::string& mission, Policy policy,
                                                                 std::optional<OracleWorldSource>& oracle_source) {
  if (policy != Policy::kOracle) return Backends{&clients_, &source_};
  // Policy oracle: efforts are the simulator's true durations and the world is the true one
  // (hidden objects included); the simulator serves its truth only in an evaluation run.
  auto truth = oracle_clients_.oracle();
  if (!truth)
    return Error(ErrorCode::kUnavailable, "policy oracle: " + truth.error().message +
                                              " (the simulator serves its truth only in an evaluation run: tamp run "
                                              "--policy oracle sets TAMP_ORACLE=1 for it)");
  logger()->info("mission {}: oracle: {} hidden object(s), {} scripted fault(s), {} commands accepted", mission,
                 truth->hidden.size(), truth->faults.size(), truth->action_count);
  oracle_source.emplace(source_, truth->hidden);
  return Backends{&oracle_clients_, &*oracle_source};
}

MissionObserver GraphManagerNode::observerFor(const std::string& mission, Clock::time_point t0) {
  MissionObserver obs;
  obs.on_state = [this, mission, t0](const std::string& s, const std::string& m) {
    current_.elapsed_s(since(t0));
    const auto st = stateOf(s);
    if (st == msg::MissionState::MISSION_SUCCEEDED || st == msg::MissionState::MISSION_FAILED ||
        st == msg::MissionState::MISSION_ABORTED)
      return;  // the final status carries the report (finishMission)
    if (s == "executing") current_.current_action(m);
    publish(mission, st, m);
  };
  obs.on_action = [this, mission](const ExecutedAction& a, double done, double total) {
    current_.last_action(a.action + (a.variant == "around" ? " [around]" : ""));
    current_.last_predicted_s(a.predicted_s);
    current_.last_measured_s(a.measured_s);
    current_.last_outcome(a.outcome);
    current_.done_predicted_s(done);
    current_.predicted_total_s(total);
    if (a.outcome == "succeeded") current_.actions_done(current_.actions_done() + 1);
    publish(mission, msg::MissionState::MISSION_EXECUTING, a.action + " " + a.outcome);
  };
  obs.on_graph = [this, mission](const ReachabilityGraph& g, const std::vector<EdgeId>& best, NodeId node) {
    current_.actions_planned(static_cast<uint32_t>(best.size()) + current_.actions_done());
    if (Status st = graph_.write(snapshotOf(mission, g, best, node)); !st)
      logger()->warn("graph snapshot: {}", st.error().message);
  };
  obs.abort_requested = [this] { return abort_.load(); };
  return obs;
}

void GraphManagerNode::finishMission(const std::string& mission, MissionRecord& record, const MissionReport& r,
                                     const std::string& scenario_path, const GraphManagerParams& p,
                                     Clock::time_point t0) {
  record.finished = true;
  record.outcome = std::string(toString(r.status));
  record.reason = r.reason;
  journal(record);
  current_.elapsed_s(since(t0));
  current_.replans(static_cast<uint32_t>(r.replans));
  current_.report_json(reportJson(r, scenario_path, std::string(toString(p.policy)), p.seed));
  current_.graph_dot(r.graph_dot);
  logger()->info("mission {}: {} ({}) executed {:.1f} s, predicted {:.1f} s, planning {:.2f} s", mission,
                 toString(r.status), r.reason, r.executed_effort_s, r.predicted_effort_s, r.planning_time_s);
  publish(mission, finalStateOf(r.status), r.reason);
}

void GraphManagerNode::runOne(const msg::MissionCommand& c, const MissionRecord* resumed) {
  const auto t0 = Clock::now();
  current_ = msg::MissionStatus{};
  const std::string id = c.mission_id();
  MissionRecord record = recordOf(c, params_.policy, resumed);
  journal(record);
  auto in = loadInputs(c, args_.scenario_file);
  if (!in) return failMission(c, record, MissionOutcome::kInputError, in.error().message);
  const GraphManagerParams p = paramsFor(c, params_);

  clients_.setRobot(in->robot);
  executor_.setMission(id);
  source_.setRobot(in->robot);
  publish(id, msg::MissionState::MISSION_PLANNING, "waiting for the world model and the robot state");
  if (Status ready = source_.waitReady(Termination::after(30.0)); !ready)
    return failMission(c, record, MissionOutcome::kUnavailable,
                       ready.error().message + " within 30 s (perception, sim running?)");
  std::optional<OracleWorldSource> oracle_source;
  auto backends = backendsFor(id, p.policy, oracle_source);
  if (!backends) return failMission(c, record, MissionOutcome::kUnavailable, backends.error().message);

  Abstraction abs(backends->source->world(), in->robot);
  auto goal = goalOf(in->scenario, in->robot, abs);
  if (!goal) return failMission(c, record, MissionOutcome::kInputError, "bad goal: " + goal.error().toString());
  if (Status s = applyCommandGoal(c, *goal); !s) return failMission(c, record, MissionOutcome::kInputError, s.error().message);
  GraphManager gm(std::move(abs), in->domain, *goal, *backends->services, p);
  gm.setBelief(beliefOf(in->scenario, resumed != nullptr));
  logger()->info("mission {}: scenario {}, policy {}, goal {} atoms", id, in->scenario.name, toString(p.policy),
                 goal->atoms.size());

  const MissionObserver obs = observerFor(id, t0);
  std::optional<JournalingExecutor> journaled;
  if (journal_) journaled.emplace(executor_, *journal_, record);
  Executor& executor = journaled ? static_cast<Executor&>(*journaled) : executor_;
  MissionReport r;
  if (resumed) {
    publish(id, msg::MissionState::MISSION_PLANNING, "resuming after a restart of the graph manager");
    r = gm.resumeMission(resumePointOf(record, *resumed), *backends->source, executor, obs);
  } else {
    r = gm.runMission(*backends->source, executor, obs);
  }
  finishMission(id, record, r, in->scenario_path, p, t0);
}

}  // namespace tamp::graph_manager
