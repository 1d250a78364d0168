#pragma once
/// @file
/// After a drop: when the world model may be trusted with where the dropped object lies.
///
/// Perception first places a released object below where it was held (a fall estimate); the
/// next frames may correct it, or find that place empty and call the object gone before seeing it
/// where it really fell (the base was moving: it lands ahead). Planned on the first estimate, a
/// re-pick reached for a box 19 cm off, or found no box at all ("no object 'box' in the world":
/// transport_drop, session 25). So the object must rest on a support and stay there, neither
/// vanishing nor moving, for `confirm_s` before the graph manager plans from it.

#include <optional>
#include <string>

#include <Eigen/Core>

#include "tamp/world/world.h"

namespace tamp::graph_manager {

class DropSettleWatch {
 public:
  /// `confirm_s` >= 0: how long the object must rest unchanged; `still_m` > 0: how far it may
  /// move meanwhile (estimate noise) without starting the wait over.
  DropSettleWatch(std::string object, double confirm_s, double still_m = 0.05);
  /// One look at the world model at time `t` (s, non-decreasing). True once `object` has rested
  /// on a support, in every look, for `confirm_s`; a look without it, or with it in the air or
  /// elsewhere, starts the wait over.
  bool settled(const world::World& w, double t);
  /// Where it rests (the last look), if it does.
  const std::optional<Eigen::Vector3d>& restingAt() const { return at_; }
  /// Times the object vanished or moved after it had been seen resting.
  int restarts() const { return restarts_; }

 private:
  std::string object_;
  double confirm_s_;
  double still_m_;
  std::optional<Eigen::Vector3d> at_;
  double since_{0.0};
  int restarts_{0};
};

}  // namespace tamp::graph_manager
