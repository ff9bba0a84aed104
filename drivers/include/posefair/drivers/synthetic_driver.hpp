#pragma once
// A simulated tracker: smooth motion plus bounded noise (core/synthetic_motion) delivered live
// at a fixed rate, for demos, soak tests and the daemon's latency benchmark. It is the replay
// driver playing motion generated at construction: blocks of at most 10 s, looped, each
// round's times continuing the last (the motion itself jumps once per block, which a window
// restart does not see because the time steps stay even).
#include <cstdint>
#include <memory>
#include <stop_token>
#include <string>
#include <string_view>

#include "posefair/drivers/driver.hpp"
#include "posefair/drivers/replay_driver.hpp"

namespace posefair::drivers {

struct SyntheticOptions {
  double rate_hz = 100.0;        // > 0
  double duration = 0.0;         // s; 0 = until stopped
  double rotation_noise = 0.01;  // rad, dist on S³; ≥ 0
  bool with_position = false;    // positions in metres, noise 1 mm
  std::uint64_t seed = 1;
  std::uint32_t stream_id = 0;
  double phase = 0.0;  // [0, 1): first sample this fraction of a period after run() starts
  // Deliver as fast as possible instead of at rate_hz (tests).
  bool as_fast_as_possible = false;
};

class SyntheticDriver final : public Driver {
 public:
  // Throws std::invalid_argument for a rate that is not finite and positive, a negative or
  // non-finite duration or noise.
  explicit SyntheticDriver(const SyntheticOptions& options);
  std::string_view name() const override { return name_; }
  void run(std::stop_token stop, SampleSink& sink) override;
  std::uint64_t delivered() const { return replay_->delivered(); }
  std::uint64_t dropped() const { return replay_->dropped(); }

 private:
  std::string name_;
  double start_delay_ = 0.0;  // s
  std::unique_ptr<ReplayDriver> replay_;
};

}  // namespace posefair::drivers
