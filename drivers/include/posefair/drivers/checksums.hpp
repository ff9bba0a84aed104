#pragma once
// The checksums device protocols use, one implementation each, shared by the decoders and the
// encoders the tests build frames with.
#include <array>
#include <cstddef>
#include <cstdint>
#include <span>

namespace posefair::drivers::checksum {

// Sum of the bytes modulo 256 (WitMotion, BNO08x UART-RVC; Xsens sums to zero with its checksum).
inline std::uint8_t sum8(std::span<const std::uint8_t> data) {
  std::uint8_t s = 0;
  for (std::uint8_t b : data) s = static_cast<std::uint8_t>(s + b);
  return s;
}

// XOR of the bytes (NMEA-style sentences: VectorNav ASCII, posefair's text sentence).
inline std::uint8_t xor8(std::span<const std::uint8_t> data) {
  std::uint8_t s = 0;
  for (std::uint8_t b : data) s ^= b;
  return s;
}

// CRC-16 with the CCITT polynomial 0x1021, MSB first, no reflection, no final XOR; `init`
// selects the variant: 0x0000 = CRC-16/XMODEM (VectorNav's "CRC16"), 0xFFFF =
// CRC-16/CCITT-FALSE (posefair's binary frame). Table-driven (the table is built at compile
// time): a byte per lookup instead of eight shifts, so CRC-checked streams decode as fast as
// summed ones.
namespace detail {
constexpr std::array<std::uint16_t, 256> make_crc16_ccitt_table() {
  std::array<std::uint16_t, 256> t{};
  for (unsigned b = 0; b < 256; ++b) {
    std::uint16_t crc = static_cast<std::uint16_t>(b << 8);
    for (int i = 0; i < 8; ++i) crc = static_cast<std::uint16_t>((crc & 0x8000u) ? (crc << 1) ^ 0x1021u : crc << 1);
    t[b] = crc;
  }
  return t;
}
inline constexpr std::array<std::uint16_t, 256> kCrc16CcittTable = make_crc16_ccitt_table();
}  // namespace detail

inline std::uint16_t crc16_ccitt(std::span<const std::uint8_t> data, std::uint16_t init) {
  std::uint16_t crc = init;
  for (std::uint8_t b : data)
    crc = static_cast<std::uint16_t>((crc << 8) ^ detail::kCrc16CcittTable[static_cast<std::uint8_t>((crc >> 8) ^ b)]);
  return crc;
}

}  // namespace posefair::drivers::checksum
