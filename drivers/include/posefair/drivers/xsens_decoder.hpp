#pragma once
// Xsens MTi series (MTi-1/10/100/600, MTi-G-710, ...) over a UART: the Xbus protocol's MTData2
// message (drivers/src/xsens_decoder.cpp says which document, which outputs and which quirks).
// Registry name: "xsens".
#include <cstdint>
#include <memory>
#include <optional>
#include <vector>

#include "posefair/drivers/decoder.hpp"

namespace posefair::drivers {

// The registry entry: name, description, no options, factory.
extern const DecoderEntry kXsensDecoder;

// The MTData2 decoder. Reads no option.
std::unique_ptr<Decoder> make_xsens_decoder(const OptionMap& options = {});

// One whole Xbus MTData2 message (preamble through checksum) as an MTi sends it: PacketCounter
// (0x1020) and SampleTimeFine (0x1060) when given, then Quaternion 0x2010 (float32, ENU; q's
// components rounded to float). force_extended_length writes the length as 0xFF + u16 even
// when it would fit in one byte (the form messages longer than 254 data bytes use).
std::vector<std::uint8_t> encode_xsens_mtdata2(const Quat& q, std::optional<std::uint16_t> packet_counter,
                                               std::optional<std::uint32_t> sample_time_fine,
                                               bool force_extended_length = false);

}  // namespace posefair::drivers
