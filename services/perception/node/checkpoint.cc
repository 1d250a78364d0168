#include "checkpoint.h"

#include <cmath>
#include <set>
#include <sstream>

#include "tamp/core/hex.h"
#include "tamp/dds/cdr.h"
#include "tamp/dds/world_sync.h"

namespace tamp::perception {
namespace {

constexpr const char* kHeader = "tamp-perception-checkpoint 1";

Error parseError(const std::string& file, int line, const std::string& field, const std::string& what) {
  return Error(ErrorCode::kParseError, what, SourceLocation{file, line, 0, field});
}

}  // namespace

std::string formatCheckpoint(const world::World& w, const std::optional<Perception::HeldGrasp>& held,
                             std::uint64_t world_version) {
  std::ostringstream out;
  out.precision(17);
  out << kHeader << "\n";
  if (world_version > 0) out << "world_version " << world_version << "\n";
  if (held) {
    out << "held " << held->object_id;
    const Eigen::Matrix4d m = held->tool_T_object.matrix();
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 4; ++c) out << " " << m(r, c);
    out << "\n";
  }
  for (const auto& o : w.objects()) {
    if (o.kind != world::ObjectKind::kMovable) continue;
    out << "object " << toHex(dds::toCdr(dds::toMsg(o, 0))) << "\n";
  }
  return out.str();
}

Result<PerceptionCheckpoint> parseCheckpoint(const std::string& text, const std::string& file) {
  PerceptionCheckpoint c;
  std::istringstream lines(text);
  std::string line;
  if (!std::getline(lines, line) || line != kHeader)
    return parseError(file, 1, "header", "not a perception checkpoint (expected '" + std::string(kHeader) + "')");
  for (int n = 2; std::getline(lines, line); ++n) {
    if (line.empty()) continue;
    std::istringstream fields(line);
    std::string kind;
    fields >> kind;
    if (kind == "world_version") {
      if (c.world_version > 0) return parseError(file, n, "world_version", "a second world version");
      std::string v, rest;
      fields >> v >> rest;
      const bool digits = !v.empty() && v.size() < 20 && v.find_first_not_of("0123456789") == std::string::npos;
      if (!digits || !rest.empty() || std::stoull(v) == 0)
        return parseError(file, n, "world_version", "expected one positive integer, got '" + v + "'");
      c.world_version = std::stoull(v);
    } else if (kind == "held") {
      if (c.held) return parseError(file, n, "held", "a second grasp");
      Perception::HeldGrasp g;
      fields >> g.object_id;
      Eigen::Matrix4d m = Eigen::Matrix4d::Identity();
      for (int r = 0; r < 3; ++r)
        for (int k = 0; k < 4; ++k) fields >> m(r, k);
      if (!fields || g.object_id.empty() || !m.allFinite())
        return parseError(file, n, "held", "expected an object id and 12 finite numbers");
      g.tool_T_object.matrix() = m;
      c.held = g;
    } else if (kind == "object") {
      std::string hex;
      fields >> hex;
      const auto bytes = fromHex(hex);
      const auto m = bytes ? dds::fromCdr<msg::WorldObject>(*bytes) : std::nullopt;
      if (!m) return parseError(file, n, "object", "not an encoded world object");
      auto o = dds::fromMsg(*m);
      if (!o) return parseError(file, n, "object", o.error().message);
      c.movables.push_back(std::move(*o));
    } else {
      return parseError(file, n, "record", "unknown record '" + kind + "'");
    }
  }
  return c;
}

Result<world::World> restoredPrior(const world::World& prior, const PerceptionCheckpoint& c) {
  world::World w = prior;
  std::set<std::string> kept;
  for (const auto& o : c.movables) kept.insert(o.id);
  for (const auto& o : prior.objects()) {
    if (o.kind == world::ObjectKind::kMovable && !kept.count(o.id)) (void)w.removeObject(o.id);
  }
  for (const auto& o : c.movables) {
    const world::Object* known = w.findObject(o.id);
    if (known != nullptr && known->kind != world::ObjectKind::kMovable)
      return Error(ErrorCode::kInvalidArgument, "checkpoint object '" + o.id + "' is static in the prior");
    Status s = known != nullptr ? w.updateObject(o) : w.addObject(o);
    if (!s) return Error(ErrorCode::kInvalidArgument, "checkpoint object '" + o.id + "': " + s.error().message);
  }
  return w;
}

}  // namespace tamp::perception
