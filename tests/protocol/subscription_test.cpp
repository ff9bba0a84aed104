// The subscription protocol's pure parts (docs/protocol.md, "Subscribing"; docs/security.md):
// the golden bytes of docs/protocol.md, every parse error, the reply never larger than the
// request, the pre-shared-key MAC, cookies (other address, other port, expired), the allow list,
// the per-source rate limiter's bounded table, the subscriber table's caps, renewals and replays,
// and the handler's rule that an address which has not echoed a cookie gets nothing but a cookie.
#include <gtest/gtest.h>

#include <array>
#include <chrono>
#include <cstdint>
#include <random>
#include <string>
#include <vector>

#include "posefair/daemon/address_allow_list.hpp"
#include "posefair/daemon/control_command.hpp"
#include "posefair/daemon/source_rate_limiter.hpp"
#include "posefair/daemon/subscriber_table.hpp"
#include "posefair/daemon/subscription_client.hpp"
#include "posefair/daemon/subscription_cookie.hpp"
#include "posefair/daemon/subscription_handler.hpp"
#include "posefair/daemon/subscription_message.hpp"

namespace posefair::daemon {
namespace {

using namespace std::chrono_literals;
using Bytes = std::vector<std::uint8_t>;

Bytes hex(const std::string& text) {
  Bytes b;
  for (std::size_t i = 0; i + 1 < text.size();) {
    if (text[i] == ' ') {
      ++i;
      continue;
    }
    b.push_back(static_cast<std::uint8_t>(std::stoi(text.substr(i, 2), nullptr, 16)));
    i += 2;
  }
  return b;
}

Endpoint ep(const char* text) { return *Endpoint::parse(text); }

// docs/protocol.md, "Subscribing", examples.
const std::string kGoldenSubscribe =
    "50 46 53 31 01 00 06 02 04 03 02 01 30 75 00 00  00 00 00 00 00 00 00 00 00 00 00 00 00 00 00 00"
    " 62 69 6e 61 72 79 01 00 00 00 07 00 00 00";
const std::string kGoldenSubscribeSigned =
    "50 46 53 31 01 02 06 02 04 03 02 01 30 75 00 00  00 00 00 00 00 00 00 00 00 00 00 00 00 00 00 00"
    " 62 69 6e 61 72 79 01 00 00 00 07 00 00 00"
    " 1f f6 cb 54 42 ce 9c 49 62 49 e8 36 46 52 72 e8 ef 32 e4 2b e0 7c c4 cb 77 a3 d9 70 e3 22 f6 b9";
const std::string kGoldenCookie =
    "50 46 53 31 81 00 00 00 04 03 02 01 00 00 00 00  00 01 02 03 04 05 06 07 08 09 0a 0b 0c 0d 0e 0f";
const std::string kGoldenSubscribed =
    "50 46 53 31 82 00 00 00 05 03 02 01 30 75 00 00  00 00 00 00 00 00 00 00 00 00 00 00 00 00 00 00";
const std::string kGoldenUnsubscribe =
    "50 46 53 31 02 00 00 00 06 03 02 01 00 00 00 00  00 01 02 03 04 05 06 07 08 09 0a 0b 0c 0d 0e 0f";

SubscriptionRequest example_subscribe() {
  SubscriptionRequest r;
  r.request_id = 0x01020304;
  r.lease_ms = 30000;
  r.encoding = "binary";
  r.streams = {1, 7};
  return r;
}

Cookie counting_cookie() {
  Cookie c{};
  for (std::size_t i = 0; i < c.size(); ++i) c[i] = static_cast<std::uint8_t>(i);
  return c;
}

PreSharedKey counting_key() {
  PreSharedKey k{};
  for (std::size_t i = 0; i < k.size(); ++i) k[i] = static_cast<std::uint8_t>(i);
  return k;
}

TEST(SubscriptionMessage, GoldenBytesOfTheSpecification) {
  EXPECT_EQ(encode_request(example_subscribe()), hex(kGoldenSubscribe));
  EXPECT_EQ(encode_request(example_subscribe(), counting_key()), hex(kGoldenSubscribeSigned));
  SubscriptionReply cookie;
  cookie.type = ReplyType::Cookie;
  cookie.request_id = 0x01020304;
  cookie.cookie = counting_cookie();
  const auto c = encode_reply(cookie);
  EXPECT_EQ(Bytes(c.begin(), c.end()), hex(kGoldenCookie));
  SubscriptionReply subscribed;
  subscribed.type = ReplyType::Subscribed;
  subscribed.request_id = 0x01020305;
  subscribed.lease_ms = 30000;
  const auto s = encode_reply(subscribed);
  EXPECT_EQ(Bytes(s.begin(), s.end()), hex(kGoldenSubscribed));
  SubscriptionRequest u;
  u.type = RequestType::Unsubscribe;
  u.request_id = 0x01020306;
  u.cookie = counting_cookie();
  EXPECT_EQ(encode_request(u), hex(kGoldenUnsubscribe));

  const Bytes golden = hex(kGoldenSubscribe);
  const ParsedRequest p = parse_request(golden);
  ASSERT_TRUE(p) << to_string(p.error);
  EXPECT_EQ(p.request.encoding, "binary");
  EXPECT_EQ(p.request.streams, (std::vector<std::uint32_t>{1, 7}));
  EXPECT_EQ(p.request.lease_ms, 30000u);
  EXPECT_FALSE(p.request.has_cookie());
  const auto r = parse_reply(hex(kGoldenCookie));
  ASSERT_TRUE(r);
  EXPECT_EQ(r->type, ReplyType::Cookie);
  EXPECT_EQ(r->cookie, counting_cookie());
}

TEST(SubscriptionMessage, EveryParseErrorHasItsCase) {
  const Bytes good = hex(kGoldenSubscribe);
  auto with = [&](std::size_t at, std::uint8_t v) {
    Bytes b = good;
    b[at] = v;
    return b;
  };
  EXPECT_EQ(parse_request(Bytes(good.begin(), good.begin() + 31)).error, RequestError::TooShort);
  EXPECT_EQ(parse_request(Bytes(1501, 0)).error, RequestError::Oversized);
  EXPECT_EQ(parse_request(with(0, 'X')).error, RequestError::BadMagic);
  EXPECT_EQ(parse_request(with(4, 3)).error, RequestError::BadType);
  EXPECT_EQ(parse_request(with(5, 0x04)).error, RequestError::UnknownFlags);
  EXPECT_EQ(parse_request(with(7, 3)).error, RequestError::BadLength);
  EXPECT_EQ(parse_request(with(7, 17)).error, RequestError::TooManyStreams);
  EXPECT_EQ(parse_request(with(32, 'B')).error, RequestError::BadEncodingName);
  Bytes extra = good;
  extra.push_back(0);
  EXPECT_EQ(parse_request(extra).error, RequestError::BadLength);
  // A SUBSCRIBE must name an encoding; an UNSUBSCRIBE need not.
  SubscriptionRequest none = example_subscribe();
  none.encoding.clear();
  none.streams.clear();
  EXPECT_EQ(parse_request(encode_request(none)).error, RequestError::BadEncodingName);
  none.type = RequestType::Unsubscribe;
  EXPECT_TRUE(parse_request(encode_request(none)));
  // Flagged as signed but without room for the MAC.
  EXPECT_EQ(parse_request(with(5, kRequestAuthenticated)).error, RequestError::BadLength);
}

TEST(SubscriptionMessage, RandomBytesNeverCrashAndEveryValidRequestIsAtLeastAReply) {
  std::mt19937 rng(7);
  for (int i = 0; i < 20000; ++i) {
    Bytes b(rng() % 120);
    for (auto& x : b) x = static_cast<std::uint8_t>(rng());
    if (b.size() >= 4 && rng() % 2) std::copy(kSubscriptionMagic.begin(), kSubscriptionMagic.end(), b.begin());
    const ParsedRequest p = parse_request(b);
    if (p) {
      EXPECT_GE(b.size(), kReplySize);
    }
  }
}

TEST(SubscriptionMessage, MacVerifiesOnlyWithTheKeyAndTheBytes) {
  const PreSharedKey key = counting_key();
  const Bytes signed_request = encode_request(example_subscribe(), key);
  EXPECT_TRUE(request_mac_valid(parse_request(signed_request), key));
  PreSharedKey other = key;
  other[0] ^= 1;
  EXPECT_FALSE(request_mac_valid(parse_request(signed_request), other));
  Bytes tampered = signed_request;
  tampered[12] ^= 1;  // the lease
  EXPECT_FALSE(request_mac_valid(parse_request(tampered), key));
  EXPECT_FALSE(request_mac_valid(parse_request(encode_request(example_subscribe())), key));  // unsigned
  EXPECT_EQ(parse_psk(" 000102030405060708090a0b0c0d0e0f101112131415161718191a1b1c1d1e1f\n"), key);
  EXPECT_FALSE(parse_psk("0001"));
  EXPECT_FALSE(parse_psk(std::string(64, 'g')));
}

TEST(SubscriptionCookie, BoundToAddressPortAndTime) {
  CookieJar jar(10s);
  const Endpoint a = ep("127.0.0.2:4000");
  const auto t = 1000s;
  const Cookie c = jar.make(a, t);
  EXPECT_TRUE(jar.valid(a, c, t));
  EXPECT_TRUE(jar.valid(a, c, t + 10s));    // the next slot still takes it
  EXPECT_FALSE(jar.valid(a, c, t + 20s));   // expired
  EXPECT_FALSE(jar.valid(ep("127.0.0.3:4000"), c, t));  // another address
  EXPECT_FALSE(jar.valid(ep("127.0.0.2:4001"), c, t));  // another port
  EXPECT_FALSE(jar.valid(a, Cookie{}, t));
  CookieJar other(10s);  // another start: another key
  EXPECT_FALSE(other.valid(a, c, t));
}

TEST(AddressAllowList, CidrRanges) {
  const auto r = CidrRange::parse("192.168.10.77/24");
  ASSERT_TRUE(r);
  EXPECT_EQ(r->to_string(), "192.168.10.0/24");
  AddressAllowList allow({*r, *CidrRange::parse("fd00::/8")});
  EXPECT_TRUE(allow.allows(ep("192.168.10.3:1")));
  EXPECT_FALSE(allow.allows(ep("192.168.11.3:1")));
  EXPECT_TRUE(allow.allows(ep("[fd12::1]:1")));
  EXPECT_FALSE(allow.allows(ep("[fe80::1]:1")));
  EXPECT_TRUE(allow.allows(ep("[::ffff:192.168.10.9]:1")));  // mapped IPv4 judged as IPv4
  EXPECT_TRUE(AddressAllowList::loopback().allows(ep("127.9.9.9:1")));
  EXPECT_TRUE(AddressAllowList::loopback().allows(ep("[::1]:1")));
  EXPECT_FALSE(AddressAllowList::loopback().allows(ep("10.0.0.1:1")));
  EXPECT_FALSE(CidrRange::parse("10.0.0.0/33"));
  EXPECT_FALSE(CidrRange::parse("10.0.0.0/"));
  EXPECT_FALSE(CidrRange::parse("host.example/8"));
  EXPECT_TRUE(CidrRange::parse("::/0"));
}

TEST(SourceRateLimiter, BucketPerSourceInAFixedTable) {
  SourceRateLimiter limiter(64, 10.0, 3.0);
  const Endpoint a = ep("127.0.0.2:1");
  const auto t = 100s;
  for (int i = 0; i < 3; ++i) EXPECT_TRUE(limiter.allow(a, t));
  EXPECT_FALSE(limiter.allow(a, t));          // burst spent
  EXPECT_TRUE(limiter.allow(a, t + 100ms));   // one token back after 1/rate
  EXPECT_TRUE(limiter.allow(ep("127.0.0.3:1"), t));  // another source has its own bucket
  // A flood of distinct sources only replaces slots; the table does not grow.
  for (int i = 0; i < 10000; ++i) {
    const std::string text = "10." + std::to_string(i / 65536 % 256) + "." + std::to_string(i / 256 % 256) + "." + std::to_string(i % 256) + ":9";
    limiter.allow(ep(text.c_str()), t);
  }
  EXPECT_EQ(limiter.slots(), 64u);
  EXPECT_GT(limiter.evictions(), 9000u);
}

Subscriber subscriber(const char* address, std::uint32_t request_id, std::int64_t expires_ns = 1'000'000'000'000) {
  Subscriber s;
  s.address = ep(address);
  s.last_request_id = request_id;
  s.expires_ns = expires_ns;
  return s;
}

TEST(SubscriberTable, CapsRenewalsReplaysAndExpiry) {
  SubscriberTable table(3, 2);
  using O = SubscriberTable::Outcome;
  EXPECT_EQ(table.subscribe(subscriber("127.0.0.2:1", 5)), O::Added);
  EXPECT_EQ(table.subscribe(subscriber("127.0.0.2:2", 5)), O::Added);
  EXPECT_EQ(table.subscribe(subscriber("127.0.0.2:3", 5)), O::AddressFull);
  EXPECT_EQ(table.subscribe(subscriber("127.0.0.3:1", 5)), O::Added);
  EXPECT_EQ(table.subscribe(subscriber("127.0.0.4:1", 5)), O::TableFull);
  EXPECT_EQ(table.subscribe(subscriber("127.0.0.2:1", 5)), O::Replayed);  // the same id again
  EXPECT_EQ(table.subscribe(subscriber("127.0.0.2:1", 4)), O::Replayed);
  EXPECT_EQ(table.subscribe(subscriber("127.0.0.2:1", 6, 10)), O::Renewed);
  EXPECT_FALSE(table.unsubscribe(ep("127.0.0.3:1"), 5));  // not a newer id
  EXPECT_TRUE(table.unsubscribe(ep("127.0.0.3:1"), 6));
  EXPECT_EQ(table.size(), 2u);
  EXPECT_EQ(table.expire(11), 1u);  // the renewed one's lease ended at 10
  EXPECT_EQ(table.size(), 1u);

  // The publisher's view starts with the table's entries, with no refresh: a subscriber that was
  // there before the first pose is sent it even when the lock is busy then (CI once lost 8 poses).
  SubscriberTable::View v = table.make_view();
  ASSERT_EQ(v.count, 1u);
  EXPECT_EQ(v.entries[0].address, ep("127.0.0.2:2"));
  // It follows the table without waiting for it.
  EXPECT_EQ(table.subscribe(subscriber("127.0.0.3:1", 7)), O::Added);
  table.refresh(v);
  ASSERT_EQ(v.count, 2u);
  EXPECT_TRUE(table.unsubscribe(ep("127.0.0.3:1"), 8));
  table.refresh(v);
  ASSERT_EQ(v.count, 1u);
  EXPECT_EQ(v.entries[0].address, ep("127.0.0.2:2"));
  table.count_sent(v.slot[0], 3);
  EXPECT_EQ(table.list().at(0).sent, 3u);
}

// What a dropped request "answers" in the assertions below: no reply type at all.
const SubscriptionReply kNoReply{static_cast<ReplyType>(0), RefuseReason::None, 0, 0, {}};

// A handler on loopback with a fixed clock the test moves.
struct HandlerFixture : ::testing::Test {
  SubscriptionSettings settings() {
    SubscriptionSettings s;
    s.rate_per_source = 1e6;
    s.burst_per_source = 1e6;
    s.max_subscribers = 4;
    s.max_per_address = 2;
    return s;
  }
  std::shared_ptr<SubscriberTable> table;
  std::unique_ptr<SubscriptionHandler> handler;
  std::chrono::nanoseconds now = 1000s;
  void SetUp() override { make(settings()); }
  void make(const SubscriptionSettings& s) {
    table = std::make_shared<SubscriberTable>(s.max_subscribers, s.max_per_address);
    handler = std::make_unique<SubscriptionHandler>(s, table);
    handler->set_streams({1, 7});
  }
  std::optional<SubscriptionReply> send(const Bytes& request, const char* from) {
    const auto reply = handler->handle(request, ep(from), now);
    if (!reply) return std::nullopt;
    EXPECT_LE(reply->size(), request.size());
    return parse_reply(*reply);
  }
  // The whole handshake from `from`; the SUBSCRIBE's reply.
  std::optional<SubscriptionReply> subscribe(const char* from, SubscriptionRequest r = example_subscribe()) {
    const auto cookie = send(encode_request(r), from);
    if (!cookie || cookie->type != ReplyType::Cookie) return cookie;
    r.cookie = cookie->cookie;
    r.request_id += 1;
    return send(encode_request(r), from);
  }
};

TEST_F(HandlerFixture, AnUnverifiedAddressGetsOnlyACookie) {
  const auto first = send(encode_request(example_subscribe()), "127.0.0.2:5000");
  ASSERT_TRUE(first);
  EXPECT_EQ(first->type, ReplyType::Cookie);
  EXPECT_EQ(table->size(), 0u);  // nothing kept for it
  const auto done = subscribe("127.0.0.2:5000");
  ASSERT_TRUE(done);
  EXPECT_EQ(done->type, ReplyType::Subscribed);
  EXPECT_EQ(done->lease_ms, 30000u);
  EXPECT_EQ(table->size(), 1u);
}

TEST_F(HandlerFixture, ExpiredReplayedAndForeignCookiesAreRefused) {
  SubscriptionRequest r = example_subscribe();
  const auto cookie = send(encode_request(r), "127.0.0.2:5000");
  ASSERT_TRUE(cookie);
  r.cookie = cookie->cookie;
  r.request_id += 1;
  // From another address, or another port: only a new cookie, and no subscriber.
  EXPECT_EQ(send(encode_request(r), "127.0.0.3:5000").value_or(kNoReply).type, ReplyType::Cookie);
  EXPECT_EQ(send(encode_request(r), "127.0.0.2:5001").value_or(kNoReply).type, ReplyType::Cookie);
  EXPECT_EQ(table->size(), 0u);
  // Expired: two slots later.
  now += 2 * handler->settings().cookie_slot;
  EXPECT_EQ(send(encode_request(r), "127.0.0.2:5000").value_or(kNoReply).type, ReplyType::Cookie);
  EXPECT_EQ(table->size(), 0u);
  EXPECT_EQ(handler->counters().bad_cookie.load(), 3u);
  // A subscription, then its exact request again (replayed): refused, no answer.
  const auto fresh = send(encode_request(example_subscribe()), "127.0.0.2:5000");
  ASSERT_TRUE(fresh);
  r.cookie = fresh->cookie;
  const Bytes accepted = encode_request(r);
  EXPECT_EQ(send(accepted, "127.0.0.2:5000").value_or(kNoReply).type, ReplyType::Subscribed);
  EXPECT_FALSE(send(accepted, "127.0.0.2:5000"));
  EXPECT_EQ(handler->counters().replayed.load(), 1u);
}

TEST_F(HandlerFixture, ALeaseRenewedFromAnotherAddressIsRefused) {
  ASSERT_EQ(subscribe("127.0.0.2:5000").value_or(kNoReply).type, ReplyType::Subscribed);
  const auto before = table->list().at(0).subscriber.expires_ns;
  now += 5s;
  // The renewal carries the victim's cookie but comes from elsewhere.
  SubscriptionRequest r = example_subscribe();
  r.cookie = send(encode_request(r), "127.0.0.2:5000").value_or(kNoReply).cookie;
  r.request_id = 0x01020400;
  EXPECT_EQ(send(encode_request(r), "127.0.0.9:5000").value_or(kNoReply).type, ReplyType::Cookie);
  EXPECT_EQ(table->list().at(0).subscriber.expires_ns, before);
  EXPECT_EQ(table->size(), 1u);
  // From the subscriber itself it renews.
  EXPECT_EQ(send(encode_request(r), "127.0.0.2:5000").value_or(SubscriptionReply{}).type, ReplyType::Subscribed);
  EXPECT_GT(table->list().at(0).subscriber.expires_ns, before);
  EXPECT_EQ(handler->counters().renewed.load(), 1u);
}

// A subscriber gets only what needs nothing configured: vmc's bones and vrchat's trackers are the
// operator's to set, and dds has no datagram to send; those are refused like an unknown name.
TEST_F(HandlerFixture, OnlyEncodingsThatNeedNoConfigurationAreOffered) {
  for (const char* name : {"vmc", "vrchat", "freed", "dds"}) {
    SubscriptionRequest r = example_subscribe();
    r.encoding = name;
    EXPECT_EQ(subscribe("127.0.0.2:1", r).value_or(kNoReply).reason, RefuseReason::UnknownEncoding) << name;
  }
  const char* from[] = {"127.0.0.3:1", "127.0.0.4:1", "127.0.0.5:1"};
  const char* offered[] = {"binary", "json", "opentrack"};
  for (std::size_t k = 0; k < 3; ++k) {
    SubscriptionRequest r = example_subscribe();
    r.encoding = offered[k];
    EXPECT_EQ(subscribe(from[k], r).value_or(kNoReply).type, ReplyType::Subscribed) << offered[k];
  }
  ASSERT_EQ(table->size(), 3u);
  for (const SubscriberTable::Listed& l : table->list())
    EXPECT_NE(table->encoders()[l.subscriber.encoding], nullptr) << "a subscriber's encoding was not built";
}

TEST_F(HandlerFixture, LimitsAreCountedAndRefusalsGoOnlyToVerifiedAddresses) {
  SubscriptionRequest unknown = example_subscribe();
  unknown.streams = {3};
  EXPECT_EQ(subscribe("127.0.0.2:1", unknown).value_or(kNoReply).reason, RefuseReason::UnknownStream);
  unknown = example_subscribe();
  unknown.encoding = "protobuf";
  EXPECT_EQ(subscribe("127.0.0.2:1", unknown).value_or(kNoReply).reason, RefuseReason::UnknownEncoding);
  EXPECT_EQ(subscribe("127.0.0.2:1").value_or(kNoReply).type, ReplyType::Subscribed);
  EXPECT_EQ(subscribe("127.0.0.2:2").value_or(kNoReply).type, ReplyType::Subscribed);
  EXPECT_EQ(subscribe("127.0.0.2:3").value_or(kNoReply).reason, RefuseReason::AddressFull);
  EXPECT_EQ(subscribe("127.0.0.3:1").value_or(kNoReply).type, ReplyType::Subscribed);
  EXPECT_EQ(subscribe("127.0.0.4:1").value_or(kNoReply).type, ReplyType::Subscribed);
  EXPECT_EQ(subscribe("127.0.0.5:1").value_or(kNoReply).reason, RefuseReason::TableFull);
  EXPECT_FALSE(send(encode_request(example_subscribe()), "10.1.2.3:1"));  // not in the allow list
  EXPECT_FALSE(send(Bytes(40, 0), "127.0.0.2:9"));                         // malformed
  EXPECT_EQ(handler->counters().not_allowed.load(), 1u);
  EXPECT_EQ(handler->counters().malformed.load(), 1u);
  EXPECT_EQ(handler->counters().refused.load(), 4u);
  // Leases end.
  now += 61s;
  EXPECT_EQ(handler->expire(now), 4u);
  EXPECT_EQ(table->size(), 0u);
}

TEST_F(HandlerFixture, RatePerSource) {
  SubscriptionSettings s = settings();
  s.rate_per_source = 2;
  s.burst_per_source = 2;
  make(s);
  const Bytes r = encode_request(example_subscribe());
  EXPECT_TRUE(send(r, "127.0.0.2:1"));
  EXPECT_TRUE(send(r, "127.0.0.2:2"));   // the bucket is the address's, whatever the port
  EXPECT_FALSE(send(r, "127.0.0.2:1"));  // spent
  EXPECT_TRUE(send(r, "127.0.0.3:1"));   // another address has its own
  now += 500ms;
  EXPECT_TRUE(send(r, "127.0.0.2:1"));   // one token back
  EXPECT_EQ(handler->counters().rate_limited.load(), 1u);
}

TEST_F(HandlerFixture, WithAPreSharedKeyUnsignedRequestsGetNothing) {
  SubscriptionSettings s = settings();
  s.psk = counting_key();
  make(s);
  EXPECT_FALSE(send(encode_request(example_subscribe()), "127.0.0.2:1"));
  PreSharedKey wrong = counting_key();
  wrong[31] ^= 0x80;
  EXPECT_FALSE(send(encode_request(example_subscribe(), wrong), "127.0.0.2:1"));
  EXPECT_EQ(handler->counters().unauthenticated.load(), 2u);
  SubscriptionRequest r = example_subscribe();
  const auto cookie = send(encode_request(r, counting_key()), "127.0.0.2:1");
  ASSERT_TRUE(cookie);
  r.cookie = cookie->cookie;
  r.request_id += 1;
  EXPECT_EQ(send(encode_request(r, counting_key()), "127.0.0.2:1").value_or(kNoReply).type, ReplyType::Subscribed);
}

// In process, the measurement docs/security.md quotes: bytes out / bytes in over 100k
// unverified requests, from as many sources, of the smallest size a request can have.
TEST_F(HandlerFixture, AmplificationBeforeVerificationIsAtMostOne) {
  SubscriptionSettings s = settings();
  s.allow = AddressAllowList({*CidrRange::parse("10.0.0.0/8")});
  make(s);
  SubscriptionRequest smallest;
  smallest.type = RequestType::Unsubscribe;
  const Bytes request = encode_request(smallest);
  ASSERT_EQ(request.size(), kReplySize);
  std::uint64_t in = 0, out = 0;
  for (std::uint32_t i = 0; i < 100000; ++i) {
    const std::string from = "10." + std::to_string(i >> 16 & 255) + "." + std::to_string(i >> 8 & 255) + "." +
                             std::to_string(i & 255) + ":" + std::to_string(1024 + i % 60000);
    in += request.size();
    if (const auto reply = handler->handle(request, ep(from.c_str()), now)) out += reply->size();
  }
  EXPECT_EQ(out, in);  // every one answered with a cookie of exactly its size
  EXPECT_EQ(handler->counters().unverified_bytes_out.load(), out);
  EXPECT_EQ(table->size(), 0u);
}

TEST(SubscriptionClientMachine, HandshakeRenewalAndRefusal) {
  const Endpoint server = ep("127.0.0.1:5710");
  SubscriptionClient client(server, example_subscribe(), std::nullopt, 10);
  auto t = SubscriptionClient::Clock::time_point{} + 1000s;
  const auto first = client.due(t);
  ASSERT_TRUE(first);
  EXPECT_FALSE(client.due(t));  // waits for the answer
  SubscriptionReply c;
  c.type = ReplyType::Cookie;
  c.request_id = 10;
  c.cookie = counting_cookie();
  auto bytes = encode_reply(c);
  EXPECT_FALSE(client.on_reply(bytes, ep("127.0.0.1:5702"), t));  // not the server
  EXPECT_TRUE(client.on_reply(bytes, server, t));
  const auto second = client.due(t);
  ASSERT_TRUE(second);
  const ParsedRequest p = parse_request(*second);
  ASSERT_TRUE(p);
  EXPECT_EQ(p.request.cookie, counting_cookie());
  EXPECT_EQ(p.request.request_id, 11u);
  SubscriptionReply ok;
  ok.type = ReplyType::Subscribed;
  ok.request_id = 11;
  ok.lease_ms = 3000;
  bytes = encode_reply(ok);
  EXPECT_TRUE(client.on_reply(bytes, server, t));
  EXPECT_EQ(client.state(), SubscriptionClient::State::Subscribed);
  EXPECT_FALSE(client.due(t + 900ms));
  const auto renewal = client.due(t + 1000ms);  // a third of the lease
  ASSERT_TRUE(renewal);
  EXPECT_FALSE(parse_request(*renewal).request.has_cookie());
  SubscriptionReply no;
  no.type = ReplyType::Refused;
  no.reason = RefuseReason::TableFull;
  no.request_id = 12;
  bytes = encode_reply(no);
  client.on_reply(bytes, server, t);
  EXPECT_EQ(client.state(), SubscriptionClient::State::Refused);
  EXPECT_EQ(client.refused_because(), RefuseReason::TableFull);
}

TEST(ControlCommandParser, CommandsAndRejections) {
  auto parse = [](const std::string& s) {
    return parse_control_command(std::span(reinterpret_cast<const std::uint8_t*>(s.data()), s.size()));
  };
  EXPECT_EQ(parse("status\n").verb, ControlVerb::Status);
  EXPECT_EQ(parse("record stop\n").verb, ControlVerb::RecordStop);
  EXPECT_EQ(parse("counters\n").verb, ControlVerb::Counters);
  EXPECT_EQ(parse("").error, ControlCommandError::Empty);
  EXPECT_EQ(parse("\n").error, ControlCommandError::Empty);
  EXPECT_EQ(parse("status").error, ControlCommandError::NoNewline);
  EXPECT_EQ(parse("status\nreload\n").error, ControlCommandError::NoNewline);
  EXPECT_EQ(parse("record  stop\n").error, ControlCommandError::BadCharacter);
  EXPECT_EQ(parse(" status\n").error, ControlCommandError::BadCharacter);
  EXPECT_EQ(parse("stat\xc3\xa9\n").error, ControlCommandError::BadCharacter);
  EXPECT_EQ(parse("shutdown\n").error, ControlCommandError::UnknownCommand);
  EXPECT_EQ(parse(std::string(300, 'a') + "\n").error, ControlCommandError::Oversized);
  EXPECT_TRUE(changes_daemon(ControlVerb::Reload));
  EXPECT_FALSE(changes_daemon(ControlVerb::Counters));
}

}  // namespace
}  // namespace posefair::daemon
