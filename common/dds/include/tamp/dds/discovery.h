#pragma once
/// @file
/// How participants find each other: multicast (Fast DDS SIMPLE discovery, the default) or through
/// Fast DDS Discovery Servers, for networks without multicast (docs/architecture.md, "Deployment").
///
/// With servers, every participant tamp::dds::Participant creates is a CLIENT of each listed
/// server; server i of the list has the well-known GUID prefix of id i (the prefix `fastdds
/// discovery -i i` uses), so a server started by `tamp launch` or by that tool serves the same
/// clients. The list comes from `ParticipantOptions::discovery_servers`, else from
/// $TAMP_DDS_DISCOVERY_SERVERS ("IP:PORT;IP:PORT"), which `tamp launch` sets for every service of a
/// deployment with `discovery: {mode: server, ...}`.

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "tamp/core/error.h"

namespace eprosima::fastdds::dds {
class DomainParticipant;
}  // namespace eprosima::fastdds::dds

namespace tamp::dds {

/// One discovery server: an IPv4 address and a UDP port.
struct DiscoveryServerAddress {
  std::string ip;
  uint16_t port{11811};
  std::string toString() const { return ip + ":" + std::to_string(port); }
};

/// Parses "a.b.c.d:port" (port 1..65535); the error names the text and what is wrong with it.
Result<DiscoveryServerAddress> parseDiscoveryServer(const std::string& text);

/// Parses a ';'-separated list (empty text: empty list); the error names the bad entry.
Result<std::vector<DiscoveryServerAddress>> parseDiscoveryServers(const std::string& text);

/// The servers a participant is to use: `explicit_list` when not empty, else
/// $TAMP_DDS_DISCOVERY_SERVERS (empty or unset: none, multicast discovery).
Result<std::vector<DiscoveryServerAddress>> resolveDiscoveryServers(const std::vector<std::string>& explicit_list);

/// A Fast DDS Discovery Server (a SERVER participant with no endpoints of its own), owned RAII.
/// Clients on any domain reach it at its address (the domain id of a server does not matter to
/// its clients; the port does).
class DiscoveryServer {
 public:
  /// Starts server `id` (its GUID prefix; the index of this address in the clients' lists)
  /// listening on `address`. Errors: kInvalidArgument for an id > 255 or an address that is not
  /// one of this host's (Fast DDS itself would start an unreachable server), kUnavailable when
  /// the UDP port is in use, kInternal when Fast DDS refuses.
  static Result<std::unique_ptr<DiscoveryServer>> start(const DiscoveryServerAddress& address, int id = 0);
  ~DiscoveryServer();
  DiscoveryServer(const DiscoveryServer&) = delete;
  DiscoveryServer& operator=(const DiscoveryServer&) = delete;
  const DiscoveryServerAddress& address() const { return address_; }

 private:
  DiscoveryServer() = default;
  eprosima::fastdds::dds::DomainParticipant* participant_{nullptr};
  DiscoveryServerAddress address_;
};

}  // namespace tamp::dds
