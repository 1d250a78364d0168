#pragma once
/// @file
/// The world model over DDS. Objects travel as keyed `msg::WorldObject` instances (one per object
/// id, RELIABLE + TRANSIENT_LOCAL: a late or restarted service gets the current objects at once);
/// regions, named locations and the world version travel in one `msg::WorldMeta` instance.
///
/// - `WorldPublisher` (perception, or a scenario loader) publishes a `world::World`: only what
///   changed since its last publish is written, and removed objects are disposed.
/// - `WorldMirror` (motion planner, graph manager, execution monitor) assembles the latest
///   `world::World` from those topics; `snapshot()` is a cheap copy.
///
/// Hidden objects are never published (perception cannot know them; a publisher refuses them).

#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <string>

#include "tamp/dds/convert.h"
#include "tamp/dds/topics.h"
#include "tamp/world/world.h"

namespace tamp::dds {

msg::ShapeSpec toMsg(const world::Shape& s);
Result<world::Shape> fromMsg(const msg::ShapeSpec& m, const std::string& field = "shape");
msg::WorldObject toMsg(const world::Object& o, uint64_t version);
/// Errors name the offending field (an invalid shape, a non-finite pose, a bad id, ...).
Result<world::Object> fromMsg(const msg::WorldObject& m);
msg::Region toMsg(const world::Region& r);
Result<world::Region> fromMsg(const msg::Region& m);
msg::WorldMeta metaToMsg(const world::World& w, const std::string& world_id);

class WorldPublisher {
 public:
  explicit WorldPublisher(std::shared_ptr<Participant> p, std::string world_id = "world");
  /// Publishes `w` (its planner view). kInvalidArgument if `w` contains hidden objects.
  Status publish(const world::World& w);
  uint64_t publishedVersion() const { return published_version_; }
  /// A restarted publisher continues above the versions published before it (its checkpoint's):
  /// from now on `w` is published at w.version() + floor. Mirrors that hold the older versions
  /// take the new ones in, clients naming an older version are served, and no version names two
  /// worlds.
  void continueAbove(uint64_t floor) { floor_ = floor; }
  /// The version publish(w) gives `w`.
  uint64_t versionOf(const world::World& w) const { return w.version() + floor_; }

 private:
  std::string world_id_;
  Writer<msg::WorldObject> objects_;
  Writer<msg::WorldMeta> meta_;
  std::optional<world::World> last_;
  std::map<std::string, uint64_t> written_;  ///< object id -> version it was last written at
  uint64_t published_version_{0};
  uint64_t floor_{0};
};

class WorldMirror {
 public:
  explicit WorldMirror(std::shared_ptr<Participant> p, std::string world_id = "world");
  /// The world as assembled so far (objects that failed validation are skipped and logged).
  world::World snapshot() const;
  /// Increments on every received change.
  uint64_t changes() const;
  /// The latest publisher's world version held completely: its WorldMeta and every object of
  /// its manifest at (at least) the listed versions have arrived, removed objects are gone
  /// (0: none yet). Objects of a newer version may already be in the snapshot.
  uint64_t publishedVersion() const;
  /// Waits until publishedVersion() >= `version`.
  bool waitForPublishedVersion(uint64_t version, const Termination& until) const;
  /// Called (on a DDS thread) after each change; keep it short. No world is passed: a copy per
  /// object sample would be O(n) each; take snapshot() when the world is needed.
  void onChange(std::function<void()> cb);

 private:
  void onObject(const msg::WorldObject& m, const SampleMeta& meta);
  void onMeta(const msg::WorldMeta& m, const SampleMeta& meta);
  void notify();
  void updateCompleteLocked();

  std::string world_id_;
  mutable std::mutex mutex_;
  world::World world_;
  uint64_t changes_{0};
  uint64_t published_version_{0};
  std::map<std::string, uint64_t> received_;  ///< object id -> version of the sample received
  uint64_t manifest_version_{0};              ///< version of the latest WorldMeta
  std::map<std::string, uint64_t> manifest_;  ///< its objects and their versions
  std::function<void()> cb_;
  Reader<msg::WorldObject> objects_;
  Reader<msg::WorldMeta> meta_;
};

}  // namespace tamp::dds
