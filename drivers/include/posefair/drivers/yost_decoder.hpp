#pragma once
// Yost Labs 3-Space sensors: wired binary streaming of the tared orientation quaternion
// (command 0x00), and optionally the corrected gyro, accelerometer and compass (commands
// 0x25..0x28, option yost_slots), with the wired response header, registry name "yost". The decoder and the
// packet encoder the tests, fuzz corpus and golden logs are built with. Conventions, quirks and
// choices: drivers/src/yost_decoder.cpp.
#include <cstdint>
#include <initializer_list>
#include <memory>
#include <vector>

#include "posefair/drivers/decoder.hpp"

namespace posefair::drivers {

// Wired response header bits (command 221), in the order their fields are sent.
enum YostHeaderBit : std::uint32_t {
  kYostSuccess = 0x01,       // 1 byte, 0 = success
  kYostTimestamp = 0x02,     // u32 big-endian, microseconds
  kYostCommandEcho = 0x04,   // 1 byte, 0xFF for streamed packets
  kYostChecksum = 0x08,      // 1 byte, sum of the data bytes modulo 256
  kYostLogicalId = 0x10,     // 1 byte
  kYostSerialNumber = 0x20,  // u32 big-endian
  kYostDataLength = 0x40,    // 1 byte, number of data bytes
};
// posefair's default: success, timestamp, command echo, checksum, data length (= 79).
inline constexpr std::uint32_t kYostDefaultHeader =
    kYostSuccess | kYostTimestamp | kYostCommandEcho | kYostChecksum | kYostDataLength;

// The registry entry: name, description, options (yost_header, yost_data_length), factory.
extern const DecoderEntry kYostDecoder;

// The decoder. Options yost_header (a number, decimal or 0x-hex; bits 0x01, 0x08 and 0x40
// required, nothing above 0x40) and yost_data_length (16..255). Throws OptionError for any
// other value.
std::unique_ptr<Decoder> make_yost_decoder(const OptionMap& options = {});

// Header fields the encoder writes (each only if its bit is set in header).
struct YostPacketFields {
  std::uint32_t header = kYostDefaultHeader;
  std::uint8_t failure = 0;          // the success/failure byte: 0 = success
  std::uint8_t command_echo = 0xFF;  // streamed packets echo 0xFF
  std::uint8_t logical_id = 0;
  std::uint32_t serial_number = 0;
  std::vector<std::uint8_t> extra;   // data of further streaming slots, after the quaternion (encode_yost_vectors)
  int checksum_delta = 0;            // added to the correct checksum (tests of bad checksums)
};

// The data of the raw-reading slots (0x25: gyro, accel, compass; 0x26..0x28: one of them), for
// YostPacketFields::extra: each vector as three big-endian IEEE floats, in the units the
// sensor sends (rad/s, g, gauss).
std::vector<std::uint8_t> encode_yost_vectors(std::initializer_list<Vec3> vectors);

// One streamed packet: the header fields, then the quaternion as four big-endian IEEE floats
// x, y, z, w (q as given: not normalised, sign kept), then fields.extra. The data length field
// is 16 + extra.size() (truncated to a byte).
std::vector<std::uint8_t> encode_yost_quaternion_packet(const Quat& q, std::uint32_t timestamp_us,
                                                        const YostPacketFields& fields = {});

}  // namespace posefair::drivers
