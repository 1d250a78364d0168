#!/usr/bin/env bash
# Installs every build, test and run dependency from Debian 12 packages.
# Idempotent: asks apt only for what is missing (a second run changes nothing and needs no network).
set -euo pipefail

PACKAGES=(
  # toolchain
  build-essential cmake ninja-build ccache pkg-config clang libclang-rt-14-dev time
  # middleware
  libfastrtps-dev fastddsgen fastdds-tools
  # planning, geometry, estimation, perception
  libompl-dev libfcl-dev libpcl-dev libeigen3-dev liboctomap-dev libceres-dev
  # robot model, config, logging, CLI, serialisation, storage, rendering
  liburdfdom-dev liborocos-kdl-dev libyaml-cpp-dev libspdlog-dev libcli11-dev nlohmann-json3-dev
  libsqlite3-dev libcairo2-dev graphviz
  # DDS Security test material (deploy/security/make_certs.sh)
  openssl
  # tests and benchmarks (iproute2 + nftables: tests/fault/two_hosts.sh namespaces, loss, duplication;
  # iptables + libnetfilter-queue-dev: its --delay (NFQUEUE rule, tamp_link_delay);
  # procps + python3: tests/fault/kill_matrix.sh, tools/evaluation)
  libgtest-dev libgmock-dev libbenchmark-dev iproute2 nftables iptables libnetfilter-queue-dev procps
  python3
)

missing=()
for p in "${PACKAGES[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done

if [ ${#missing[@]} -eq 0 ]; then
  echo "deploy/install_deps.sh: all ${#PACKAGES[@]} packages already installed"
  exit 0
fi

SUDO=""
if [ "$(id -u)" -ne 0 ]; then
  command -v sudo >/dev/null || { echo "need root (or sudo) to install: ${missing[*]}" >&2; exit 1; }
  SUDO=sudo
fi
echo "deploy/install_deps.sh: installing ${#missing[@]} package(s): ${missing[*]}"
$SUDO apt-get update -qq
DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
