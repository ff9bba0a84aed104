#pragma once
// CEVA (Hillcrest Labs) BNO080/BNO085/BNO086 in UART-RVC mode: 19-byte frames headed 0xAA 0xAA
// with yaw, pitch, roll in 0.01° and a sum checksum, registry name "bno08x-rvc". The decoder and
// the frame encoder the tests, fuzz corpus and golden logs are built with. Conventions, quirks
// and choices: drivers/src/bno08x_rvc_decoder.cpp.
#include <array>
#include <cstddef>
#include <cstdint>
#include <memory>

#include "posefair/drivers/decoder.hpp"

namespace posefair::drivers {

inline constexpr std::size_t kBno08xRvcFrameSize = 19;  // 0xAA 0xAA, index, 6 int16, 3 reserved, checksum

// The registry entry: name, description, no options, factory.
extern const DecoderEntry kBno08xRvcDecoder;

// The decoder (it reads no option). Samples carry the frame index, unwrapped, as frame_counter.
std::unique_ptr<Decoder> make_bno08x_rvc_decoder(const OptionMap& options = {});

// One frame: the angles times 100 and the accelerations (mg) rounded and saturated to int16,
// the three bytes after the accelerations (motion intent, motion request, reserved on the
// BNO086; zero on the BNO080) as given, and the checksum (low byte of the sum of bytes 2..17).
std::array<std::uint8_t, kBno08xRvcFrameSize> encode_bno08x_rvc(std::uint8_t index, double yaw_deg, double pitch_deg,
                                                                double roll_deg, double accel_x_mg = 0.0,
                                                                double accel_y_mg = 0.0, double accel_z_mg = 1000.0,
                                                                const std::array<std::uint8_t, 3>& tail = {0, 0, 0});

}  // namespace posefair::drivers
