#!/usr/bin/env bash
# Runs the tests labelled `hw` (SocketCAN on vcan, HID through uhid/hidraw, GPIO on gpio-sim)
# inside Debian's own kernel under qemu, in one boot: the build machines' kernel has none of
# these interfaces. The guest is a busybox initramfs that loads the modules, mounts this
# machine's root read-only over 9p and chroots into it, so the test binaries built on the host
# run in place with the host's libraries; a second, writable 9p share brings back the exit
# status and the guest's kernel log. How and why: tests/hw/README.md.
#
# Usage: tests/hw/vm/run_hw_tests.sh BUILD_DIR [extra ctest arguments]
# Environment: VM_TIMEOUT (s, default 900), VM_MEM (default 1G), VM_CPUS (default 2).
# Needs (tools/setup-debian.sh installs them on amd64): qemu-system-x86, linux-image-amd64,
# linux-headers-amd64, busybox-static, kmod, cpio, zstd, xz-utils, file, make, gcc, and for
# the tests' peers can-utils, python3-can, gpiod.
set -euo pipefail

build=$(cd "${1:?usage: $0 BUILD_DIR [ctest arguments]}" && pwd)
shift
t0=$SECONDS
say() { echo "[hw-vm +$((SECONDS - t0))s] $*"; }

# Where qemu cannot run at all the tests are skipped, saying why; anywhere else they run.
if [[ $(uname -m) != x86_64 ]]; then
  say "SKIPPED: the hw tests boot Debian's amd64 kernel under qemu; this machine is $(uname -m)"
  exit 0
fi
for tool in qemu-system-x86_64 busybox modinfo cpio; do
  command -v "$tool" >/dev/null || { echo "hw-vm: $tool is missing (tools/setup-debian.sh installs it)" >&2; exit 1; }
done

kver=$(cd /lib/modules 2>/dev/null && ls -d *-amd64 2>/dev/null | sort -V | tail -1 || true)
[[ -n $kver && -f /boot/vmlinuz-$kver ]] || { echo "hw-vm: no Debian amd64 kernel in /boot and /lib/modules (package linux-image-amd64)" >&2; exit 1; }
[[ -d /lib/modules/$kver/build ]] || { echo "hw-vm: no headers for $kver (package linux-headers-amd64)" >&2; exit 1; }

# Everything made here is kept per kernel version under the build directory.
work=$build/hw-vm/$kver
mkdir -p "$work"
say "kernel $kver, work directory $work"

# 1. gpio-sim: not enabled in any Debian amd64 kernel, so built out of tree from the matching
#    linux-source package (three GPL-2.0 files). irq_to_desc() is not exported to modules;
#    generic_handle_irq() does the same for this simulator. Loading it taints the kernel
#    (out-of-tree module), which is harmless here.
build_gpio_sim() {
  local src=$work/gpio-sim kmm
  kmm=$(cut -d. -f1,2 <<<"$kver")   # 6.1.0-57-amd64 -> 6.1
  [[ -f $src/gpio-sim.ko ]] && return
  rm -rf "$src" && mkdir -p "$src"
  # (apt-get download, as root, warns that its sandbox user cannot write here: harmless, hidden)
  (cd "$work" && apt-get download -qq "linux-source-$kmm" >"$work/download.log" 2>&1) ||
    { cat "$work/download.log" >&2; echo "hw-vm: cannot download linux-source-$kmm (for gpio-sim)" >&2; exit 1; }
  dpkg-deb --fsys-tarfile "$work"/linux-source-"$kmm"_*.deb | tar -xO "./usr/src/linux-source-$kmm.tar.xz" |
    tar -xJ --strip-components=1 -C "$src" --wildcards \
      "*/drivers/gpio/gpio-sim.c" "*/drivers/gpio/gpiolib.h" "*/kernel/irq/irq_sim.c"
  rm -f "$work"/linux-source-*.deb
  mv "$src/drivers/gpio/gpio-sim.c" "$src/gpio-sim-core.c"
  mv "$src/drivers/gpio/gpiolib.h" "$src/kernel/irq/irq_sim.c" "$src/"
  rm -rf "$src/drivers" "$src/kernel"
  sed -i 's/handle_simple_irq(irq_to_desc(irqnum));/generic_handle_irq(irqnum);/' "$src/irq_sim.c"
  grep -q 'generic_handle_irq(irqnum);' "$src/irq_sim.c" || { echo "hw-vm: irq_sim.c changed upstream; the patch no longer applies" >&2; exit 1; }
  printf 'obj-m := gpio-sim.o\ngpio-sim-objs := gpio-sim-core.o irq_sim.o\nccflags-y := -I$(src)\n' >"$src/Kbuild"
  make -s -C "/lib/modules/$kver/build" M="$src" modules >"$src/make.log" 2>&1 ||
    { cat "$src/make.log" >&2; echo "hw-vm: building gpio-sim failed" >&2; exit 1; }
  strip --strip-debug "$src/gpio-sim.ko"
}
build_gpio_sim
say "gpio-sim.ko built"

# 2. An uncompressed ELF vmlinux lets qemu boot the kernel directly (PVH): about 6 s to /init
#    instead of 13 s with the bzImage's own decompressor under emulation.
extract_vmlinux() {
  local img=/boot/vmlinuz-$kver out=$work/vmlinux c magic off
  [[ -f $out ]] && return
  for c in xz zstd gzip; do   # the compressed payload, found by its magic number
    case $c in xz) magic=$'\xfd7zXZ' ;; zstd) magic=$'\x28\xb5\x2f\xfd' ;; gzip) magic=$'\x1f\x8b\x08' ;; esac
    for off in $(grep -abo "$magic" "$img" | head -3 | cut -d: -f1); do
      tail -c +$((off + 1)) "$img" | $c -dc >"$out.tmp" 2>/dev/null || true
      if file "$out.tmp" | grep -q ELF; then mv "$out.tmp" "$out"; return; fi
    done
  done
  say "no ELF payload found in $img; booting the bzImage"
  cp "$img" "$out"
}
extract_vmlinux

# 3. The initramfs: busybox, the modules with their dependencies (modinfo), decompressed, in
#    load order, and /init. Nothing autoloads modules in this guest, so every driver the tests
#    need is listed; hid-sensor-hub is deliberately absent (it would take the HID sensor test
#    device without a hidraw node; docs/hid-gpio.md).
modules=(vcan can-raw can-bcm configfs uhid hid-generic 9p 9pnet_virtio virtio_pci "$work/gpio-sim/gpio-sim.ko")
root=$work/initramfs
rm -rf "$root"
mkdir -p "$root"/{bin,dev,proc,sys,mnt/host,mnt/res,lib/modules}
cp "$(command -v busybox)" "$root/bin/busybox"
for applet in $("$root/bin/busybox" --list); do [[ $applet == busybox ]] || ln -s busybox "$root/bin/$applet"; done
declare -A seen=()
order=()
add_module() {
  local path dep
  if [[ $1 == */* ]]; then path=$1; else path=$(modinfo -k "$kver" -n "$1"); fi
  [[ $path == /* && -z ${seen[$path]:-} ]] || return 0   # built in, or already listed
  seen[$path]=1
  for dep in $(modinfo -k "$kver" -F depends "$path" | tr , ' '); do add_module "$dep"; done
  order+=("$path")
}
for m in "${modules[@]}"; do add_module "$m"; done
for path in "${order[@]}"; do
  name=$(basename "$path"); name=${name%.xz}; name=${name%.zst}; name=${name%.gz}
  case $path in
    *.xz) xz -dc "$path" ;; *.zst) zstd -qdc "$path" ;; *.gz) gzip -dc "$path" ;; *) cat "$path" ;;
  esac >"$root/lib/modules/$name"
  echo "$name" >>"$root/lib/modules/load.order"
done
cp "$(dirname "$0")/guest_init.sh" "$root/init"
chmod +x "$root/init"
(cd "$root" && find . | cpio -o -H newc --quiet | gzip -1) >"$work/initramfs.cpio.gz"
say "initramfs with ${#order[@]} modules"

# 4. Boot and run ctest. The host root is read-only in the guest: /run gets a tmpfs (TMPDIR
#    points there), and so does the build tree's Testing/ (ctest's own logs); /tmp and
#    /var/tmp too unless the build tree is under them. The results come back through res/.
res=$work/res
rm -rf "$res" && mkdir -p "$res" "$build/Testing"
writable=("$build/Testing")
for d in /tmp /var/tmp; do [[ $build == "$d"/* ]] || writable+=("$d"); done
printf '%s\n' "${writable[@]}" >"$res/tmpfs"
{
  echo '#!/bin/sh'
  echo 'export TMPDIR=/run/tmp HOME=/run/tmp; mkdir -p /run/tmp'
  printf 'cd %q || exit 125\n' "$build"
  printf 'ctest -L hw --output-on-failure --timeout 300'
  printf ' %q' "$@"
  echo
} >"$res/cmd.sh"

rc=0
timeout -k 10 "${VM_TIMEOUT:-900}" qemu-system-x86_64 -accel tcg -m "${VM_MEM:-1G}" -smp "${VM_CPUS:-2}" \
  -nographic -no-reboot -net none \
  -kernel "$work/vmlinux" -initrd "$work/initramfs.cpio.gz" -append "console=ttyS0 panic=-1 quiet" \
  -virtfs local,path=/,mount_tag=hostroot,security_model=none,readonly=on,multidevs=remap \
  -virtfs local,path="$res",mount_tag=res,security_model=none </dev/null | tr -d '\r' || rc=$?
if [[ ! -f $res/rc ]]; then
  say "the VM ended without a test result (qemu/timeout status $rc); guest log: $work/res/dmesg.txt"
  exit 1
fi
rc=$(cat "$res/rc")
say "hw tests finished in the VM with status $rc (guest kernel log: $res/dmesg.txt)"
exit "$rc"
