#!/usr/bin/env bash
# Installs every Debian 12 package posefair needs to build, test and benchmark.
# Idempotent: when everything is present it only checks and prints nothing.
#   tools/setup-debian.sh           build dependencies (what tools/demo.sh needs)
#   tools/setup-debian.sh --tests   also the kernel interface tests' VM and peers (tools/test.sh)
#   tools/setup-debian.sh --plots   also what tools/plot_*.py need (matplotlib)
set -euo pipefail

packages=(
  build-essential cmake ninja-build pkg-config
  lld                    # links faster than GNU ld (CMakeLists.txt, POSEFAIR_USE_LLD)
  libeigen3-dev          # core math
  googletest libgtest-dev libgmock-dev  # tests
  libbenchmark-dev       # benchmarks
  libcli11-dev           # the posefair command line
  libtomlplusplus-dev    # posefaird's configuration files
  libspdlog-dev          # posefaird's logging (stderr or journald)
  libsystemd-dev         # sd_notify and the journald log sink
  libboost-dev           # Boost.Lockfree, the ring benchmark's yardstick
  systemd                # systemd-analyze verify checks config/posefaird.service
  python3                # the Python subscriber client and its test
  zlib1g-dev             # CRC-32 of the sample log (drivers)
  libserialport-dev      # the serial driver: ports by path or USB id, settings (drivers)
  libnlopt-cxx-dev       # the quaternion spline optimiser (core)
  nlohmann-json3-dev     # BROAD's trials.json (posefair bench fusion), posefair ctl's JSON replies (tools)
  libgpiod-dev           # GPIO data-ready and scope lines, libgpiod 1.6 (drivers)
  liblo-dev              # OSC bundles of the vmc and vrchat output encodings (daemon)
  cyclonedds-dev cyclonedds-tools  # the dds output encoding: Cyclone DDS and its idlc (daemon)
  libsodium-dev          # subscription cookies and pre-shared-key MACs (daemon)
  iproute2 util-linux    # the attack tests' network namespaces and other users (ip, setpriv)
)
# The client encodings' independent peers (docs/outputs.md): oscdump receives the OSC
# encodings, a Fast DDS reader (fastddsgen generates its type) the dds one.
if [[ "${1:-}" == "--tests" ]]; then
  packages+=(liblo-tools libfastrtps-dev fastddsgen)
  packages+=(libfaketime)  # the soak steps the daemon's CLOCK_REALTIME, not the host's (tools/soak.sh)
fi
# The hw tests' VM (tests/hw/vm/): Debian's own kernel under qemu, gpio-sim built against its
# headers, and the tests' independent peers. Only amd64 boots that kernel.
if [[ "${1:-}" == "--tests" && $(dpkg --print-architecture) == amd64 ]]; then
  packages+=(qemu-system-x86 linux-image-amd64 linux-headers-amd64 busybox-static kmod cpio
             xz-utils zstd file make gcc libc6-dev
             iproute2 can-utils python3-can)
fi
if [[ "${1:-}" == "--plots" ]]; then
  packages+=(python3 python3-matplotlib python3-numpy)
fi

missing=()
for p in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done
[[ ${#missing[@]} -eq 0 ]] && exit 0

echo "setup: installing ${missing[*]}" >&2
if [[ $(id -u) -eq 0 ]]; then
  sudo=()
elif command -v sudo >/dev/null 2>&1; then
  sudo=(sudo)
else
  echo "setup: need root (or sudo) to install: ${missing[*]}" >&2
  exit 1
fi
export DEBIAN_FRONTEND=noninteractive
# A fresh machine often has unattended-upgrades holding the dpkg lock for minutes: wait for it
# (up to 10 minutes) rather than fail.
apt=(apt-get -o DPkg::Lock::Timeout=600)
if ! "${sudo[@]}" "${apt[@]}" install -y -qq --no-install-recommends "${missing[@]}" >/tmp/posefair-apt.log 2>&1; then
  # A fresh machine has no package lists yet: fetch them once and try again.
  "${sudo[@]}" "${apt[@]}" update -qq >>/tmp/posefair-apt.log 2>&1 || true
  if ! "${sudo[@]}" "${apt[@]}" install -y -qq --no-install-recommends "${missing[@]}" >>/tmp/posefair-apt.log 2>&1; then
    echo "setup: could not install some of: ${missing[*]}" >&2
    for p in "${missing[@]}"; do
      apt-cache policy "$p" 2>/dev/null | grep -q "Candidate: (none)" && echo "setup:   no installable candidate for '$p'" >&2
    done
    echo "setup: apt-get output is in /tmp/posefair-apt.log" >&2
    tail -n 5 /tmp/posefair-apt.log >&2
    exit 1
  fi
fi
