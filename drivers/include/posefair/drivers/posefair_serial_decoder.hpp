#pragma once
// posefair's own serial protocol for microcontroller trackers (docs/protocol.md, "Serial
// protocol for microcontroller trackers"): the text sentences $PFQ (orientation) and $PFI (raw
// IMU) and the binary frame F5 50, interleaved freely on one line. Registry name: "posefair".
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "posefair/drivers/decoder.hpp"

namespace posefair::drivers {

// The registry entry: name, description, no options, factory.
extern const DecoderEntry kPosefairSerialDecoder;

// The decoder of both forms. Reads no option.
std::unique_ptr<Decoder> make_posefair_serial_decoder(const OptionMap& options = {});

// The text sentence "$PFQ,<time>,<w>,<x>,<y>,<z>[,<px>,<py>,<pz>]*HH\r\n", every number
// written in its shortest round-trip form (a sentence decodes to exactly these doubles).
// position may be null.
std::string encode_posefair_sentence(std::uint32_t device_time_us, const Quat& q, const Vec3* position);

// The raw-IMU sentence "$PFI,<time>,<gx>,<gy>,<gz>,<ax>,<ay>,<az>[,<mx>,<my>,<mz>]*HH\r\n"
// (rad/s, m/s², µT), numbers as above. mag may be null.
std::string encode_posefair_imu_sentence(std::uint32_t device_time_us, const Vec3& gyro, const Vec3& accel,
                                         const Vec3* mag);

// The binary frame (version 1): sync F5 50, version, flags, length, u32 LE time in µs, q as
// 4 × float32 LE, position as 3 × float32 LE when given, CRC-16/CCITT-FALSE LE.
std::vector<std::uint8_t> encode_posefair_frame(std::uint32_t device_time_us, const Quat& q, const Vec3* position);

struct PosefairImuReading {
  Vec3 gyro = Vec3::Zero();   // rad/s
  Vec3 accel = Vec3::Zero();  // m/s²
};
// Any binary frame: each part present when its pointer is (q null: flag bit 3, a raw-only
// frame), in the order quaternion, position, gyroscope and accelerometer, magnetometer.
std::vector<std::uint8_t> encode_posefair_frame(std::uint32_t device_time_us, const Quat* q, const Vec3* position,
                                                const PosefairImuReading* imu, const Vec3* mag);

}  // namespace posefair::drivers
