#pragma once
// Reading fixed-width numbers out of device frames, independent of the host's byte order and
// of alignment (the frames' fields sit at any offset). Shared by every decoder.
#include <bit>
#include <cstdint>

namespace posefair::drivers::bytes {

inline std::uint16_t le_u16(const std::uint8_t* p) { return static_cast<std::uint16_t>(p[0] | (p[1] << 8)); }
inline std::uint16_t be_u16(const std::uint8_t* p) { return static_cast<std::uint16_t>((p[0] << 8) | p[1]); }
inline std::int16_t le_i16(const std::uint8_t* p) { return static_cast<std::int16_t>(le_u16(p)); }
inline std::int16_t be_i16(const std::uint8_t* p) { return static_cast<std::int16_t>(be_u16(p)); }
inline std::uint32_t le_u32(const std::uint8_t* p) {
  return static_cast<std::uint32_t>(p[0]) | static_cast<std::uint32_t>(p[1]) << 8 | static_cast<std::uint32_t>(p[2]) << 16 |
         static_cast<std::uint32_t>(p[3]) << 24;
}
inline std::uint32_t be_u32(const std::uint8_t* p) {
  return static_cast<std::uint32_t>(p[0]) << 24 | static_cast<std::uint32_t>(p[1]) << 16 | static_cast<std::uint32_t>(p[2]) << 8 |
         static_cast<std::uint32_t>(p[3]);
}
inline float le_f32(const std::uint8_t* p) { return std::bit_cast<float>(le_u32(p)); }
inline float be_f32(const std::uint8_t* p) { return std::bit_cast<float>(be_u32(p)); }

inline void put_le_u16(std::uint8_t* p, std::uint16_t v) {
  p[0] = static_cast<std::uint8_t>(v);
  p[1] = static_cast<std::uint8_t>(v >> 8);
}
inline void put_be_u16(std::uint8_t* p, std::uint16_t v) {
  p[0] = static_cast<std::uint8_t>(v >> 8);
  p[1] = static_cast<std::uint8_t>(v);
}
inline void put_le_u32(std::uint8_t* p, std::uint32_t v) {
  for (int i = 0; i < 4; ++i) p[i] = static_cast<std::uint8_t>(v >> (8 * i));
}
inline void put_be_u32(std::uint8_t* p, std::uint32_t v) {
  for (int i = 0; i < 4; ++i) p[i] = static_cast<std::uint8_t>(v >> (24 - 8 * i));
}
inline void put_le_f32(std::uint8_t* p, float v) { put_le_u32(p, std::bit_cast<std::uint32_t>(v)); }
inline void put_be_f32(std::uint8_t* p, float v) { put_be_u32(p, std::bit_cast<std::uint32_t>(v)); }

}  // namespace posefair::drivers::bytes
