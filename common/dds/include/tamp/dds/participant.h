#pragma once
/// @file
/// A DDS domain participant created from the project's XML QoS profiles (config/dds/), owned RAII.
///
/// Every writer, reader and RPC endpoint holds a `std::shared_ptr<Participant>`, so the participant
/// outlives its entities. The domain id comes from `ParticipantOptions::domain_id`, else from the
/// environment variable `TAMP_DOMAIN_ID`, else 0: tests pick their own domain and run in parallel
/// without seeing each other.
///
/// DDS Security (docs/architecture.md, "Security profile"): with a security directory made by
/// deploy/security/make_certs.sh -- `ParticipantOptions::security_dir`, else `$TAMP_DDS_SECURITY` --
/// the participant authenticates with DIR/<identity>/{cert,key}.pem against DIR/ca.pem (builtin
/// PKI-DH), is checked against DIR/governance.p7s and DIR/<identity>/permissions.p7s (builtin
/// Access-Permissions) and encrypts (builtin AES-GCM-GMAC). A writer or reader its permissions do
/// not grant cannot be created (Writer/Reader throw). Secured, the default profile is UDPv4 only
/// (tamp_udp): shared memory with RTPS encryption lost samples on Fast DDS 2.9.1.

#include <filesystem>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "tamp/core/error.h"

namespace eprosima::fastdds::dds {
class DomainParticipant;
class Publisher;
class Subscriber;
class Topic;
class TopicDataType;
class DomainParticipantListener;
}  // namespace eprosima::fastdds::dds

namespace tamp::dds {

/// Participant profiles defined in config/dds/tamp_profiles.xml.
inline constexpr const char* kProfileDefault = "tamp_default";  ///< UDPv4 + shared memory
inline constexpr const char* kProfileUdp = "tamp_udp";          ///< UDPv4 only
inline constexpr const char* kProfileShm = "tamp_shm";          ///< shared memory only (one host)

struct ParticipantOptions {
  int domain_id{-1};                  ///< 0..232; -1: $TAMP_DOMAIN_ID or 0
  std::string profile{kProfileDefault};  ///< participant profile name; $TAMP_DDS_PROFILE overrides the default
  std::string name;                   ///< participant name shown by DDS tools; default "tamp"
  std::filesystem::path profiles_file;  ///< default: $TAMP_DDS_PROFILES or configDir()/dds/tamp_profiles.xml
  /// DDS Security material (make_certs.sh layout); empty: $TAMP_DDS_SECURITY; empty there too, or
  /// "none": no security.
  std::string security_dir{};
  /// Certificate and permissions to use from the security directory (its sub-directory): empty:
  /// $TAMP_DDS_SECURITY_IDENTITY, else "tamp" (the command-line tools' identity).
  std::string security_identity{};
  /// Explicit security files (tests: forged or foreign credentials); when set, the two fields
  /// above are not used.
  struct SecurityFiles {
    std::filesystem::path identity_ca, certificate, private_key, permissions_ca, governance, permissions;
  };
  std::optional<SecurityFiles> security{};
  /// Discovery servers ("IP:PORT", discovery.h): this participant is a CLIENT of each; empty:
  /// $TAMP_DDS_DISCOVERY_SERVERS, and unset there too: multicast (SIMPLE) discovery.
  std::vector<std::string> discovery_servers{};
};

/// The security files of `identity` in a make_certs.sh directory (not checked for existence).
ParticipantOptions::SecurityFiles securityFiles(const std::filesystem::path& dir, const std::string& identity);

/// The domain id the options resolve to (flag, then $TAMP_DOMAIN_ID, then 0); an error names the
/// offending value when it is not an integer in [0, 232].
Result<int> resolveDomainId(int flag_value);

/// The run id a process belongs to: `flag_value` when not empty, else $TAMP_RUN_ID, else "" (no
/// run: the default partition). A run id is 1-64 characters of [A-Za-z0-9_.-]; the error names
/// the offending value otherwise.
Result<std::string> resolveRunId(const std::string& flag_value);

/// The DDS partition of a run: "tamp.run.<run_id>", or "" (the default partition) for no run.
/// Every publisher and subscriber of a participant is in its run's partition, so two runs on one
/// domain never match each other's endpoints (and a run never matches a process of no run).
std::string runPartition(const std::string& run_id);

class Participant : public std::enable_shared_from_this<Participant> {
 public:
  /// Loads the XML profiles (once per process and file) and creates the participant.
  /// Errors: kNotFound/kParseError for the profiles file, kInvalidArgument for a bad domain id or
  /// unknown profile, kInternal when Fast DDS refuses.
  static Result<std::shared_ptr<Participant>> create(const ParticipantOptions& options = {});
  /// As create(options), in the partition of `run_id` (see resolveRunId: "" means $TAMP_RUN_ID
  /// or no run). Errors: those of create(), kInvalidArgument for a malformed run id.
  static Result<std::shared_ptr<Participant>> create(const ParticipantOptions& options, const std::string& run_id);
  ~Participant();
  Participant(const Participant&) = delete;
  Participant& operator=(const Participant&) = delete;

  int domainId() const { return domain_id_; }
  const std::string& name() const { return name_; }
  const std::string& profile() const { return profile_; }
  /// The run this participant belongs to ("" for none).
  const std::string& runId() const { return run_id_; }
  /// The security identity (certificate CN) when DDS Security is on; empty otherwise.
  const std::string& securityIdentity() const { return security_identity_; }
  /// True when this participant discovers through discovery servers (a CLIENT), not multicast.
  bool usesDiscoveryServer() const { return discovery_client_; }
  /// This participant's GUID prefix as hex, unique per process and domain.
  std::string guid() const;

  // ---- used by Writer/Reader/RPC (not needed by application code) ----
  /// Registers the type (once) and returns the topic `name` (created once per participant).
  /// @throws std::runtime_error when a topic of that name exists with another type.
  eprosima::fastdds::dds::Topic* topic(const std::string& name,
                                       const std::function<eprosima::fastdds::dds::TopicDataType*()>& make_type);
  eprosima::fastdds::dds::Publisher* publisher() const { return publisher_; }
  eprosima::fastdds::dds::Subscriber* subscriber() const { return subscriber_; }
  eprosima::fastdds::dds::DomainParticipant* native() const { return participant_; }

 private:
  Participant();
  /// Logs each peer's discovery and authentication time (participant.cc); outlives participant_.
  std::unique_ptr<eprosima::fastdds::dds::DomainParticipantListener> peer_log_;
  eprosima::fastdds::dds::DomainParticipant* participant_{nullptr};
  eprosima::fastdds::dds::Publisher* publisher_{nullptr};
  eprosima::fastdds::dds::Subscriber* subscriber_{nullptr};
  std::mutex mutex_;
  std::map<std::string, eprosima::fastdds::dds::Topic*> topics_;
  int domain_id_{0};
  std::string name_;
  std::string profile_;
  std::string run_id_;
  std::string security_identity_;
  bool discovery_client_{false};
};

}  // namespace tamp::dds
