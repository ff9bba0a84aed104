#pragma once
// What travels through the daemon's rings: plain, trivially copyable records (the rings store
// items as machine words, and Eigen's types are not trivially copyable), each stamped with the
// CLOCK_MONOTONIC time its sample was handed to the daemon, so the publisher can measure the
// processing latency from hand-over to datagram sent.
#include <cstdint>
#include <ctime>
#include <type_traits>

#include "posefair/core/sample.hpp"

namespace posefair::daemon {

// A Sample, flattened.
struct RingSample {
  std::uint32_t stream_id;
  std::uint32_t flags;
  std::uint64_t sequence;
  double time, device_time, receive_time;
  double q[4];  // w x y z
  double p[3];
  double gyro[3], accel[3], mag[3];  // raw inertial readings, valid with their flags (issue 17)
  std::uint64_t enqueued_ns;  // CLOCK_MONOTONIC when the driver handed it over
};
static_assert(std::is_trivially_copyable_v<RingSample>);

// A FairedPose on its way to the publisher.
struct RingPose {
  std::uint32_t stream_index;  // index into the pipeline's stream table (not the wire id)
  std::uint32_t flags;         // the sample's flags plus kClamped
  double time;
  double step;                 // FairedPose::step (0: take the time since the previous pose)
  double q[4];
  double p[3];
  std::uint64_t enqueued_ns;   // hand-over time of the sample whose arrival emitted this pose
  std::uint64_t faired_ns;     // CLOCK_MONOTONIC when the engine made it (for the hand-off stage)
};
static_assert(std::is_trivially_copyable_v<RingPose>);

inline std::uint64_t monotonic_ns() {
  timespec ts{};
  ::clock_gettime(CLOCK_MONOTONIC, &ts);
  return static_cast<std::uint64_t>(ts.tv_sec) * 1'000'000'000u + static_cast<std::uint64_t>(ts.tv_nsec);
}

inline RingSample pack(const Sample& s, std::uint64_t enqueued_ns) {
  return RingSample{s.stream_id,
                    s.flags,
                    s.sequence,
                    s.time,
                    s.device_time,
                    s.receive_time,
                    {s.orientation.w(), s.orientation.x(), s.orientation.y(), s.orientation.z()},
                    {s.position.x(), s.position.y(), s.position.z()},
                    {s.gyro.x(), s.gyro.y(), s.gyro.z()},
                    {s.accel.x(), s.accel.y(), s.accel.z()},
                    {s.mag.x(), s.mag.y(), s.mag.z()},
                    enqueued_ns};
}

inline Sample unpack(const RingSample& r) {
  Sample s;
  s.stream_id = r.stream_id;
  s.flags = r.flags;
  s.sequence = r.sequence;
  s.time = r.time;
  s.device_time = r.device_time;
  s.receive_time = r.receive_time;
  s.orientation = Quat(r.q[0], r.q[1], r.q[2], r.q[3]);
  s.position = Vec3(r.p[0], r.p[1], r.p[2]);
  s.gyro = Vec3(r.gyro[0], r.gyro[1], r.gyro[2]);
  s.accel = Vec3(r.accel[0], r.accel[1], r.accel[2]);
  s.mag = Vec3(r.mag[0], r.mag[1], r.mag[2]);
  return s;
}

inline RingPose pack(const FairedPose& f, std::uint32_t stream_index, std::uint64_t enqueued_ns, std::uint64_t faired_ns = 0) {
  return RingPose{stream_index,
                  f.flags,
                  f.time,
                  f.step,
                  {f.orientation.w(), f.orientation.x(), f.orientation.y(), f.orientation.z()},
                  {f.position.x(), f.position.y(), f.position.z()},
                  enqueued_ns,
                  faired_ns};
}

}  // namespace posefair::daemon
