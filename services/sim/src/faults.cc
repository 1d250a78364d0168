#include "tamp/sim/faults.h"

#include <array>
#include <cmath>
#include <utility>

namespace tamp::sim {
namespace {

constexpr std::array<std::pair<FaultType, std::string_view>, 4> kNames{{
    {FaultType::kDropHeldObject, "drop_held_object"},
    {FaultType::kSpawnObject, "spawn_object"},
    {FaultType::kFailAction, "fail_action"},
    {FaultType::kRemoveObject, "remove_object"},
}};

Error invalid(const std::string& field, const std::string& message) {
  return Error(ErrorCode::kInvalidArgument, field + ": " + message, SourceLocation{"", 0, 0, field});
}

}  // namespace

std::string_view toString(FaultType type) {
  for (const auto& [t, n] : kNames) {
    if (t == type) return n;
  }
  return "unknown";
}

std::optional<FaultType> faultTypeFromString(std::string_view name) {
  for (const auto& [t, n] : kNames) {
    if (n == name) return t;
  }
  return std::nullopt;
}

Status Fault::validate(bool scripted) const {
  if (toString(type) == "unknown") {
    return invalid("type", "unknown fault type " + std::to_string(static_cast<int>(type)));
  }
  if (scripted) {
    if (trigger.time_s.has_value() == trigger.step.has_value()) {
      return invalid("trigger", "a scripted fault needs exactly one of time_s and step");
    }
    if (trigger.time_s && !(std::isfinite(*trigger.time_s) && *trigger.time_s >= 0.0)) {
      return invalid("trigger.time_s", "must be finite and >= 0, got " + std::to_string(*trigger.time_s));
    }
    if (trigger.step && *trigger.step < 0) {
      return invalid("trigger.step", "must be >= 0, got " + std::to_string(*trigger.step));
    }
  }
  if (!(trigger.fraction >= 0.0 && trigger.fraction <= 1.0)) {
    return invalid("trigger.fraction", "must be in [0, 1], got " + std::to_string(trigger.fraction));
  }
  if (action && type != FaultType::kFailAction && type != FaultType::kDropHeldObject) {
    return invalid("action", "only for a failing action or a drop");
  }
  if (scripted && action && type == FaultType::kDropHeldObject && !trigger.step) {
    return invalid("action", "a drop waits for an action of a kind only with a step trigger");
  }
  if (type == FaultType::kSpawnObject) {
    if (auto why = object.invalidReason()) return invalid("object", *why);
  }
  if (type == FaultType::kRemoveObject && !world::isValidId(object_id)) {
    return invalid("object_id", "'" + object_id + "' is not a valid object id");
  }
  return Status::Ok();
}

}  // namespace tamp::sim
