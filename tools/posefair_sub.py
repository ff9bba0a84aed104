#!/usr/bin/env python3
"""posefair_sub.py: a posefair wire protocol v1 subscriber in plain Python 3 (standard library only).

Receives posefair poses over UDP, binary v1 ("PFP1") and JSON lines alike, prints them, and
counts lost, reordered and duplicate datagrams per (session, stream), malformed ones by
reason, and latency. It behaves like `posefair sub` (same options, output formats, statistics
line and exit codes) and doubles as the reference decoder for other languages: see
docs/protocol.md, which is the specification.

    python3 tools/posefair_sub.py --listen 0.0.0.0:5700 --format csv --count 1000
    python3 tools/posefair_sub.py --group 239.255.80.70 --interface eth0
    python3 tools/posefair_sub.py --subscribe 127.0.0.1:5710 --streams 1,2 --encoding json

The decoding functions (decode_binary, decode_json, decode) can be imported:
    from posefair_sub import decode, DecodeError
"""

import argparse
import hashlib
import hmac
import json
import math
import random
import signal
import socket
import struct
import sys
import time

# --- Protocol constants (docs/protocol.md) --------------------------------------------------------
MAGIC = b"PFP1"
VERSION = 1
HEADER_SIZE = 56
MAX_DATAGRAM_SIZE = 1500
DEFAULT_PORT = 5700
MAX_QUATERNION_NORM_ERROR = 1e-3

FLAG_POSITION = 1 << 0
FLAG_ANGULAR_VELOCITY = 1 << 1
FLAG_CLAMPED = 1 << 2
FLAG_BRIDGED = 1 << 3
KNOWN_FLAGS = FLAG_POSITION | FLAG_ANGULAR_VELOCITY | FLAG_CLAMPED | FLAG_BRIDGED

# magic, version, header length, flags, session, stream, sequence, sample time, send time, reserved
HEADER = struct.Struct("<4sBBHIIQdd16x")
assert HEADER.size == HEADER_SIZE

# Rejection reasons, in the order the C++ DecodeError enumerates them (and the stats line lists them).
REASONS = [
    "too-short",
    "oversized",
    "bad-magic",
    "bad-version",
    "bad-header-length",
    "length-mismatch",
    "unknown-flags",
    "non-finite",
    "bad-quaternion",
    "json-syntax",
    "json-schema",
]

EXIT_OK = 0
EXIT_USAGE = 64  # EX_USAGE
EXIT_UNAVAILABLE = 69  # EX_UNAVAILABLE


class DecodeError(Exception):
    """A rejected datagram; .reason is one of REASONS."""

    def __init__(self, reason):
        super().__init__(reason)
        self.reason = reason


class Pose:
    """One decoded pose. q = (w, x, y, z); p and w are (x, y, z) tuples or None."""

    __slots__ = ("session", "stream", "seq", "t", "sent", "q", "p", "w", "flags")

    def __init__(self, session, stream, seq, t, sent, q, p, w, flags):
        self.session, self.stream, self.seq = session, stream, seq
        self.t, self.sent, self.q, self.p, self.w, self.flags = t, sent, q, p, w, flags

    @property
    def clamped(self):
        return bool(self.flags & FLAG_CLAMPED)

    @property
    def bridged(self):
        return bool(self.flags & FLAG_BRIDGED)


def payload_size(flags):
    n = 32
    if flags & FLAG_POSITION:
        n += 24
    if flags & FLAG_ANGULAR_VELOCITY:
        n += 24
    return n


def _check_semantics(pose, unknown_flag=False, non_finite=False):
    """The checks after parsing, in the specification's order."""
    if unknown_flag or pose.flags & ~KNOWN_FLAGS:
        raise DecodeError("unknown-flags")
    numbers = [pose.t, pose.sent, *pose.q, *(pose.p or ()), *(pose.w or ())]
    if non_finite or not all(math.isfinite(v) for v in numbers):
        raise DecodeError("non-finite")
    norm = math.sqrt(sum(c * c for c in pose.q))
    if not abs(norm - 1.0) <= MAX_QUATERNION_NORM_ERROR:  # also catches an overflowed norm
        raise DecodeError("bad-quaternion")
    return pose


def decode_binary(data):
    """Decodes one binary v1 datagram (bytes) into a Pose or raises DecodeError."""
    n = len(data)
    if n > MAX_DATAGRAM_SIZE:
        raise DecodeError("oversized")
    if n < 4:
        raise DecodeError("too-short")
    if data[:4] != MAGIC:
        raise DecodeError("bad-magic")
    if n < 5:
        raise DecodeError("too-short")
    if data[4] != VERSION:
        raise DecodeError("bad-version")
    if n < HEADER_SIZE:
        raise DecodeError("too-short")
    _, _, header_length, flags, session, stream, seq, t, sent = HEADER.unpack_from(data, 0)
    if header_length < HEADER_SIZE:
        raise DecodeError("bad-header-length")
    if flags & ~KNOWN_FLAGS:
        raise DecodeError("unknown-flags")
    if n != header_length + payload_size(flags):
        raise DecodeError("length-mismatch")
    values = struct.unpack_from("<%dd" % ((n - header_length) // 8), data, header_length)
    q, rest = tuple(values[:4]), values[4:]
    p = w = None
    if flags & FLAG_POSITION:
        p, rest = tuple(rest[:3]), rest[3:]
    if flags & FLAG_ANGULAR_VELOCITY:
        w = tuple(rest[:3])
    return _check_semantics(Pose(session, stream, seq, t, sent, q, p, w, flags))


def _reject_constant(name):
    raise ValueError("not JSON: " + name)  # NaN, Infinity, -Infinity


def _no_duplicates(pairs):
    obj = {}
    for key, value in pairs:
        if key in obj:
            obj.setdefault("\0duplicates", set()).add(key)
        obj[key] = value
    return obj


def _is_int(v):
    return isinstance(v, int) and not isinstance(v, bool)


def _is_number(v):
    return (isinstance(v, (int, float)) and not isinstance(v, bool)) or v is None


MAX_JSON_DEPTH = 16  # more nested arrays/objects than this (the top object included) are a syntax error


def _depth(v):
    """Nesting depth of arrays/objects; -1 if a string holds a lone surrogate (invalid JSON text)."""
    if isinstance(v, str):
        return -1 if any("\ud800" <= c <= "\udfff" for c in v) else 0
    if isinstance(v, dict):
        inner = [_depth(x) for x in v.values()] + [_depth(k) for k in v]
    elif isinstance(v, list):
        inner = [_depth(x) for x in v]
    else:
        return 0
    return -1 if -1 in inner else 1 + max(inner, default=0)


def decode_json(data):
    """Decodes one JSON-line datagram (bytes) into a Pose or raises DecodeError."""
    if len(data) > MAX_DATAGRAM_SIZE:
        raise DecodeError("oversized")
    try:
        obj = json.loads(data.decode("utf-8"), parse_constant=_reject_constant, object_pairs_hook=_no_duplicates)
    except (ValueError, UnicodeDecodeError, RecursionError):
        raise DecodeError("json-syntax") from None
    depth = _depth(obj)
    if depth < 0 or depth > MAX_JSON_DEPTH:
        raise DecodeError("json-syntax")
    if not isinstance(obj, dict):
        raise DecodeError("json-schema")
    known = ("v", "session", "stream", "seq", "t", "sent", "q", "p", "w", "flags")
    if any(k in known for k in obj.get("\0duplicates", ())):
        raise DecodeError("json-schema")
    if any(k not in obj for k in ("v", "session", "stream", "seq", "t", "sent", "q")):
        raise DecodeError("json-schema")
    v = obj["v"]
    if not _is_int(v) or not 0 <= v <= 255:
        raise DecodeError("json-schema")
    if v != VERSION:
        raise DecodeError("bad-version")
    for key, limit in (("session", 2**32 - 1), ("stream", 2**32 - 1), ("seq", 2**64 - 1)):
        if not _is_int(obj[key]) or not 0 <= obj[key] <= limit:
            raise DecodeError("json-schema")

    def array(key, n):
        a = obj[key]
        if not isinstance(a, list) or len(a) != n or not all(_is_number(x) for x in a):
            raise DecodeError("json-schema")
        return a

    for key in ("t", "sent"):
        if not _is_number(obj[key]):
            raise DecodeError("json-schema")
    q = array("q", 4)
    p = array("p", 3) if "p" in obj else None
    w = array("w", 3) if "w" in obj else None
    flags = (FLAG_POSITION if p is not None else 0) | (FLAG_ANGULAR_VELOCITY if w is not None else 0)
    unknown_flag = False
    if "flags" in obj:
        names = obj["flags"]
        if not isinstance(names, list) or not all(isinstance(x, str) for x in names):
            raise DecodeError("json-schema")
        for name in names:
            if name == "clamped":
                flags |= FLAG_CLAMPED
            elif name == "bridged":
                flags |= FLAG_BRIDGED
            else:
                unknown_flag = True
    # null stands for a non-finite number (JSON has none); 1e999 reads as inf.
    raw = [obj["t"], obj["sent"], *q, *(p or ()), *(w or ())]
    non_finite = any(x is None for x in raw)

    def f(x):
        if x is None:
            return float("nan")
        try:
            return float(x)
        except OverflowError:  # an integer token beyond the double range
            return float("inf") if x > 0 else float("-inf")

    pose = Pose(obj["session"], obj["stream"], obj["seq"], f(obj["t"]), f(obj["sent"]), tuple(f(x) for x in q),
                None if p is None else tuple(f(x) for x in p), None if w is None else tuple(f(x) for x in w), flags)
    return _check_semantics(pose, unknown_flag, non_finite)


def decode(data):
    """Either encoding: a datagram starting with '{' is a JSON line, anything else binary."""
    if data[:1] == b"{":
        return decode_json(data)
    return decode_binary(data)


def _num(x):
    return "%.17g" % x


def encode_json(pose):
    """The JSON line for a pose, byte for byte as posefair writes it."""
    parts = ['{"v":1,"session":%d,"stream":%d,"seq":%d,"t":%s,"sent":%s' % (
        pose.session, pose.stream, pose.seq, _num(pose.t), _num(pose.sent))]
    parts.append(',"q":[%s]' % ",".join(_num(c) for c in pose.q))
    if pose.p is not None:
        parts.append(',"p":[%s]' % ",".join(_num(c) for c in pose.p))
    if pose.w is not None:
        parts.append(',"w":[%s]' % ",".join(_num(c) for c in pose.w))
    names = [n for bit, n in ((FLAG_CLAMPED, '"clamped"'), (FLAG_BRIDGED, '"bridged"')) if pose.flags & bit]
    parts.append(',"flags":[%s]}\n' % ",".join(names))
    return "".join(parts)


# --- Receiver accounting (docs/protocol.md, "Receiver accounting") -------------------------------
class SequenceTracker:
    WINDOW = 4096

    def __init__(self):
        self.started = False
        self.first = self.highest = 0
        self.received = self.lost = self.reordered = self.duplicates = 0
        self.seen = set()  # sequence numbers within WINDOW below the highest

    def observe(self, s):
        self.received += 1
        if not self.started:
            self.started = True
            self.first = self.highest = s
            self.seen.add(s)
            return "first"
        if s > self.highest:
            gap = s - self.highest - 1
            self.lost += gap
            self.highest = s
            self.seen.add(s)
            if len(self.seen) > 2 * self.WINDOW:
                self.seen = {x for x in self.seen if self.highest - x < self.WINDOW}
            return "after-gap" if gap else "next"
        in_window = self.highest - s < self.WINDOW
        if in_window and s in self.seen:
            self.duplicates += 1
            return "duplicate"
        self.reordered += 1
        if in_window:
            self.seen.add(s)
        if s > self.first and self.lost > 0:
            self.lost -= 1
        return "reordered"


class Latency:
    MAX_SAMPLES = 200000

    def __init__(self):
        self.count = 0
        self.min = self.max = 0.0
        self.samples = []
        self.rng = random.Random(0x5EED)

    def add(self, x):
        if self.count == 0:
            self.min = self.max = x
        else:
            self.min, self.max = min(self.min, x), max(self.max, x)
        self.count += 1
        if len(self.samples) < self.MAX_SAMPLES:
            self.samples.append(x)
        else:
            k = self.rng.randrange(self.count)
            if k < self.MAX_SAMPLES:
                self.samples[k] = x

    def quantile(self, q):
        s = sorted(self.samples)
        rank = math.ceil(q * len(s))
        return s[min(len(s) - 1, max(rank - 1, 0))]


class Stats:
    def __init__(self):
        self.streams = {}  # (session, stream) -> SequenceTracker
        self.malformed = {r: 0 for r in REASONS}
        self.latency = Latency()

    def observe(self, pose, received_at):
        if pose.sent != 0.0:
            self.latency.add(received_at - pose.sent)
        return self.streams.setdefault((pose.session, pose.stream), SequenceTracker()).observe(pose.seq)

    def total(self, attr):
        return sum(getattr(t, attr) for t in self.streams.values())

    def summary_line(self):
        bad = sum(self.malformed.values())
        line = "stats: received %d, lost %d, reordered %d, duplicates %d, malformed %d" % (
            self.total("received"), self.total("lost"), self.total("reordered"), self.total("duplicates"), bad)
        if bad:
            line += " (%s)" % ", ".join("%s %d" % (r, n) for r, n in self.malformed.items() if n)
        if self.latency.count == 0:
            line += ", latency n/a"
        else:
            line += ", latency min %.0f µs p50 %.0f µs p99 %.0f µs max %.0f µs" % (
                self.latency.min * 1e6, self.latency.quantile(0.5) * 1e6, self.latency.quantile(0.99) * 1e6,
                self.latency.max * 1e6)
        return line

    def stream_lines(self):
        return ["stream %d session %08x: received %d, lost %d, reordered %d, duplicates %d, seq %d..%d" % (
            stream, session, t.received, t.lost, t.reordered, t.duplicates, t.first, t.highest)
            for (session, stream), t in sorted(self.streams.items())]


# --- Output --------------------------------------------------------------------------------------
CSV_HEADER = "session,stream,seq,t,sent,qw,qx,qy,qz,px,py,pz,wx,wy,wz,flags,latency_us\n"


def format_text(pose):
    s = "session %08x stream %d seq %d t %.6f q %.6f %.6f %.6f %.6f" % (pose.session, pose.stream, pose.seq, pose.t,
                                                                       *pose.q)
    if pose.p is not None:
        s += " p %.6f %.6f %.6f" % pose.p
    if pose.w is not None:
        s += " w %.6f %.6f %.6f" % pose.w
    if pose.clamped:
        s += " clamped"
    if pose.bridged:
        s += " bridged"
    return s + "\n"


def format_csv(pose, received_at):
    fields = [str(pose.session), str(pose.stream), str(pose.seq), _num(pose.t), _num(pose.sent)]
    fields += [_num(c) for c in pose.q]
    for v in (pose.p, pose.w):
        fields += [_num(c) for c in v] if v is not None else ["", "", ""]
    fields.append(str(pose.flags))
    fields.append("%.1f" % ((received_at - pose.sent) * 1e6) if pose.sent != 0.0 else "")
    return ",".join(fields) + "\n"


# --- Subscribing (docs/protocol.md, "Subscribing") ----------------------------------------------
SUB_MAGIC = b"PFS1"
DEFAULT_CONTROL_PORT = 5710
SUBSCRIBE, UNSUBSCRIBE = 1, 2
COOKIE, SUBSCRIBED, UNSUBSCRIBED, REFUSED = 0x81, 0x82, 0x83, 0x84
REQ_ANGULAR_VELOCITY, REQ_AUTHENTICATED = 1, 2
REFUSE_REASONS = {1: "unknown-encoding", 2: "unknown-stream", 3: "too-many-subscribers", 4: "too-many-for-address"}
# magic, type, flags, encoding length, stream count, request id, lease ms, cookie
REQUEST = struct.Struct("<4sBBBBII16s")
# magic, type, reason, reserved, request id, lease ms, cookie
REPLY = struct.Struct("<4sBBHII16s")
NO_COOKIE = bytes(16)


def encode_request(kind, request_id, lease_ms=0, cookie=NO_COOKIE, encoding="", streams=(), angular_velocity=False,
                   psk=None):
    """A SUBSCRIBE or UNSUBSCRIBE; with psk (32 bytes), flagged and followed by its HMAC-SHA-512-256."""
    flags = (REQ_ANGULAR_VELOCITY if angular_velocity else 0) | (REQ_AUTHENTICATED if psk else 0)
    name = encoding.encode("ascii")
    body = REQUEST.pack(SUB_MAGIC, kind, flags, len(name), len(streams), request_id, lease_ms, cookie)
    body += name + b"".join(struct.pack("<I", s) for s in streams)
    if psk:
        body += hmac.new(psk, body, hashlib.sha512).digest()[:32]  # libsodium crypto_auth
    return body


def parse_reply(data):
    """(type, reason, request id, lease ms, cookie), or None if data is not a reply."""
    if len(data) != REPLY.size:
        return None
    magic, kind, reason, reserved, request_id, lease_ms, cookie = REPLY.unpack(data)
    if magic != SUB_MAGIC or kind not in (COOKIE, SUBSCRIBED, UNSUBSCRIBED, REFUSED) or reserved or reason > 4:
        return None
    return kind, reason, request_id, lease_ms, cookie


def first_request_id_now():
    """Tenths of a second since 2025-01-01 UTC: above any id an earlier run on the same port used."""
    return max(1, int(time.time() * 10) - 1735689600 * 10) & 0xFFFFFFFF


class SubscriptionClient:
    """The handshake as src/subscription_client.cpp does it: due() says what to send, on_reply() takes replies."""
    RETRY = 0.3
    MAX_TRIES = 10

    def __init__(self, server, encoding, streams, lease_ms, angular_velocity, psk):
        self.server = server
        self.encoding, self.streams, self.lease_ms = encoding, streams, lease_ms
        self.angular_velocity, self.psk = angular_velocity, psk
        self.next_id = first_request_id_now()
        self.awaiting = 0
        self.state = "starting"
        self.cookie = NO_COOKIE
        self.next_send = 0.0
        self.lease_end = 0.0
        self.tries = 0
        self.subscribed_once = False
        self.granted_ms = 0
        self.refused = None

    def _request(self, kind, with_cookie):
        self.awaiting = self.next_id
        self.next_id = (self.next_id + 1) & 0xFFFFFFFF
        cookie = self.cookie if with_cookie else NO_COOKIE
        if kind == UNSUBSCRIBE:
            return encode_request(kind, self.awaiting, 0, cookie, psk=self.psk)
        return encode_request(kind, self.awaiting, self.lease_ms, cookie, self.encoding, self.streams,
                              self.angular_velocity, self.psk)

    def due(self, now):
        if self.state in ("refused", "failed"):
            return None
        if self.state == "subscribed":
            if now < self.next_send:
                return None
            self.state, self.tries = "starting", 0
        if self.state == "starting":
            self.state, self.next_send = "awaiting-cookie", now + self.RETRY
            self.tries += 1
            return self._request(SUBSCRIBE, False)
        if now < self.next_send:
            return None
        if self.tries >= self.MAX_TRIES and (not self.subscribed_once or now >= self.lease_end):
            self.state = "failed"
            return None
        self.tries += 1
        self.next_send = now + self.RETRY
        return self._request(SUBSCRIBE, self.state == "awaiting-subscribed")

    def on_reply(self, data, source, now):
        """True when data was the server's reply (consumed)."""
        if source[:2] != self.server[:2]:
            return False
        reply = parse_reply(data)
        if reply is None:
            return False
        kind, reason, request_id, lease_ms, cookie = reply
        if request_id != self.awaiting:
            return True
        if kind == COOKIE:
            self.cookie = cookie
            if self.state in ("awaiting-cookie", "awaiting-subscribed"):
                self.state, self.next_send = "awaiting-subscribed", now
        elif kind == SUBSCRIBED:
            self.state, self.subscribed_once, self.granted_ms, self.tries = "subscribed", True, lease_ms, 0
            self.lease_end = now + lease_ms / 1000.0
            self.next_send = now + lease_ms / 3000.0
        elif kind == REFUSED:
            self.state, self.refused = "refused", REFUSE_REASONS.get(reason, str(reason))
        return True

    def unsubscribe(self):
        return self._request(UNSUBSCRIBE, True)


def read_psk(path):
    with open(path) as f:
        text = f.read().strip()
    key = bytes.fromhex(text)
    if len(text) != 64 or len(key) != 32:
        raise ValueError("not 64 hex digits")
    return key


# --- Sockets -------------------------------------------------------------------------------------
def parse_endpoint(text, default_port=None):
    """'ADDR:PORT' or '[IPV6]:PORT' (numeric addresses only) -> (family, sockaddr) or None."""
    host, port = text, default_port
    if text.startswith("["):
        close = text.find("]")
        if close < 0:
            return None
        host, rest = text[1:close], text[close + 1:]
        if rest:
            if not rest.startswith(":") or not rest[1:].isdigit():
                return None
            port = int(rest[1:])
    elif text.count(":") == 1:
        host, _, p = text.partition(":")
        if not p.isdigit() or len(p) > 5:
            return None
        port = int(p)
    if port is None or not 0 <= port <= 65535:
        return None
    family = socket.AF_INET6 if ":" in host else socket.AF_INET
    if family == socket.AF_INET:
        try:
            socket.inet_pton(socket.AF_INET, host)
        except OSError:
            return None
    try:
        info = socket.getaddrinfo(host, port, family, socket.SOCK_DGRAM, 0, socket.AI_NUMERICHOST)
    except socket.gaierror:
        return None
    return family, info[0][4]


def is_multicast(family, address):
    if family == socket.AF_INET:
        return 224 <= int(address.split(".")[0]) <= 239
    return address.lower().startswith("ff")


def interface_index(name_or_address):
    try:
        return socket.if_nametoindex(name_or_address)
    except OSError:
        pass
    if name_or_address.isdigit():
        return int(name_or_address)
    raise OSError("no network interface '%s'" % name_or_address)


def open_socket(listen, group, interface):
    family, sockaddr = listen
    sock = socket.socket(family, socket.SOCK_DGRAM)
    try:
        if group is not None:
            sock.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
        try:
            sock.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, 1 << 20)
        except OSError:
            pass
        try:
            sock.bind(sockaddr)
        except OSError as e:
            raise OSError("cannot bind UDP %s: %s" % (format_endpoint(family, sockaddr), e.strerror or e)) from None
        if group is not None:
            gfamily, gaddr = group
            try:
                if gfamily == socket.AF_INET:
                    group_bytes = socket.inet_pton(socket.AF_INET, gaddr[0])
                    if not interface:
                        mreq = group_bytes + socket.inet_pton(socket.AF_INET, "0.0.0.0") + struct.pack("=i", 0)
                    else:
                        try:
                            mreq = group_bytes + socket.inet_pton(socket.AF_INET, interface) + struct.pack("=i", 0)
                        except OSError:
                            mreq = (group_bytes + socket.inet_pton(socket.AF_INET, "0.0.0.0") +
                                    struct.pack("=i", interface_index(interface)))
                    sock.setsockopt(socket.IPPROTO_IP, socket.IP_ADD_MEMBERSHIP, mreq)
                else:
                    index = interface_index(interface) if interface else 0
                    mreq = socket.inet_pton(socket.AF_INET6, gaddr[0].split("%")[0]) + struct.pack("=I", index)
                    sock.setsockopt(socket.IPPROTO_IPV6, socket.IPV6_JOIN_GROUP, mreq)
            except OSError as e:
                raise OSError("cannot join multicast group %s: %s" % (gaddr[0], e.strerror or e)) from None
        return sock
    except BaseException:
        sock.close()
        raise


def format_endpoint(family, sockaddr):
    if family == socket.AF_INET6:
        return "[%s]:%d" % (sockaddr[0], sockaddr[1])
    return "%s:%d" % (sockaddr[0], sockaddr[1])


# --- Main ----------------------------------------------------------------------------------------
class _Parser(argparse.ArgumentParser):
    def error(self, message):
        self.print_usage(sys.stderr)
        sys.stderr.write("%s: error: %s\n" % (self.prog, message))
        sys.exit(EXIT_USAGE)


def _non_negative(kind):
    def check(text):
        value = kind(text)
        if value < 0 or (kind is float and not math.isfinite(value)):
            raise argparse.ArgumentTypeError("must be a non-negative number")
        return value
    return check


def main(argv=None):
    ap = _Parser(prog="posefair_sub.py", description="Subscribe to posefair poses over UDP (wire protocol v1, "
                 "binary or JSON lines) and print them with loss, reordering and latency statistics.")
    ap.add_argument("--listen", help="local ADDR:PORT or [IPV6]:PORT to bind (port 0: any free port; "
                    "default 0.0.0.0:%d)" % DEFAULT_PORT)
    ap.add_argument("--group", help="multicast group to join")
    ap.add_argument("--interface", help="interface (address or name) to join the group on")
    ap.add_argument("--format", choices=("text", "json", "csv"), default="text")
    ap.add_argument("--count", type=_non_negative(int), default=0, help="exit after N poses (0: no limit)")
    ap.add_argument("--duration", type=_non_negative(float), default=0.0, help="exit after S seconds (0: no limit)")
    ap.add_argument("--quiet", action="store_true", help="print no poses, only the statistics")
    ap.add_argument("--stats", action="store_true", help="also print one line per (session, stream) at exit")
    ap.add_argument("--subscribe", help="sign up on a daemon's subscription port HOST:PORT (default port %d) "
                    "and keep the lease" % DEFAULT_CONTROL_PORT)
    ap.add_argument("--streams", default="", help="with --subscribe: stream ids wanted, comma separated (default: all)")
    ap.add_argument("--encoding", default="binary", help="with --subscribe: the encoding wanted (binary, json)")
    ap.add_argument("--lease", type=float, default=30.0, help="with --subscribe: seconds of lease asked for")
    ap.add_argument("--angular-velocity", action="store_true", help="with --subscribe: poses carry the body rate")
    ap.add_argument("--psk-file", help="with --subscribe: the daemon's pre-shared key (64 hex digits)")
    args = ap.parse_args(argv)
    me = "posefair_sub.py"

    client = None
    if args.subscribe:
        server = parse_endpoint(args.subscribe, DEFAULT_CONTROL_PORT)
        try:
            streams = [int(x) for x in args.streams.split(",") if x]
        except ValueError:
            streams = None
        if server is None or streams is None or len(streams) > 16 or not 1 <= args.lease <= 86400:
            sys.stderr.write("%s: bad --subscribe, --streams or --lease\n" % me)
            return EXIT_USAGE
        psk = None
        if args.psk_file:
            try:
                psk = read_psk(args.psk_file)
            except (OSError, ValueError):
                sys.stderr.write("%s: --psk-file %s does not hold a key (64 hex digits)\n" % (me, args.psk_file))
                return EXIT_USAGE
        client = SubscriptionClient(server[1], args.encoding, streams, int(args.lease * 1000), args.angular_velocity, psk)
        if args.listen is None:
            args.listen = "[::]:0" if server[0] == socket.AF_INET6 else "0.0.0.0:0"
    elif args.streams or args.psk_file or args.angular_velocity:
        sys.stderr.write("%s: --streams, --psk-file and --angular-velocity need --subscribe\n" % me)
        return EXIT_USAGE

    group = None
    if args.group:
        group = parse_endpoint("[%s]" % args.group if ":" in args.group else args.group, 0)
        if group is None or not is_multicast(group[0], group[1][0]):
            sys.stderr.write("%s: --group %s is not a multicast address\n" % (me, args.group))
            return EXIT_USAGE
    listen_text = args.listen
    if listen_text is None:
        ipv6_group = group is not None and group[0] == socket.AF_INET6
        listen_text = ("[::]:%d" if ipv6_group else "0.0.0.0:%d") % DEFAULT_PORT
    listen = parse_endpoint(listen_text, DEFAULT_PORT)
    if listen is None:
        sys.stderr.write("%s: --listen %s is not ADDR:PORT or [IPV6]:PORT\n" % (me, listen_text))
        return EXIT_USAGE
    if group is not None and group[0] != listen[0]:
        sys.stderr.write("%s: --group %s and --listen %s are of different address families\n" %
                         (me, args.group, listen_text))
        return EXIT_USAGE
    if args.interface and group is None:
        sys.stderr.write("%s: --interface needs --group\n" % me)
        return EXIT_USAGE

    try:
        sock = open_socket(listen, group, args.interface)
    except OSError as e:
        sys.stderr.write("%s: %s\n" % (me, e))
        return EXIT_UNAVAILABLE
    local = sock.getsockname()
    line = "%s: listening on %s" % (me, format_endpoint(listen[0], local))
    if group is not None:
        line += ", group %s" % group[1][0] + (" on %s" % args.interface if args.interface else "")
    sys.stderr.write(line + "\n")
    sys.stderr.flush()

    stop = []
    previous = {s: signal.signal(s, lambda *_: stop.append(True)) for s in (signal.SIGINT, signal.SIGTERM)}
    out = sys.stdout
    if args.format == "csv" and not args.quiet:
        out.write(CSV_HEADER)
        out.flush()
    stats = Stats()
    poses = 0
    deadline = time.monotonic() + args.duration if args.duration > 0 else None
    status = EXIT_OK
    try:
        while not stop and (args.count == 0 or poses < args.count):
            wait = 0.2
            if client is not None:
                request = client.due(time.monotonic())
                if request is not None:
                    sock.sendto(request, client.server)
                if client.state in ("refused", "failed"):
                    why = "refused the subscription: %s" % client.refused if client.refused else "did not answer"
                    sys.stderr.write("%s: %s %s\n" % (me, format_endpoint(listen[0], client.server), why))
                    status = EXIT_UNAVAILABLE
                    break
                wait = 0.05
            if deadline is not None:
                left = deadline - time.monotonic()
                if left <= 0:
                    break
                wait = min(wait, left)
            sock.settimeout(wait)
            try:
                data, source = sock.recvfrom(65536)
            except (socket.timeout, InterruptedError):
                continue
            if client is not None:
                was = client.subscribed_once
                if client.on_reply(data, source, time.monotonic()):
                    if not was and client.subscribed_once:
                        sys.stderr.write("%s: subscribed, lease %g s\n" % (me, client.granted_ms / 1000.0))
                        sys.stderr.flush()
                    continue
            received_at = time.time()
            try:
                pose = decode(data)
            except DecodeError as e:
                stats.malformed[e.reason] += 1
                continue
            stats.observe(pose, received_at)
            poses += 1
            if args.quiet:
                continue
            if args.format == "csv":
                out.write(format_csv(pose, received_at))
            elif args.format == "json":
                out.write(encode_json(pose))
            else:
                out.write(format_text(pose))
            out.flush()
        if client is not None and client.subscribed_once:
            unsubscribe(sock, client)
    finally:
        for s, handler in previous.items():
            signal.signal(s, handler)
        sock.close()
    out.flush()
    if args.stats:
        for line in stats.stream_lines():
            sys.stderr.write(line + "\n")
    sys.stderr.write(stats.summary_line() + "\n")
    return status


def unsubscribe(sock, client):
    """UNSUBSCRIBE with the last cookie; once more with a fresh one if the daemon sends it."""
    for _ in range(2):
        sock.sendto(client.unsubscribe(), client.server)
        until = time.monotonic() + 0.25
        while time.monotonic() < until:
            sock.settimeout(0.05)
            try:
                data, source = sock.recvfrom(65536)
            except (socket.timeout, InterruptedError):
                continue
            reply = parse_reply(data) if source[:2] == client.server[:2] else None
            if reply is None:
                continue
            if reply[0] == UNSUBSCRIBED:
                return
            client.on_reply(data, source, time.monotonic())
            break


if __name__ == "__main__":
    sys.exit(main())
