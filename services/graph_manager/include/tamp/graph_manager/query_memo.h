#pragma once
// Answers the services already gave in the world as it stands (issue 12, replanning latency).
//
// One Traverse, the next one and the preparation of a command ask many questions twice: two
// edges whose lazy paths cross the same object ask for the same stands beside it, a branch and its
// sibling ask for the same way round, `prepare` asks for the arm motion Traverse priced. An
// identical question in an unchanged world is answered from memory. Only successes are kept: a
// motion that failed within its budget may succeed when asked again (the planners sample).
// The graph manager clears the memo whenever it takes in a changed world (clearWorldCaches).
#include <cstddef>
#include <map>
#include <string>
#include <vector>

#include "tamp/graph_manager/clients.h"

namespace tamp::graph_manager {

class QueryMemo {
 public:
  /// The kept answer to `q`, or null.
  const MotionAnswer* motion(const MotionQuery& q) const;
  /// Keeps `a` for `q` when it is a success.
  void keep(const MotionQuery& q, const MotionAnswer& a);
  const std::vector<GraspOption>* grasps(const GraspQuery& q) const;
  /// Keeps a non-empty list of grasps for `q`.
  void keep(const GraspQuery& q, const std::vector<GraspOption>& g);
  void clear();
  std::size_t size() const { return motions_.size() + grasps_.size(); }

  /// Every field of the question that changes the answer, numbers rounded to 0.1 mm / 0.1 mrad.
  static std::string key(const MotionQuery& q);
  static std::string key(const GraspQuery& q);

 private:
  std::map<std::string, MotionAnswer> motions_;
  std::map<std::string, std::vector<GraspOption>> grasps_;
};

}  // namespace tamp::graph_manager
