#pragma once
// Xsens/Movella MTi 600-series (and Avior, Sirius) CAN output: the quaternion message (data
// identifier 0x21), SampleTime and GroupCounter (drivers/src/xsens_can_decoder.cpp says which
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

}  // namespace posefair::drivers
