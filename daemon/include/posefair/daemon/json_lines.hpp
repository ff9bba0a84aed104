#pragma once
// JSON lines encoding of wire protocol v1 (docs/protocol.md, "JSON lines"): one JSON object per
// datagram, ending with '\n', for subscribers that would rather not parse binary:
//   {"v":1,"session":N,"stream":N,"seq":N,"t":F,"sent":F,"q":[w,x,y,z],"p":[x,y,z],"w":[x,y,z],
//    "flags":["clamped","bridged"]}
// "p" and "w" appear only when present. Numbers are written with 17 significant digits
// (locale-independent std::to_chars), so every finite double round-trips bit for bit.
//
// The decoder is a small strict JSON parser written for this shape: no JSON library is among
// the project's dependencies, and a hand-written one is easy to fuzz and bounds-check. It
// accepts any RFC 8259 object (members in any order, whitespace, escapes, unknown members
// skipped — later v1 revisions may add members) and rejects everything else.
#include <span>
#include <string>
#include <string_view>

#include "posefair/daemon/wire_protocol.hpp"

namespace posefair::daemon {

// The JSON line for m, with the trailing '\n'. Non-finite numbers (which JSON cannot express)
// are written as null, which decode_json rejects as kNonFinite.
std::string encode_json(const PoseMessage& m);

// Decodes one JSON-line datagram (trailing whitespace, including the '\n', is optional).
// Errors: kOversized, kJsonSyntax, kJsonSchema, kUnsupportedVersion ("v" != 1),
// kUnknownFlags (a flag name other than "clamped"/"bridged"), kNonFinite, kBadQuaternion.
DecodeResult decode_json(std::span<const std::uint8_t> datagram);
DecodeResult decode_json(std::string_view text);

}  // namespace posefair::daemon
