#include "tamp/dds/participant.h"

#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cctype>
#include <chrono>
#include <cstdlib>
#include <set>
#include <sstream>

#include <fastdds/dds/domain/DomainParticipant.hpp>
#include <fastdds/dds/domain/DomainParticipantFactory.hpp>
#include <fastdds/dds/domain/DomainParticipantListener.hpp>
#include <fastdds/dds/publisher/Publisher.hpp>
#include <fastdds/dds/subscriber/Subscriber.hpp>
#include <fastdds/dds/topic/Topic.hpp>
#include <fastdds/dds/topic/TypeSupport.hpp>

#include <fastdds/rtps/attributes/ServerAttributes.h>
#include <fastrtps/config.h>
#include <fastrtps/utils/IPLocator.h>

#include "tamp/core/log.h"
#include "tamp/core/paths.h"
#include "tamp/dds/discovery.h"

namespace fdds = eprosima::fastdds::dds;

namespace tamp::dds {
namespace {

std::string rc(const ReturnCode_t& r) { return std::to_string(r()); }

/// Loads each profiles file once per process (Fast DDS keeps profiles globally).
Status loadProfiles(const std::filesystem::path& file) {
  static std::mutex m;
  static std::set<std::string> loaded;
  std::lock_guard lock(m);
  const std::string key = std::filesystem::absolute(file).lexically_normal().string();
  if (loaded.count(key) != 0) return Status::Ok();
  std::error_code ec;
  if (!std::filesystem::exists(file, ec)) {
    return Error(ErrorCode::kNotFound, "DDS profiles file does not exist", SourceLocation{file.string()});
  }
  ReturnCode_t r = fdds::DomainParticipantFactory::get_instance()->load_XML_profiles_file(file.string());
  if (r != ReturnCode_t::RETCODE_OK) {
    return Error(ErrorCode::kParseError, "Fast DDS could not load the XML profiles (see its log above)",
                 SourceLocation{file.string()});
  }
  loaded.insert(key);
  return Status::Ok();
}

/// Resolves the security files of the options; nullopt: no security.
Result<std::optional<ParticipantOptions::SecurityFiles>> resolveSecurity(const ParticipantOptions& o,
                                                                          std::string& identity) {
  using Files = ParticipantOptions::SecurityFiles;
  std::optional<Files> files = o.security;
  if (!files) {
    std::string dir = o.security_dir;
    if (dir.empty()) {
      if (const char* env = std::getenv("TAMP_DDS_SECURITY"); env != nullptr) dir = env;
    }
    if (dir.empty() || dir == "none") return std::optional<Files>{};
    identity = o.security_identity;
    if (identity.empty()) {
      const char* env = std::getenv("TAMP_DDS_SECURITY_IDENTITY");
      identity = (env != nullptr && *env != '\0') ? env : "tamp";
    }
    if (identity.find('/') != std::string::npos || identity == "." || identity == "..") {
      return Error(ErrorCode::kInvalidArgument, "DDS security identity '" + identity + "' is not a plain name");
    }
    files = securityFiles(dir, identity);
  } else if (identity.empty()) {
    identity = "explicit";
  }
  for (const auto* f : {&files->identity_ca, &files->certificate, &files->private_key, &files->permissions_ca,
                        &files->governance, &files->permissions}) {
    std::error_code ec;
    if (!std::filesystem::is_regular_file(*f, ec)) {
      return Error(ErrorCode::kNotFound,
                   "DDS Security file missing for identity '" + identity +
                       "' (make it with deploy/security/make_certs.sh DIR)",
                   SourceLocation{f->string()});
    }
  }
  return files;
}

/// Fast DDS has a secure discovery server from 2.10 on. Before, a secured client of a (plain)
/// server never authenticates it, and Debian's 2.9.1 aborts on an assertion in
/// SecurityManager::encode_rtps_message (a secured two-host run, session 24): refused here, by name.
Status secureDiscoverySupported(bool secured, const std::vector<DiscoveryServerAddress>& servers) {
  constexpr bool kHasSecureServer =
      FASTRTPS_VERSION_MAJOR > 2 || (FASTRTPS_VERSION_MAJOR == 2 && FASTRTPS_VERSION_MINOR >= 10);
  if (!secured || servers.empty() || kHasSecureServer) return Status::Ok();
  return Error(ErrorCode::kUnsupported,
               "DDS Security with a discovery server ($TAMP_DDS_DISCOVERY_SERVERS or the deployment's discovery: "
               "{mode: server}) needs Fast DDS 2.10 or later (its secure discovery server); this build has " +
                   std::to_string(FASTRTPS_VERSION_MAJOR) + "." + std::to_string(FASTRTPS_VERSION_MINOR) + "." +
                   std::to_string(FASTRTPS_VERSION_MICRO) +
                   ": use multicast discovery (discovery: {mode: multicast}) with security, or no security");
}

/// Makes the participant a CLIENT of each server (server i has the default GUID prefix of id i).
void useDiscoveryServers(fdds::DomainParticipantQos& qos, const std::vector<DiscoveryServerAddress>& servers) {
  namespace rtps = eprosima::fastrtps::rtps;
  auto& dc = qos.wire_protocol().builtin.discovery_config;
  dc.discoveryProtocol = rtps::DiscoveryProtocol_t::CLIENT;
  dc.m_DiscoveryServers.clear();
  for (std::size_t i = 0; i < servers.size(); ++i) {
    rtps::RemoteServerAttributes server;
    rtps::get_server_client_default_guidPrefix(static_cast<int>(i), server.guidPrefix);
    rtps::Locator_t locator;
    rtps::IPLocator::setIPv4(locator, servers[i].ip);
    locator.port = servers[i].port;
    server.metatrafficUnicastLocatorList.push_back(locator);
    dc.m_DiscoveryServers.push_back(server);
  }
}

std::string fileUri(const std::filesystem::path& p) { return "file://" + std::filesystem::absolute(p).string(); }

/// Participant ids this process tries, in turn: from one drawn from its pid, so that a service
/// restarted after a crash does not take over the transport ports of the process it replaces.
/// Peers keep that process until its lease ends (tamp_profiles.xml: 5 s), and their shared-memory
/// transport keeps writing into the segment of its old port, which the restarted process has
/// replaced: requests to the restarted service were lost until the lease ended, or for good
/// (kill -9 matrix, effort estimator, seed 1; EffortRestartTest). Ids 0..99 keep every port of a
/// domain inside its 250-port block; Fast DDS moves on to a free port when one is taken.
constexpr int kSpreadIds = 100;

int32_t nextParticipantId() {
  static const int base = static_cast<int>(::getpid() % kSpreadIds);
  static std::atomic<int> created{0};
  return static_cast<int32_t>((base + created.fetch_add(1)) % kSpreadIds);
}


/// Logs when each remote participant is discovered and authenticated (DDS Security), as seconds
/// since this participant was created: the handshake time of each pair, which Debian's Fast DDS
/// 2.9.1 does not log (its security logging is compiled out). A handshake of a second or more is
/// logged at info level, others at debug. Participant callbacks only: the listener's status mask
/// is none, so no entity's data or matching callback is routed here.
class PeerLog : public fdds::DomainParticipantListener {
 public:
  PeerLog(std::string self, bool secured) : secured_(secured), self_(std::move(self)) {}

  void on_participant_discovery(fdds::DomainParticipant*, eprosima::fastrtps::rtps::ParticipantDiscoveryInfo&& info) override {
    using Info = eprosima::fastrtps::rtps::ParticipantDiscoveryInfo;
    const double t = since();
    const std::string guid = prefix(info.info.m_guid);
    std::lock_guard lock(mutex_);
    Peer& peer = peers_[guid];
    peer.name = info.info.m_participantName.to_string();
    if (info.status == Info::DISCOVERED_PARTICIPANT) {
      peer.discovered = t;
      report(guid, peer);
    } else if (info.status == Info::REMOVED_PARTICIPANT || info.status == Info::DROPPED_PARTICIPANT) {
      log::get("dds")->debug("{}: peer '{}' ({}) {} at +{:.2f} s", self_, peer.name, guid,
                             info.status == Info::REMOVED_PARTICIPANT ? "removed" : "dropped", t);
      peers_.erase(guid);
    }
  }

#if HAVE_SECURITY
  void onParticipantAuthentication(fdds::DomainParticipant*,
                                   eprosima::fastrtps::rtps::ParticipantAuthenticationInfo&& info) override {
    using Info = eprosima::fastrtps::rtps::ParticipantAuthenticationInfo;
    const double t = since();
    const std::string guid = prefix(info.guid);
    std::lock_guard lock(mutex_);
    if (info.status != Info::AUTHORIZED_PARTICIPANT) {
      log::get("dds")->warn("{}: peer {} not authenticated (refused, or its handshake failed) at +{:.2f} s", self_,
                            guid, t);
      return;
    }
    Peer& peer = peers_[guid];
    peer.authenticated = t;
    report(guid, peer);
  }
#endif

 private:
  struct Peer {
    std::string name;
    double discovered{-1.0};
    double authenticated{-1.0};
    bool reported{false};
  };

  static std::string prefix(const eprosima::fastrtps::rtps::GUID_t& g) {
    std::ostringstream ss;
    ss << g.guidPrefix;
    return ss.str();
  }
  double since() const { return std::chrono::duration<double>(std::chrono::steady_clock::now() - created_).count(); }

  /// Once per peer, when what there is to know is known (secured: both events; plain: discovery).
  void report(const std::string& guid, Peer& peer) {  // caller holds mutex_
    if (peer.reported || peer.discovered < 0.0 || (secured_ && peer.authenticated < 0.0)) return;
    peer.reported = true;
    const double last = std::max(peer.discovered, peer.authenticated);
    const auto level = last >= 1.0 && secured_ ? spdlog::level::info : spdlog::level::debug;
    if (secured_) {
      log::get("dds")->log(level, "{}: peer '{}' ({}) authenticated at +{:.2f} s, discovered at +{:.2f} s", self_,
                           peer.name, guid, peer.authenticated, peer.discovered);
    } else {
      log::get("dds")->log(level, "{}: peer '{}' ({}) discovered at +{:.2f} s", self_, peer.name, guid, peer.discovered);
    }
  }

  bool secured_;
  std::string self_;
  std::chrono::steady_clock::time_point created_{std::chrono::steady_clock::now()};
  std::mutex mutex_;
  std::map<std::string, Peer> peers_;
};

}  // namespace

ParticipantOptions::SecurityFiles securityFiles(const std::filesystem::path& dir, const std::string& identity) {
  ParticipantOptions::SecurityFiles f;
  f.identity_ca = dir / "ca.pem";
  f.permissions_ca = dir / "ca.pem";
  f.governance = dir / "governance.p7s";
  f.certificate = dir / identity / "cert.pem";
  f.private_key = dir / identity / "key.pem";
  f.permissions = dir / identity / "permissions.p7s";
  return f;
}

Result<int> resolveDomainId(int flag_value) {
  int id = flag_value;
  if (id < 0) {
    const char* env = std::getenv("TAMP_DOMAIN_ID");
    if (env != nullptr && *env != '\0') {
      char* end = nullptr;
      long v = std::strtol(env, &end, 10);
      if (*end != '\0' || v < 0 || v > 232) {
        return Error(ErrorCode::kInvalidArgument,
                     std::string("TAMP_DOMAIN_ID must be an integer in [0, 232], got '") + env + "'");
      }
      id = static_cast<int>(v);
    } else {
      id = 0;
    }
  }
  if (id > 232) {
    return Error(ErrorCode::kInvalidArgument, "DDS domain id must be in [0, 232], got " + std::to_string(id));
  }
  return id;
}

Result<std::string> resolveRunId(const std::string& flag_value) {
  std::string id = flag_value;
  std::string origin = "--run-id";
  if (id.empty()) {
    const char* env = std::getenv("TAMP_RUN_ID");
    if (env == nullptr || *env == '\0') return std::string();
    id = env;
    origin = "TAMP_RUN_ID";
  }
  const bool valid_chars = std::all_of(id.begin(), id.end(), [](char c) {
    return std::isalnum(static_cast<unsigned char>(c)) != 0 || c == '_' || c == '-' || c == '.';
  });
  if (id.size() > 64 || !valid_chars) {
    return Error(ErrorCode::kInvalidArgument,
                 origin + " must be 1-64 characters of [A-Za-z0-9_.-], got '" + id + "'");
  }
  return id;
}

std::string runPartition(const std::string& run_id) { return run_id.empty() ? std::string() : "tamp.run." + run_id; }

Result<std::shared_ptr<Participant>> Participant::create(const ParticipantOptions& options) {
  return create(options, std::string());
}

Result<std::shared_ptr<Participant>> Participant::create(const ParticipantOptions& options,
                                                         const std::string& run_id_flag) {
  auto domain = resolveDomainId(options.domain_id);
  if (!domain) return domain.error();
  auto run_id = resolveRunId(run_id_flag);
  if (!run_id) return run_id.error();

  std::filesystem::path file = options.profiles_file;
  if (file.empty()) {
    const char* env = std::getenv("TAMP_DDS_PROFILES");
    file = (env != nullptr && *env != '\0') ? std::filesystem::path(env) : configDir() / "dds" / "tamp_profiles.xml";
  }
  if (Status s = loadProfiles(file); !s.ok()) return s.error();

  std::string profile = options.profile.empty() ? kProfileDefault : options.profile;
  if (profile == kProfileDefault) {
    if (const char* env = std::getenv("TAMP_DDS_PROFILE"); env != nullptr && *env != '\0') profile = env;
  }
  std::string identity;
  auto security = resolveSecurity(options, identity);
  if (!security) return security.error();
  // Secured, the default profile (shared memory + UDPv4) becomes UDPv4 only: with RTPS
  // protection over Fast DDS 2.9.1's shared-memory transport, samples were lost (the secured
  // corridor mission failed in 2 runs of 2 for want of the robot state and the world model; UDPv4
  // only: succeeded). An explicit tamp_shm stays what it says.
  if (*security && profile == kProfileDefault) profile = kProfileUdp;
  auto* factory = fdds::DomainParticipantFactory::get_instance();
  fdds::DomainParticipantQos qos;
  if (factory->get_participant_qos_from_profile(profile, qos) != ReturnCode_t::RETCODE_OK) {
    return Error(ErrorCode::kInvalidArgument, "unknown DDS participant profile '" + profile + "' in " + file.string());
  }
  qos.name(options.name.empty() ? "tamp" : options.name);
  auto servers = resolveDiscoveryServers(options.discovery_servers);
  if (!servers) return servers.error();
  if (Status s = secureDiscoverySupported(security->has_value(), *servers); !s.ok()) return s.error();
  if (!servers->empty()) useDiscoveryServers(qos, *servers);

  if (*security) {
    const auto& f = **security;
    auto& props = qos.properties().properties();
    auto set = [&props](const std::string& name, const std::string& value) { props.emplace_back(name, value); };
    set("dds.sec.auth.plugin", "builtin.PKI-DH");
    set("dds.sec.auth.builtin.PKI-DH.identity_ca", fileUri(f.identity_ca));
    set("dds.sec.auth.builtin.PKI-DH.identity_certificate", fileUri(f.certificate));
    set("dds.sec.auth.builtin.PKI-DH.private_key", fileUri(f.private_key));
    set("dds.sec.access.plugin", "builtin.Access-Permissions");
    set("dds.sec.access.builtin.Access-Permissions.permissions_ca", fileUri(f.permissions_ca));
    set("dds.sec.access.builtin.Access-Permissions.governance", fileUri(f.governance));
    set("dds.sec.access.builtin.Access-Permissions.permissions", fileUri(f.permissions));
    set("dds.sec.crypto.plugin", "builtin.AES-GCM-GMAC");
  }

  std::shared_ptr<Participant> p(new Participant());
  p->security_identity_ = *security ? identity : std::string();
  p->discovery_client_ = !servers->empty();
  p->domain_id_ = *domain;
  p->name_ = qos.name().to_string();
  p->profile_ = profile;
  p->peer_log_ = std::make_unique<PeerLog>(p->name_, security->has_value());
  fdds::DomainParticipantListener* listener = p->peer_log_.get();
  if (qos.wire_protocol().participant_id < 0) {
    // An id already used in this process is refused: the next one, then Fast DDS's own choice.
    for (int attempt = 0; attempt < 8 && p->participant_ == nullptr; ++attempt) {
      qos.wire_protocol().participant_id = nextParticipantId();
      p->participant_ = factory->create_participant(static_cast<fdds::DomainId_t>(*domain), qos, listener,
                                                    fdds::StatusMask::none());
    }
    qos.wire_protocol().participant_id = -1;
  }
  if (p->participant_ == nullptr) {
    p->participant_ =
        factory->create_participant(static_cast<fdds::DomainId_t>(*domain), qos, listener, fdds::StatusMask::none());
  }
  if (p->participant_ == nullptr) {
    return Error(ErrorCode::kInternal,
                 "Fast DDS could not create a participant on domain " + std::to_string(*domain) + " with profile '" +
                     profile + "'" + (servers->empty() ? std::string() : " as a discovery-server client") +
                     (*security ? " and DDS Security identity '" + identity +
                                      "' (certificate, key, governance or permissions refused: see the Fast DDS log)"
                                : std::string()));
  }
  p->run_id_ = *run_id;
  // Isolation of runs: every writer and reader of this participant lives in its run's partition.
  fdds::PublisherQos pub_qos = fdds::PUBLISHER_QOS_DEFAULT;
  fdds::SubscriberQos sub_qos = fdds::SUBSCRIBER_QOS_DEFAULT;
  if (!p->run_id_.empty()) {
    pub_qos.partition().push_back(runPartition(p->run_id_).c_str());
    sub_qos.partition().push_back(runPartition(p->run_id_).c_str());
  }
  p->publisher_ = p->participant_->create_publisher(pub_qos);
  p->subscriber_ = p->participant_->create_subscriber(sub_qos);
  if (p->publisher_ == nullptr || p->subscriber_ == nullptr) {
    return Error(ErrorCode::kInternal, "Fast DDS could not create a publisher/subscriber");
  }
  return p;
}

Participant::Participant() = default;

Participant::~Participant() {
  if (participant_ == nullptr) return;
  // Entities were deleted by their owners (they hold a shared_ptr to us); delete what is left.
  ReturnCode_t r = participant_->delete_contained_entities();
  if (r != ReturnCode_t::RETCODE_OK) log::get("dds")->warn("delete_contained_entities failed: {}", rc(r));
  r = fdds::DomainParticipantFactory::get_instance()->delete_participant(participant_);
  if (r != ReturnCode_t::RETCODE_OK) log::get("dds")->warn("delete_participant failed: {}", rc(r));
}

std::string Participant::guid() const {
  std::ostringstream ss;
  ss << participant_->guid();
  return ss.str();
}

fdds::Topic* Participant::topic(const std::string& name, const std::function<fdds::TopicDataType*()>& make_type) {
  std::lock_guard lock(mutex_);
  fdds::TypeSupport type(make_type());
  auto it = topics_.find(name);
  if (it != topics_.end()) {
    if (it->second->get_type_name() != type.get_type_name()) {
      throw std::runtime_error("topic '" + name + "' already exists with type " + it->second->get_type_name() +
                               ", not " + type.get_type_name());
    }
    return it->second;
  }
  if (!participant_->find_type(type.get_type_name()).empty()) {
    // already registered by another topic of the same type
  } else if (ReturnCode_t r = type.register_type(participant_); r != ReturnCode_t::RETCODE_OK) {
    throw std::runtime_error("cannot register type " + type.get_type_name() + ": return code " + rc(r));
  }
  fdds::Topic* t = participant_->create_topic(name, type.get_type_name(), fdds::TOPIC_QOS_DEFAULT);
  if (t == nullptr) throw std::runtime_error("Fast DDS could not create topic '" + name + "'");
  topics_[name] = t;
  return t;
}

}  // namespace tamp::dds
