#include "tamp/dds/endpoint.h"

#include <cstring>
#include <set>
#include <sstream>
#include <thread>

#include <fastdds/dds/domain/DomainParticipant.hpp>
#include <fastdds/dds/publisher/DataWriter.hpp>
#include <fastdds/dds/publisher/DataWriterListener.hpp>
#include <fastdds/dds/publisher/Publisher.hpp>
#include <fastdds/dds/subscriber/DataReader.hpp>
#include <fastdds/dds/subscriber/DataReaderListener.hpp>
#include <fastdds/dds/subscriber/SampleInfo.hpp>
#include <fastdds/dds/subscriber/Subscriber.hpp>
#include <fastdds/dds/topic/ContentFilteredTopic.hpp>
#include <fastdds/dds/topic/Topic.hpp>
#include <fastdds/dds/topic/TopicDataType.hpp>

#include "tamp/core/log.h"

namespace fdds = eprosima::fastdds::dds;

namespace tamp::dds {
namespace {

std::string rcName(const ReturnCode_t& r) {
  switch (r()) {
    case ReturnCode_t::RETCODE_OK: return "OK";
    case ReturnCode_t::RETCODE_ERROR: return "ERROR";
    case ReturnCode_t::RETCODE_UNSUPPORTED: return "UNSUPPORTED";
    case ReturnCode_t::RETCODE_BAD_PARAMETER: return "BAD_PARAMETER";
    case ReturnCode_t::RETCODE_PRECONDITION_NOT_MET: return "PRECONDITION_NOT_MET";
    case ReturnCode_t::RETCODE_OUT_OF_RESOURCES: return "OUT_OF_RESOURCES";
    case ReturnCode_t::RETCODE_NOT_ENABLED: return "NOT_ENABLED";
    case ReturnCode_t::RETCODE_IMMUTABLE_POLICY: return "IMMUTABLE_POLICY";
    case ReturnCode_t::RETCODE_INCONSISTENT_POLICY: return "INCONSISTENT_POLICY";
    case ReturnCode_t::RETCODE_ALREADY_DELETED: return "ALREADY_DELETED";
    case ReturnCode_t::RETCODE_TIMEOUT: return "TIMEOUT";
    case ReturnCode_t::RETCODE_NO_DATA: return "NO_DATA";
    case ReturnCode_t::RETCODE_ILLEGAL_OPERATION: return "ILLEGAL_OPERATION";
    default: return "code " + std::to_string(r());
  }
}

Status fromReturnCode(const ReturnCode_t& r, const std::string& what) {
  if (r == ReturnCode_t::RETCODE_OK) return Status::Ok();
  return Error(r == ReturnCode_t::RETCODE_TIMEOUT ? ErrorCode::kTimeout : ErrorCode::kInternal,
               what + " failed: " + rcName(r));
}

std::string guidString(const eprosima::fastrtps::rtps::GUID_t& g) {
  std::ostringstream ss;
  ss << g;
  return ss.str();
}

}  // namespace

// ---- writer --------------------------------------------------------------------------------------

/// Keeps the GUID prefixes (participants) of the matched readers: Fast DDS 2.9's
/// DataWriter::get_matched_subscriptions() is not implemented (RETCODE_UNSUPPORTED).
class WriterBase::Listener : public fdds::DataWriterListener {
 public:
  void on_publication_matched(fdds::DataWriter*, const fdds::PublicationMatchedStatus& info) override {
    eprosima::fastrtps::rtps::GUID_t reader;
    eprosima::fastrtps::rtps::iHandle2GUID(reader, info.last_subscription_handle);
    std::ostringstream prefix;
    prefix << reader.guidPrefix;
    std::lock_guard lock(mutex_);
    if (info.current_count_change > 0) {
      participants_.insert(prefix.str());
    } else if (info.current_count_change < 0) {
      auto it = participants_.find(prefix.str());
      if (it != participants_.end()) participants_.erase(it);
    }
  }
  bool has(const std::string& prefix) const {
    std::lock_guard lock(mutex_);
    return participants_.count(prefix) != 0;
  }

 private:
  mutable std::mutex mutex_;
  std::multiset<std::string> participants_;  // one entry per matched reader
};

WriterBase::WriterBase(std::shared_ptr<Participant> p, const std::string& topic,
                       const std::function<fdds::TopicDataType*()>& make_type, QosClass qos,
                       const WriterOptions& options)
    : participant_(std::move(p)), topic_name_(topic) {
  fdds::Topic* t = participant_->topic(topic, make_type);
  type_ = participant_->native()->find_type(t->get_type_name()).get();
  const std::string profile = options.profile.empty() ? writerProfile(qos) : options.profile;
  listener_ = std::make_unique<Listener>();
  writer_ = participant_->publisher()->create_datawriter_with_profile(t, profile, listener_.get(),
                                                                      fdds::StatusMask::publication_matched());
  if (writer_ == nullptr) {
    throw std::runtime_error("cannot create a DDS writer on '" + topic + "' with profile '" + profile +
                             "' (is the profile defined in the XML profiles file?)");
  }
}

WriterBase::~WriterBase() {
  if (writer_ == nullptr) return;
  ReturnCode_t r = participant_->publisher()->delete_datawriter(writer_);
  if (r != ReturnCode_t::RETCODE_OK) log::get("dds")->warn("delete_datawriter({}) failed: {}", topic_name_, rcName(r));
}

Status WriterBase::writeRaw(const void* sample) {
  ReturnCode_t r = writer_->write(const_cast<void*>(sample), fdds::HANDLE_NIL);
  return fromReturnCode(r, "write on '" + topic_name_ + "'");
}

Status WriterBase::disposeRaw(const void* sample) {
  ReturnCode_t r = writer_->dispose(const_cast<void*>(sample), fdds::HANDLE_NIL);
  return fromReturnCode(r, "dispose on '" + topic_name_ + "'");
}

Status WriterBase::unregisterRaw(const void* sample) {
  ReturnCode_t r = writer_->unregister_instance(const_cast<void*>(sample), fdds::HANDLE_NIL);
  return fromReturnCode(r, "unregister_instance on '" + topic_name_ + "'");
}

uint32_t WriterBase::serializedSizeRaw(const void* sample) const {
  return type_->getSerializedSizeProvider(const_cast<void*>(sample))();
}

int WriterBase::matchedReaders() const {
  fdds::PublicationMatchedStatus st;
  if (writer_->get_publication_matched_status(st) != ReturnCode_t::RETCODE_OK) return 0;
  return st.current_count;
}

int WriterBase::readersEverMatched() const {
  fdds::PublicationMatchedStatus st;
  if (writer_->get_publication_matched_status(st) != ReturnCode_t::RETCODE_OK) return 0;
  return st.total_count;
}

bool WriterBase::waitForReaders(const Termination& until, int count) const {
  while (matchedReaders() < count) {
    if (until()) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  return true;
}

bool WriterBase::matchesParticipantOf(const std::string& writer_guid) const {
  // SampleMeta::writer_guid is "<prefix>|<entity id>"; the prefix names the participant.
  return listener_->has(writer_guid.substr(0, writer_guid.find('|')));
}

bool WriterBase::waitForParticipantOf(const std::string& writer_guid, const Termination& until) const {
  while (!matchesParticipantOf(writer_guid)) {
    if (until()) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
  return true;
}

// ---- reader --------------------------------------------------------------------------------------

class ReaderBase::Listener : public fdds::DataReaderListener {
 public:
  explicit Listener(ReaderBase* owner) : owner_(owner) {}
  // Runs on a Fast DDS thread that holds the reader's lock: raise the flag for the dispatch
  // thread, or (inline mode) run the short callback right here.
  void on_data_available(fdds::DataReader*) override {
    if (owner_->inline_) {
      ++owner_->in_flight_;
      if (owner_->active_) owner_->deliverNow();
      --owner_->in_flight_;
      return;
    }
    {
      std::lock_guard lock(owner_->signal_mutex_);
      owner_->pending_ = true;
    }
    owner_->signal_cv_.notify_one();
  }

 private:
  ReaderBase* owner_;
};

ReaderBase::ReaderBase(std::shared_ptr<Participant> p, const std::string& topic,
                       const std::function<fdds::TopicDataType*()>& make_type, QosClass qos,
                       const ReaderOptions& options)
    : participant_(std::move(p)), topic_name_(topic) {
  fdds::Topic* t = participant_->topic(topic, make_type);
  fdds::TopicDescription* desc = t;
  if (!options.filter.empty()) {
    static std::atomic<uint64_t> counter{0};
    const std::string name = topic + "/filtered/" + std::to_string(++counter);
    filtered_ = participant_->native()->create_contentfilteredtopic(name, t, options.filter,
                                                                    options.filter_parameters);
    if (filtered_ == nullptr) {
      throw std::runtime_error("cannot create content filter '" + options.filter + "' on '" + topic + "'");
    }
    desc = filtered_;
  }
  const std::string profile = options.profile.empty() ? readerProfile(qos) : options.profile;
  reader_ = participant_->subscriber()->create_datareader_with_profile(desc, profile);
  if (reader_ == nullptr) {
    throw std::runtime_error("cannot create a DDS reader on '" + topic + "' with profile '" + profile + "'");
  }
  listener_ = std::make_unique<Listener>(this);
  inline_ = options.inline_callbacks;
}

void ReaderBase::deliverNow() {
  try {
    onDataAvailable();
  } catch (const std::exception& e) {
    countCallbackError();
    log::get("dds")->error("reader callback on '{}' threw: {}", topic_name_, e.what());
  } catch (...) {
    countCallbackError();
    log::get("dds")->error("reader callback on '{}' threw an unknown exception", topic_name_);
  }
}

ReaderBase::~ReaderBase() {
  stopListening();
  if (reader_ != nullptr) {
    ReturnCode_t r = participant_->subscriber()->delete_datareader(reader_);
    if (r != ReturnCode_t::RETCODE_OK) log::get("dds")->warn("delete_datareader({}) failed: {}", topic_name_, rcName(r));
  }
  if (filtered_ != nullptr) {
    ReturnCode_t r = participant_->native()->delete_contentfilteredtopic(filtered_);
    if (r != ReturnCode_t::RETCODE_OK) log::get("dds")->warn("delete_contentfilteredtopic failed: {}", rcName(r));
  }
}

void ReaderBase::startListening() {
  if (inline_) {
    active_ = true;
    ReturnCode_t r = reader_->set_listener(listener_.get(), fdds::StatusMask::data_available());
    if (r != ReturnCode_t::RETCODE_OK) {
      active_ = false;
      throw std::runtime_error("cannot attach a listener on '" + topic_name_ + "': " + rcName(r));
    }
    deliverNow();  // what arrived before the listener; no lock of ours is held here
    return;
  }
  {
    std::lock_guard lock(signal_mutex_);
    pending_ = true;  // deliver what arrived before the listener (transient-local history)
    stop_ = false;
  }
  // The listener goes on before the dispatch thread starts: a sample arriving between the first
  // delivery and the attachment would otherwise sit unread until the next one (found by the
  // effort estimator's node tests). Signals before the thread runs are kept in pending_.
  ReturnCode_t r = reader_->set_listener(listener_.get(), fdds::StatusMask::data_available());
  if (r != ReturnCode_t::RETCODE_OK) {
    (void)reader_->set_listener(nullptr);
    throw std::runtime_error("cannot attach a listener on '" + topic_name_ + "': " + rcName(r));
  }
  dispatcher_ = std::thread([this] {
    while (true) {
      {
        std::unique_lock lock(signal_mutex_);
        signal_cv_.wait(lock, [this] { return pending_ || stop_; });
        if (stop_) return;
        pending_ = false;
      }
      deliverNow();
    }
  });
}

void ReaderBase::stopListening() {
  active_ = false;
  if (reader_ != nullptr) (void)reader_->set_listener(nullptr);
  // Inline mode: wait for a callback still running on a Fast DDS thread.
  while (in_flight_.load() > 0) std::this_thread::yield();
  {
    std::lock_guard lock(signal_mutex_);
    stop_ = true;
  }
  signal_cv_.notify_one();
  if (dispatcher_.joinable()) {
    // A callback that destroys its own reader cannot join itself.
    if (dispatcher_.get_id() == std::this_thread::get_id()) {
      dispatcher_.detach();
    } else {
      dispatcher_.join();
    }
  }
}

bool ReaderBase::takeNextRaw(void* sample, SampleMeta& meta) {
  fdds::SampleInfo info;
  ReturnCode_t r = reader_->take_next_sample(sample, &info);
  if (r != ReturnCode_t::RETCODE_OK) {
    if (r != ReturnCode_t::RETCODE_NO_DATA) log::get("dds")->warn("take on '{}': {}", topic_name_, rcName(r));
    return false;
  }
  meta.alive = info.valid_data && info.instance_state == fdds::ALIVE_INSTANCE_STATE;
  std::memcpy(meta.instance.data(), info.instance_handle.value, 16);
  meta.source_stamp_ns = static_cast<int64_t>(info.source_timestamp.to_ns());
  meta.writer_guid = guidString(info.sample_identity.writer_guid());
  return true;
}

int ReaderBase::matchedWriters() const {
  fdds::SubscriptionMatchedStatus st;
  if (reader_->get_subscription_matched_status(st) != ReturnCode_t::RETCODE_OK) return 0;
  return st.current_count;
}

bool ReaderBase::waitForWriters(const Termination& until, int count) const {
  while (matchedWriters() < count) {
    if (until()) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  return true;
}

}  // namespace tamp::dds
