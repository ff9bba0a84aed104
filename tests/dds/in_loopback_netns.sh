#!/bin/sh
# Runs a command in a network namespace of its own whose only interface is loopback, made
# multicast-capable so DDS discovery (SPDP multicast) works there and never leaves it. As root
# a plain network namespace (unshare -n); otherwise inside a user namespace too (unshare -rn,
# Debian 12 allows it), which grants the namespace's own CAP_NET_ADMIN for `ip`.
set -e
if [ "$(id -u)" -eq 0 ]; then userns=""; else userns="-r"; fi
exec unshare $userns -n sh -c 'ip link set lo up && ip link set lo multicast on && ip route add 224.0.0.0/4 dev lo && exec "$@"' sh "$@"
