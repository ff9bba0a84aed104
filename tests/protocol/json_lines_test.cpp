// Wire protocol v1, JSON lines: round trips, what the strict parser accepts, and what it rejects.
#include "posefair/daemon/json_lines.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include "protocol_samples.hpp"

namespace posefair::daemon {
namespace {

constexpr const char* kMinimal = R"({"v":1,"session":1,"stream":2,"seq":3,"t":0.5,"sent":0,"q":[1,0,0,0]})";

DecodeError error_of(const std::string& s) { return decode_json(s).error; }

TEST(JsonLines, RoundTripIsBitExactForEveryFlagCombination) {
  for (std::uint16_t flags = 0; flags <= kKnownFlags; ++flags) {
    const PoseMessage m = testing::sample_message(flags, 500 + flags);
    const std::string line = encode_json(m);
    ASSERT_FALSE(line.empty());
    EXPECT_EQ(line.back(), '\n');
    EXPECT_EQ(line.find('\n'), line.size() - 1) << "one line per datagram";
    EXPECT_EQ(line.find("\"p\":") != std::string::npos, m.position.has_value());
    EXPECT_EQ(line.find("\"w\":") != std::string::npos, m.angular_velocity.has_value());
    EXPECT_EQ(line.find("\"clamped\"") != std::string::npos, m.clamped());
    EXPECT_EQ(line.find("\"bridged\"") != std::string::npos, m.bridged());
    const DecodeResult r = decode_json(line);
    ASSERT_TRUE(r.ok()) << line << " -> " << to_string(r.error);
    EXPECT_EQ(r.encoding, WireEncoding::kJson);
    EXPECT_TRUE(bitwise_equal(r.message, m)) << line;
    EXPECT_EQ(encode_json(r.message), line);
  }
}

TEST(JsonLines, SeventeenDigitsRoundTripAwkwardDoubles) {
  PoseMessage m = testing::sample_message(kFlagPosition | kFlagAngularVelocity, 1);
  m.sequence = std::numeric_limits<std::uint64_t>::max();
  m.session = std::numeric_limits<std::uint32_t>::max();
  m.sample_time = 0.1;
  m.send_time = 1.0 / 3.0;
  m.position = Vec3(std::numeric_limits<double>::denorm_min(), -std::numeric_limits<double>::max(), -0.0);
  m.angular_velocity = Vec3(std::numeric_limits<double>::min(), 1e-5, 123456789.123456789);
  const std::string line = encode_json(m);
  EXPECT_NE(line.find("\"t\":0.10000000000000001"), std::string::npos) << line;
  EXPECT_NE(line.find("\"seq\":18446744073709551615"), std::string::npos) << line;
  const DecodeResult r = decode_json(line);
  ASSERT_TRUE(r.ok()) << line << " -> " << to_string(r.error);
  EXPECT_TRUE(bitwise_equal(r.message, m)) << line;
  EXPECT_TRUE(std::signbit(r.message.position->z()));
}

TEST(JsonLines, AcceptsAnyValidJsonOfTheShape) {
  const DecodeResult minimal = decode_json(kMinimal);
  ASSERT_TRUE(minimal.ok()) << to_string(minimal.error);
  EXPECT_EQ(minimal.message.session, 1u);
  EXPECT_EQ(minimal.message.stream, 2u);
  EXPECT_EQ(minimal.message.sequence, 3u);
  EXPECT_EQ(minimal.message.flags, 0);
  EXPECT_FALSE(minimal.message.position);
  // Whitespace, member order, escaped names, unknown members (skipped, whatever their value),
  // exponents, no trailing newline, CRLF.
  const std::string fancy =
      " \t{ \"flags\" : [ \"bridged\" , \"clamped\" ] ,\r\n \"q\":[ -1.0E0 , 0, 0 ,0 ],\"extra\":{\"a\":[1,{\"b\":null}],\"c\":true},"
      "\"\\u0076\":1, \"sent\": 1.7e9, \"t\":-2.5e-3,\"seq\":0,\"stream\":4294967295,\"session\":0,"
      "\"p\":[1e2,2E+1,-3],\"w\":[0.0,-0,1e-400],\"note\":\"\\\"\\\\\\/\\b\\f\\n\\r\\t\\u00e9\\ud83d\\ude00\"}\r\n";
  const DecodeResult r = decode_json(fancy);
  ASSERT_TRUE(r.ok()) << to_string(r.error);
  EXPECT_EQ(r.message.flags, kFlagPosition | kFlagAngularVelocity | kFlagClamped | kFlagBridged);
  EXPECT_EQ(r.message.stream, 4294967295u);
  EXPECT_EQ(r.message.orientation.w(), -1.0);
  EXPECT_EQ(r.message.sample_time, -2.5e-3);
  EXPECT_EQ(*r.message.position, Vec3(100, 20, -3));
  EXPECT_EQ(r.message.angular_velocity->z(), 0.0);  // 1e-400 underflows to 0, not an error
  EXPECT_TRUE(std::signbit(r.message.angular_velocity->y()));
  // Raw UTF-8 in strings, and 16 nested containers (the limit, the top object included).
  EXPECT_TRUE(decode_json(std::string(kMinimal).insert(1, "\"n\u00f6te\":\"\xc3\xa9\xe2\x82\xac\xf0\x9f\x98\x80\",")).ok());
  EXPECT_TRUE(decode_json(std::string(kMinimal).insert(1, "\"x\":" + std::string(15, '[') + std::string(15, ']') + ",")).ok());
}

TEST(JsonLines, RejectsMalformedJsonAsSyntaxErrors) {
  const std::string m = kMinimal;
  const std::vector<std::string> bad = {
      "",
      "{",
      m.substr(0, m.size() - 1),                                // unterminated
      m + "x",                                                  // trailing garbage
      m + m,                                                    // two objects
      R"({"v":1,})",                                            // trailing comma
      R"({'v':1})",                                             // single quotes
      R"({"v":1 "session":1})",                                 // missing comma
      R"({"v"1})",                                              // missing colon
      R"({v:1})",                                               // bare name
      R"({"v":01,"session":1,"stream":2,"seq":3,"t":0.5,"sent":0,"q":[1,0,0,0]})",   // leading zero
      R"({"v":+1,"session":1,"stream":2,"seq":3,"t":0.5,"sent":0,"q":[1,0,0,0]})",   // plus sign
      R"({"v":1,"session":1,"stream":2,"seq":3,"t":.5,"sent":0,"q":[1,0,0,0]})",     // no leading digit
      R"({"v":1,"session":1,"stream":2,"seq":3,"t":1.,"sent":0,"q":[1,0,0,0]})",     // no fraction digit
      R"({"v":1,"session":1,"stream":2,"seq":3,"t":1e,"sent":0,"q":[1,0,0,0]})",     // no exponent digit
      R"({"v":1,"session":1,"stream":2,"seq":3,"t":NaN,"sent":0,"q":[1,0,0,0]})",    // not JSON
      R"({"v":1,"session":1,"stream":2,"seq":3,"t":Infinity,"sent":0,"q":[1,0,0,0]})",
      R"({"v":1,"session":1,"stream":2,"seq":3,"t":0x10,"sent":0,"q":[1,0,0,0]})",
      R"({"v":1,"session":1,"stream":2,"seq":3,"t":0.5,"sent":0,"q":[1,0,0,0,]})",   // trailing comma
      R"({"v":1,"session":1,"stream":2,"seq":3,"t":0.5,"sent":0,"q":[1,0,0,0})",     // unclosed array
      R"({"v":1,"session":1,"stream":2,"seq":3,"t":0.5,"sent":0,"q":[1,0,0,0],"x":tru})",
      R"({"v":1,"session":1,"stream":2,"seq":3,"t":0.5,"sent":0,"q":[1,0,0,0],"x":"\q"})",    // bad escape
      R"({"v":1,"session":1,"stream":2,"seq":3,"t":0.5,"sent":0,"q":[1,0,0,0],"x":"\u12"})",  // short \u
      R"({"v":1,"session":1,"stream":2,"seq":3,"t":0.5,"sent":0,"q":[1,0,0,0],"x":"\udc00"})",  // lone surrogate
      R"({"v":1,"session":1,"stream":2,"seq":3,"t":0.5,"sent":0,"q":[1,0,0,0],"x":"\ud800x"})",
      R"({"v":1,"session":1,"stream":2,"seq":3,"t":0.5,"sent":0,"q":[1,0,0,0],"x":")" "\x01\"}",
      R"({"v":1,"session":1,"stream":2,"seq":3,"t":0.5,"sent":0,"q":[1,0,0,0],"x":)" + std::string(16, '[') +
          std::string(16, ']') + "}",  // 17 nested containers with the top object
      // Invalid UTF-8 in a string: a stray byte, an overlong '/', a cut sequence, a UTF-16 surrogate.
      R"({"v":1,"session":1,"stream":2,"seq":3,"t":0.5,"sent":0,"q":[1,0,0,0],"x":")" "\xff\"}",
      R"({"v":1,"session":1,"stream":2,"seq":3,"t":0.5,"sent":0,"q":[1,0,0,0],"x":")" "\xc0\xaf\"}",
      R"({"v":1,"session":1,"stream":2,"seq":3,"t":0.5,"sent":0,"q":[1,0,0,0],"x":")" "\xe2\x82\"}",
      R"({"v":1,"session":1,"stream":2,"seq":3,"t":0.5,"sent":0,"q":[1,0,0,0],"x":")" "\xed\xa0\x80\"}",
  };
  for (const std::string& s : bad) EXPECT_EQ(error_of(s), DecodeError::kJsonSyntax) << s;
}

TEST(JsonLines, RejectsWrongShapeAsSchemaErrors) {
  const std::vector<std::string> bad = {
      "[1,2,3]",
      "{}",
      R"({"session":1,"stream":2,"seq":3,"t":0.5,"sent":0,"q":[1,0,0,0]})",          // no v
      R"({"v":1,"stream":2,"seq":3,"t":0.5,"sent":0,"q":[1,0,0,0]})",                // no session
      R"({"v":1,"session":1,"seq":3,"t":0.5,"sent":0,"q":[1,0,0,0]})",               // no stream
      R"({"v":1,"session":1,"stream":2,"t":0.5,"sent":0,"q":[1,0,0,0]})",            // no seq
      R"({"v":1,"session":1,"stream":2,"seq":3,"sent":0,"q":[1,0,0,0]})",            // no t
      R"({"v":1,"session":1,"stream":2,"seq":3,"t":0.5,"q":[1,0,0,0]})",             // no sent
      R"({"v":1,"session":1,"stream":2,"seq":3,"t":0.5,"sent":0})",                  // no q
      R"({"v":"1","session":1,"stream":2,"seq":3,"t":0.5,"sent":0,"q":[1,0,0,0]})",  // v a string
      R"({"v":1.0,"session":1,"stream":2,"seq":3,"t":0.5,"sent":0,"q":[1,0,0,0]})",  // v not an integer
      R"({"v":1,"session":-1,"stream":2,"seq":3,"t":0.5,"sent":0,"q":[1,0,0,0]})",
      R"({"v":1,"session":4294967296,"stream":2,"seq":3,"t":0.5,"sent":0,"q":[1,0,0,0]})",
      R"({"v":1,"session":1,"stream":2.5,"seq":3,"t":0.5,"sent":0,"q":[1,0,0,0]})",
      R"({"v":1,"session":1,"stream":2,"seq":1e3,"t":0.5,"sent":0,"q":[1,0,0,0]})",
      R"({"v":1,"session":1,"stream":2,"seq":18446744073709551616,"t":0.5,"sent":0,"q":[1,0,0,0]})",
      R"({"v":1,"session":1,"stream":2,"seq":true,"t":0.5,"sent":0,"q":[1,0,0,0]})",
      R"({"v":1,"session":1,"stream":2,"seq":3,"t":"0.5","sent":0,"q":[1,0,0,0]})",
      R"({"v":1,"session":1,"stream":2,"seq":3,"t":0.5,"sent":0,"q":[1,0,0]})",       // 3 components
      R"({"v":1,"session":1,"stream":2,"seq":3,"t":0.5,"sent":0,"q":[1,0,0,0,0]})",
      R"({"v":1,"session":1,"stream":2,"seq":3,"t":0.5,"sent":0,"q":{"w":1}})",
      R"({"v":1,"session":1,"stream":2,"seq":3,"t":0.5,"sent":0,"q":[1,0,0,"0"]})",
      R"({"v":1,"session":1,"stream":2,"seq":3,"t":0.5,"sent":0,"q":[1,0,0,0],"p":[1,2]})",
      R"({"v":1,"session":1,"stream":2,"seq":3,"t":0.5,"sent":0,"q":[1,0,0,0],"w":null})",
      R"({"v":1,"session":1,"stream":2,"seq":3,"t":0.5,"sent":0,"q":[1,0,0,0],"flags":"clamped"})",
      R"({"v":1,"session":1,"stream":2,"seq":3,"t":0.5,"sent":0,"q":[1,0,0,0],"flags":[4]})",
      R"({"v":1,"session":1,"stream":2,"seq":3,"seq":4,"t":0.5,"sent":0,"q":[1,0,0,0]})",  // duplicate
      // A schema error outranks a non-finite value elsewhere.
      R"({"v":1,"session":1,"stream":2,"seq":3,"t":null,"sent":0,"q":[1,0,0]})",
  };
  for (const std::string& s : bad) EXPECT_EQ(error_of(s), DecodeError::kJsonSchema) << s;
}

TEST(JsonLines, RejectsSemanticErrorsWithTheBinaryCodes) {
  EXPECT_EQ(error_of(R"({"v":2,"session":1,"stream":2,"seq":3,"t":0.5,"sent":0,"q":[1,0,0,0]})"),
            DecodeError::kUnsupportedVersion);
  EXPECT_EQ(error_of(R"({"v":0,"session":1,"stream":2,"seq":3,"t":0.5,"sent":0,"q":[1,0,0,0]})"),
            DecodeError::kUnsupportedVersion);
  EXPECT_EQ(error_of(R"({"v":1,"session":1,"stream":2,"seq":3,"t":0.5,"sent":0,"q":[1,0,0,0],"flags":["wobbly"]})"),
            DecodeError::kUnknownFlags);
  EXPECT_EQ(error_of(R"({"v":1,"session":1,"stream":2,"seq":3,"t":null,"sent":0,"q":[1,0,0,0]})"),
            DecodeError::kNonFinite);
  EXPECT_EQ(error_of(R"({"v":1,"session":1,"stream":2,"seq":3,"t":0.5,"sent":1e999,"q":[1,0,0,0]})"),
            DecodeError::kNonFinite);
  EXPECT_EQ(error_of(R"({"v":1,"session":1,"stream":2,"seq":3,"t":0.5,"sent":0,"q":[1,0,0,0],"p":[0,-1e309,0]})"),
            DecodeError::kNonFinite);
  EXPECT_EQ(error_of(R"({"v":1,"session":1,"stream":2,"seq":3,"t":0.5,"sent":0,"q":[0,0,0,0]})"),
            DecodeError::kBadQuaternion);
  EXPECT_EQ(error_of(R"({"v":1,"session":1,"stream":2,"seq":3,"t":0.5,"sent":0,"q":[1.01,0,0,0]})"),
            DecodeError::kBadQuaternion);
  // The encoder writes null for a non-finite number, so such a message cannot pass as valid.
  PoseMessage m = testing::sample_message(kFlagPosition, 4);
  m.position->y() = std::numeric_limits<double>::infinity();
  const std::string line = encode_json(m);
  EXPECT_NE(line.find("null"), std::string::npos);
  EXPECT_EQ(decode_json(line).error, DecodeError::kNonFinite);
}

TEST(JsonLines, OversizedLinesAreRejectedBeforeParsing) {
  std::string big = kMinimal;
  big.insert(big.size() - 1, ",\"pad\":\"" + std::string(1500, 'x') + "\"");
  EXPECT_EQ(error_of(big), DecodeError::kOversized);
}

}  // namespace
}  // namespace posefair::daemon
