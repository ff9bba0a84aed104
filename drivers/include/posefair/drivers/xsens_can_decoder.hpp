#pragma once
// Xsens/Movella MTi 600-series (and Avior, Sirius) CAN output: the quaternion message (data
// identifier 0x21), SampleTime and GroupCounter, and optionally (xsens_raw) RateOfTurn,
// Acceleration and MagneticField (drivers/src/xsens_can_decoder.cpp says which
// documents and which choices). Registry name: "xsens-can".
#include <cstdint>
#include <memory>
#include <optional>
#include <vector>

#include "posefair/drivers/can_decoder.hpp"

namespace posefair::drivers {

// The registry entry: name, description, options (xsens_*), factory.
extern const CanDecoderEntry kXsensCanDecoder;

// Reads the xsens_* options; throws OptionError for a bad one.
std::unique_ptr<CanDecoder> make_xsens_can_decoder(const OptionMap& options = {});

// The frames an MTi sends for one sample with the default identifiers (standard format): the
// GroupCounter (0x006) and SampleTime (0x005) messages when given, then the quaternion
// (0x021, q0..q3 int16 big-endian, q rounded to value · 32767).
std::vector<CanFrame> encode_xsens_can(const Quat& q, std::optional<std::uint32_t> sample_time,
                                       std::optional<std::uint16_t> group_counter, double timestamp = 0.0);

// The raw messages that follow the quaternion in a group, with the default identifiers: those
// given, in identifier order: RateOfTurn (0x032, rad/s · 2^9), Acceleration (0x034, m/s² · 2^8),
// MagneticField (0x041, arbitrary units · 2^10), each three int16 big-endian, rounded and
// clamped to the int16 range.
std::vector<CanFrame> encode_xsens_can_raw(const std::optional<Vec3>& rate_of_turn, const std::optional<Vec3>& acceleration,
                                           const std::optional<Vec3>& magnetic_field_au, double timestamp = 0.0);

}  // namespace posefair::drivers
