#pragma once
// posefair's own CAN layout for microcontroller trackers (docs/can-protocol.md): a quaternion
// frame (four int16) and optional device-time and position frames tied by a sequence counter,
// and raw IMU frames that make raw-only samples.
// Registry name: "posefair-can".
#include <cstdint>
#include <memory>
#include <optional>
#include <vector>

#include "posefair/drivers/can_decoder.hpp"

namespace posefair::drivers {

// The registry entry: name, description, options (posefair_base_id, posefair_id_format), factory.
extern const CanDecoderEntry kPosefairCanDecoder;

// Reads the options posefair_base_id and posefair_id_format; throws OptionError for a bad one.
std::unique_ptr<CanDecoder> make_posefair_can_decoder(const OptionMap& options = {});

// What a sender puts on the bus for one sample, in the order it sends it: the time frame (when
// device_time_us is given), the position frame (when position is given; metres, rounded to mm),
// then the quaternion frame (q rounded to int16 / 32767). `sequence` goes into the time and
// position frames. Identifiers base, base + 1, base + 2.
std::vector<CanFrame> encode_posefair_can(std::uint32_t base_id, bool extended, const Quat& q,
                                          std::optional<std::uint32_t> device_time_us,
                                          const Vec3* position, std::uint8_t sequence, double timestamp = 0.0);

// The RAW frames (identifier base + 3) of one raw-only sample, in the order gyroscope (rad/s,
// rounded to 0.001), accelerometer (m/s², 0.01), magnetometer (µT, 0.01), each when given; the
// last one marks the end of the set. Sent after the period's time frame (encode_posefair_can
// with the same sequence, or alone).
std::vector<CanFrame> encode_posefair_can_raw(std::uint32_t base_id, bool extended, const Vec3* gyro,
                                              const Vec3* accel, const Vec3* mag, std::uint8_t sequence,
                                              double timestamp = 0.0);

}  // namespace posefair::drivers
