#pragma once
// VectorNav ASCII asynchronous outputs (VN-100/VN-200/VN-300: $VNQMR, $VNYMR, $VNQTN, $VNYPR
// with an 8-bit XOR checksum or a CRC-16), registry name "vectornav". The decoder and the
// sentence encoders the tests, fuzz corpus and golden logs are built with. Conventions, quirks
// and choices: drivers/src/vectornav_decoder.cpp.
#include <cstddef>
#include <memory>
#include <string>

#include "posefair/drivers/decoder.hpp"

namespace posefair::drivers {

// Longest sentence kept, from '$' through '\n'. Longer ones are discarded and counted
// (resyncs, skipped_bytes), never buffered further.
inline constexpr std::size_t kVectorNavMaxSentence = 256;

// The registry entry: name, description, options (vectornav_unchecked), factory.
extern const DecoderEntry kVectorNavDecoder;

// The decoder. Option vectornav_unchecked: "reject" (default: a sentence whose checksum field
// is "XX"/"XXXX", i.e. checksums disabled on the device, counts as bad_checksum) or "accept"
// (used after strict content checks). Throws OptionError for any other value.
std::unique_ptr<Decoder> make_vectornav_decoder(const OptionMap& options = {});

// "$VNQMR,<x>,<y>,<z>,<w>,<mag x3>,<accel x3>,<gyro x3>*<CS>\r\n" as the device prints it:
// quaternion components of q as given (scalar last, "%+.6f", not normalised, sign kept), fixed
// plausible magnetic/acceleration/rate fields, and a 2-digit XOR checksum or, with crc16, a
// 4-digit CRC-16/XMODEM.
std::string encode_vectornav_vnqmr(const Quat& q, bool crc16);

// "$VNYMR,<yaw>,<pitch>,<roll>,<mag x3>,<accel x3>,<gyro x3>*<CS>\r\n", angles in degrees
// ("%+08.3f", as given: no range check).
std::string encode_vectornav_vnymr(double yaw_deg, double pitch_deg, double roll_deg, bool crc16);

// The checksum field for a sentence body (the bytes between '$' and '*'): 2 hex digits (XOR)
// or 4 (CRC-16/XMODEM), upper case. For tests that build sentences by hand.
std::string vectornav_checksum(const std::string& body, bool crc16);

}  // namespace posefair::drivers
