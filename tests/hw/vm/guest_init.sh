#!/bin/sh
# /init of the hw test VM (tests/hw/vm/run_hw_tests.sh): loads the modules, mounts the host's
# root read-only over 9p with tmpfs where the tests write, and runs /mnt/res/cmd.sh chrooted
# into it. Its exit status goes back in res/rc, the guest's kernel log in res/dmesg.txt.
export PATH=/bin
mount -t proc proc /proc
mount -t sysfs sysfs /sys
mount -t devtmpfs dev /dev
for m in $(cat /lib/modules/load.order); do
  insmod "/lib/modules/$m" || echo "hw-vm guest: insmod $m failed"
done
o=trans=virtio,version=9p2000.L,msize=512000
mount -t 9p -o "$o,cache=loose,ro" hostroot /mnt/host && mount -t 9p -o "$o" res /mnt/res ||
  { echo "hw-vm guest: 9p mounts failed"; poweroff -f; }
h=/mnt/host
mount -t proc proc $h/proc
mount -t sysfs sysfs $h/sys
mount -t configfs configfs $h/sys/kernel/config
mkdir -p /dev/pts /dev/shm
mount -t tmpfs tmpfs /dev/shm
mount -o bind /dev $h/dev
mount -t devpts devpts $h/dev/pts
for d in /run $(cat /mnt/res/tmpfs); do mount -t tmpfs tmpfs "$h$d"; done
mkdir -p $h/run/vmres && mount -o bind /mnt/res $h/run/vmres
ip link set lo up
echo "hw-vm guest: ready after $(cut -d' ' -f1 /proc/uptime) s"
chroot $h /bin/sh -c '/bin/sh /run/vmres/cmd.sh; echo $? > /run/vmres/rc'
echo "hw-vm guest: done after $(cut -d' ' -f1 /proc/uptime) s"
dmesg > /mnt/res/dmesg.txt
sync
umount /mnt/res
poweroff -f
