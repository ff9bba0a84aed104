#pragma once
// WitMotion serial protocol (WT901 family: 0x55-framed 11-byte packets with a sum checksum),
// registry name "witmotion". The decoder and the frame encoders the tests, fuzz corpus and
// golden logs are built with. Conventions, quirks and choices: drivers/src/witmotion_decoder.cpp.
#include <array>
#include <cstddef>
#include <cstdint>
#include <memory>

#include "posefair/drivers/decoder.hpp"

namespace posefair::drivers {

inline constexpr std::size_t kWitMotionFrameSize = 11;  // 0x55, type, 8 data bytes, checksum

// The registry entry: name, description, options (witmotion_scalar), factory.
extern const DecoderEntry kWitMotionDecoder;

// The decoder. Option witmotion_scalar: "first" (default: q0 q1 q2 q3 = w x y z, as the
// WitMotion documents number them) or "last" (x y z w). Throws OptionError for any other value.
std::unique_ptr<Decoder> make_witmotion_decoder(const OptionMap& options = {});

// Any packet: 0x55, type, the 8 data bytes, the checksum (low byte of the sum of the first 10).
std::array<std::uint8_t, kWitMotionFrameSize> encode_witmotion_frame(std::uint8_t type,
                                                                     const std::array<std::uint8_t, 8>& data);

// 0x59: each component of q (as given: not normalised, sign kept) times 32768, rounded and
// saturated to int16; scalar first (w x y z) or last (x y z w).
std::array<std::uint8_t, kWitMotionFrameSize> encode_witmotion_quaternion(const Quat& q, bool scalar_first = true);

// 0x53: angles in degrees times 32768/180, rounded and wrapped into int16 (so 180° is sent as
// -180°), then the version word.
std::array<std::uint8_t, kWitMotionFrameSize> encode_witmotion_angles(double roll_deg, double pitch_deg, double yaw_deg,
                                                                      std::uint16_t version = 0);

// 0x51 (v in m/s²), 0x52 (rad/s) or 0x54 (µT): each component in the packet's units (16 g ·
// 9.8 m/s² / 32768, 2000 °/s / 32768, 0.1 µT per count), rounded and saturated to int16; then
// the temperature word (°C · 100 on the 0x51 and 0x52 packets).
std::array<std::uint8_t, kWitMotionFrameSize> encode_witmotion_vector(std::uint8_t type, const Vec3& v,
                                                                      std::uint16_t temperature = 0);

// 0x50: year (20YY: pass YY, 0..99), month, day, hour, minute, second, millisecond. Each field is
// written as given (truncated to its byte / 16-bit word), so tests can build impossible times.
std::array<std::uint8_t, kWitMotionFrameSize> encode_witmotion_time(int yy, int month, int day, int hour, int minute,
                                                                    int second, int millisecond);

}  // namespace posefair::drivers
