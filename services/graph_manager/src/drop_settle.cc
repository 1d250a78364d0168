#include "tamp/graph_manager/drop_settle.h"

#include <cmath>
#include <stdexcept>
#include <utility>

namespace tamp::graph_manager {

namespace {

/// Where `object` rests on the support below it in `w`, or nullopt (absent, or in the air).
std::optional<Eigen::Vector3d> restingPlace(const world::World& w, const std::string& object) {
  const world::Object* o = w.findObject(object);
  if (o == nullptr) return std::nullopt;
  const Eigen::Vector3d bottom = o->pose.translation() - Eigen::Vector3d(0, 0, o->shape.halfHeight());
  const world::Region* below = w.regionBelow(bottom, 0.05);
  const double support = below ? below->height : 0.0;
  if (std::abs(bottom.z() - support) > 0.05) return std::nullopt;
  return o->pose.translation();
}

}  // namespace

DropSettleWatch::DropSettleWatch(std::string object, double confirm_s, double still_m)
    : object_(std::move(object)), confirm_s_(confirm_s), still_m_(still_m) {
  if (!(confirm_s >= 0) || !std::isfinite(confirm_s) || !(still_m > 0))
    throw std::invalid_argument("DropSettleWatch: confirm_s must be >= 0 and still_m > 0");
}

bool DropSettleWatch::settled(const world::World& w, double t) {
  const std::optional<Eigen::Vector3d> now = restingPlace(w, object_);
  if (!now) {
    if (at_) ++restarts_;
    at_.reset();
    return false;
  }
  if (!at_ || (*now - *at_).norm() > still_m_) {
    if (at_) ++restarts_;
    since_ = t;
  }
  at_ = now;
  return t - since_ >= confirm_s_;
}

}  // namespace tamp::graph_manager
