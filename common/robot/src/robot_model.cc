#include "tamp/robot/robot_model.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <map>
#include <limits>
#include <numeric>
#include <optional>
#include <set>
#include <sstream>

#include <console_bridge/console.h>
#include <tinyxml2.h>
#include <urdf_parser/urdf_parser.h>
#include <kdl/chain.hpp>
#include <kdl/chainfksolverpos_recursive.hpp>
#include <kdl/chainiksolverpos_lma.hpp>
#include <kdl/frames.hpp>
#include <kdl/jntarray.hpp>

#include "tamp/config/yaml_reader.h"
#include "tamp/core/paths.h"
#include "tamp/core/trajectory.h"
#include "tamp/core/xml_error.h"

namespace tamp::robot {

std::string_view toString(JointType type) {
  switch (type) {
    case JointType::kFixed:
      return "fixed";
    case JointType::kRevolute:
      return "revolute";
    case JointType::kContinuous:
      return "continuous";
    case JointType::kPrismatic:
      return "prismatic";
  }
  return "unknown";
}

std::string_view toString(IkStatus status) {
  switch (status) {
    case IkStatus::kSolved:
      return "solved";
    case IkStatus::kNoSolution:
      return "no solution";
    case IkStatus::kTimeout:
      return "timeout";
    case IkStatus::kInvalidInput:
      return "invalid input";
  }
  return "unknown";
}

namespace {

/// Collects urdfdom's console_bridge messages during one parse (instead of printing them).
class CaptureHandler : public console_bridge::OutputHandler {
 public:
  void log(const std::string& text, console_bridge::LogLevel level, const char*, int) override {
    if (level >= console_bridge::CONSOLE_BRIDGE_LOG_ERROR) messages.push_back(text);
  }
  std::vector<std::string> messages;
};

Eigen::Isometry3d toEigen(const urdf::Pose& p) {
  double x = 0, y = 0, z = 0, w = 1;
  p.rotation.getQuaternion(x, y, z, w);
  Eigen::Quaterniond q(w, x, y, z);
  if (!(q.norm() > 0) || !std::isfinite(q.norm())) q = Eigen::Quaterniond::Identity();
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = q.normalized().toRotationMatrix();
  T.translation() = Eigen::Vector3d(p.position.x, p.position.y, p.position.z);
  return T;
}

KDL::Frame toKdl(const Eigen::Isometry3d& T) {
  KDL::Frame f;
  for (int r = 0; r < 3; ++r) {
    f.p(r) = T.translation()(r);
    for (int c = 0; c < 3; ++c) f.M(r, c) = T.linear()(r, c);
  }
  return f;
}

Eigen::Isometry3d toEigen(const KDL::Frame& f) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  for (int r = 0; r < 3; ++r) {
    T.translation()(r) = f.p(r);
    for (int c = 0; c < 3; ++c) T.linear()(r, c) = f.M(r, c);
  }
  return T;
}

Eigen::Isometry3d jointMotion(const Joint& j, double q) {
  Eigen::Isometry3d M = Eigen::Isometry3d::Identity();
  switch (j.type) {
    case JointType::kRevolute:
    case JointType::kContinuous:
      M.linear() = Eigen::AngleAxisd(q, j.axis).toRotationMatrix();
      break;
    case JointType::kPrismatic:
      M.translation() = q * j.axis;
      break;
    case JointType::kFixed:
      break;
  }
  return M;
}


double angleOf(const Eigen::Matrix3d& R) {
  const double c = std::clamp((R.trace() - 1.0) / 2.0, -1.0, 1.0);
  return std::acos(c);
}

/// Where each joint's value comes from in a RobotState.
struct ValueSource {
  enum Kind { kZero, kArm, kGripper, kMimic } kind{kZero};
  int index{0};  // arm index, or the mimicked joint's index
  double multiplier{1.0}, offset{0.0};
};

/// Where the elements of a URDF document stand, for the messages of fromUrdfString: the line of its
/// <robot> and of every named <link> and <joint>.
struct UrdfLines {
  UrdfLines(const tinyxml2::XMLElement& robot_el, std::string source_name)
      : source(std::move(source_name)), robot(robot_el.GetLineNum()) {
    for (const auto* e = robot_el.FirstChildElement(); e != nullptr; e = e->NextSiblingElement()) {
      const char* n = e->Attribute("name");
      if (n == nullptr) continue;
      if (std::string_view(e->Name()) == "link") links[n] = e->GetLineNum();
      if (std::string_view(e->Name()) == "joint") joints[n] = e->GetLineNum();
    }
  }

  Error error(ErrorCode code, const std::string& msg, int line = 0,
              const std::string& field = "") const {
    return Error(code, msg, SourceLocation{source, line, 0, field});
  }
  int ofLink(const std::string& n) const {
    auto it = links.find(n);
    return it == links.end() ? robot : it->second;
  }
  int ofJoint(const std::string& n) const {
    auto it = joints.find(n);
    return it == joints.end() ? robot : it->second;
  }

  std::string source;
  int robot;
  std::map<std::string, int> links, joints;
};

/// The joints' tree structure, checked before urdfdom: a link that is its own ancestor makes
/// urdfdom build (and leak) a cyclic graph.
Status checkJointTree(const tinyxml2::XMLElement& robot_el, const UrdfLines& lines) {
  std::map<std::string, std::pair<std::string, std::string>> parent_of;  // child -> (parent, joint)
  for (const auto* e = robot_el.FirstChildElement("joint"); e != nullptr;
       e = e->NextSiblingElement("joint")) {
    const char* jn = e->Attribute("name");
    const auto* pe = e->FirstChildElement("parent");
    const auto* ce = e->FirstChildElement("child");
    if (jn == nullptr || pe == nullptr || ce == nullptr || pe->Attribute("link") == nullptr ||
        ce->Attribute("link") == nullptr) {
      continue;  // urdfdom reports these
    }
    const std::string parent = pe->Attribute("link"), child = ce->Attribute("link");
    if (parent == child) {
      return lines.error(
          ErrorCode::kParseError,
          "joint '" + std::string(jn) + "': parent and child are the same link '" + child + "'",
          e->GetLineNum(), "joint." + std::string(jn));
    }
    auto [it, fresh] = parent_of.emplace(child, std::make_pair(parent, std::string(jn)));
    if (!fresh) {
      return lines.error(ErrorCode::kParseError,
                         "link '" + child + "' is the child of two joints, '" + it->second.second +
                             "' and '" + jn + "'",
                         e->GetLineNum(), "joint." + std::string(jn));
    }
  }
  for (const auto& [child, pj] : parent_of) {
    std::string at = child;
    for (size_t steps = 0; steps <= parent_of.size(); ++steps) {
      auto up = parent_of.find(at);
      if (up == parent_of.end()) break;
      at = up->second.first;
      if (at == child) {
        return lines.error(ErrorCode::kParseError,
                           "the joints form a cycle through link '" + child + "'",
                           lines.ofJoint(pj.second), "joint." + pj.second);
      }
    }
  }
  return Status::Ok();
}

/// urdfdom's model of `xml`, with its diagnostics captured instead of printed; an error points at
/// the element its message names, when it names one.
Result<urdf::ModelInterfaceSharedPtr> parseWithUrdfdom(const std::string& xml,
                                                       const UrdfLines& lines) {
  urdf::ModelInterfaceSharedPtr model;
  CaptureHandler capture;
  const console_bridge::LogLevel old_level = console_bridge::getLogLevel();
  console_bridge::useOutputHandler(&capture);
  console_bridge::setLogLevel(console_bridge::CONSOLE_BRIDGE_LOG_ERROR);
  try {
    model = urdf::parseURDF(xml);
  } catch (const std::exception& e) {
    capture.messages.emplace_back(e.what());
    model.reset();
  }
  console_bridge::restorePreviousOutputHandler();
  console_bridge::setLogLevel(old_level);
  if (!model || !model->getRoot()) {
    std::string msg = "invalid URDF";
    int line = lines.robot;
    for (const auto& m : capture.messages) {
      msg += ": " + m;
      // Point at the element the message names, when it names one.
      for (const auto& [n, l] : lines.links) {
        if (m.find("[" + n + "]") != std::string::npos ||
            m.find("'" + n + "'") != std::string::npos)
          line = l;
      }
      for (const auto& [n, l] : lines.joints) {
        if (m.find("[" + n + "]") != std::string::npos ||
            m.find("'" + n + "'") != std::string::npos)
          line = l;
      }
    }
    return lines.error(ErrorCode::kParseError, msg, line);
  }
  return model;
}

/// The links from the root, parents before children (children by name).
std::vector<urdf::LinkConstSharedPtr> linksInOrder(const urdf::ModelInterface& model) {
  std::vector<urdf::LinkConstSharedPtr> order{model.getRoot()};
  for (size_t i = 0; i < order.size(); ++i) {
    std::vector<urdf::LinkSharedPtr> kids = order[i]->child_links;
    std::sort(kids.begin(), kids.end(),
              [](const auto& a, const auto& b) { return a->name < b->name; });
    for (const auto& c : kids) order.push_back(c);
  }
  return order;
}

/// The URDF joint `uj` in this model's terms; nullopt for an unsupported type or a zero axis.
/// Errors go to `errors`: those two, and limits that are not finite with lower <= upper.
std::optional<Joint> toJoint(const urdf::JointSharedPtr& uj, const UrdfLines& lines,
                             std::vector<Error>& errors) {
  Joint j;
  j.name = uj->name;
  j.parent_link = uj->parent_link_name;
  j.child_link = uj->child_link_name;
  j.parent_T_joint = toEigen(uj->parent_to_joint_origin_transform);
  j.axis = Eigen::Vector3d(uj->axis.x, uj->axis.y, uj->axis.z);
  const int line = lines.ofJoint(uj->name);
  switch (uj->type) {
    case urdf::Joint::FIXED:
      j.type = JointType::kFixed;
      break;
    case urdf::Joint::REVOLUTE:
      j.type = JointType::kRevolute;
      break;
    case urdf::Joint::CONTINUOUS:
      j.type = JointType::kContinuous;
      break;
    case urdf::Joint::PRISMATIC:
      j.type = JointType::kPrismatic;
      break;
    default:
      errors.push_back(
          lines.error(ErrorCode::kUnsupported,
                      "joint '" + uj->name +
                          "': only fixed, revolute, continuous and prismatic joints are supported",
                      line, "joint." + uj->name));
      return std::nullopt;
  }
  if (j.type != JointType::kFixed) {
    if (!(j.axis.norm() > 1e-9) || !j.axis.allFinite()) {
      errors.push_back(lines.error(ErrorCode::kInvalidArgument,
                                   "joint '" + uj->name + "': axis must be non-zero", line,
                                   "joint." + uj->name + ".axis"));
      return std::nullopt;
    }
    j.axis.normalize();
  }
  if (uj->limits) {
    j.limits =
        JointLimits{uj->limits->lower, uj->limits->upper, uj->limits->velocity, uj->limits->effort};
  }
  if (j.type == JointType::kContinuous) {
    j.limits.lower = -std::numeric_limits<double>::infinity();
    j.limits.upper = std::numeric_limits<double>::infinity();
  } else if (j.type != JointType::kFixed) {
    if (!std::isfinite(j.limits.lower) || !std::isfinite(j.limits.upper) ||
        j.limits.lower > j.limits.upper) {
      errors.push_back(lines.error(
          ErrorCode::kInvalidArgument,
          "joint '" + uj->name + "': limits must be finite with lower <= upper, got [" +
              std::to_string(j.limits.lower) + ", " + std::to_string(j.limits.upper) + "]",
          line, "joint." + uj->name + ".limit"));
    }
  }
  if (uj->mimic) {
    j.mimic = uj->mimic->joint_name;
    j.mimic_multiplier = uj->mimic->multiplier;
    j.mimic_offset = uj->mimic->offset;
  }
  return j;
}

}  // namespace

struct RobotModel::Impl {
  std::string name;
  std::string source;
  RobotModelOptions options;
  std::vector<std::string> links;    // topological
  std::vector<int> link_parent;      // -1 for the root
  std::vector<int> link_joint;       // joint index whose child is this link, -1 root
  std::vector<Joint> joints;         // index = order of child links (root has none)
  std::vector<ValueSource> sources;  // per joint
  std::vector<std::string> arm_joints;
  std::vector<int> arm_joint_index;  // into joints
  std::vector<JointLimits> arm_limits;
  int gripper_joint{-1};
  int tool_link{-1};
  KDL::Chain chain;
  /// No tool position is farther than `reach_bound` from `reach_origin` (base_link): the first arm
  /// joint's axis point, fixed in base_link. A revolute joint keeps the distance from its axis
  /// point to the next one, so the sum of those distances (at zero), the last one's to the tool
  /// and the prismatic joints' travel bound the reach (the triangle inequality).
  Eigen::Vector3d reach_origin{Eigen::Vector3d::Zero()};
  double reach_bound{std::numeric_limits<double>::infinity()};
  void boundReach();
  // Steps of fromUrdfString (robot_model.cc).
  Status addLinksAndJoints(const std::vector<urdf::LinkConstSharedPtr>& order,
                           const std::map<std::string, int>& index, const UrdfLines& lines);
  Status addArmChain(const std::map<std::string, int>& index, const UrdfLines& lines);
  Status addCollisionGeometry(const std::vector<urdf::LinkConstSharedPtr>& order,
                              const UrdfLines& lines);
  void allowSelfCollisions(const std::map<std::string, int>& index);
  collision::RobotGeometry geometry;
  world::Polygon2 footprint;
  double base_radius{0.0};

  /// Joint values of every joint for a state (mimics resolved in order).
  void jointValues(const RobotState& s, std::vector<double>& v) const {
    v.assign(joints.size(), 0.0);
    for (size_t j = 0; j < joints.size(); ++j) {
      const ValueSource& src = sources[j];
      if (src.kind == ValueSource::kArm)
        v[j] = s.arm[static_cast<size_t>(src.index)];
      else if (src.kind == ValueSource::kGripper)
        v[j] = s.gripper;
    }
    for (size_t j = 0; j < joints.size(); ++j) {
      const ValueSource& src = sources[j];
      if (src.kind == ValueSource::kMimic)
        v[j] = src.multiplier * v[static_cast<size_t>(src.index)] + src.offset;
    }
  }

  void poses(const RobotState& s, std::vector<Eigen::Isometry3d>& out) const {
    if (s.arm.size() != arm_joints.size()) {
      throw std::invalid_argument("RobotModel: state has " + std::to_string(s.arm.size()) +
                                  " arm values, robot has " + std::to_string(arm_joints.size()) +
                                  " arm joints");
    }
    std::vector<double> v;
    jointValues(s, v);
    out.resize(links.size());
    out[0] = s.base.toIsometry(0.0);
    for (size_t i = 1; i < links.size(); ++i) {
      const Joint& j = joints[static_cast<size_t>(link_joint[i])];
      out[i] = out[static_cast<size_t>(link_parent[i])] * j.parent_T_joint *
               jointMotion(j, v[static_cast<size_t>(link_joint[i])]);
    }
  }
};

/// reach_origin and reach_bound from the chain at zero (see Impl).
void RobotModel::Impl::boundReach() {
  Impl& m = *this;
  KDL::Frame f = KDL::Frame::Identity();
  std::optional<Eigen::Vector3d> first, last;
  double bound = 0.0;
  for (unsigned i = 0; i < m.chain.getNrOfSegments(); ++i) {
    const KDL::Segment& seg = m.chain.getSegment(i);
    const KDL::Joint& j = seg.getJoint();
    if (j.getType() != KDL::Joint::None) {
      const KDL::Vector p = f * j.JointOrigin();
      const Eigen::Vector3d o(p.x(), p.y(), p.z());
      if (!first) first = o;
      if (last) bound += (o - *last).norm();
      last = o;
    }
    f = f * seg.pose(0.0);
  }
  if (!first) return;
  bound += (Eigen::Vector3d(f.p.x(), f.p.y(), f.p.z()) - *last).norm();
  for (std::size_t k = 0; k < m.arm_joint_index.size(); ++k) {
    const Joint& j = m.joints[static_cast<std::size_t>(m.arm_joint_index[k])];
    if (j.type != JointType::kPrismatic) continue;
    const JointLimits& l = m.arm_limits[k];
    if (!std::isfinite(l.lower) || !std::isfinite(l.upper)) return;  // unbounded travel: no bound
    bound += std::max(std::abs(l.lower), std::abs(l.upper));
  }
  m.reach_origin = *first;
  m.reach_bound = bound;
}

RobotModel::RobotModel() : impl_(std::make_unique<Impl>()) {}
RobotModel::RobotModel(const RobotModel& other) : impl_(std::make_unique<Impl>(*other.impl_)) {}
RobotModel& RobotModel::operator=(const RobotModel& other) {
  if (this != &other) impl_ = std::make_unique<Impl>(*other.impl_);
  return *this;
}
RobotModel::RobotModel(RobotModel&&) noexcept = default;
RobotModel& RobotModel::operator=(RobotModel&&) noexcept = default;
RobotModel::~RobotModel() = default;

// ---- loading ------------------------------------------------------------------------------------

Result<RobotModel> RobotModel::loadFile(const std::filesystem::path& file,
                                        const RobotModelOptions& options) {
  auto text = readTextFile(file);
  if (!text) return text.error();
  return fromUrdfString(*text, file.string(), options);
}

Result<RobotModel> RobotModel::loadDefault() {
  return loadDescription(configDir() / "robots" / "mobile_manipulator.yaml");
}

Result<RobotModel> RobotModel::loadDescription(const std::filesystem::path& yaml_file) {
  auto doc = config::loadYamlFile(yaml_file);
  if (!doc) return doc.error();
  config::FieldReader r(*doc);
  RobotModelOptions o;
  std::string urdf;
  r.required("urdf", urdf);
  r.optional("base_link", o.base_link);
  r.optional("tool_link", o.tool_link);
  r.optional("gripper_joint", o.gripper_joint);
  r.optional("camera_frame", o.camera_frame);
  if (r.required("payload", o.payload) && !(std::isfinite(o.payload) && o.payload >= 0)) {
    std::ostringstream got;
    got << o.payload;
    r.fail("payload", "must be a finite mass >= 0 (kg), got " + got.str());
  }
  if (r.optional("push_limit", o.push_limit) && !(std::isfinite(o.push_limit) && o.push_limit >= 0)) {
    std::ostringstream got;
    got << o.push_limit;
    r.fail("push_limit", "must be a finite mass >= 0 (kg), got " + got.str());
  }
  {
    auto g = r.child("gripper", false);
    if (r.has("gripper")) {
      g.required("open", o.gripper_open);
      g.required("closed", o.gripper_closed);
      g.refuseUnknownKeys();
    }
  }
  {
    auto named = r.child("named_configurations", false);
    if (named.isMap()) {
      for (auto it = named.node().begin(); it != named.node().end(); ++it) {
        const std::string name = it->first.as<std::string>();
        std::vector<double> q;
        if (named.required(name, q)) o.named_configurations.emplace_back(name, std::move(q));
      }
    }
  }
  r.refuseUnknownKeys();
  if (!r.ok()) return r.errors().size() == 1 ? r.errors().front() : r.status().error();
  auto model = loadFile(resolveRelativeTo(yaml_file, urdf), o);
  if (!model) return model.error();
  // Named configurations must fit the arm; gripper values its joint.
  std::vector<Error> errors;
  const config::FieldReader named = r.child("named_configurations", false);
  for (const auto& [name, q] : o.named_configurations) {
    const SourceLocation where = named.locationOf(name);
    if (q.size() != model->armDof()) {
      errors.emplace_back(ErrorCode::kInvalidArgument,
                          "has " + std::to_string(q.size()) + " values, the arm has " +
                              std::to_string(model->armDof()) + " joints",
                          where);
    } else if (!model->withinLimits(q)) {
      errors.emplace_back(ErrorCode::kInvalidArgument, "is outside the joint limits", where);
    }
  }
  const auto gl = model->gripperLimits();
  if (!model->gripperJointName().empty() &&
      (o.gripper_open < gl.lower || o.gripper_open > gl.upper || o.gripper_closed < gl.lower ||
       o.gripper_closed > gl.upper)) {
    errors.emplace_back(ErrorCode::kInvalidArgument,
                        "open/closed values must be within the gripper joint limits",
                        r.locationOf("gripper"));
  }
  if (errors.size() == 1) return errors.front();
  if (!errors.empty()) return Error(errors.front().code, joinErrors(errors));
  return model;
}

/// Links, their parents and joints from the URDF links in `order` (linksInOrder), `index` their
/// positions there. Errors: every joint that is not supported or not valid (toJoint).
Status RobotModel::Impl::addLinksAndJoints(const std::vector<urdf::LinkConstSharedPtr>& order,
                                           const std::map<std::string, int>& index,
                                           const UrdfLines& lines) {
  std::vector<Error> errors;
  links.resize(order.size());
  link_parent.assign(order.size(), -1);
  link_joint.assign(order.size(), -1);
  for (size_t i = 0; i < order.size(); ++i) {
    links[i] = order[i]->name;
    if (i == 0) continue;
    const urdf::JointSharedPtr& uj = order[i]->parent_joint;
    std::optional<Joint> j = toJoint(uj, lines, errors);
    if (!j) continue;
    link_parent[i] = index.at(uj->parent_link_name);
    link_joint[i] = static_cast<int>(joints.size());
    joints.push_back(std::move(*j));
  }
  if (!errors.empty()) return Error(errors.front().code, joinErrors(errors));
  return Status::Ok();
}

/// The arm chain base -> tool, and the value source of every joint.
Status RobotModel::Impl::addArmChain(const std::map<std::string, int>& index,
                                     const UrdfLines& lines) {
  auto li = index.find(options.tool_link);
  if (li == index.end()) {
    return lines.error(
        ErrorCode::kInvalidArgument,
        "tool link '" + options.tool_link + "' is not a link of robot '" + name + "'", lines.robot,
        "tool_link");
  }
  tool_link = li->second;
  std::vector<int> chain_joints;
  for (int l = tool_link; l > 0; l = link_parent[static_cast<size_t>(l)])
    chain_joints.push_back(link_joint[static_cast<size_t>(l)]);
  std::reverse(chain_joints.begin(), chain_joints.end());
  sources.assign(joints.size(), ValueSource{});
  for (int ji : chain_joints) {
    const Joint& j = joints[static_cast<size_t>(ji)];
    KDL::Joint kj(j.name, KDL::Joint::None);
    const KDL::Frame origin = toKdl(j.parent_T_joint);
    const KDL::Vector axis = origin.M * KDL::Vector(j.axis.x(), j.axis.y(), j.axis.z());
    if (j.type == JointType::kRevolute || j.type == JointType::kContinuous) {
      kj = KDL::Joint(j.name, origin.p, axis, KDL::Joint::RotAxis);
    } else if (j.type == JointType::kPrismatic) {
      kj = KDL::Joint(j.name, origin.p, axis, KDL::Joint::TransAxis);
    }
    chain.addSegment(KDL::Segment(j.child_link, kj, origin));
    if (j.type != JointType::kFixed && j.mimic.empty()) {
      sources[static_cast<size_t>(ji)] =
          ValueSource{ValueSource::kArm, static_cast<int>(arm_joints.size()), 1, 0};
      arm_joints.push_back(j.name);
      arm_joint_index.push_back(ji);
      arm_limits.push_back(j.limits);
    } else if (!j.mimic.empty()) {
      return lines.error(
          ErrorCode::kUnsupported,
          "joint '" + j.name + "': mimic joints inside the arm chain are not supported",
          lines.ofJoint(j.name), "joint." + j.name + ".mimic");
    }
  }
  if (arm_joints.empty()) {
    return lines.error(ErrorCode::kInvalidArgument,
                       "the chain from '" + options.base_link + "' to '" + options.tool_link +
                           "' has no movable joint",
                       lines.ofLink(options.tool_link), "tool_link");
  }
  boundReach();
  if (!options.gripper_joint.empty()) {
    auto it = std::find_if(joints.begin(), joints.end(),
                           [&](const Joint& j) { return j.name == options.gripper_joint; });
    if (it == joints.end() || it->type != JointType::kPrismatic) {
      return lines.error(ErrorCode::kInvalidArgument,
                         "gripper joint '" + options.gripper_joint +
                             "' must be a prismatic joint of robot '" + name + "'",
                         it == joints.end() ? lines.robot : lines.ofJoint(it->name),
                         "gripper_joint");
    }
    gripper_joint = static_cast<int>(it - joints.begin());
    sources[static_cast<size_t>(gripper_joint)] = ValueSource{ValueSource::kGripper, 0, 1, 0};
  }
  for (size_t ji = 0; ji < joints.size(); ++ji) {
    const Joint& j = joints[ji];
    if (j.mimic.empty()) continue;
    auto it = std::find_if(joints.begin(), joints.end(),
                           [&](const Joint& o) { return o.name == j.mimic; });
    if (it == joints.end() || !it->mimic.empty()) {
      return lines.error(
          ErrorCode::kInvalidArgument,
          "joint '" + j.name + "' mimics '" + j.mimic + "', which is not a driven joint",
          lines.ofJoint(j.name), "joint." + j.name + ".mimic");
    }
    sources[ji] = ValueSource{ValueSource::kMimic, static_cast<int>(it - joints.begin()),
                              j.mimic_multiplier, j.mimic_offset};
  }
  if (!options.camera_frame.empty() && index.count(options.camera_frame) == 0) {
    return lines.error(
        ErrorCode::kInvalidArgument,
        "camera frame '" + options.camera_frame + "' is not a link of robot '" + name + "'",
        lines.robot, "camera_frame");
  }
  return Status::Ok();
}

/// Collision geometry, and the base footprint: the xy hull of base_link's shapes (boxes and discs
/// projected).
Status RobotModel::Impl::addCollisionGeometry(const std::vector<urdf::LinkConstSharedPtr>& order,
                                              const UrdfLines& lines) {
  std::vector<Error> errors;
  geometry.links = links;
  for (size_t i = 0; i < order.size(); ++i) {
    for (const auto& c : order[i]->collision_array) {
      if (!c || !c->geometry) continue;
      collision::RobotPart part;
      part.link = static_cast<int>(i);
      part.link_T_shape = toEigen(c->origin);
      const auto& g = c->geometry;
      const int line = lines.ofLink(order[i]->name);
      const std::string field = "link." + order[i]->name + ".collision";
      if (auto b = std::dynamic_pointer_cast<urdf::Box>(g)) {
        part.shape = world::Shape::box(b->dim.x, b->dim.y, b->dim.z);
      } else if (auto cy = std::dynamic_pointer_cast<urdf::Cylinder>(g)) {
        part.shape = world::Shape::cylinder(cy->radius, cy->length);
      } else if (auto sp = std::dynamic_pointer_cast<urdf::Sphere>(g)) {
        part.shape = world::Shape::sphere(sp->radius);
      } else {
        errors.push_back(
            lines.error(ErrorCode::kUnsupported,
                        "link '" + order[i]->name +
                            "': only box, cylinder and sphere collision geometry is supported",
                        line, field));
        continue;
      }
      if (auto why = part.shape.invalidReason()) {
        errors.push_back(lines.error(ErrorCode::kInvalidArgument,
                                     "link '" + order[i]->name + "': " + *why, line, field));
        continue;
      }
      geometry.parts.push_back(std::move(part));
    }
  }
  if (!errors.empty()) return Error(errors.front().code, joinErrors(errors));

  // Base footprint: the xy hull of base_link's shapes (boxes and discs projected).
  Aabb fb;
  for (const auto& p : geometry.parts) {
    if (p.link != 0) continue;
    fb.extend(p.shape.aabb(p.link_T_shape));
  }
  if (!fb.empty()) {
    footprint = {{fb.min.x(), fb.min.y()},
                 {fb.max.x(), fb.min.y()},
                 {fb.max.x(), fb.max.y()},
                 {fb.min.x(), fb.max.y()}};
    base_radius = world::circumradius(footprint, Eigen::Vector2d::Zero());
  }
  return Status::Ok();
}

/// Allowed self-collisions: rigid groups (fixed joints), adjacent groups, and pairs touching in the
/// zero configuration with the gripper closed and open.
void RobotModel::Impl::allowSelfCollisions(const std::map<std::string, int>& index) {
  std::vector<int> group(links.size());
  std::iota(group.begin(), group.end(), 0);
  for (size_t i = 1; i < links.size(); ++i) {
    if (joints[static_cast<size_t>(link_joint[i])].type == JointType::kFixed)
      group[i] = group[static_cast<size_t>(link_parent[i])];
  }
  std::set<std::pair<int, int>> allowed;
  auto allow = [&](int a, int b) {
    if (a != b) allowed.insert({std::min(a, b), std::max(a, b)});
  };
  const int n = static_cast<int>(links.size());
  for (int a = 0; a < n; ++a) {
    for (int b = a + 1; b < n; ++b) {
      if (group[static_cast<size_t>(a)] == group[static_cast<size_t>(b)]) allow(a, b);
    }
  }
  // Adjacent groups: a group's root link hangs from a link of the other group.
  for (int a = 1; a < n; ++a) {
    const int root_a = group[static_cast<size_t>(a)];
    if (root_a == 0) continue;  // the base's group has no parent
    const int parent_group = group[static_cast<size_t>(link_parent[static_cast<size_t>(root_a)])];
    for (int b = 0; b < n; ++b) {
      if (group[static_cast<size_t>(b)] == parent_group) allow(a, b);
    }
  }
  {
    collision::Scene scene;
    scene.setRobot(geometry);
    RobotState s;
    s.arm.assign(arm_joints.size(), 0.0);
    for (size_t k = 0; k < s.arm.size(); ++k)
      s.arm[k] = std::clamp(0.0, arm_limits[k].lower, arm_limits[k].upper);
    std::vector<Eigen::Isometry3d> P;
    const double g_hi =
        gripper_joint >= 0 ? joints[static_cast<size_t>(gripper_joint)].limits.upper : 0.0;
    const double g_lo =
        gripper_joint >= 0 ? joints[static_cast<size_t>(gripper_joint)].limits.lower : 0.0;
    for (double g : {g_lo, g_hi}) {
      s.gripper = g;
      poses(s, P);
      scene.setLinkPoses(P);
      for (const auto& [a, b] : scene.selfCollisions()) allow(index.at(a), index.at(b));
    }
  }
  geometry.allowed_self_collisions.assign(allowed.begin(), allowed.end());
}

Result<RobotModel> RobotModel::fromUrdfString(const std::string& xml, const std::string& source,
                                              const RobotModelOptions& options) {
  // 1. XML syntax, with a line number, and the line of every <link>/<joint> for later messages.
  tinyxml2::XMLDocument doc;
  if (doc.Parse(xml.c_str(), xml.size()) != tinyxml2::XML_SUCCESS) {
    return Error(ErrorCode::kParseError, "invalid XML: " + xmlErrorMessage(doc),
                 SourceLocation{source, doc.ErrorLineNum(), 0, ""});
  }
  const tinyxml2::XMLElement* robot_el = doc.RootElement();
  if (robot_el == nullptr || std::string_view(robot_el->Name()) != "robot") {
    return Error(ErrorCode::kParseError, "the root element must be <robot>",
                 SourceLocation{source, robot_el ? robot_el->GetLineNum() : 1, 0, ""});
  }
  const UrdfLines lines(*robot_el, source);
  if (Status s = checkJointTree(*robot_el, lines); !s.ok()) return s.error();

  // 2. urdfdom, with its diagnostics captured instead of printed.
  auto parsed = parseWithUrdfdom(xml, lines);
  if (!parsed) return parsed.error();
  const urdf::ModelInterfaceSharedPtr& model = *parsed;

  RobotModel rm;
  Impl& m = *rm.impl_;
  m.name = model->getName();
  m.source = source;
  m.options = options;

  // 3. Topology: the base link must be the root (its planar motion is virtual, see header).
  const std::string root = model->getRoot()->name;
  if (root != options.base_link) {
    return lines.error(ErrorCode::kInvalidArgument,
                       "the base link '" + options.base_link +
                           "' must be the root of the URDF tree, but the root is '" + root + "'",
                       lines.ofLink(root), "base_link");
  }
  const std::vector<urdf::LinkConstSharedPtr> order = linksInOrder(*model);
  std::map<std::string, int> index;
  for (size_t i = 0; i < order.size(); ++i) index[order[i]->name] = static_cast<int>(i);
  if (Status s = m.addLinksAndJoints(order, index, lines); !s.ok()) return s.error();

  // 4. The arm chain base -> tool, and the value source of every joint.
  if (Status s = m.addArmChain(index, lines); !s.ok()) return s.error();

  // 5. Collision geometry.
  if (Status s = m.addCollisionGeometry(order, lines); !s.ok()) return s.error();

  // 6. Allowed self-collisions.
  m.allowSelfCollisions(index);
  return rm;
}

// ---- accessors ----------------------------------------------------------------------------------

const std::string& RobotModel::name() const { return impl_->name; }
const std::string& RobotModel::sourceFile() const { return impl_->source; }
const RobotModelOptions& RobotModel::options() const { return impl_->options; }
const std::vector<std::string>& RobotModel::linkNames() const { return impl_->links; }
const std::vector<Joint>& RobotModel::joints() const { return impl_->joints; }
const Joint* RobotModel::findJoint(std::string_view name) const {
  for (const auto& j : impl_->joints) {
    if (j.name == name) return &j;
  }
  return nullptr;
}
int RobotModel::linkIndex(std::string_view name) const {
  auto it = std::find(impl_->links.begin(), impl_->links.end(), name);
  return it == impl_->links.end() ? -1 : static_cast<int>(it - impl_->links.begin());
}
const std::vector<std::string>& RobotModel::armJointNames() const { return impl_->arm_joints; }
const std::vector<JointLimits>& RobotModel::armLimits() const { return impl_->arm_limits; }
const std::string& RobotModel::gripperJointName() const {
  static const std::string kNone;
  return impl_->gripper_joint >= 0 ? impl_->joints[static_cast<size_t>(impl_->gripper_joint)].name
                                   : kNone;
}
JointLimits RobotModel::gripperLimits() const {
  return impl_->gripper_joint >= 0 ? impl_->joints[static_cast<size_t>(impl_->gripper_joint)].limits
                                   : JointLimits{};
}

double RobotModel::maxGraspWidth() const {
  return impl_->gripper_joint >= 0 ? 2.0 * std::max(0.0, gripperLimits().upper) : 0.0;
}

std::vector<std::string> RobotModel::fullJointNames() const {
  std::vector<std::string> out(kBaseJointNames.begin(), kBaseJointNames.end());
  out.insert(out.end(), impl_->arm_joints.begin(), impl_->arm_joints.end());
  if (impl_->gripper_joint >= 0) out.push_back(gripperJointName());
  return out;
}

std::vector<double> RobotModel::toJointValues(const RobotState& s) const {
  std::vector<double> v{s.base.x, s.base.y, s.base.theta};
  v.insert(v.end(), s.arm.begin(), s.arm.end());
  if (impl_->gripper_joint >= 0) v.push_back(s.gripper);
  return v;
}

Result<RobotState> RobotModel::fromJointValues(const std::vector<std::string>& names,
                                               std::span<const double> values,
                                               const RobotState& defaults) const {
  if (names.size() != values.size()) {
    return Error(ErrorCode::kInvalidArgument, std::to_string(names.size()) + " joint names but " +
                                                  std::to_string(values.size()) + " values");
  }
  RobotState s = defaults;
  if (s.arm.size() != armDof()) s.arm.assign(armDof(), 0.0);
  for (size_t i = 0; i < names.size(); ++i) {
    const std::string& n = names[i];
    const double v = values[i];
    if (!std::isfinite(v))
      return Error(ErrorCode::kInvalidArgument, "joint '" + n + "': value is not finite");
    if (n == kBaseJointNames[0])
      s.base.x = v;
    else if (n == kBaseJointNames[1])
      s.base.y = v;
    else if (n == kBaseJointNames[2])
      s.base.theta = v;
    else if (impl_->gripper_joint >= 0 && n == gripperJointName())
      s.gripper = v;
    else {
      auto it = std::find(impl_->arm_joints.begin(), impl_->arm_joints.end(), n);
      if (it == impl_->arm_joints.end()) {
        return Error(ErrorCode::kInvalidArgument,
                     "joint '" + n + "' is not a joint of robot '" + impl_->name + "'");
      }
      s.arm[static_cast<size_t>(it - impl_->arm_joints.begin())] = v;
    }
  }
  return s;
}

bool RobotModel::withinLimits(std::span<const double> arm, double tolerance) const {
  if (arm.size() != armDof()) return false;
  for (size_t k = 0; k < arm.size(); ++k) {
    if (!(arm[k] >= impl_->arm_limits[k].lower - tolerance &&
          arm[k] <= impl_->arm_limits[k].upper + tolerance))
      return false;
  }
  return true;
}

std::vector<double> RobotModel::randomArmConfiguration(std::mt19937& rng) const {
  std::vector<double> q(armDof());
  for (size_t k = 0; k < q.size(); ++k) {
    double lo = impl_->arm_limits[k].lower, hi = impl_->arm_limits[k].upper;
    if (!std::isfinite(lo)) lo = -M_PI;
    if (!std::isfinite(hi)) hi = M_PI;
    q[k] = std::uniform_real_distribution<double>(lo, hi)(rng);
  }
  return q;
}

RobotState RobotModel::defaultState(const Pose2D& base) const {
  RobotState s;
  s.base = base;
  if (auto stow = namedConfiguration("stow")) {
    s.arm = *stow;
  } else {
    s.arm.assign(armDof(), 0.0);
    for (size_t k = 0; k < s.arm.size(); ++k)
      s.arm[k] = std::clamp(0.0, impl_->arm_limits[k].lower, impl_->arm_limits[k].upper);
  }
  s.gripper = impl_->gripper_joint >= 0 ? impl_->options.gripper_closed : 0.0;
  return s;
}

std::optional<std::vector<double>> RobotModel::namedConfiguration(std::string_view name) const {
  for (const auto& [n, q] : impl_->options.named_configurations) {
    if (n == name && q.size() == armDof()) return q;
  }
  return std::nullopt;
}

std::vector<std::string> RobotModel::namedConfigurationNames() const {
  std::vector<std::string> out;
  for (const auto& nq : impl_->options.named_configurations) out.push_back(nq.first);
  return out;
}

// ---- kinematics ---------------------------------------------------------------------------------

Eigen::Isometry3d RobotModel::toolPose(std::span<const double> arm) const {
  if (arm.size() != armDof()) {
    throw std::invalid_argument("RobotModel::toolPose: got " + std::to_string(arm.size()) +
                                " values, robot has " + std::to_string(armDof()) + " arm joints");
  }
  KDL::ChainFkSolverPos_recursive fk(impl_->chain);
  KDL::JntArray q(static_cast<unsigned>(arm.size()));
  for (size_t k = 0; k < arm.size(); ++k) q(static_cast<unsigned>(k)) = arm[k];
  KDL::Frame f;
  fk.JntToCart(q, f);
  return toEigen(f);
}

Eigen::Isometry3d RobotModel::toolPoseInWorld(const RobotState& s) const {
  return s.base.toIsometry(0.0) * toolPose(s.arm);
}

Result<Eigen::Isometry3d> RobotModel::linkPoseInWorld(std::string_view link,
                                                      const RobotState& s) const {
  const int i = linkIndex(link);
  if (i < 0)
    return Error(ErrorCode::kNotFound,
                 "robot '" + impl_->name + "' has no link '" + std::string(link) + "'");
  std::vector<Eigen::Isometry3d> P;
  impl_->poses(s, P);
  return P[static_cast<size_t>(i)];
}

void RobotModel::linkPoses(const RobotState& s, std::vector<Eigen::Isometry3d>& out) const {
  impl_->poses(s, out);
}

RobotModel::ReachSphere RobotModel::armReach() const { return {impl_->reach_origin, impl_->reach_bound}; }

IkResult RobotModel::inverseKinematics(const Eigen::Isometry3d& target,
                                       std::span<const double> seed, const IkOptions& options,
                                       const Termination& termination) const {
  IkResult r;
  const size_t dof = armDof();
  if (!target.matrix().allFinite() || (!seed.empty() && seed.size() != dof) ||
      options.max_attempts < 1) {
    r.status = IkStatus::kInvalidInput;
    return r;
  }
  for (double v : seed) {
    if (!std::isfinite(v)) {
      r.status = IkStatus::kInvalidInput;
      return r;
    }
  }
  if ((target.translation() - impl_->reach_origin).norm() > impl_->reach_bound + options.position_tolerance) {
    r.status = IkStatus::kNoSolution;  // farther than any configuration reaches: no attempt can succeed
    return r;
  }
  Eigen::Matrix<double, 6, 1> L;
  L << 1, 1, 1, 0.3, 0.3, 0.3;
  KDL::ChainIkSolverPos_LMA solver(impl_->chain, L, 1e-7, 300, 1e-12);
  const KDL::Frame goal = toKdl(target);
  std::mt19937 rng(options.seed);
  KDL::JntArray q0(static_cast<unsigned>(dof)), q(static_cast<unsigned>(dof));
  double best = std::numeric_limits<double>::infinity();
  const auto& lim = impl_->arm_limits;
  for (int attempt = 0; attempt < options.max_attempts; ++attempt) {
    if (termination()) {
      r.status = IkStatus::kTimeout;
      return r;
    }
    r.attempts = attempt + 1;
    std::vector<double> start = attempt == 0 && !seed.empty()
                                    ? std::vector<double>(seed.begin(), seed.end())
                                : attempt == 0 ? defaultState().arm
                                               : randomArmConfiguration(rng);
    for (size_t k = 0; k < dof; ++k) q0(static_cast<unsigned>(k)) = start[k];
    solver.CartToJnt(q0, goal, q);
    std::vector<double> sol(dof);
    bool in_limits = true;
    for (size_t k = 0; k < dof; ++k) {
      double v = q(static_cast<unsigned>(k));
      if (!std::isfinite(v)) {
        in_limits = false;
        break;
      }
      const Joint& j = impl_->joints[static_cast<size_t>(impl_->arm_joint_index[k])];
      if (j.type == JointType::kRevolute || j.type == JointType::kContinuous) {
        // Bring the angle into [lower, lower + 2 pi) when the limits allow.
        if (std::isfinite(lim[k].lower)) {
          v = lim[k].lower + std::fmod(std::fmod(v - lim[k].lower, 2 * M_PI) + 2 * M_PI, 2 * M_PI);
          if (v > lim[k].upper && v - 2 * M_PI >= lim[k].lower) v -= 2 * M_PI;
        } else {
          v = wrapAngle(v);
        }
      }
      if (v < lim[k].lower - 1e-9 || v > lim[k].upper + 1e-9) in_limits = false;
      sol[k] = std::clamp(v, lim[k].lower, lim[k].upper);
    }
    if (!in_limits) continue;
    const Eigen::Isometry3d got = toolPose(sol);
    const double pe = (got.translation() - target.translation()).norm();
    const double oe = angleOf(target.linear().transpose() * got.linear());
    const bool ok = pe <= options.position_tolerance && oe <= options.orientation_tolerance;
    if (ok && (!options.accept || options.accept(sol))) {
      r.status = IkStatus::kSolved;
      r.q = std::move(sol);
      r.position_error = pe;
      r.orientation_error = oe;
      return r;
    }
    if (pe + oe < best) {
      best = pe + oe;
      r.q = sol;
      r.position_error = pe;
      r.orientation_error = oe;
    }
  }
  r.status = IkStatus::kNoSolution;
  return r;
}

// ---- geometry and grasping ----------------------------------------------------------------------

const collision::RobotGeometry& RobotModel::collisionGeometry() const { return impl_->geometry; }
const world::Polygon2& RobotModel::baseFootprint() const { return impl_->footprint; }
double RobotModel::baseRadius() const { return impl_->base_radius; }

world::HeldObject RobotModel::hold(const std::string& object_id, const RobotState& s,
                                   const Eigen::Isometry3d& world_T_object) const {
  world::HeldObject h;
  h.object_id = object_id;
  h.link = impl_->options.tool_link;
  h.link_T_object = toolPoseInWorld(s).inverse() * world_T_object;
  return h;
}

Result<Eigen::Isometry3d> RobotModel::heldObjectPose(const RobotState& s,
                                                     const world::HeldObject& held) const {
  auto L = linkPoseInWorld(held.link, s);
  if (!L) return L.error();
  return Eigen::Isometry3d(*L * held.link_T_object);
}

}  // namespace tamp::robot
