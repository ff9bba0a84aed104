#pragma once
// [stream.engine] gyro_stream (docs/fusion.md, "A gyroscope from another stream"): an
// orientation stream gets its gyroscope readings from another stream on the same body, e.g. an
// optical tracker at 120 Hz from an IMU at 1 kHz. Each stream has its own engine role
// (pipeline.cpp): the source's holder adds each gyroscope reading here (add), and the paired
// stream's holder, before fairing each orientation sample, gives it the source's angular velocity
// at its time (apply). The two may run on two threads at once, so add() only puts the reading into
// an inbox (an SPSC ring that keeps the newest kCapacity), and apply() moves the inbox into the
// readings it matches against, which are its own: no lock, no allocation after construction.
//
// The match, for an orientation sample at time t whose previous sample was at t_prev: the mean
// m and mean time c of the source's readings stamped in (t_prev, t]. The mean is the rate at c,
// not at t (half an interval earlier, 4 ms at 120 Hz), and the engine takes a sample's gyro as
// the rate at the sample's time: that half interval would land in its time-offset estimate.
// So m is carried from c to t along the line through the previous interval's (c', m'):
// ω(t) = m + (m − m')·(t − c)/(c − c'), at most one interval ahead (exact for a rate that
// changes linearly; on white noise it costs 1.6× the mean's noise, still far below one reading's
// at 8 readings per interval). No reading in the interval: no match, and the sample goes on
// without a gyro (the engine's no-gyro path). After a gap in the orientation stream (an interval
// over twice the one before) only the last interval of the old length is averaged. The IMU's
// readings are in its own frame: the engine's gyro_mounting, bias and time offset apply as to a
// gyro in the sample itself.
#include <cstddef>
#include <cstdint>
#include <limits>
#include <memory>
#include <vector>

#include "posefair/core/sample.hpp"
#include "posefair/daemon/spsc_ring.hpp"

namespace posefair::daemon {

class GyroPairing {
 public:
  // Readings kept: 1 s at 1 kHz. Enough for any interval the engine does not treat as a gap.
  static constexpr std::size_t kCapacity = 1024;

  GyroPairing();

  // A reading of the source stream (its Sample::time, rad/s in the source's frame), from the
  // source's engine role. One that is not finite, or not later than the newest kept, is left out.
  void add(double time, const Vec3& gyro);
  // An orientation sample of the paired stream, in arrival order: on a match its gyro becomes
  // the source's rate at its time (kHasGyro); otherwise any gyro it had is taken away, so the
  // engine never mixes the stream's own gyro with the source's.
  void apply(Sample& s);

  std::uint64_t matched() const { return matched_; }
  std::uint64_t unmatched() const { return unmatched_; }

 private:
  struct Reading {
    double time = 0.0;
    Vec3 gyro = Vec3::Zero();
  };
  struct InboxReading {  // trivially copyable, for the SPSC ring
    double time;
    double gyro[3];
  };
  void keep(double time, const Vec3& gyro);  // a reading from the inbox into ring_
  std::unique_ptr<SpscRing<InboxReading>> inbox_;  // add() → apply(), across threads
  std::vector<Reading> ring_;  // kCapacity entries, the newest at next_ - 1 (apply()'s thread only)
  std::size_t next_ = 0, count_ = 0;
  double last_time_ = std::numeric_limits<double>::quiet_NaN();  // the previous orientation sample's time
  double last_interval_ = 0.0;  // t − t_prev of the previous sample; 0 before the second sample
  bool have_previous_ = false;  // the previous interval matched: (previous_time_, previous_mean_) is its (c', m')
  double previous_time_ = 0.0;
  Vec3 previous_mean_ = Vec3::Zero();
  std::uint64_t matched_ = 0, unmatched_ = 0;
};

}  // namespace posefair::daemon
