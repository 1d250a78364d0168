#pragma once
/// @file
/// Typed, RAII-owned DDS writers and readers over a small type-erased core.
///
///   auto p = tamp::dds::Participant::create({.domain_id = 7}).value();
///   tamp::dds::Writer<tamp::msg::Heartbeat> w(p, tamp::dds::topics::kHeartbeat);
///   tamp::dds::Reader<tamp::msg::Heartbeat> r(p, tamp::dds::topics::kHeartbeat,
///       [](const tamp::msg::Heartbeat& hb, const tamp::dds::SampleMeta& m) { ... });
///
/// Callbacks run on the reader's own dispatch thread, never on a Fast DDS thread: the DDS listener
/// only raises a flag, so a slow callback (a perception frame, a planning request) cannot stall
/// the participant's receive path, and no lock of ours is ever held while Fast DDS holds its own.
/// Nothing may escape a callback (an exception is caught, logged and counted). Destruction stops
/// the dispatch thread after the running callback. Every Fast DDS `ReturnCode_t` is checked.

#include <array>
#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "tamp/core/error.h"
#include "tamp/core/termination.h"
#include "tamp/dds/participant.h"
#include "tamp/dds/qos.h"

namespace eprosima::fastdds::dds {
class DataWriter;
class DataReader;
class ContentFilteredTopic;
}  // namespace eprosima::fastdds::dds

namespace tamp::dds {

/// Maps an IDL type to its generated PubSubType. Specialised for every topic type in topics.h.
template <typename T>
struct TypeSupport;

/// A topic: its name, type and QoS class. The registry of all topics is tamp/dds/topics.h.
template <typename T>
struct TopicSpec {
  const char* name;
  QosClass qos;
};

/// What a reader knows about a sample besides its data.
struct SampleMeta {
  bool alive{true};
  std::array<uint8_t, 16> instance{};  ///< instance handle (keyed topics)             ///< false: the instance was disposed or its writer unregistered/died
  int64_t source_stamp_ns{0};   ///< writer's timestamp
  std::string writer_guid;      ///< writer GUID (hex), identifies the sending process
};

struct WriterOptions {
  std::string profile;  ///< overrides the QoS class's writer profile
};

struct ReaderOptions {
  std::string profile;  ///< overrides the QoS class's reader profile
  /// Content filter (DDS-SQL, e.g. "header.client_id = %0") evaluated on the writer side where
  /// possible; empty: no filter.
  std::string filter;
  std::vector<std::string> filter_parameters;
  /// Run the callback directly on Fast DDS's receive thread instead of the reader's dispatch
  /// thread (saves a thread hop, ~50 us on a loaded 2-core VM). Only for callbacks that are short,
  /// thread-safe (they may run on two threads at once) and never wait on anything that calls into
  /// Fast DDS; the RPC layer uses it to route replies and queue requests.
  bool inline_callbacks{false};
};

class WriterBase {
 public:
  WriterBase(const WriterBase&) = delete;
  WriterBase& operator=(const WriterBase&) = delete;
  virtual ~WriterBase();

  const std::string& topicName() const { return topic_name_; }
  /// Number of readers currently matched.
  int matchedReaders() const;
  /// Readers matched since the writer was created, past ones included: a reader that restarted
  /// (a new participant) counts again, so a rise says a reader may have missed what was written.
  int readersEverMatched() const;
  /// Waits until at least `count` readers are matched or the termination fires.
  bool waitForReaders(const Termination& until, int count = 1) const;
  /// True when this writer is matched with a reader of the participant (process) that wrote
  /// `writer_guid` (a SampleMeta::writer_guid): what this writer writes now reaches that
  /// participant. A reader's own matching is no proof of it: under DDS Security each side of a
  /// pair matches when the other's crypto tokens arrive, so a client can hear a server's reply
  /// writer while that writer does not know the client's reader yet, and VOLATILE samples written
  /// before it does are never delivered to it.
  bool matchesParticipantOf(const std::string& writer_guid) const;
  /// Waits until matchesParticipantOf(writer_guid) or the termination fires.
  bool waitForParticipantOf(const std::string& writer_guid, const Termination& until) const;

 protected:
  WriterBase(std::shared_ptr<Participant> p, const std::string& topic,
             const std::function<eprosima::fastdds::dds::TopicDataType*()>& make_type, QosClass qos,
             const WriterOptions& options);
  Status writeRaw(const void* sample);
  Status disposeRaw(const void* sample);
  Status unregisterRaw(const void* sample);
  /// Serialized size of `sample` in bytes (CDR), for payload limits.
  uint32_t serializedSizeRaw(const void* sample) const;

 private:
  class Listener;
  std::shared_ptr<Participant> participant_;
  std::string topic_name_;
  std::unique_ptr<Listener> listener_;  // outlives writer_ (deleted in the destructor's body)
  eprosima::fastdds::dds::DataWriter* writer_{nullptr};
  eprosima::fastdds::dds::TopicDataType* type_{nullptr};
};

template <typename T>
class Writer : public WriterBase {
 public:
  Writer(std::shared_ptr<Participant> p, const TopicSpec<T>& spec, const WriterOptions& options = {})
      : WriterBase(std::move(p), spec.name, [] { return new typename TypeSupport<T>::type(); }, spec.qos,
                   options) {}
  /// Publishes a sample. Errors: kInternal with the Fast DDS return code, kInvalidArgument when the
  /// sample cannot be serialized.
  Status write(const T& sample) { return writeRaw(&sample); }
  /// Keyed topics: disposes the instance with this sample's key (readers see alive=false).
  Status dispose(const T& key_sample) { return disposeRaw(&key_sample); }
  /// Keyed topics: unregisters the instance (clean shutdown of its only writer).
  Status unregister(const T& key_sample) { return unregisterRaw(&key_sample); }
  uint32_t serializedSize(const T& sample) const { return serializedSizeRaw(&sample); }
};

class ReaderBase {
 public:
  ReaderBase(const ReaderBase&) = delete;
  ReaderBase& operator=(const ReaderBase&) = delete;
  virtual ~ReaderBase();

  const std::string& topicName() const { return topic_name_; }
  int matchedWriters() const;
  bool waitForWriters(const Termination& until, int count = 1) const;
  /// Samples that reached a callback which threw (the exception was logged, the reader continued).
  uint64_t callbackErrors() const { return callback_errors_.load(); }

 protected:
  class Listener;
  ReaderBase(std::shared_ptr<Participant> p, const std::string& topic,
             const std::function<eprosima::fastdds::dds::TopicDataType*()>& make_type, QosClass qos,
             const ReaderOptions& options);
  /// Starts the dispatch thread and attaches the listener; derived constructors call it last, so
  /// no callback sees a half-built object. Samples that arrived earlier are delivered first.
  void startListening();
  /// Detaches the listener and joins the dispatch thread (after a running callback); derived
  /// destructors call it first.
  void stopListening();
  /// Takes the next sample into `sample`. Returns false when none is left. For a not-alive
  /// instance, only the key fields of `sample` are filled.
  bool takeNextRaw(void* sample, SampleMeta& meta);
  /// Called on the listener thread when data is available (derived: loop over takeNextRaw).
  virtual void onDataAvailable() = 0;
  void countCallbackError() { ++callback_errors_; }
  /// Runs onDataAvailable(), containing and counting exceptions.
  void deliverNow();

 private:
  std::shared_ptr<Participant> participant_;
  std::string topic_name_;
  eprosima::fastdds::dds::DataReader* reader_{nullptr};
  eprosima::fastdds::dds::ContentFilteredTopic* filtered_{nullptr};
  std::unique_ptr<Listener> listener_;
  std::mutex signal_mutex_;  // guards pending_/stop_ only; never held while calling Fast DDS
  std::condition_variable signal_cv_;
  bool pending_{false};
  bool stop_{false};
  std::thread dispatcher_;
  bool inline_{false};
  std::atomic<bool> active_{false};   // inline mode: callbacks allowed
  std::atomic<int> in_flight_{0};     // inline mode: callbacks running now
  std::atomic<uint64_t> callback_errors_{0};
};

template <typename T>
class Reader : public ReaderBase {
 public:
  using Callback = std::function<void(const T&, const SampleMeta&)>;

  /// With a callback, samples are delivered on the listener thread; without one, poll takeNext().
  Reader(std::shared_ptr<Participant> p, const TopicSpec<T>& spec, Callback cb = {},
         const ReaderOptions& options = {})
      : ReaderBase(std::move(p), spec.name, [] { return new typename TypeSupport<T>::type(); }, spec.qos,
                   options),
        cb_(std::move(cb)),
        keyed_(typename TypeSupport<T>::type().m_isGetKeyDefined) {
    if (cb_) startListening();
  }
  ~Reader() override { stopListening(); }

  /// The next unread sample (polling mode), alive samples only.
  std::optional<T> takeNext() {
    T sample;
    SampleMeta meta;
    while (takeNextRaw(&sample, meta)) {
      if (meta.alive) return sample;
    }
    return std::nullopt;
  }

 protected:
  void onDataAvailable() override {
    T sample;
    SampleMeta meta;
    while (takeNextRaw(&sample, meta)) {
      // A not-alive sample carries no data; report it with the instance's last known sample.
      if (keyed_) {
        std::lock_guard lock(last_mutex_);
        if (meta.alive) {
          last_[meta.instance] = sample;
        } else {
          auto it = last_.find(meta.instance);
          if (it == last_.end()) continue;
          sample = std::move(it->second);
          last_.erase(it);
        }
      } else if (!meta.alive) {
        continue;
      }
      try {
        cb_(sample, meta);
      } catch (...) {
        countCallbackError();
      }
      sample = T();
    }
  }

 private:
  Callback cb_;
  bool keyed_;
  std::mutex last_mutex_;
  std::map<std::array<uint8_t, 16>, T> last_;
};

}  // namespace tamp::dds
