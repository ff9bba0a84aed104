#pragma once
// Valid sample messages for the protocol tests.
#include <cstdint>
#include <random>

#include "posefair/daemon/wire_protocol.hpp"

namespace posefair::daemon::testing {

// A valid message with the given flags word (position / angular velocity present exactly when
// its presence bit is set) and values drawn from seed: awkward doubles (not short decimals),
// a unit quaternion in either hemisphere.
inline PoseMessage sample_message(std::uint16_t flags, std::uint64_t seed, std::uint32_t session = 0x5EED0001u,
                                  std::uint32_t stream = 3) {
  std::mt19937_64 rng(seed * 7919 + 17);
  std::normal_distribution<double> n(0.0, 1.0);
  PoseMessage m;
  m.session = session;
  m.stream = stream;
  m.sequence = seed;
  m.sample_time = 1000.0 + static_cast<double>(seed) / 1000.0 + 1e-7 * n(rng);
  m.send_time = 1.7e9 + static_cast<double>(seed) * 0.001 + 1e-9 * n(rng);
  m.orientation = Quat(n(rng), n(rng), n(rng), n(rng)).normalized();
  if (flags & kFlagPosition) m.position = Vec3(n(rng), 10 * n(rng), 1e-3 * n(rng));
  if (flags & kFlagAngularVelocity) m.angular_velocity = Vec3(n(rng), n(rng), 100 * n(rng));
  m.flags = flags;
  return m;
}

}  // namespace posefair::daemon::testing
