#!/usr/bin/env python3
"""The soak with injected faults (docs/reliability.md). Started by tools/soak.sh, which puts it in a
mount namespace of its own with the recordings on a small tmpfs; run that, not this.

Runs the real posefaird with 16 streams at 1 kHz (synthetic, serial through pseudo-terminals fed
from here, a pose file replayed, a CAN candump log replayed), the recorder on, a receiver of its
own that checks every sequence number, and injects on a schedule: SIGHUP with good and bad
configs, a serial unplug, a full recording volume, SIGKILL and a restart, subscriber churn, a
CLOCK_REALTIME step (libfaketime, the host clock untouched) and CPU starvation. Prints one line
per check and a table per fault; exits 1 when a check fails.
"""
import argparse
import errno
import json
import os
import re
import select
import signal
import socket
import struct
import subprocess
import sys
import threading
import time
import tty
import zlib
from math import cos, pi, sin

REPO = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
DEMO_CSV = os.path.join(REPO, "data/demo/broad-07-excerpt.csv")  # 285.7 Hz
CANDUMP = os.path.join(REPO, "tests/fuzz/corpus/candump_log/posefair_can_bus.log")  # 100 Hz
SYNTHETIC = range(1, 11)
SERIAL = (11, 12)
POSE_FILE = (13, 14)
CAN = (15, 16)
RATE_HZ = 1000.0
SO_RXQ_OVFL = 40

checks = []  # (ok, name, detail)


def check(ok, name, detail=""):
    checks.append((bool(ok), name, detail))
    print(f"  [{'PASS' if ok else 'FAIL'}] {name}{': ' + detail if detail else ''}", flush=True)
    return ok


def free_udp_port():
    s = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    s.bind(("127.0.0.1", 0))
    port = s.getsockname()[1]
    s.close()
    return port


# ------------------------------------------------------------------------------------------------
# Configurations

def config_text(a, variant):
    """The soak's configuration; variant 0 and 1 are good (they differ in the engine's window),
    2.. are bad in different ways (a reload must refuse them)."""
    window_time = 0.5 if variant % 2 == 0 else 0.25
    t = ["[logging]", "status_interval = 0", "",
         "[engine]", f"window_time = {window_time}", ""]
    if variant == 2:
        t += ["[engine]", "window_time = 0.5", ""]  # a table twice: a TOML error
    for i in SYNTHETIC:
        t += ["[[stream]]", f"id = {i}", f'name = "synthetic{i}"',
              f"driver = {{ type = \"synthetic\", rate_hz = {RATE_HZ}, seed = {i}, phase = {(i - 1) / 10} }}", ""]
    for i in SERIAL:
        t += ["[[stream]]", f"id = {i}", f'name = "serial{i}"',
              f'driver = {{ type = "serial", device = "{a.work}/tty{i}", protocol = "posefair", '
              f'reconnect_min = 0.05, reconnect_max = 0.2 }}', f"engine = {{ rate_hz = {RATE_HZ} }}", ""]
    for i in POSE_FILE:
        path = DEMO_CSV if variant != 3 else DEMO_CSV + ".missing"
        t += ["[[stream]]", f"id = {i}", f'name = "posefile{i}"',
              f'driver = {{ type = "replay", path = "{path}", speed = 3.5, loop = true }}', ""]
    for i in CAN:
        t += ["[[stream]]", f"id = {i}", f'name = "can{i}"',
              f'driver = {{ type = "replay", candump = "{CANDUMP}", protocol = "posefair-can", speed = 10.0, '
              f'loop = true, time_source = "receive" }}', ""]
    t += ["[[output]]", f'destinations = ["127.0.0.1:{a.receiver_port}"]', ""]
    t += ["[recorder]", f'path = "{a.recordings}/soak-%Y%m%d-%H%M%S.pflog"', f"max_file_bytes = {4 << 20}",
          "flush_interval = 0.5", ""]
    t += ["[subscription]", f'listen = "127.0.0.1:{a.subscription_port}"', "max_lease = 5", "max_per_address = 8", ""]
    t += ["[control]", f'socket = "{a.work}/control.sock"', ""]
    if variant == 4:
        t += ["[daemon]", "no_such_key = 1"]
    return "\n".join(t) + "\n"


def write_config(a, variant):
    tmp = a.config + ".tmp"
    with open(tmp, "w") as f:
        f.write(config_text(a, variant))
    os.replace(tmp, a.config)


# ------------------------------------------------------------------------------------------------
# Serial devices: pseudo-terminals fed at 1 kHz with $PFQ sentences, by a process of their own
# (in this one they would wait for the receiver thread's share of the interpreter lock)

def pfq_sentence(k):
    a = 0.6 * sin(2 * pi * 0.3 * k / RATE_HZ)
    body = "PFQ,%d,%.7f,0.0000000,0.0000000,%.7f" % ((k * 1000) & 0xFFFFFFFF, cos(a / 2), sin(a / 2))
    x = 0
    for c in body.encode():
        x ^= c
    return "$%s*%02X\r\n" % (body, x)


def serial_feeder(work):
    """The devices: commands 'unplug N', 'plug N' and 'stop' on stdin, answered on stdout. A
    device holds what the port does not take yet in a 64 KiB FIFO, as a UART's driver would, and
    counts the samples that overflow it (the host did not read for that long)."""
    masters, pending = {}, {i: b"" for i in SERIAL}
    sent, overflowed = {i: 0 for i in SERIAL}, {i: 0 for i in SERIAL}

    def plug(i):
        master, slave = os.openpty()
        tty.setraw(slave)
        name = os.ttyname(slave)
        os.close(slave)
        os.set_blocking(master, False)
        link = f"{work}/tty{i}"
        if os.path.lexists(link + ".new"):
            os.unlink(link + ".new")
        os.symlink(name, link + ".new")
        os.replace(link + ".new", link)
        masters[i] = master
        pending[i] = b""

    def unplug(i):
        os.unlink(f"{work}/tty{i}")
        os.close(masters.pop(i))

    for i in SERIAL:
        plug(i)
    k, t0, commands = 0, time.monotonic(), b""
    while True:
        r, _, _ = select.select([0], [], [], max(0.0, t0 + (k + 1) / RATE_HZ - time.monotonic()))
        if r:
            commands += os.read(0, 256)
            while b"\n" in commands:
                line, commands = commands.split(b"\n", 1)
                verb, *arg = line.decode().split()
                if verb == "stop":
                    print(json.dumps({"sent": sent, "overflowed": overflowed}), flush=True)
                    return 0
                (unplug if verb == "unplug" else plug)(int(arg[0]))
                print("ok", flush=True)
        lines = []
        while t0 + k / RATE_HZ <= time.monotonic():
            lines.append(pfq_sentence(k))
            k += 1
        data = "".join(lines).encode()
        for i, m in masters.items():
            if len(pending[i]) + len(data) > 65536:
                overflowed[i] += len(lines)
            else:
                pending[i] += data
                sent[i] += len(lines)
            try:
                n = os.write(m, pending[i]) if pending[i] else 0
                pending[i] = pending[i][n:]
            except BlockingIOError:
                pass


class SerialDevices:
    def __init__(self, work):
        self.proc = subprocess.Popen([sys.executable, os.path.abspath(__file__), "--serial-feeder", work],
                                     stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True)
        self.stats = {}

    def command(self, text):
        self.proc.stdin.write(text + "\n")
        self.proc.stdin.flush()
        return self.proc.stdout.readline().strip()

    def plug(self, i):
        self.command(f"plug {i}")

    def unplug(self, i):
        self.command(f"unplug {i}")

    def close(self):
        if self.proc.poll() is None:
            self.stats = json.loads(self.command("stop") or "{}")
            self.proc.wait()


# ------------------------------------------------------------------------------------------------
# The receiver: every datagram of the configured output, every sequence number checked

class SocketReader:
    """A thread that hands every datagram of `sock` and its ancillary data to handle()."""

    def __init__(self, sock, size, ancillary):
        self.sock, self.size, self.ancillary = sock, size, ancillary
        self.sock.settimeout(0.2)
        self.stop = False
        self.thread = threading.Thread(target=self.run, daemon=True)
        self.thread.start()

    def run(self):
        while not self.stop:
            try:
                data, anc, _, _ = self.sock.recvmsg(self.size, self.ancillary)
            except socket.timeout:
                continue
            self.handle(data, anc)

    def close(self):
        self.stop = True
        self.thread.join()


class Receiver(SocketReader):
    HEADER = struct.Struct("<4sBBHIIQdd")

    def __init__(self, phase):
        self.phase = phase
        self.sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        try:
            self.sock.setsockopt(socket.SOL_SOCKET, 33, 32 << 20)  # SO_RCVBUFFORCE (root)
        except OSError:
            self.sock.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, 32 << 20)
        self.sock.setsockopt(socket.SOL_SOCKET, SO_RXQ_OVFL, 1)
        self.sock.bind(("127.0.0.1", 0))
        self.port = self.sock.getsockname()[1]
        self.streams = {}  # (session, stream) -> dict
        self.per_phase = {}  # phase -> dict(datagrams, max sample gap, send offsets)
        self.overflow = 0  # datagrams the kernel dropped at this socket (SO_RXQ_OVFL)
        self.malformed = 0
        super().__init__(self.sock, 2048, socket.CMSG_SPACE(4))

    def handle(self, data, anc):
        for level, kind, value in anc:
            if level == socket.SOL_SOCKET and kind == SO_RXQ_OVFL and len(value) >= 4:
                self.overflow = struct.unpack("<I", value[:4])[0]
        if len(data) < 56 or data[:4] != b"PFP1":
            self.malformed += 1
            return
        _, _, _, _, session, stream, seq, sample_time, send_time = self.HEADER.unpack_from(data)
        now = time.time()
        ph = self.per_phase.setdefault(self.phase[0], {"datagrams": 0, "max_gap": 0.0, "offset_min": 0.0, "offset_max": 0.0})
        ph["datagrams"] += 1
        offset = send_time - now
        ph["offset_min"] = min(ph["offset_min"], offset)
        ph["offset_max"] = max(ph["offset_max"], offset)
        s = self.streams.get((session, stream))
        if s is None:
            self.streams[(session, stream)] = {"first": seq, "last": seq, "count": 1, "gaps": 0, "back": 0,
                                                "time": sample_time, "time_back": 0}
            return
        s["count"] += 1
        if seq > s["last"]:
            s["gaps"] += seq - s["last"] - 1
            s["last"] = seq
        else:
            s["back"] += 1  # a duplicate or a reordered datagram
        if sample_time <= s["time"]:
            s["time_back"] += 1
        elif stream in SYNTHETIC:
            ph["max_gap"] = max(ph["max_gap"], sample_time - s["time"])
        s["time"] = max(s["time"], sample_time)

    def close(self):
        time.sleep(0.5)  # the datagrams still in flight (the daemon has stopped)
        super().close()


# ------------------------------------------------------------------------------------------------
# The notify socket: READY=1, WATCHDOG=1, STATUS=... with the sender's pid (SO_PASSCRED)

class NotifySocket(SocketReader):
    def __init__(self, path, phase):
        self.phase = phase
        self.messages = []  # (monotonic time, pid, phase, text)
        sock = socket.socket(socket.AF_UNIX, socket.SOCK_DGRAM)
        sock.setsockopt(socket.SOL_SOCKET, socket.SO_PASSCRED, 1)
        sock.bind(path)
        super().__init__(sock, 8192, socket.CMSG_SPACE(12))

    def handle(self, data, anc):
        pid = 0
        for level, kind, value in anc:
            if level == socket.SOL_SOCKET and kind == socket.SCM_CREDENTIALS:
                pid = struct.unpack("<iII", value[:12])[0]
        self.messages.append((time.monotonic(), pid, self.phase[0], data.decode(errors="replace")))

    def wait_for(self, pid, text, timeout):
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline:
            if any(p == pid and text in m for _, p, _, m in list(self.messages)):
                return True
            time.sleep(0.05)
        return False



# ------------------------------------------------------------------------------------------------
# The daemon, its counters (posefair ctl), its memory and descriptors

class Daemon:
    def __init__(self, a, index):
        env = dict(os.environ)
        env.update(NOTIFY_SOCKET=a.notify, WATCHDOG_USEC=str(a.watchdog_usec))
        env.pop("WATCHDOG_PID", None)
        if a.faketime_lib:
            env.update(LD_PRELOAD=a.faketime_lib, FAKETIME_TIMESTAMP_FILE=a.faketime_file,
                       FAKETIME_DONT_FAKE_MONOTONIC="1", FAKETIME_NO_CACHE="1")
            # ASan wants to be the first library; libfaketime only wraps the clock calls.
            env["ASAN_OPTIONS"] = ":".join(x for x in (env.get("ASAN_OPTIONS", ""), "verify_asan_link_order=0") if x)
        self.log_path = f"{a.work}/posefaird-{index}.log"
        self.log = open(self.log_path, "w")
        self.proc = subprocess.Popen([a.posefaird, "-c", a.config, "--log-target", "stderr"], env=env,
                                     stdout=self.log, stderr=subprocess.STDOUT)
        self.pid = self.proc.pid
        self.started = time.monotonic()
        self.ended = None

    def text(self):
        with open(self.log_path, errors="replace") as f:
            return f.read()

    def count(self, needle):
        return self.text().count(needle)

    def wait_log(self, needle, occurrences, timeout):
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline:
            if self.count(needle) >= occurrences:
                return True
            if self.proc.poll() is not None:
                return self.count(needle) >= occurrences
            time.sleep(0.05)
        return False


def proc_sample(pid):
    """(RSS in KiB, number of open descriptors, what they are)."""
    try:
        with open(f"/proc/{pid}/status") as f:
            rss = next(int(l.split()[1]) for l in f if l.startswith("VmRSS:"))
        targets = []
        for fd in os.listdir(f"/proc/{pid}/fd"):
            try:
                targets.append(os.readlink(f"/proc/{pid}/fd/{fd}"))
            except OSError:
                pass
        return rss, len(targets), sorted(re.sub(r"\[\d+\]|/dev/pts/\d+", "", t) for t in targets)
    except (OSError, StopIteration):
        return None


def ctl(a, *command):
    try:
        r = subprocess.run([a.posefair, "ctl", "--socket", f"{a.work}/control.sock", "--json", *command],
                           capture_output=True, text=True, timeout=5)
        return json.loads(r.stdout) if r.stdout.strip() else None
    except (subprocess.TimeoutExpired, json.JSONDecodeError):
        return None


class Monitor:
    """Once a second: RSS and descriptors of the running daemon, its counters, the recordings'
    retention (older parts deleted: a 30-minute run does not fit the small volume)."""

    def __init__(self, a, phase):
        self.a = a
        self.phase = phase
        self.daemon = None
        self.samples = []  # (t, phase, pid, rss_kib, fds)
        self.counters = []  # (t, phase, pid, streams list)
        self.retention = True
        self.ctl_failures = 0
        self.stop = False
        self.thread = threading.Thread(target=self.run, daemon=True)
        self.thread.start()

    def run(self):
        while not self.stop:
            t = time.monotonic()
            d = self.daemon
            if d is not None and d.proc.poll() is None:
                s = proc_sample(d.pid)
                if s:
                    self.samples.append((t, self.phase[0], d.pid, s[0], s[1], s[2]))
                reply = ctl(self.a, "counters")
                if reply and reply.get("ok"):
                    self.counters.append((t, self.phase[0], d.pid, reply["streams"]))
                elif d.proc.poll() is None:
                    self.ctl_failures += 1
            if self.retention:
                parts = sorted((os.path.getmtime(p), p) for p in recordings(self.a))
                for _, p in parts[:-2]:
                    try:
                        os.unlink(p)
                    except OSError:
                        pass
            time.sleep(max(0.0, t + 1.0 - time.monotonic()))

    def latest(self, pid):
        for t, ph, p, streams in reversed(self.counters):
            if p == pid:
                return {s["id"]: s for s in streams}
        return None


def recordings(a):
    return [os.path.join(a.recordings, n) for n in os.listdir(a.recordings) if n.endswith(".pflog")]


# ------------------------------------------------------------------------------------------------
# A sample log read independently of posefair's reader (docs/recording.md)

def read_pflog(path):
    with open(path, "rb") as f:
        b = f.read()
    if b[:8] != b"PFLOG\x00\x00\x01":
        return None, 0, "bad magic"
    h = struct.unpack_from("<H", b, 10)[0]
    if zlib.crc32(b[:h - 4]) != struct.unpack_from("<I", b, h - 4)[0]:
        return None, 0, "header CRC"
    at, records = h, 0
    while at < len(b):
        if len(b) - at < 9:
            return records, at, "truncated record"
        length, kind = struct.unpack_from("<IB", b, at)
        if length > 1 << 20:
            return records, at, "corrupt length"
        if at + 9 + length > len(b):
            return records, at, "truncated record"
        if zlib.crc32(b[at + 4:at + 5 + length]) != struct.unpack_from("<I", b, at + 5 + length)[0]:
            return records, at, "record CRC mismatch"
        records += 1
        at += 9 + length
    return records, at, ""


# ------------------------------------------------------------------------------------------------
# Counter lines in the daemon's log: the drained pipelines' exact accounting

COUNTER_LINE = re.compile(r"stream (\S+) \(id (\d+), .*?\): received (\d+)[ ,].*?dropped \d+ \(ring (\d+), publish (\d+)\), "
                          r"rejected (\d+), out-of-order (\d+), (?:raw-only (\d+) .*?, )?emitted (\d+), .*?published (\d+), "
                          r"send failures (\d+), recorded (\d+) \(dropped (\d+)\)")
SESSION = re.compile(r"(?:started|reloaded): .*session ([0-9a-f]{8})")


def drained_pipelines(log):
    """[(session, {id: counters})] of every pipeline whose counters were logged as it ended (at a
    reload or at SIGTERM); the counters follow 'reloading' or 'draining' and precede the next
    session's line."""
    out, session, block, draining = [], None, {}, False
    for line in log.splitlines():
        m = SESSION.search(line)
        if m:
            if draining and block:
                out.append((session, block))
            session, block, draining = m.group(1), {}, False
            continue
        if "reloading " in line or "draining and stopping" in line:
            draining = True
            continue
        if "reload refused" in line:
            draining = False
            continue
        m = COUNTER_LINE.search(line)
        if m and draining:
            g = [int(x) if x is not None and x.isdigit() else 0 for x in m.groups()[1:]]
            block[g[0]] = dict(received=g[1], ring=g[2], publish=g[3], rejected=g[4], out_of_order=g[5], raw=g[6],
                               emitted=g[7], published=g[8], send_failures=g[9], recorded=g[10], record_dropped=g[11])
        if "exiting" in line and draining and block:
            out.append((session, block))
            block, draining = {}, False
    return out


# ------------------------------------------------------------------------------------------------
# The faults

class Soak:
    def __init__(self, a):
        self.a = a
        self.phase = ["start"]
        self.phases = []  # [name, t0, t1, loadavg at the end, key]; key = name#index, one per occurrence
        self.busy = []
        self.churn_results = []
        self.killed_sessions = set()
        self.daemons = []

    def enter(self, name):
        self.phase[0] = f"{name}#{len(self.phases)}"
        self.phases.append([name, time.monotonic(), None, None, self.phase[0]])
        print(f"soak: {time.monotonic() - self.t0:6.1f} s  {name}", flush=True)

    def leave(self):
        self.phases[-1][2] = time.monotonic()
        with open("/proc/loadavg") as f:
            self.phases[-1][3] = float(f.read().split()[0])

    def start_daemon(self):
        d = Daemon(self.a, len(self.daemons) + 1)
        self.daemons.append(d)
        ok = self.notify.wait_for(d.pid, "READY=1", 30)
        check(ok, f"daemon {len(self.daemons)} ready (READY=1)", "" if ok else d.text()[-2000:])
        if not ok:
            raise SystemExit(self.report())
        self.monitor.daemon = d
        return d

    @property
    def d(self):
        return self.daemons[-1]

    def session(self):
        r = ctl(self.a, "status")
        return r.get("session") if r else None

    def run(self):
        a = self.a
        self.t0 = time.monotonic()
        with open(a.faketime_file, "w") as f:
            f.write("+0\n")
        self.serial = SerialDevices(a.work)
        self.receiver = Receiver(self.phase)
        a.receiver_port = self.receiver.port
        a.subscription_port = free_udp_port()
        write_config(a, 0)
        self.notify = NotifySocket(a.notify, self.phase)
        self.monitor = Monitor(a, self.phase)
        end = self.t0 + a.duration
        try:
            self.enter("warm-up")
            self.start_daemon()
            time.sleep(4)
            self.leave()
            self.fault_kill()
            cycle = 0
            while True:
                cycle += 1
                self.quiet(f"baseline", 5)
                for fault in (self.fault_sighup, self.fault_serial, self.fault_disk_full, self.fault_churn,
                              self.fault_clock_step, self.fault_starvation):
                    fault()
                if time.monotonic() + 50 > end:
                    break
            self.quiet("tail", 4)
            self.enter("stop")
            self.d.proc.send_signal(signal.SIGTERM)
            try:
                status = self.d.proc.wait(60)
            except subprocess.TimeoutExpired:
                self.d.proc.kill()
                status = "timeout"
            self.d.ended = time.monotonic()
            self.leave()
            check(status == 0, "SIGTERM: drained and exited 0 (under ASan: no leak reported)",
                  f"exit {status}" + ("" if status == 0 else "\n" + self.d.text()[-3000:]))
        finally:
            for p in self.busy:
                p.kill()
            for d in self.daemons:
                if d.proc.poll() is None:
                    d.proc.kill()
                    d.proc.wait()
            self.monitor.stop = True
            self.serial.close()
            self.receiver.close()
            self.notify.close()
        return self.report()

    def quiet(self, name, seconds):
        self.enter(name)
        time.sleep(seconds)
        self.leave()

    def fault_kill(self):
        self.enter("sigkill+restart")
        old = self.d
        self.monitor.retention = False
        self.killed_sessions.add(self.session())
        old.proc.send_signal(signal.SIGKILL)
        old.proc.wait()
        old.ended = time.monotonic()
        parts = sorted(recordings(self.a))
        # The recording of the killed daemon: every part whole, the last one up to its last
        # complete record.
        problems, records = [], 0
        for p in parts:
            n, _, why = read_pflog(p)
            records += n or 0
            if why and (p != parts[-1] or why not in ("truncated record",)):
                problems.append(f"{os.path.basename(p)}: {why}")
        check(parts and not problems, "SIGKILL: the killed daemon's recording reads up to its last complete record",
              f"{len(parts)} parts, {records} records" + (f"; {problems}" if problems else ""))
        # posefair's own reader: a replay of the last part loads (posefaird --check).
        cfg = f"{self.a.work}/replay-check.toml"
        with open(cfg, "w") as f:
            f.write(f'[[stream]]\nid = 1\nname = "killed"\ndriver = {{ type = "replay", path = "{parts[-1]}", source_stream = 1 }}\n')
        r = subprocess.run([self.a.posefaird, "--check", "-c", cfg], capture_output=True, text=True)
        check(r.returncode == 0, "SIGKILL: posefaird replays the killed recording", (r.stdout + r.stderr).strip()[-300:])
        time.sleep(0.1)  # RestartSec's default
        self.start_daemon()
        for p in parts:
            os.unlink(p)
        self.monitor.retention = True
        time.sleep(2)
        self.leave()

    def fault_sighup(self):
        self.enter("sighup")
        d = self.d
        good0, bad0 = d.count("reloaded: "), d.count("reload refused")
        good = bad = 0
        for variant in (1, 2, 0, 3, 1, 4):  # 0, 1 good; 2 a TOML error, 3 a missing replay file, 4 an unknown key
            write_config(self.a, variant)
            before = self.session()
            got = self.receiver.per_phase.get(self.phase[0], {}).get("datagrams", 0)
            d.proc.send_signal(signal.SIGHUP)
            if variant in (0, 1):
                good += 1
                d.wait_log("reloaded: ", good0 + good, 20)
            else:
                bad += 1
                d.wait_log("reload refused", bad0 + bad, 20)
                time.sleep(0.5)
                after = self.session()
                check(after == before and self.receiver.per_phase.get(self.phase[0], {}).get("datagrams", 0) > got,
                      f"SIGHUP with a bad config (variant {variant}) refused, the session kept and poses flowing",
                      f"session {before} -> {after}")
            time.sleep(1.0)
        write_config(self.a, 0)
        d.proc.send_signal(signal.SIGHUP)
        good += 1
        ok = d.wait_log("reloaded: ", good0 + good, 20)
        check(ok and d.count("reloaded: ") - good0 == good and d.count("reload refused") - bad0 == bad,
              "SIGHUP: every good config taken, every bad one refused",
              f"{good} good, {bad} bad")
        time.sleep(1.5)
        self.leave()

    def counters(self):
        """{stream id: counters} now, from the control socket ({} when it does not answer)."""
        r = ctl(self.a, "counters")
        return {x["id"]: x for x in r["streams"]} if r and r.get("ok") else {}

    def received(self, stream):
        return self.counters().get(stream, {}).get("received", 0)

    def fault_serial(self):
        self.enter("serial-unplug")
        d = self.d
        i = SERIAL[0]
        lost = f"stream 'serial{i}': lost the device"
        lost0 = d.count(lost)
        self.serial.unplug(i)
        d.wait_log(lost, lost0 + 1, 5)
        time.sleep(1.0)
        before = self.received(i)
        self.serial.plug(i)
        deadline = time.monotonic() + 30  # a pty carries 4 KiB: on a machine loaded far beyond its cores it crawls
        after = before
        while time.monotonic() < deadline and after < before + 50:
            time.sleep(0.5)
            after = self.received(i)
        lines0 = d.count(f"stream serial{i} ")
        d.proc.send_signal(signal.SIGUSR1)
        d.wait_log(f"stream serial{i} ", lines0 + 1, 5)
        lines = [l for l in d.text().splitlines() if f"stream serial{i} " in l and "device " in l]
        last = lines[-1] if lines else ""
        link = last[last.find("device "):last.find(", read errors")]
        check(d.count(lost) == lost0 + 1 and "device connected, outages 1, reconnects 1" in last and after >= before + 50,
              "serial unplug: one outage, then samples resume", f"received {before} -> {after} after the replug; {link}")
        self.leave()

    def fault_disk_full(self):
        self.enter("disk-full")
        d = self.d
        a = self.a
        self.monitor.retention = False
        full0, again0 = d.count("cannot write: No space left on device"), d.count("writing again")
        c0 = self.counters()
        filler = f"{a.recordings}/filler"
        fd = os.open(filler, os.O_WRONLY | os.O_CREAT | os.O_TRUNC, 0o644)
        for chunk in (1 << 20, 4096, 512):
            try:
                while True:
                    os.write(fd, b"\0" * chunk)
            except OSError as e:
                if e.errno != errno.ENOSPC:
                    raise
        os.close(fd)
        full = d.wait_log("cannot write: No space left on device", full0 + 1, 10)
        time.sleep(3)
        c1 = self.counters()
        os.unlink(filler)
        again = d.wait_log("writing again", again0 + 1, 10)
        time.sleep(2)
        c2 = self.counters()
        self.monitor.retention = True
        drops = sum(c1[i]["record_dropped"] - c0[i]["record_dropped"] for i in c1 if i in c0)
        resumed = all(c2[i]["recorded"] > c1[i]["recorded"] for i in SYNTHETIC if i in c1 and i in c2) and len(c2) == 16
        check(full and again and d.count("cannot write: ") == full0 + 1 and resumed and drops > 0,
              "disk full: one log line, recorder drops counted, recording resumes when space returns",
              f"recorder drops {drops} while full; logged {d.count('cannot write: ') - full0}x full, "
              f"{d.count('writing again') - again0}x again")
        self.leave()

    def fault_churn(self):
        self.enter("subscriber-churn")
        a = self.a
        procs = []
        for k in range(12):
            procs.append(subprocess.Popen(
                [a.posefair, "sub", "--subscribe", f"127.0.0.1:{a.subscription_port}", "--listen", "127.0.0.1:0",
                 "--streams", str(SYNTHETIC[k % len(SYNTHETIC)]), "--quiet", "--stats", "--duration", "1.5", "--lease", "2"],
                stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True))
            time.sleep(0.35)
        bad = []
        for p in procs:
            out = p.communicate(timeout=20)[0]
            m = re.search(r"received (\d+), lost (\d+)", out)
            if p.returncode != 0 or not m or int(m.group(1)) == 0 or int(m.group(2)) != 0:
                bad.append(f"exit {p.returncode}: {out.strip()[-200:]}")
        time.sleep(3)  # the leases end
        subs = ctl(a, "subscribers")
        left = len(subs["subscribers"]) if subs and subs.get("ok") else None
        check(not bad and left == 0, "subscriber churn: 12 subscribers served in turn (poses, none lost), none left afterwards",
              f"{len(bad)} failed, {left} left" + (f"; {bad[:2]}" if bad else ""))
        self.leave()

    def fault_clock_step(self):
        self.enter("clock-step")
        a = self.a
        c0 = self.counters()
        for offset in ("+3600", "-3600", "+0"):
            with open(a.faketime_file, "w") as f:
                f.write(offset + "\n")
            time.sleep(2.5)
        c1 = self.counters()
        ph = self.receiver.per_phase.get(self.phase[0], {})
        both = [i for i in SYNTHETIC if i in c0 and i in c1]
        delta = lambda i, k: c1[i][k] - c0[i][k]
        # A jump of the synthetic drivers' monotonic clock would restart their windows (a step of
        # more than 0.25 s in sample time) without any drop, and move sample times by the step
        # (3600 s). A starved daemon also restarts windows, but after counted ring drops (the
        # samples in between are gone), and leaves steps of the starvation's length.
        moved = {i: delta(i, "restarts") + delta(i, "out_of_order") for i in both}
        unexplained = [i for i in both if moved[i] > 0 and delta(i, "ring_dropped") == 0]
        dropped = sum(delta(i, "ring_dropped") + delta(i, "publish_dropped") for i in both)
        stepped = ph.get("offset_max", 0) > 3000 and ph.get("offset_min", 0) < -3000
        check(stepped, "clock step: the daemon's CLOCK_REALTIME stepped +1 h and -1 h (send times seen)",
              f"send time - real time from {ph.get('offset_min', 0):.0f} s to {ph.get('offset_max', 0):.0f} s")
        gap = ph.get("max_gap", 1)
        check(len(both) == len(SYNTHETIC) and not unexplained and (gap < 0.05 or (dropped > 0 and gap < 60)),
              "clock step: nothing on the monotonic clock moved (no window restart or sample-time step but after counted drops)",
              f"restarts + out-of-order {sum(moved.values())} (without a ring drop: streams {unexplained}); "
              f"largest sample-time step at the receiver {gap * 1000:.1f} ms, {dropped} poses dropped (counted) meanwhile")
        self.leave()

    def fault_starvation(self):
        self.enter("cpu-starvation")
        n = 3 * (os.cpu_count() or 2)
        self.busy = [subprocess.Popen(["sh", "-c", "while :; do :; done"]) for _ in range(n)]
        time.sleep(6)
        for p in self.busy:
            p.kill()
            p.wait()
        self.busy = []
        time.sleep(1)
        self.leave()

    # --------------------------------------------------------------------------------------------
    def report(self):
        a = self.a
        print("\nsoak: report", flush=True)
        logs = [(d, d.text()) for d in self.daemons]
        # Accounting of every drained pipeline (each reload and the final stop): exact.
        drained, bad = 0, []
        published = {}
        for d, text in logs:
            for session, block in drained_pipelines(text):
                for i, c in block.items():
                    drained += 1
                    published[(int(session, 16), i)] = c
                    engine = c["ring"] + c["rejected"] + c["out_of_order"] + c["raw"] + c["emitted"]
                    if c["received"] != engine or c["emitted"] != c["published"] + c["publish"] or \
                            c["received"] != c["recorded"] + c["record_dropped"]:
                        bad.append(f"session {session} stream {i}: {c}")
        check(drained >= 16 and not bad, "accounting: received = dropped by reason + emitted, emitted = published + dropped, "
              "received = recorded + recorder drops, for every stream of every drained pipeline",
              f"{drained} stream pipelines checked" + (f"; {bad[:3]}" if bad else ""))
        # Every sequence number at the receiver: lost ones only where a counter says so.
        missing = back = time_back = 0
        send_failures = sum(c["send_failures"] for c in published.values())
        for (session, stream), s in self.receiver.streams.items():
            back += s["back"]
            time_back += s["time_back"]
            c = published.get((session, stream))
            if c is not None:
                missing += c["published"] - s["count"] + s["back"]
            else:  # the killed daemon's session, or a pipeline whose end was not logged: gaps only
                missing += s["gaps"] + s["first"]
        check(back == 0 and time_back == 0, "receiver: no duplicate, reordered or backward datagram",
              f"{back} out of sequence, {time_back} sample times not increasing")
        check(missing <= send_failures + self.receiver.overflow and self.receiver.malformed == 0,
              "receiver: every sequence number arrived, or a counter accounts for it",
              f"{sum(s['count'] for s in self.receiver.streams.values())} datagrams in "
              f"{len(self.receiver.streams)} (session, stream) pairs; missing {missing}, send failures {send_failures}, "
              f"dropped at the receiving socket (SO_RXQ_OVFL) {self.receiver.overflow}")
        # The watchdog: per daemon, no interval between WATCHDOG=1 (from READY=1 to its end) longer
        # than WATCHDOG_USEC.
        worst = 0.0
        for d in self.daemons:
            times = [t for t, p, _, m in self.notify.messages if p == d.pid and "WATCHDOG=1" in m]
            ready = next((t for t, p, _, m in self.notify.messages if p == d.pid and "READY=1" in m), d.started)
            stops = [t for t, p, _, m in self.notify.messages if p == d.pid and "STOPPING=1" in m]
            end = stops[0] if stops else (d.ended or time.monotonic())
            points = [ready] + [t for t in times if t < end] + [end]
            worst = max([worst] + [b - a_ for a_, b in zip(points, points[1:])])
        check(worst < a.watchdog_usec / 1e6, "watchdog: never missed",
              f"longest interval between WATCHDOG=1 {worst:.2f} s (WATCHDOG_USEC {a.watchdog_usec / 1e6:.0f} s)")
        # Leaks: RSS and descriptors of the last daemon at the end of every phase from the end of
        # its first SIGHUP phase on. That phase is the warm-up: the first reloads free the first
        # pipeline's rings and glibc's malloc raises its mmap threshold, so the next pipelines'
        # rings stay in the heap (RSS steps up once, then stays).
        last = self.daemons[-1]
        ends = [ph[2] for ph in self.phases if ph[2]]
        first_hup = next((ph[2] for ph in self.phases if ph[0] == "sighup" and ph[2]), None)
        points = []
        for t in ends:
            s_ = [x for x in self.monitor.samples if x[2] == last.pid and x[0] <= t]
            if s_ and first_hup is not None and t >= first_hup and (last.ended is None or t < last.ended):
                points.append((s_[-1][3], s_[-1][4], s_[-1][5]))
        if len(points) >= 2:
            # RSS moves up and down by a few MiB with what the faults touch; a leak shows as the last
            # value above everything seen in the first third after the warm-up.
            early = max(p_[0] for p_ in points[:max(1, len(points) // 3)])
            growth = points[-1][0] - early
            fds = [p_[1] for p_ in points]
            extra = sorted(set(points[-1][2]) - set(points[0][2])) if points[-1][1] != points[0][1] else []
            # A phase may end while a device is being reopened or a client served: a transient
            # descriptor, one up or down, is no leak; a leak keeps the last phase ends above the first.
            first_third = fds[:max(1, len(fds) // 3)]
            check(min(fds[-3:]) <= max(first_third), "leaks: open descriptors flat after warm-up (the last phase ends not above the first third's)",
                  f"{fds}" + (f"; new: {extra}" if extra else ""))
            detail = (f"first {points[0][0]} KiB, largest in the first third {early} KiB, last {points[-1][0]} KiB "
                      f"({growth:+d} KiB; {len(points)} phase ends, range {min(p_[0] for p_ in points)}..{max(p_[0] for p_ in points)} KiB)")
            if a.asan:  # ASan's quarantine grows the RSS by design; LeakSanitizer checks at the exit
                print(f"  [INFO] leaks: RSS under ASan (not judged; LeakSanitizer runs at the exit): {detail}")
            else:
                check(growth <= 2048, "leaks: RSS flat after warm-up (the last at most 2 MiB above the first third's largest)", detail)
        else:
            check(False, "leaks: at least two phase ends sampled after warm-up", str(points))
        # Latency and drops per fault (every occurrence of a phase together): the daemon's STATUS=
        # p99 of each second, per stream; drops from the counters at the phase's start and end.
        print("\n| phase | times | s | load avg (max) | datagrams/s | p99 per second, median / max (µs) | ring drops | publish drops | recorder drops | RSS KiB, fds at the last end |")
        print("|---|---|---|---|---|---|---|---|---|---|")
        status = re.compile(r"(\S+) ([\d.]+)/s drop (\d+) p99 ([\d.]+)us")
        names = []
        for ph in self.phases:
            if ph[2] is not None and ph[0] not in names:
                names.append(ph[0])
        for name in names:
            runs = [ph for ph in self.phases if ph[0] == name and ph[2] is not None]
            seconds = sum(t1 - t0 for _, t0, t1, _, _ in runs)
            p99, drops, mem, datagrams = [], {"ring_dropped": 0, "publish_dropped": 0, "record_dropped": 0}, [], 0
            for _, t0, t1, _, key in runs:
                p99 += [float(m.group(4)) for t, _, _, msg in self.notify.messages if t0 <= t < t1 and msg.startswith("STATUS=")
                        for m in status.finditer(msg) if float(m.group(2)) > 0]
                cs = [c for c in self.monitor.counters if t0 <= c[0] <= t1]
                if len(cs) >= 2 and cs[0][2] == cs[-1][2]:
                    first = {x["id"]: x for x in cs[0][3]}
                    for k in drops:
                        drops[k] += sum(max(0, x[k] - first[x["id"]][k]) for x in cs[-1][3] if x["id"] in first)
                mem = [x for x in self.monitor.samples if t0 <= x[0] <= t1] or mem
                datagrams += self.receiver.per_phase.get(key, {}).get("datagrams", 0)
            p99.sort()
            p = f"{p99[len(p99) // 2]:.0f} / {p99[-1]:.0f}" if p99 else "–"
            print(f"| {name} | {len(runs)} | {seconds:.0f} | {max(r[3] for r in runs):.1f} | {datagrams / max(seconds, 0.001):.0f} | {p} |",
                  f"{drops['ring_dropped']} | {drops['publish_dropped']} | {drops['record_dropped']} |",
                  f"{mem[-1][3]}, {mem[-1][4]} |" if mem else "– |")
        rss = [x[3] for x in self.monitor.samples if x[2] == last.pid]
        fds = [x[4] for x in self.monitor.samples if x[2] == last.pid]
        if rss:
            print(f"\nsoak: daemon {last.pid}: RSS {min(rss)}..{max(rss)} KiB, descriptors {min(fds)}..{max(fds)}, "
                  f"{len(rss)} samples; control socket polls failed {self.monitor.ctl_failures}")
        print(f"soak: serial devices: samples sent {self.serial.stats.get('sent')}, lost in their full FIFO "
              f"(the port not read for 30 ms or more) {self.serial.stats.get('overflowed')}")
        failed = [c for c in checks if not c[0]]
        print(f"soak: {len(checks) - len(failed)} of {len(checks)} checks passed"
              + (": FAILED " + "; ".join(c[1] for c in failed) if failed else ""), flush=True)
        return 1 if failed else 0


def main():
    if len(sys.argv) == 3 and sys.argv[1] == "--serial-feeder":
        return serial_feeder(sys.argv[2])
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--duration", type=float, required=True)
    p.add_argument("--posefaird", required=True)
    p.add_argument("--posefair", required=True)
    p.add_argument("--work", required=True)
    p.add_argument("--recordings", required=True)
    p.add_argument("--faketime-lib", default="")
    p.add_argument("--watchdog-usec", type=int, default=10_000_000)
    p.add_argument("--asan", action="store_true", help="the daemon is an ASan build: RSS grows with its quarantine")
    a = p.parse_args()
    a.config = f"{a.work}/posefaird.toml"
    a.notify = f"{a.work}/notify.sock"
    a.faketime_file = f"{a.work}/faketime"
    return Soak(a).run()


if __name__ == "__main__":
    sys.exit(main())
