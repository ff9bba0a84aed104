#!/bin/sh
# Runs a command in a network namespace of its own whose only interface is loopback, made
# multicast-capable so DDS discovery (SPDP multicast) works there and never leaves it.
# Needs root (or CAP_SYS_ADMIN): unshare -n.
set -e
exec unshare -n sh -c 'ip link set lo up && ip link set lo multicast on && ip route add 224.0.0.0/4 dev lo && exec "$@"' sh "$@"
