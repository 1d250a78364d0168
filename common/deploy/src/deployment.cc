#include "tamp/deploy/deployment.h"

#include <arpa/inet.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdlib>
#include <set>

#include "tamp/config/yaml_reader.h"

namespace fs = std::filesystem;

namespace tamp::deploy {
namespace {

void checkEnv(config::FieldReader& r, const std::vector<std::string>& env) {
  for (std::size_t i = 0; i < env.size(); ++i) {
    const auto eq = env[i].find('=');
    r.check(eq != std::string::npos && eq > 0, "env",
            "entry " + std::to_string(i) + " must be KEY=value, got '" + env[i] + "'");
  }
}

std::string listOf(const std::vector<HostSpec>& hosts) {
  std::string out;
  for (const auto& h : hosts) out += (out.empty() ? "" : ", ") + h.name;
  return out;
}

std::string replaceAll(std::string s, const std::string& key, const std::string& value) {
  for (std::size_t pos = 0; (pos = s.find(key, pos)) != std::string::npos; pos += value.size()) {
    s.replace(pos, key.size(), value);
  }
  return s;
}

/// "" when `text` is IPv4:PORT, else what is wrong (tamp::dds parses it again; no DDS here).
std::string badServerAddress(const std::string& text) {
  const auto colon = text.rfind(':');
  if (colon == std::string::npos) return "'" + text + "' must be IPv4:PORT (e.g. 10.0.0.1:11811)";
  in_addr addr{};
  if (inet_pton(AF_INET, text.substr(0, colon).c_str(), &addr) != 1) {
    return "'" + text.substr(0, colon) + "' is not an IPv4 address";
  }
  const std::string port = text.substr(colon + 1);
  char* end = nullptr;
  const long p = std::strtol(port.c_str(), &end, 10);
  if (port.empty() || *end != '\0' || p < 1 || p > 65535) return "port must be in [1, 65535], got '" + port + "'";
  return {};
}

/// `server_host` (every server) or `server_hosts` (one per server), each a declared host.
void readServerHosts(config::FieldReader& dr, Deployment& d) {
  std::string one;
  std::vector<std::string> each;
  dr.optional("server_host", one);
  dr.optional("server_hosts", each);
  const std::string hosts = listOf(d.hosts);
  if (!dr.check(one.empty() != each.empty(), one.empty() ? "server_host" : "server_hosts",
                "give either server_host (the host of every server) or server_hosts (one per server)"))
    return;
  if (!one.empty()) {
    dr.check(d.host(one) != nullptr, "server_host",
             "must name a declared host that runs the discovery servers (hosts: " + hosts + "), got '" + one + "'");
    d.discovery.server_hosts.assign(d.discovery.servers.size(), one);
    return;
  }
  if (!dr.check(each.size() == d.discovery.servers.size(), "server_hosts",
                "one host per server: " + std::to_string(d.discovery.servers.size()) + " servers, " +
                    std::to_string(each.size()) + " hosts"))
    return;
  for (std::size_t i = 0; i < each.size(); ++i)
    dr.check(d.host(each[i]) != nullptr, "server_hosts",
             "entry " + std::to_string(i) + ": must name a declared host (hosts: " + hosts + "), got '" + each[i] + "'");
  d.discovery.server_hosts = std::move(each);
}

/// The `discovery` mapping (after `hosts`: the server hosts must name them).
void readDiscovery(config::FieldReader& r, Deployment& d) {
  auto dr = r.child("discovery");
  std::string mode = "multicast";
  dr.required("mode", mode);
  dr.optional("servers", d.discovery.servers);
  if (mode == "server") {
    d.discovery.mode = DiscoverySpec::Mode::kServer;
    dr.check(!d.discovery.servers.empty(), "servers", "mode 'server' needs at least one server (\"IPv4:PORT\")");
    for (std::size_t i = 0; i < d.discovery.servers.size(); ++i) {
      const std::string bad = badServerAddress(d.discovery.servers[i]);
      dr.check(bad.empty(), "servers", "entry " + std::to_string(i) + ": " + bad);
    }
    readServerHosts(dr, d);
  } else {
    std::string one;
    std::vector<std::string> each;
    dr.optional("server_host", one);
    dr.optional("server_hosts", each);
    dr.check(mode == "multicast", "mode", "must be 'multicast' or 'server', got '" + mode + "'");
    dr.check(d.discovery.servers.empty(), "servers", "only with mode 'server'");
    dr.check(one.empty(), "server_host", "only with mode 'server'");
    dr.check(each.empty(), "server_hosts", "only with mode 'server'");
  }
  dr.refuseUnknownKeys();
}

}  // namespace

std::string DiscoverySpec::serversEnv() const {
  if (mode != Mode::kServer) return {};
  std::string out;
  for (const auto& s : servers) out += (out.empty() ? "" : ";") + s;
  return out;
}

std::vector<std::size_t> DiscoverySpec::serversOn(const std::string& host) const {
  std::vector<std::size_t> out;
  if (mode != Mode::kServer) return out;
  for (std::size_t i = 0; i < servers.size() && i < server_hosts.size(); ++i)
    if (server_hosts[i] == host) out.push_back(i);
  return out;
}

const HostSpec* Deployment::host(const std::string& name) const {
  for (const auto& h : hosts) {
    if (h.name == name) return &h;
  }
  return nullptr;
}

std::vector<const ServiceSpec*> Deployment::servicesOn(const std::string& host_name) const {
  std::vector<const ServiceSpec*> out;
  for (const auto& s : services) {
    if (host_name.empty() || s.host == host_name) out.push_back(&s);
  }
  return out;
}

Result<Deployment> loadDeployment(const fs::path& file) {
  std::error_code ec;
  if (!fs::is_regular_file(file, ec)) {
    return Error(ErrorCode::kNotFound, "deployment file does not exist",
                 SourceLocation{file.string()});
  }
  auto doc = config::loadYamlFile(file);
  if (!doc) return doc.error();
  config::FieldReader r(*doc);
  Deployment d;
  d.file = file.string();
  if (!r.isMap()) {
    return Error(ErrorCode::kInvalidArgument,
                 "a deployment must be a mapping with a 'services' list",
                 SourceLocation{file.string(), 1});
  }
  r.optional("heartbeat_period_s", d.heartbeat_period_s);
  r.optional("liveness_periods", d.liveness_periods);
  r.optional("startup_timeout_s", d.startup_timeout_s);
  r.optional("orphan_timeout_s", d.orphan_timeout_s);
  r.optional("stall_timeout_s", d.stall_timeout_s);
  r.optional("ready_timeout_s", d.ready_timeout_s);
  r.optional("ready_restarts", d.ready_restarts);
  r.check(d.heartbeat_period_s > 0 && d.heartbeat_period_s <= 10, "heartbeat_period_s",
          "must be in (0, 10]");
  r.check(d.liveness_periods >= 2, "liveness_periods", "must be at least 2");
  r.check(d.startup_timeout_s > 0, "startup_timeout_s", "must be positive");
  r.check(d.orphan_timeout_s >= 0, "orphan_timeout_s", "must not be negative (0: never)");
  r.check(std::isfinite(d.stall_timeout_s) && d.stall_timeout_s >= 0, "stall_timeout_s",
          "must be finite and not negative (0: never)");
  r.check(std::isfinite(d.ready_timeout_s) && d.ready_timeout_s > 0, "ready_timeout_s", "must be finite and positive");
  r.check(d.ready_restarts >= 0, "ready_restarts", "must not be negative (0: never)");
  if (r.has("restart")) {
    auto rr = r.child("restart");
    rr.optional("max_restarts", d.restart.max_restarts);
    rr.optional("backoff_s", d.restart.backoff_s);
    rr.optional("backoff_max_s", d.restart.backoff_max_s);
    rr.optional("stable_after_s", d.restart.stable_after_s);
    rr.check(d.restart.max_restarts >= 0, "max_restarts", "must not be negative");
    rr.check(d.restart.backoff_s > 0, "backoff_s", "must be positive");
    rr.check(d.restart.backoff_max_s >= d.restart.backoff_s, "backoff_max_s",
             "must be at least backoff_s");
    rr.check(d.restart.stable_after_s > 0, "stable_after_s", "must be positive");
    rr.refuseUnknownKeys();
  }
  const bool has_hosts = r.has("hosts");
  if (has_hosts) {
    for (auto& [name, h] : r.entries("hosts")) {
      HostSpec host;
      host.name = name;
      if (h.isMap()) {
        h.optional("description", host.description);
        h.optional("env", host.env);
        checkEnv(h, host.env);
        h.refuseUnknownKeys();
      }  // else: null (no settings), or the reader recorded "expected a mapping"
      r.check(!name.empty() && name.find('/') == std::string::npos, "hosts",
              "bad host name '" + name + "'");
      d.hosts.push_back(std::move(host));
    }
    r.check(!d.hosts.empty(), "hosts", "must name at least one host");
  } else {
    d.hosts.push_back(HostSpec{kLocalHost, "this machine", {}});
  }
  if (r.has("discovery")) readDiscovery(r, d);
  std::set<std::string> names;
  for (auto& s : r.sequence("services")) {
    ServiceSpec e;
    s.required("name", e.name);
    s.required("executable", e.executable);
    e.executable_at = s.locationOf("executable");
    s.optional("args", e.args);
    s.optional("env", e.env);
    s.optional("optional", e.optional);
    s.optional("restart", e.restart);
    checkEnv(s, e.env);
    if (has_hosts) {
      if (s.required("host", e.host)) {
        s.check(d.host(e.host) != nullptr, "host",
                "unknown host '" + e.host + "' (hosts: " + listOf(d.hosts) + ")");
      }
    } else {
      if (s.optional("host", e.host)) {
        s.check(e.host == kLocalHost, "host",
                "host '" + e.host +
                    "' is not declared: add a 'hosts' mapping (without one every service is on "
                    "'local')");
      }
      e.host = kLocalHost;
    }
    s.check(!names.count(e.name) || e.name.empty(), "name",
            "duplicate service name '" + e.name + "'");
    const bool safe_name = !e.name.empty() && std::all_of(e.name.begin(), e.name.end(), [](char c) {
      return std::isalnum(static_cast<unsigned char>(c)) != 0 || c == '_' || c == '-';
    });
    if (s.has("name"))
      s.check(safe_name, "name",
              "must be [A-Za-z0-9_-]+ (it names log files), got '" + e.name + "'");
    if (s.has("executable")) s.check(!e.executable.empty(), "executable", "must not be empty");
    s.refuseUnknownKeys();
    names.insert(e.name);
    d.services.push_back(std::move(e));
  }
  r.check(!d.services.empty() || !r.ok(), "services", "must list at least one service");
  r.refuseUnknownKeys();
  if (!r.ok()) return r.status().error();
  return d;
}

fs::path resolveExecutable(const ServiceSpec& service, const fs::path& bin_dir) {
  const fs::path exe(service.executable);
  return exe.is_absolute() ? exe : bin_dir / exe;
}

Status checkExecutables(const Deployment& d, const fs::path& bin_dir, const std::string& host) {
  std::vector<Error> errors;
  for (const ServiceSpec* s : d.servicesOn(host)) {
    const fs::path exe = resolveExecutable(*s, bin_dir);
    std::error_code ec;
    if (!fs::is_regular_file(exe, ec) || access(exe.c_str(), X_OK) != 0) {
      errors.emplace_back(ErrorCode::kNotFound,
                          "service '" + s->name + "': no executable " + exe.string() +
                              (fs::path(s->executable).is_absolute() ? "" : " (is it built?)"),
                          s->executable_at);
    }
  }
  if (errors.empty()) return Status::Ok();
  if (errors.size() == 1) return errors.front();
  return Error(ErrorCode::kNotFound, joinErrors(errors));
}

std::vector<std::string> expandArgs(const ServiceSpec& service, const Placeholders& v) {
  std::vector<std::string> out;
  const auto& a = service.args;
  for (std::size_t i = 0; i < a.size(); ++i) {
    if (v.scenario.empty() && i + 1 < a.size() && a[i].rfind("--", 0) == 0 &&
        a[i + 1] == "{scenario}") {
      ++i;
      continue;
    }
    std::string s = a[i];
    s = replaceAll(s, "{scenario}", v.scenario);
    s = replaceAll(s, "{config}", v.config_dir);
    s = replaceAll(s, "{run_dir}", v.run_dir);
    s = replaceAll(s, "{run_id}", v.run_id);
    s = replaceAll(s, "{host}", v.host);
    out.push_back(std::move(s));
  }
  return out;
}

}  // namespace tamp::deploy
