#pragma once
// Turns a device driver's decoded samples into Samples: stream id, sequence number, the receive
// time of the read that completed them, and the time the time base gives (time_base.hpp); then
// hands them to the sink, counting what it took and what it dropped. Shared by the serial,
// SocketCAN and hidraw drivers. Private to drivers/src.
#include <atomic>
#include <cstdint>
#include <optional>

#include "posefair/drivers/decoder.hpp"
#include "posefair/drivers/driver.hpp"
#include "posefair/drivers/time_base.hpp"

namespace posefair::drivers {

class SampleStamper final : public DecodedSink {
 public:
  // `sequence` runs on across reconnects (it belongs to the driver's run()).
  SampleStamper(std::uint32_t stream_id, TimeBase& time_base, SampleSink& sink, std::uint64_t& sequence,
                std::atomic<std::uint64_t>& samples, std::atomic<std::uint64_t>& dropped)
      : stream_id_(stream_id), time_base_(time_base), sink_(sink), sequence_(sequence), samples_(samples), dropped_(dropped) {}

  void set_receive_time(double t) { receive_time_ = t; }

  void on_sample(const DecodedSample& d) override {
    Sample s;
    s.stream_id = stream_id_;
    s.sequence = sequence_++;
    s.receive_time = receive_time_;
    fill_sample(d, s);
    std::optional<double> device;
    if ((s.flags & kHasDeviceTime) != 0) device = d.device_time;
    s.time = time_base_.update(receive_time_, device).time;
    if (sink_.push(s))
      samples_.fetch_add(1, std::memory_order_relaxed);
    else
      dropped_.fetch_add(1, std::memory_order_relaxed);
  }

 private:
  std::uint32_t stream_id_;
  TimeBase& time_base_;
  SampleSink& sink_;
  std::uint64_t& sequence_;
  std::atomic<std::uint64_t>& samples_;
  std::atomic<std::uint64_t>& dropped_;
  double receive_time_ = 0.0;
};

}  // namespace posefair::drivers
