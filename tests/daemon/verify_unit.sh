#!/usr/bin/env bash
# Checks config/posefaird.service with systemd's own parser (systemd-analyze verify), with
# ExecStart pointed at the freshly built posefaird, and checks the promises docs/operations.md
# makes about it are in the file.
set -euo pipefail
unit_src=$1 posefaird=$2
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
sed "s|/usr/bin/posefaird|$posefaird|" "$unit_src" >"$dir/posefaird.service"
out=$(systemd-analyze verify "$dir/posefaird.service" 2>&1 || true)
if [[ -n "$out" ]]; then
  echo "systemd-analyze verify complained:" >&2
  echo "$out" >&2
  exit 1
fi
for line in 'Type=notify' 'RestartPreventExitStatus=78' 'Restart=on-failure' 'WatchdogSec=' 'NoNewPrivileges=yes' \
            'ProtectSystem=strict' 'RestrictAddressFamilies=' 'DevicePolicy=closed' 'DeviceAllow=char-hidraw rw' \
            'DeviceAllow=char-gpiochip rw' 'DeviceAllow=char-ttyUSB rw' 'User=posefair' 'ExecReload=/bin/kill -HUP $MAINPID' \
            'RuntimeDirectory=posefaird' 'RuntimeDirectoryMode=0750'; do
  grep -qF -- "$line" "$unit_src" || { echo "missing from the unit: $line" >&2; exit 1; }
done
echo "unit ok"
