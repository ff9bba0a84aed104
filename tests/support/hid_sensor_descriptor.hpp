#pragma once
// A genuine HID Sensor orientation report descriptor, for the HID decoder tests and the uhid
// test device of the VM tests.
//
// Source: STMicroelectronics' USB custom HID IMU firmware, file usbd_custom_hid_if_imu.c
// ("USB Device Custom HID interface file for IMU", v1.0_Cube, (c) 2022 STMicroelectronics),
// array CUSTOM_HID_IMU_ReportDesc_HS: the report descriptor an STM32 IMU board presents to the
// host, with one top-level Physical collection per sensor (accelerometer 0x73, gyrometer 0x76,
// compass, device orientation 0x8A, ambient light 0x41, ...). The bytes below are its Device
// Orientation collection, copied byte for byte with the hidrd-style comments the file carries
// (only the comment text is shortened). It was found through a code search of public GitHub
// repositories whose index did not name the repository; the file name, array name and
// copyright line above identify it.
//
// What it declares:
// - Feature report 7: connection type, reporting state, power state, sensor state (8 bits each),
//   report interval (32 bits), and the quaternion's change sensitivity / maximum / minimum
//   (usages 0x1483, 0x2483, 0x3483: 0x0483 with the data field modifiers in the high nibble).
// - Input report 8 (20 bytes with the ID): sensor state (8 bits), sensor event (8 bits), the
//   quaternion 0x0483 as 4 x 32 bits, logical range -2147483647..2147483647, unit exponent
//   0x08 = -8 (a count is 1e-8), then magnetometer accuracy 0x0488 (8 bits).
// Quirks kept as the device has them: the sensor state and event selectors are declared
// Input (Data, Variable) with one 8-bit value for seven usages (sensor descriptors usually say
// Array), and the collection is Physical, not Application, at top level.
#include <array>
#include <cstddef>
#include <cstdint>

namespace posefair::testing {

inline constexpr std::array<std::uint8_t, 330> kStImuOrientationDescriptor = {
    0x05, 0x20,                    // Usage Page (20h)
    0x09, 0x8A,                    // Usage (8Ah)                   Device Orientation
    0xA1, 0x00,                    // Collection (Physical)
    0x85, 0x07,                    //   Report ID (7)
    0x05, 0x20,                    //   Usage Page (20h)
    0x0A, 0x09, 0x03,              //   Usage (0309h)               connection type
    0x15, 0x00,                    //   Logical Minimum (0)
    0x25, 0x02,                    //   Logical Maximum (2)
    0x75, 0x08,                    //   Report Size (8)
    0x95, 0x01,                    //   Report Count (1)
    0xA1, 0x02,                    //   Collection (Logical)
    0x0A, 0x30, 0x08,              //     Usage (0830h)
    0x0A, 0x31, 0x08,              //     Usage (0831h)
    0x0A, 0x32, 0x08,              //     Usage (0832h)
    0xB1, 0x01,                    //     Feature (Constant)
    0xC0,                          //   End Collection
    0x0A, 0x16, 0x03,              //   Usage (0316h)               reporting state
    0x15, 0x00,                    //   Logical Minimum (0)
    0x25, 0x05,                    //   Logical Maximum (5)
    0x75, 0x08,                    //   Report Size (8)
    0x95, 0x01,                    //   Report Count (1)
    0xA1, 0x02,                    //   Collection (Logical)
    0x0A, 0x40, 0x08,              //     Usage (0840h)
    0x0A, 0x41, 0x08,              //     Usage (0841h)
    0x0A, 0x42, 0x08,              //     Usage (0842h)
    0x0A, 0x43, 0x08,              //     Usage (0843h)
    0x0A, 0x44, 0x08,              //     Usage (0844h)
    0x0A, 0x45, 0x08,              //     Usage (0845h)
    0xB1, 0x00,                    //     Feature
    0xC0,                          //   End Collection
    0x0A, 0x19, 0x03,              //   Usage (0319h)               power state
    0x15, 0x01,                    //   Logical Minimum (1)
    0x25, 0x06,                    //   Logical Maximum (6)
    0x75, 0x08,                    //   Report Size (8)
    0x95, 0x01,                    //   Report Count (1)
    0xA1, 0x02,                    //   Collection (Logical)
    0x0A, 0x50, 0x08,              //     Usage (0850h)
    0x0A, 0x51, 0x08,              //     Usage (0851h)
    0x0A, 0x52, 0x08,              //     Usage (0852h)
    0x0A, 0x53, 0x08,              //     Usage (0853h)
    0x0A, 0x54, 0x08,              //     Usage (0854h)
    0x0A, 0x55, 0x08,              //     Usage (0855h)
    0xB1, 0x00,                    //     Feature
    0xC0,                          //   End Collection
    0x0A, 0x01, 0x02,              //   Usage (0201h)               sensor state
    0x15, 0x00,                    //   Logical Minimum (0)
    0x25, 0x06,                    //   Logical Maximum (6)
    0x75, 0x08,                    //   Report Size (8)
    0x95, 0x01,                    //   Report Count (1)
    0xA1, 0x02,                    //   Collection (Logical)
    0x0A, 0x00, 0x08,              //     Usage (0800h)
    0x0A, 0x01, 0x08,              //     Usage (0801h)
    0x0A, 0x02, 0x08,              //     Usage (0802h)
    0x0A, 0x03, 0x08,              //     Usage (0803h)
    0x0A, 0x04, 0x08,              //     Usage (0804h)
    0x0A, 0x05, 0x08,              //     Usage (0805h)
    0x0A, 0x06, 0x08,              //     Usage (0806h)
    0xB1, 0x00,                    //     Feature
    0xC0,                          //   End Collection
    0x0A, 0x0E, 0x03,              //   Usage (030Eh)               report interval
    0x15, 0x00,                    //   Logical Minimum (0)
    0x27, 0xFF, 0xFF, 0xFF, 0x00,  //   Logical Maximum (16777215)
    0x75, 0x20,                    //   Report Size (32)
    0x95, 0x01,                    //   Report Count (1)
    0x55, 0x00,                    //   Unit Exponent (0)
    0xB1, 0x03,                    //   Feature (Constant, Variable)
    0x0A, 0x83, 0x14,              //   Usage (1483h)               quaternion, change sensitivity
    0x15, 0x00,                    //   Logical Minimum (0)
    0x26, 0xFF, 0x00,              //   Logical Maximum (255)
    0x75, 0x10,                    //   Report Size (16)
    0x95, 0x01,                    //   Report Count (1)
    0x55, 0x0E,                    //   Unit Exponent (14)
    0xB1, 0x02,                    //   Feature (Variable)
    0x0A, 0x83, 0x24,              //   Usage (2483h)               quaternion, maximum
    0x16, 0x01, 0x80,              //   Logical Minimum (-32767)
    0x26, 0xFF, 0x7F,              //   Logical Maximum (32767)
    0x75, 0x10,                    //   Report Size (16)
    0x95, 0x01,                    //   Report Count (1)
    0x55, 0x01,                    //   Unit Exponent (1)
    0xB1, 0x02,                    //   Feature (Variable)
    0x0A, 0x83, 0x34,              //   Usage (3483h)               quaternion, minimum
    0x16, 0x01, 0x80,              //   Logical Minimum (-32767)
    0x26, 0xFF, 0x7F,              //   Logical Maximum (32767)
    0x75, 0x10,                    //   Report Size (16)
    0x95, 0x01,                    //   Report Count (1)
    0x55, 0x01,                    //   Unit Exponent (1)
    0xB1, 0x02,                    //   Feature (Variable)
    0x85, 0x08,                    //   Report ID (8)
    0x05, 0x20,                    //   Usage Page (20h)
    0x0A, 0x01, 0x02,              //   Usage (0201h)               sensor state
    0x15, 0x00,                    //   Logical Minimum (0)
    0x25, 0x06,                    //   Logical Maximum (6)
    0x75, 0x08,                    //   Report Size (8)
    0x95, 0x01,                    //   Report Count (1)
    0xA1, 0x02,                    //   Collection (Logical)
    0x0A, 0x00, 0x08,              //     Usage (0800h)
    0x0A, 0x01, 0x08,              //     Usage (0801h)
    0x0A, 0x02, 0x08,              //     Usage (0802h)
    0x0A, 0x03, 0x08,              //     Usage (0803h)
    0x0A, 0x04, 0x08,              //     Usage (0804h)
    0x0A, 0x05, 0x08,              //     Usage (0805h)
    0x0A, 0x06, 0x08,              //     Usage (0806h)
    0x81, 0x02,                    //     Input (Variable)
    0xC0,                          //   End Collection
    0x0A, 0x02, 0x02,              //   Usage (0202h)               sensor event
    0x15, 0x00,                    //   Logical Minimum (0)
    0x25, 0x05,                    //   Logical Maximum (5)
    0x75, 0x08,                    //   Report Size (8)
    0x95, 0x01,                    //   Report Count (1)
    0xA1, 0x02,                    //   Collection (Logical)
    0x0A, 0x10, 0x08,              //     Usage (0810h)
    0x0A, 0x11, 0x08,              //     Usage (0811h)
    0x0A, 0x12, 0x08,              //     Usage (0812h)
    0x0A, 0x13, 0x08,              //     Usage (0813h)
    0x0A, 0x14, 0x08,              //     Usage (0814h)
    0x0A, 0x15, 0x08,              //     Usage (0815h)
    0x81, 0x02,                    //     Input (Variable)
    0xC0,                          //   End Collection
    0x0A, 0x83, 0x04,              //   Usage (0483h)               quaternion
    0x17, 0x01, 0x00, 0x00, 0x80,  //   Logical Minimum (-2147483647)
    0x27, 0xFF, 0xFF, 0xFF, 0x7F,  //   Logical Maximum (2147483647)
    0x75, 0x20,                    //   Report Size (32)
    0x95, 0x04,                    //   Report Count (4)
    0x55, 0x08,                    //   Unit Exponent (8)
    0x81, 0x02,                    //   Input (Variable)
    0x0A, 0x88, 0x04,              //   Usage (0488h)               magnetometer accuracy
    0x15, 0x00,                    //   Logical Minimum (0)
    0x25, 0x02,                    //   Logical Maximum (2)
    0x75, 0x08,                    //   Report Size (8)
    0x95, 0x01,                    //   Report Count (1)
    0xA1, 0x02,                    //   Collection (Logical)
    0x0A, 0xE0, 0x08,              //     Usage (08E0h)
    0x0A, 0xE1, 0x08,              //     Usage (08E1h)
    0x0A, 0xE2, 0x08,              //     Usage (08E2h)
    0x81, 0x00,                    //     Input
    0xC0,                          //   End Collection
    0xC0,                          // End Collection
};

// Its input report: ID 8, then 19 data bytes.
inline constexpr std::uint8_t kStImuOrientationReportId = 8;
inline constexpr std::size_t kStImuOrientationReportBytes = 20;

}  // namespace posefair::testing
