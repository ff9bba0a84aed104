// Fuzz target: the subscription port (daemon/subscription_message.hpp, subscription_handler.hpp).
// Any bytes either parse or are refused with an error; the handler given them (from a few
// sources, a pre-shared key or none) never answers with more bytes than came in, never answers
// anything but a cookie to an address whose cookie it did not see, and never throws.
#include <cstdint>
#include <cstdlib>
#include <memory>
#include <span>

#include "posefair/daemon/subscription_handler.hpp"
#include "posefair/daemon/subscription_message.hpp"

namespace {
using namespace posefair::daemon;

struct Fixture {
  std::shared_ptr<SubscriberTable> table = std::make_shared<SubscriberTable>(8, 4);
  std::unique_ptr<SubscriptionHandler> plain, keyed;
  Fixture() {
    SubscriptionSettings s;
    s.rate_per_source = 1e9;
    s.burst_per_source = 1e9;
    plain = std::make_unique<SubscriptionHandler>(s, table);
    plain->set_streams({1, 2, 7});
    s.psk = PreSharedKey{};
    keyed = std::make_unique<SubscriptionHandler>(s, std::make_shared<SubscriberTable>(8, 4));
  }
};
}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static Fixture f;
  static std::int64_t tick = 0;
  const std::span<const std::uint8_t> bytes(data, size);
  const ParsedRequest p = parse_request(bytes);
  if (p) {
    // What parses encodes back to the same bytes (unsigned requests; a signed one carries its MAC).
    if (p.mac.empty() && encode_request(p.request) != std::vector<std::uint8_t>(bytes.begin(), bytes.end())) std::abort();
  }
  (void)parse_reply(bytes);
  const auto now = std::chrono::nanoseconds(++tick * 1'000'000);
  for (const char* from : {"127.0.0.1:5000", "127.0.0.2:6000"}) {
    for (SubscriptionHandler* h : {f.plain.get(), f.keyed.get()}) {
      const auto reply = h->handle(bytes, *Endpoint::parse(from), now);
      if (!reply) continue;
      if (reply->size() > size) std::abort();
      const auto r = parse_reply(*reply);
      if (!r) std::abort();
      // A request without the source's cookie (random bytes cannot hold it) gets only a cookie.
      if (p && !p.request.has_cookie() && r->type != ReplyType::Cookie) std::abort();
    }
  }
  return 0;
}
