#pragma once
// DroneCAN (UAVCAN v0) uavcan.equipment.ahrs.Solution (data type id 1000): multi-frame transfer
// reassembly, transfer CRC, float16 quaternion x y z w, µs timestamp
// (drivers/src/dronecan_ahrs_decoder.cpp says which documents and choices).
// Registry name: "dronecan-ahrs".
#include <array>
#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include "posefair/drivers/can_decoder.hpp"

namespace posefair::drivers {

inline constexpr std::uint16_t kDroneCanAhrsSolutionId = 1000;
inline constexpr std::uint64_t kDroneCanAhrsSolutionSignature = 0x72A63A3C6F41FA9Bull;

// The registry entry: name, description, options (dronecan_node_id), factory.
extern const CanDecoderEntry kDroneCanAhrsDecoder;

// Reads the option dronecan_node_id; throws OptionError for a bad one.
std::unique_ptr<CanDecoder> make_dronecan_ahrs_decoder(const OptionMap& options = {});

// The transfer CRC: CRC-16/CCITT-FALSE over the data type signature (8 bytes, least
// significant first), then the payload.
std::uint16_t dronecan_transfer_crc(std::uint64_t signature, std::span<const std::uint8_t> payload);

// The serialized payload of one ahrs.Solution: timestamp (uint56 µs), orientation as float16
// x y z w, then the covariance arrays with the given lengths (0..9 each; their entries are
// 0.01 · (index + 1)), angular velocity and linear acceleration (float16, set to small
// distinct values). The last array uses tail array optimisation (no length field).
std::vector<std::uint8_t> serialize_dronecan_ahrs_solution(const Quat& q, std::uint64_t timestamp_us,
                                                           std::array<std::uint8_t, 3> covariance_lengths = {0, 0, 0});

// The frames of one message transfer (classic CAN, 29-bit identifiers): a single frame with the
// payload and a tail byte when it fits in 7 bytes, else CRC + payload cut into 8-byte frames with
// tail bytes (start, end, toggle, transfer id).
std::vector<CanFrame> encode_dronecan_transfer(std::uint16_t data_type_id, std::uint64_t signature,
                                               std::span<const std::uint8_t> payload, std::uint8_t source_node,
                                               std::uint8_t transfer_id, std::uint8_t priority = 16, double timestamp = 0.0);

}  // namespace posefair::drivers
