#include "posefair/daemon/source_rate_limiter.hpp"

#include <sodium.h>

#include <algorithm>
#include <cstring>
#include <stdexcept>

namespace posefair::daemon {

bool TokenBucket::take(double rate, double burst, std::chrono::nanoseconds now) {
  if (now > last) tokens = std::min(burst, tokens + rate * std::chrono::duration<double>(now - last).count());
  last = std::max(last, now);
  if (tokens < 1.0) return false;
  tokens -= 1.0;
  return true;
}

SourceRateLimiter::SourceRateLimiter(std::size_t slots, double rate, double burst)
    : table_(std::max<std::size_t>(slots, 1)), rate_(rate), burst_(std::max(burst, 1.0)) {
  if (::sodium_init() < 0) throw std::runtime_error("libsodium could not be initialised");
  ::randombytes_buf(key_.data(), key_.size());
}

bool SourceRateLimiter::allow(const Endpoint& source, std::chrono::nanoseconds now) {
  constexpr std::size_t kProbes = 4;
  const AddressBytes a = address_bytes(source);
  std::array<std::uint8_t, 17> in{};
  in[0] = static_cast<std::uint8_t>(a.family == AF_INET ? 4 : 6);
  std::copy(a.bytes.begin(), a.bytes.end(), in.begin() + 1);
  std::uint64_t h = 0;
  std::array<std::uint8_t, 8> out{};
  ::crypto_shorthash(out.data(), in.data(), in.size(), key_.data());
  std::memcpy(&h, out.data(), sizeof h);
  Slot* victim = nullptr;
  for (std::size_t i = 0; i < kProbes; ++i) {
    Slot& s = table_[(h + i) % table_.size()];
    if (s.used && s.address.family == a.family && s.address.bytes == a.bytes) return s.bucket.take(rate_, burst_, now);
    if (!s.used) {
      if (!victim || victim->used) victim = &s;
    } else if (!victim || (victim->used && s.bucket.last < victim->bucket.last)) {
      victim = &s;
    }
  }
  if (victim->used) ++evictions_;
  victim->used = true;
  victim->address = a;
  victim->bucket = TokenBucket{burst_, now};
  return victim->bucket.take(rate_, burst_, now);
}

}  // namespace posefair::daemon
