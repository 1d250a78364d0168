#include "checkpoint.h"

#include <cmath>
#include <sstream>

#include "tamp/core/hex.h"
#include "tamp/core/paths.h"
#include "tamp/dds/cdr.h"
#include "tamp/dds/world_sync.h"

namespace tamp::sim {
namespace {

constexpr const char* kHeader = "tamp-sim-checkpoint 1";

Error parseError(const std::string& file, int line, const std::string& field,
                 const std::string& what) {
  return Error(ErrorCode::kParseError, what, SourceLocation{file, line, 0, field});
}

std::optional<Outcome> outcomeFromString(const std::string& s) {
  for (Outcome o :
       {Outcome::kSucceeded, Outcome::kBlocked, Outcome::kFailed, Outcome::kCancelled}) {
    if (toString(o) == s) return o;
  }
  return std::nullopt;
}

/// Reads `n` finite numbers; false when one is missing or not finite.
bool readNumbers(std::istream& in, double* out, int n) {
  for (int i = 0; i < n; ++i) {
    if (!(in >> out[i]) || !std::isfinite(out[i])) return false;
  }
  return true;
}

/// "-" for an empty string, else its bytes in hex (free text and ids may hold spaces).
std::string encode(const std::string& s) { return s.empty() ? "-" : toHex(s); }
std::optional<std::string> decode(const std::string& token) {
  if (token == "-") return std::string();
  return fromHex(token);
}

void formatAction(std::ostream& out, const ActionLogEntry& e) {
  out << "action " << e.step << " " << e.start_s << " " << toString(e.kind) << " "
      << encode(e.command_id);
  if (!e.result) {
    out << " running\n";
    return;
  }
  const ActionResult& r = *e.result;
  out << " " << toString(r.outcome) << " " << r.duration_s << " " << r.progress << " "
      << encode(r.blocking_object_id) << " " << encode(r.reason) << "\n";
}

/// One `action` record (after the keyword).
Result<ActionLogEntry> parseAction(std::istringstream& fields, const std::string& file, int n) {
  ActionLogEntry e;
  std::string kind, id, state;
  if (!(fields >> e.step) || e.step < 0)
    return parseError(file, n, "action.step", "expected a step index >= 0");
  if (!readNumbers(fields, &e.start_s, 1))
    return parseError(file, n, "action.start_s", "expected a finite number");
  fields >> kind;
  const auto k = actionKindFromString(kind);
  if (!k) return parseError(file, n, "action.kind", "unknown action kind '" + kind + "'");
  e.kind = *k;
  fields >> id;
  const auto cid = decode(id);
  if (!cid || cid->empty())
    return parseError(file, n, "action.command_id", "expected a command id in hex");
  e.command_id = *cid;
  fields >> state;
  if (state == "running") return e;
  const auto outcome = outcomeFromString(state);
  if (!outcome)
    return parseError(file, n, "action.outcome",
                      "expected running or an outcome, got '" + state + "'");
  ActionResult r;
  r.command_id = e.command_id;
  r.outcome = *outcome;
  double nums[2];
  if (!readNumbers(fields, nums, 2))
    return parseError(file, n, "action.duration_s", "expected duration and progress");
  r.duration_s = nums[0];
  r.progress = nums[1];
  std::string blocking, reason;
  fields >> blocking >> reason;
  const auto b = decode(blocking);
  const auto why = decode(reason);
  if (!b || !why)
    return parseError(file, n, "action.reason",
                      "expected the blocking object and the reason in hex");
  r.blocking_object_id = *b;
  r.reason = *why;
  e.result = r;
  return e;
}

Result<world::Object> parseObject(std::istringstream& fields, const std::string& file, int n) {
  std::string visibility, hex;
  fields >> visibility >> hex;
  if (visibility != "visible" && visibility != "hidden") {
    return parseError(file, n, "object.hidden",
                      "expected visible or hidden, got '" + visibility + "'");
  }
  const auto bytes = fromHex(hex);
  const auto m = bytes ? dds::fromCdr<msg::WorldObject>(*bytes) : std::nullopt;
  if (!m) return parseError(file, n, "object", "not an encoded world object");
  auto o = dds::fromMsg(*m);
  if (!o) return parseError(file, n, "object", o.error().message);
  o->hidden = visibility == "hidden";
  return std::move(o).value();
}

}  // namespace

std::string formatCheckpoint(const SimSnapshot& s) {
  std::ostringstream out;
  out.precision(17);
  out << kHeader << "\n";
  out << "time " << s.time_s << "\n";
  out << "epoch " << s.epoch_s << "\n";
  out << "robot " << s.robot.base.x << " " << s.robot.base.y << " " << s.robot.base.theta << " "
      << s.robot.gripper;
  for (double q : s.robot.arm) out << " " << q;
  out << "\n";
  if (s.held) {
    out << "held " << s.held->object_id << " " << s.held->link;
    const Eigen::Matrix4d m = s.held->link_T_object.matrix();
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 4; ++c) out << " " << m(r, c);
    out << "\n";
  }
  for (const auto& o : s.objects) {
    // The message folds "hidden" into the object's kind (static or movable): the record keeps both.
    world::Object told = o;
    told.hidden = false;
    out << "object " << (o.hidden ? "hidden" : "visible") << " "
        << toHex(dds::toCdr(dds::toMsg(told, 0))) << "\n";
  }
  for (const auto& id : s.fired_faults) out << "fired " << id << "\n";
  for (const auto& id : s.pending_faults) out << "pending " << id << "\n";
  for (const auto& e : s.log) formatAction(out, e);
  for (const auto& [commanded, truth] : s.names) out << "name " << commanded << " " << truth << "\n";
  return out.str();
}

Result<SimSnapshot> parseCheckpoint(const std::string& text, const std::string& file) {
  SimSnapshot s;
  std::istringstream lines(text);
  std::string line;
  if (!std::getline(lines, line) || line != kHeader) {
    return parseError(file, 1, "header",
                      "not a simulator checkpoint (expected '" + std::string(kHeader) + "')");
  }
  bool have_time = false, have_epoch = false, have_robot = false;
  int n = 1;
  for (n = 2; std::getline(lines, line); ++n) {
    if (line.empty()) continue;
    std::istringstream fields(line);
    std::string kind;
    fields >> kind;
    if (kind == "time") {
      if (!readNumbers(fields, &s.time_s, 1) || s.time_s < 0)
        return parseError(file, n, "time", "expected a finite time >= 0");
      have_time = true;
    } else if (kind == "epoch") {
      if (!readNumbers(fields, &s.epoch_s, 1) || s.epoch_s <= 0)
        return parseError(file, n, "epoch", "expected a wall-clock time > 0");
      have_epoch = true;
    } else if (kind == "robot") {
      double base[4];
      if (!readNumbers(fields, base, 4))
        return parseError(file, n, "robot", "expected base x, y, theta and the gripper");
      s.robot.base = Pose2D{base[0], base[1], base[2]};
      s.robot.gripper = base[3];
      std::string token;
      while (fields >> token) {
        char* end = nullptr;
        const double q = std::strtod(token.c_str(), &end);
        if (end == token.c_str() || *end != '\0' || !std::isfinite(q)) {
          return parseError(file, n, "robot.arm[" + std::to_string(s.robot.arm.size()) + "]",
                            "not a finite number: '" + token + "'");
        }
        s.robot.arm.push_back(q);
      }
      have_robot = true;
    } else if (kind == "held") {
      if (s.held) return parseError(file, n, "held", "a second held object");
      world::HeldObject h;
      fields >> h.object_id >> h.link;
      double m[12];
      if (h.object_id.empty() || h.link.empty() || !readNumbers(fields, m, 12)) {
        return parseError(file, n, "held", "expected an object id, a link and 12 finite numbers");
      }
      Eigen::Matrix4d t = Eigen::Matrix4d::Identity();
      for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 4; ++c) t(r, c) = m[r * 4 + c];
      h.link_T_object.matrix() = t;
      s.held = h;
    } else if (kind == "object") {
      auto o = parseObject(fields, file, n);
      if (!o) return o.error();
      s.objects.push_back(std::move(o).value());
    } else if (kind == "fired" || kind == "pending") {
      std::string id;
      if (!(fields >> id)) return parseError(file, n, kind, "expected a fault id");
      (kind == "fired" ? s.fired_faults : s.pending_faults).push_back(id);
    } else if (kind == "name") {
      std::string commanded, truth;
      if (!(fields >> commanded >> truth) || !world::isValidId(commanded) || !world::isValidId(truth))
        return parseError(file, n, "name", "expected a commanded object id and the truth's id");
      if (!s.names.emplace(commanded, truth).second) return parseError(file, n, "name", "'" + commanded + "' bound twice");
    } else if (kind == "action") {
      auto e = parseAction(fields, file, n);
      if (!e) return e.error();
      s.log.push_back(std::move(e).value());
    } else {
      return parseError(file, n, "record", "unknown record '" + kind + "'");
    }
  }
  if (!have_time) return parseError(file, n, "time", "missing");
  if (!have_epoch) return parseError(file, n, "epoch", "missing");
  if (!have_robot) return parseError(file, n, "robot", "missing");
  return s;
}

Result<SimSnapshot> readCheckpoint(const std::filesystem::path& file) {
  auto text = readTextFile(file);
  if (!text) return text.error();
  return parseCheckpoint(*text, file.string());
}

}  // namespace tamp::sim
