#pragma once
// A token bucket per source address for the subscription port (chrony's ratelimit, in spirit),
// in a fixed table: memory does not grow with the number of sources, however many a flood
// spoofs. The table is indexed by a keyed hash (libsodium crypto_shorthash, SipHash) under a
// random key, so an attacker cannot aim many sources at one slot; among a few probed slots the
// least recently seen is replaced. A source pushed out starts again with a full bucket, which
// errs towards serving a legitimate client.
#include <array>
#include <chrono>
#include <cstdint>
#include <vector>

#include "posefair/daemon/address_allow_list.hpp"

namespace posefair::daemon {

// One bucket: `rate` tokens a second up to `burst`.
struct TokenBucket {
  double tokens = 0.0;
  std::chrono::nanoseconds last{0};
  bool take(double rate, double burst, std::chrono::nanoseconds now);
};

class SourceRateLimiter {
 public:
  SourceRateLimiter(std::size_t slots, double rate, double burst);
  // True when the source may send one more datagram now (a token was taken).
  bool allow(const Endpoint& source, std::chrono::nanoseconds now);
  std::uint64_t evictions() const { return evictions_; }
  std::size_t slots() const { return table_.size(); }

 private:
  struct Slot {
    AddressBytes address;
    TokenBucket bucket;
    bool used = false;
  };
  std::vector<Slot> table_;  // allocated once
  std::array<std::uint8_t, 16> key_{};
  double rate_, burst_;
  std::uint64_t evictions_ = 0;
};

}  // namespace posefair::daemon
