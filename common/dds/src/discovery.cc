#include "tamp/dds/discovery.h"

#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <cstring>

#include <fastdds/dds/domain/DomainParticipant.hpp>
#include <fastdds/dds/domain/DomainParticipantFactory.hpp>
#include <fastdds/rtps/attributes/ServerAttributes.h>
#include <fastrtps/utils/IPLocator.h>

#include "tamp/core/log.h"

namespace fdds = eprosima::fastdds::dds;
namespace rtps = eprosima::fastrtps::rtps;

namespace tamp::dds {

Result<DiscoveryServerAddress> parseDiscoveryServer(const std::string& text) {
  const auto colon = text.rfind(':');
  if (colon == std::string::npos) {
    return Error(ErrorCode::kInvalidArgument, "discovery server '" + text + "' must be IPv4:PORT (e.g. 10.0.0.1:11811)");
  }
  DiscoveryServerAddress a;
  a.ip = text.substr(0, colon);
  in_addr addr{};
  if (inet_pton(AF_INET, a.ip.c_str(), &addr) != 1) {
    return Error(ErrorCode::kInvalidArgument, "discovery server '" + text + "': '" + a.ip + "' is not an IPv4 address");
  }
  const std::string port = text.substr(colon + 1);
  char* end = nullptr;
  const long p = std::strtol(port.c_str(), &end, 10);
  if (port.empty() || *end != '\0' || p < 1 || p > 65535) {
    return Error(ErrorCode::kInvalidArgument, "discovery server '" + text + "': port must be in [1, 65535], got '" + port + "'");
  }
  a.port = static_cast<uint16_t>(p);
  return a;
}

Result<std::vector<DiscoveryServerAddress>> parseDiscoveryServers(const std::string& text) {
  std::vector<DiscoveryServerAddress> out;
  std::size_t start = 0;
  while (start <= text.size() && !text.empty()) {
    const auto semi = text.find(';', start);
    const std::string item = text.substr(start, semi == std::string::npos ? std::string::npos : semi - start);
    auto a = parseDiscoveryServer(item);
    if (!a) return a.error();
    out.push_back(*a);
    if (semi == std::string::npos) break;
    start = semi + 1;
  }
  return out;
}

Result<std::vector<DiscoveryServerAddress>> resolveDiscoveryServers(const std::vector<std::string>& explicit_list) {
  if (!explicit_list.empty()) {
    std::vector<DiscoveryServerAddress> out;
    for (const auto& s : explicit_list) {
      auto a = parseDiscoveryServer(s);
      if (!a) return a.error();
      out.push_back(*a);
    }
    return out;
  }
  const char* env = std::getenv("TAMP_DDS_DISCOVERY_SERVERS");
  if (env == nullptr || *env == '\0') return std::vector<DiscoveryServerAddress>{};
  auto list = parseDiscoveryServers(env);
  if (!list) return Error(ErrorCode::kInvalidArgument, "TAMP_DDS_DISCOVERY_SERVERS: " + list.error().message);
  return list;
}

namespace {

/// Fast DDS creates a server on any address, reachable or not: bind a UDP socket to it first so
/// that an address of another host or a port in use is an error naming it.
Status checkBindable(const DiscoveryServerAddress& address) {
  const int fd = ::socket(AF_INET, SOCK_DGRAM, 0);
  if (fd < 0) return Error(ErrorCode::kInternal, std::string("socket(): ") + std::strerror(errno));
  sockaddr_in sa{};
  sa.sin_family = AF_INET;
  sa.sin_port = htons(address.port);
  if (inet_pton(AF_INET, address.ip.c_str(), &sa.sin_addr) != 1) {
    ::close(fd);
    return Error(ErrorCode::kInvalidArgument, "discovery server '" + address.toString() + "': not an IPv4 address");
  }
  const int rc = ::bind(fd, reinterpret_cast<const sockaddr*>(&sa), sizeof(sa));
  const int err = errno;
  ::close(fd);
  if (rc == 0) return Status::Ok();
  if (err == EADDRNOTAVAIL) {
    return Error(ErrorCode::kInvalidArgument, "discovery server " + address.toString() +
                                                  ": the address is not one of this host's (run it on its host)");
  }
  if (err == EADDRINUSE) {
    return Error(ErrorCode::kUnavailable, "discovery server " + address.toString() +
                                              ": the UDP port is in use (another server or process)");
  }
  return Error(ErrorCode::kInternal, "discovery server " + address.toString() + ": bind: " + std::strerror(err));
}

}  // namespace

Result<std::unique_ptr<DiscoveryServer>> DiscoveryServer::start(const DiscoveryServerAddress& address, int id) {
  if (id < 0 || id > 255) {
    return Error(ErrorCode::kInvalidArgument, "discovery server id must be in [0, 255], got " + std::to_string(id));
  }
  if (Status s = checkBindable(address); !s.ok()) return s.error();
  fdds::DomainParticipantQos qos = fdds::PARTICIPANT_QOS_DEFAULT;
  qos.name("tamp/discovery_server");
  auto& builtin = qos.wire_protocol().builtin;
  builtin.discovery_config.discoveryProtocol = rtps::DiscoveryProtocol_t::SERVER;
  // Clients of a dead peer are forgotten within the lease of the tamp profiles (5 s).
  builtin.discovery_config.leaseDuration = eprosima::fastrtps::Duration_t(5, 0);
  builtin.discovery_config.leaseDuration_announcementperiod = eprosima::fastrtps::Duration_t(1, 0);
  if (!rtps::get_server_client_default_guidPrefix(id, qos.wire_protocol().prefix)) {
    return Error(ErrorCode::kInvalidArgument, "no default GUID prefix for discovery server id " + std::to_string(id));
  }
  rtps::Locator_t locator;
  rtps::IPLocator::setIPv4(locator, address.ip);
  locator.port = address.port;
  builtin.metatrafficUnicastLocatorList.push_back(locator);
  std::unique_ptr<DiscoveryServer> s(new DiscoveryServer());
  s->address_ = address;
  s->participant_ = fdds::DomainParticipantFactory::get_instance()->create_participant(0, qos);
  if (s->participant_ == nullptr) {
    return Error(ErrorCode::kInternal, "Fast DDS could not start a discovery server on " + address.toString() +
                                           " (is the address one of this host's? is the port free?)");
  }
  return s;
}

DiscoveryServer::~DiscoveryServer() {
  if (participant_ == nullptr) return;
  if (fdds::DomainParticipantFactory::get_instance()->delete_participant(participant_) != ReturnCode_t::RETCODE_OK) {
    log::get("dds")->warn("could not delete the discovery server participant");
  }
}

}  // namespace tamp::dds
