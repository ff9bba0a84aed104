#include "posefair/daemon/json_lines.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <limits>
#include <memory>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "posefair/daemon/output_encoder.hpp"

namespace posefair::daemon {
namespace {

// ---------------------------------------------------------------------------------------------
// Encoder

void append_number(std::string& out, double v) {
  if (!std::isfinite(v)) {
    out += "null";
    return;
  }
  char buf[40];
  const auto r = std::to_chars(buf, buf + sizeof buf, v, std::chars_format::general, 17);
  out.append(buf, r.ptr);
}

void append_integer(std::string& out, std::uint64_t v) {
  char buf[24];
  const auto r = std::to_chars(buf, buf + sizeof buf, v);
  out.append(buf, r.ptr);
}

void append_array(std::string& out, std::initializer_list<double> values) {
  out += '[';
  bool first = true;
  for (double v : values) {
    if (!first) out += ',';
    first = false;
    append_number(out, v);
  }
  out += ']';
}

// ---------------------------------------------------------------------------------------------
// A small strict JSON (RFC 8259) parser into a tiny document tree. Inputs are at most
// kMaxDatagramSize bytes, nesting is limited, and every read is bounds-checked.

struct Value {
  enum class Kind { kNull, kBool, kNumber, kString, kArray, kObject } kind = Kind::kNull;
  std::string_view number;  // the number's token, grammar already checked
  std::string string;       // decoded string
  std::vector<Value> items;  // array elements
  std::vector<std::pair<std::string, Value>> members;  // object members, in order
};

// At most this many nested arrays/objects, the top-level object included.
constexpr int kMaxDepth = 16;

class Parser {
 public:
  explicit Parser(std::string_view s) : s_(s) {}

  // The whole text: one value (must be an object for us), then only whitespace.
  bool parse_document(Value& v) {
    skip_ws();
    if (!parse_value(v, 0)) return false;
    skip_ws();
    return i_ == s_.size();
  }

 private:
  bool at_end() const { return i_ >= s_.size(); }
  char peek() const { return s_[i_]; }

  void skip_ws() {
    while (!at_end() && (peek() == ' ' || peek() == '\t' || peek() == '\n' || peek() == '\r')) ++i_;
  }

  bool literal(std::string_view word) {
    if (s_.substr(i_, word.size()) != word) return false;
    i_ += word.size();
    return true;
  }

  // depth: how many arrays/objects enclose this value.
  bool parse_value(Value& v, int depth) {
    if (at_end()) return false;
    switch (peek()) {
      case '{': return depth < kMaxDepth && parse_object(v, depth);
      case '[': return depth < kMaxDepth && parse_array(v, depth);
      case '"':
        v.kind = Value::Kind::kString;
        return parse_string(v.string);
      case 't':
        v.kind = Value::Kind::kBool;
        return literal("true");
      case 'f':
        v.kind = Value::Kind::kBool;
        return literal("false");
      case 'n':
        v.kind = Value::Kind::kNull;
        return literal("null");
      default:
        v.kind = Value::Kind::kNumber;
        return parse_number(v.number);
    }
  }

  bool parse_object(Value& v, int depth) {
    v.kind = Value::Kind::kObject;
    ++i_;  // '{'
    skip_ws();
    if (!at_end() && peek() == '}') {
      ++i_;
      return true;
    }
    for (;;) {
      skip_ws();
      if (at_end() || peek() != '"') return false;
      std::string key;
      if (!parse_string(key)) return false;
      skip_ws();
      if (at_end() || peek() != ':') return false;
      ++i_;
      skip_ws();
      Value member;
      if (!parse_value(member, depth + 1)) return false;
      v.members.emplace_back(std::move(key), std::move(member));
      skip_ws();
      if (at_end()) return false;
      if (peek() == ',') {
        ++i_;
        continue;
      }
      if (peek() == '}') {
        ++i_;
        return true;
      }
      return false;
    }
  }

  bool parse_array(Value& v, int depth) {
    v.kind = Value::Kind::kArray;
    ++i_;  // '['
    skip_ws();
    if (!at_end() && peek() == ']') {
      ++i_;
      return true;
    }
    for (;;) {
      skip_ws();
      Value item;
      if (!parse_value(item, depth + 1)) return false;
      v.items.push_back(std::move(item));
      skip_ws();
      if (at_end()) return false;
      if (peek() == ',') {
        ++i_;
        continue;
      }
      if (peek() == ']') {
        ++i_;
        return true;
      }
      return false;
    }
  }

  static int hex_digit(char c) {
    if (c >= '0' && c <= '9') return c - '0';
    if (c >= 'a' && c <= 'f') return c - 'a' + 10;
    if (c >= 'A' && c <= 'F') return c - 'A' + 10;
    return -1;
  }

  bool parse_hex4(std::uint32_t& u) {
    if (s_.size() - i_ < 4) return false;
    u = 0;
    for (int k = 0; k < 4; ++k) {
      const int d = hex_digit(s_[i_++]);
      if (d < 0) return false;
      u = u * 16 + static_cast<std::uint32_t>(d);
    }
    return true;
  }

  static void append_utf8(std::string& out, std::uint32_t cp) {
    if (cp < 0x80) {
      out += static_cast<char>(cp);
    } else if (cp < 0x800) {
      out += static_cast<char>(0xC0 | (cp >> 6));
      out += static_cast<char>(0x80 | (cp & 0x3F));
    } else if (cp < 0x10000) {
      out += static_cast<char>(0xE0 | (cp >> 12));
      out += static_cast<char>(0x80 | ((cp >> 6) & 0x3F));
      out += static_cast<char>(0x80 | (cp & 0x3F));
    } else {
      out += static_cast<char>(0xF0 | (cp >> 18));
      out += static_cast<char>(0x80 | ((cp >> 12) & 0x3F));
      out += static_cast<char>(0x80 | ((cp >> 6) & 0x3F));
      out += static_cast<char>(0x80 | (cp & 0x3F));
    }
  }

  // One UTF-8 encoded character starting at i_ (its first byte >= 0x80), RFC 3629: no
  // overlong forms, no surrogates, nothing above U+10FFFF.
  bool utf8_sequence(std::string& out) {
    const auto b0 = static_cast<unsigned char>(s_[i_]);
    std::size_t len = 0;
    std::uint32_t cp = 0, min = 0;
    if (b0 >= 0xC2 && b0 <= 0xDF) {
      len = 2, cp = b0 & 0x1Fu, min = 0x80;
    } else if (b0 >= 0xE0 && b0 <= 0xEF) {
      len = 3, cp = b0 & 0x0Fu, min = 0x800;
    } else if (b0 >= 0xF0 && b0 <= 0xF4) {
      len = 4, cp = b0 & 0x07u, min = 0x10000;
    } else {
      return false;
    }
    if (s_.size() - i_ < len) return false;
    for (std::size_t k = 1; k < len; ++k) {
      const auto b = static_cast<unsigned char>(s_[i_ + k]);
      if ((b & 0xC0) != 0x80) return false;
      cp = (cp << 6) | (b & 0x3Fu);
    }
    if (cp < min || cp > 0x10FFFF || (cp >= 0xD800 && cp <= 0xDFFF)) return false;
    out.append(s_.substr(i_, len));
    i_ += len;
    return true;
  }

  // Strings: escapes decoded, UTF-8 checked, raw control characters rejected.
  bool parse_string(std::string& out) {
    ++i_;  // opening quote
    while (!at_end()) {
      if (static_cast<unsigned char>(peek()) >= 0x80) {
        if (!utf8_sequence(out)) return false;
        continue;
      }
      const char c = s_[i_++];
      if (c == '"') return true;
      if (static_cast<unsigned char>(c) < 0x20) return false;
      if (c != '\\') {
        out += c;
        continue;
      }
      if (at_end()) return false;
      const char e = s_[i_++];
      switch (e) {
        case '"': out += '"'; break;
        case '\\': out += '\\'; break;
        case '/': out += '/'; break;
        case 'b': out += '\b'; break;
        case 'f': out += '\f'; break;
        case 'n': out += '\n'; break;
        case 'r': out += '\r'; break;
        case 't': out += '\t'; break;
        case 'u': {
          std::uint32_t u = 0;
          if (!parse_hex4(u)) return false;
          if (u >= 0xD800 && u <= 0xDBFF) {  // high surrogate: a low one must follow
            std::uint32_t lo = 0;
            if (!literal("\\u") || !parse_hex4(lo) || lo < 0xDC00 || lo > 0xDFFF) return false;
            u = 0x10000 + ((u - 0xD800) << 10) + (lo - 0xDC00);
          } else if (u >= 0xDC00 && u <= 0xDFFF) {
            return false;  // lone low surrogate
          }
          append_utf8(out, u);
          break;
        }
        default: return false;
      }
    }
    return false;  // unterminated
  }

  bool digits() {
    const std::size_t start = i_;
    while (!at_end() && peek() >= '0' && peek() <= '9') ++i_;
    return i_ > start;
  }

  // -?(0|[1-9][0-9]*)(\.[0-9]+)?([eE][+-]?[0-9]+)?
  bool parse_number(std::string_view& token) {
    const std::size_t start = i_;
    if (!at_end() && peek() == '-') ++i_;
    if (at_end()) return false;
    if (peek() == '0') {
      ++i_;
    } else if (peek() >= '1' && peek() <= '9') {
      digits();
    } else {
      return false;
    }
    if (!at_end() && peek() == '.') {
      ++i_;
      if (!digits()) return false;
    }
    if (!at_end() && (peek() == 'e' || peek() == 'E')) {
      ++i_;
      if (!at_end() && (peek() == '+' || peek() == '-')) ++i_;
      if (!digits()) return false;
    }
    token = s_.substr(start, i_ - start);
    return true;
  }

  std::string_view s_;
  std::size_t i_ = 0;
};

// ---------------------------------------------------------------------------------------------
// Schema: the pose object.

// Whether |x| < 1 for a (grammar-checked, non-zero) number token: the decimal exponent of its
// first significant digit is negative. Only asked when the value is outside the double range,
// where it tells underflow from overflow.
bool decimal_magnitude_negative(std::string_view t) {
  std::size_t i = (!t.empty() && t[0] == '-') ? 1 : 0;
  long long lead = 0;  // decimal exponent of the first significant digit, before the 'e' part
  bool seen = false;
  std::size_t int_digits = 0;
  for (; i < t.size() && t[i] >= '0' && t[i] <= '9'; ++i) {
    if (t[i] != '0' || seen) {
      seen = true;
      ++int_digits;
    }
  }
  if (seen) {
    lead = static_cast<long long>(int_digits) - 1;
  } else if (i < t.size() && t[i] == '.') {
    for (++i; i < t.size() && t[i] == '0'; ++i) --lead;
    lead -= 1;
  }
  while (i < t.size() && t[i] != 'e' && t[i] != 'E') ++i;
  long long exponent = 0;
  if (i < t.size()) {
    ++i;
    bool negative = false;
    if (i < t.size() && (t[i] == '+' || t[i] == '-')) negative = t[i++] == '-';
    for (; i < t.size(); ++i) exponent = std::min<long long>(exponent * 10 + (t[i] - '0'), 1'000'000'000);
    if (negative) exponent = -exponent;
  }
  return lead + exponent < 0;
}

// A number member as a double. null (what the encoder writes for a non-finite number) and
// numbers beyond the double range are kNonFinite; anything else but a number is kJsonSchema.
DecodeError to_double(const Value& v, double& out) {
  if (v.kind == Value::Kind::kNull) return DecodeError::kNonFinite;
  if (v.kind != Value::Kind::kNumber) return DecodeError::kJsonSchema;
  const char* first = v.number.data();
  const char* last = first + v.number.size();
  const auto r = std::from_chars(first, last, out);
  if (r.ec == std::errc::result_out_of_range) {
    // Underflow towards zero is a legitimate tiny number (it reads as ±0); overflow is not a
    // finite double.
    if (decimal_magnitude_negative(v.number)) {
      out = v.number.front() == '-' ? -0.0 : 0.0;
      return DecodeError::kNone;
    }
    return DecodeError::kNonFinite;
  }
  if (r.ec != std::errc() || r.ptr != last) return DecodeError::kJsonSchema;
  return std::isfinite(out) ? DecodeError::kNone : DecodeError::kNonFinite;
}

// A non-negative integer member (no fraction, no exponent) no larger than max.
DecodeError to_unsigned(const Value& v, std::uint64_t max, std::uint64_t& out) {
  if (v.kind != Value::Kind::kNumber) return DecodeError::kJsonSchema;
  if (v.number.find_first_of("-.eE") != std::string_view::npos) return DecodeError::kJsonSchema;
  const char* first = v.number.data();
  const char* last = first + v.number.size();
  const auto r = std::from_chars(first, last, out);
  if (r.ec != std::errc() || r.ptr != last || out > max) return DecodeError::kJsonSchema;
  return DecodeError::kNone;
}

template <std::size_t N>
DecodeError to_doubles(const Value& v, double (&out)[N]) {
  if (v.kind != Value::Kind::kArray || v.items.size() != N) return DecodeError::kJsonSchema;
  // A schema error anywhere in the array outranks a non-finite element.
  DecodeError worst = DecodeError::kNone;
  for (std::size_t k = 0; k < N; ++k) {
    const DecodeError e = to_double(v.items[k], out[k]);
    if (e == DecodeError::kJsonSchema) return e;
    if (e != DecodeError::kNone) worst = e;
  }
  return worst;
}

}  // namespace

std::string encode_json(const PoseMessage& m) {
  std::string out;
  out.reserve(400);
  out += "{\"v\":1,\"session\":";
  append_integer(out, m.session);
  out += ",\"stream\":";
  append_integer(out, m.stream);
  out += ",\"seq\":";
  append_integer(out, m.sequence);
  out += ",\"t\":";
  append_number(out, m.sample_time);
  out += ",\"sent\":";
  append_number(out, m.send_time);
  out += ",\"q\":";
  append_array(out, {m.orientation.w(), m.orientation.x(), m.orientation.y(), m.orientation.z()});
  if (m.position) {
    out += ",\"p\":";
    append_array(out, {m.position->x(), m.position->y(), m.position->z()});
  }
  if (m.angular_velocity) {
    out += ",\"w\":";
    append_array(out, {m.angular_velocity->x(), m.angular_velocity->y(), m.angular_velocity->z()});
  }
  out += ",\"flags\":[";
  bool first = true;
  for (const auto& [bit, name] : {std::pair{kFlagClamped, "\"clamped\""}, std::pair{kFlagBridged, "\"bridged\""}}) {
    if (!(m.flags & bit)) continue;
    if (!first) out += ',';
    first = false;
    out += name;
  }
  out += "]}\n";
  return out;
}

DecodeResult decode_json(std::string_view text) {
  auto fail = [](DecodeError e) { return rejected(e, WireEncoding::kJson); };
  DecodeResult r;
  r.encoding = WireEncoding::kJson;
  if (text.size() > kMaxDatagramSize) return fail(DecodeError::kOversized);
  Value doc;
  if (!Parser(text).parse_document(doc)) return fail(DecodeError::kJsonSyntax);
  if (doc.kind != Value::Kind::kObject) return fail(DecodeError::kJsonSchema);

  // Known members, each at most once; unknown members are ignored.
  enum Member { kV, kSession, kStream, kSeq, kT, kSent, kQ, kP, kW, kFlags, kMemberCount };
  static constexpr std::string_view kNames[kMemberCount] = {"v", "session", "stream", "seq", "t",
                                                            "sent", "q", "p", "w", "flags"};
  const Value* found[kMemberCount] = {};
  for (const auto& [key, value] : doc.members) {
    for (int k = 0; k < kMemberCount; ++k) {
      if (key != kNames[k]) continue;
      if (found[k]) return fail(DecodeError::kJsonSchema);  // duplicate member
      found[k] = &value;
    }
  }
  for (int k : {kV, kSession, kStream, kSeq, kT, kSent, kQ})
    if (!found[k]) return fail(DecodeError::kJsonSchema);

  std::uint64_t version = 0;
  if (to_unsigned(*found[kV], 255, version) != DecodeError::kNone) return fail(DecodeError::kJsonSchema);
  if (version != kWireVersion) return fail(DecodeError::kUnsupportedVersion);

  PoseMessage& m = r.message;
  std::uint64_t u = 0;
  if (DecodeError e = to_unsigned(*found[kSession], std::numeric_limits<std::uint32_t>::max(), u);
      e != DecodeError::kNone)
    return fail(e);
  m.session = static_cast<std::uint32_t>(u);
  if (DecodeError e = to_unsigned(*found[kStream], std::numeric_limits<std::uint32_t>::max(), u);
      e != DecodeError::kNone)
    return fail(e);
  m.stream = static_cast<std::uint32_t>(u);
  if (DecodeError e = to_unsigned(*found[kSeq], std::numeric_limits<std::uint64_t>::max(), m.sequence);
      e != DecodeError::kNone)
    return fail(e);

  // Numbers: a schema error (wrong type or shape) outranks a non-finite value anywhere.
  DecodeError non_finite = DecodeError::kNone;
  auto note = [&non_finite](DecodeError e) {
    if (e == DecodeError::kJsonSchema) return false;
    if (e != DecodeError::kNone) non_finite = e;
    return true;
  };
  if (!note(to_double(*found[kT], m.sample_time))) return fail(DecodeError::kJsonSchema);
  if (!note(to_double(*found[kSent], m.send_time))) return fail(DecodeError::kJsonSchema);
  double q[4];
  if (!note(to_doubles(*found[kQ], q))) return fail(DecodeError::kJsonSchema);
  m.orientation = Quat(q[0], q[1], q[2], q[3]);
  std::uint16_t flags = 0;
  if (found[kP]) {
    double p[3];
    if (!note(to_doubles(*found[kP], p))) return fail(DecodeError::kJsonSchema);
    m.position = Vec3(p[0], p[1], p[2]);
    flags |= kFlagPosition;
  }
  if (found[kW]) {
    double w[3];
    if (!note(to_doubles(*found[kW], w))) return fail(DecodeError::kJsonSchema);
    m.angular_velocity = Vec3(w[0], w[1], w[2]);
    flags |= kFlagAngularVelocity;
  }
  bool unknown_flag = false;
  if (found[kFlags]) {
    const Value& f = *found[kFlags];
    if (f.kind != Value::Kind::kArray) return fail(DecodeError::kJsonSchema);
    for (const Value& name : f.items) {
      if (name.kind != Value::Kind::kString) return fail(DecodeError::kJsonSchema);
      if (name.string == "clamped")
        flags |= kFlagClamped;
      else if (name.string == "bridged")
        flags |= kFlagBridged;
      else
        unknown_flag = true;
    }
  }
  m.flags = flags;
  // Same precedence as the binary decoder: unknown flags, then non-finite, then the norm.
  if (unknown_flag) return fail(DecodeError::kUnknownFlags);
  if (non_finite != DecodeError::kNone) return fail(non_finite);
  if (const DecodeError e = validate(m); e != DecodeError::kNone) return fail(e);
  return r;
}

DecodeResult decode_json(std::span<const std::uint8_t> datagram) {
  return decode_json(std::string_view(reinterpret_cast<const char*>(datagram.data()), datagram.size()));
}

namespace {

// [[output]] encoding = "json": one JSON line per datagram. It builds a std::string per pose,
// so it allocates on the publisher thread (the JSON lines are a convenience, not the real-time
// path); the copy into the publisher's buffer keeps the interface one for every encoding.
class JsonLinesOutputEncoder final : public OutputEncoder {
 public:
  std::string_view name() const override { return "json"; }
  std::size_t encode(const PoseMessage& m, std::span<std::uint8_t> out) const override {
    const std::string line = encode_json(m);
    if (out.size() < line.size()) throw std::length_error("encode_json: output buffer too small");
    std::copy(line.begin(), line.end(), out.begin());
    return line.size();
  }
};

}  // namespace

// Registered in output_encoder_registry.cpp. No options: every JSON output shares one encoder.
const OutputEncoderEntry& json_lines_output_encoding() {
  static const OutputEncoderEntry entry{
      "json", "JSON lines: one JSON object per datagram, for scripts and debugging", {},
      [](const posefair::OptionMap& options, std::span<const OutputStream>) -> std::shared_ptr<const OutputEncoder> {
        (void)posefair::OptionReader({}, options);  // it reads none: refuses any
        static const auto encoder = std::make_shared<const JsonLinesOutputEncoder>();
        return encoder;
      }};
  return entry;
}

}  // namespace posefair::daemon
