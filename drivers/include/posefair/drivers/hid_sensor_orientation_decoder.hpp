#pragma once
// HID Sensor usage page (0x20) orientation sensors: the quaternion data field (usage 0x200483)
// of a Device Orientation (0x20008A), Relative Orientation (0x20008E) or Geomagnetic
// Orientation (0x2000C1) sensor collection, and the optional Timestamp (0x200529) of the same
// report. drivers/src/hid_sensor_orientation_decoder.cpp names the documents and the choices.
// Protocol name: "hid-sensor".
#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "posefair/core/sample.hpp"
#include "posefair/drivers/hid_report_decoder.hpp"
#include "posefair/drivers/hid_report_descriptor.hpp"

namespace posefair::drivers {

inline constexpr HidUsage kHidSensorQuaternion = 0x200483;
inline constexpr HidUsage kHidSensorDeviceOrientation = 0x20008A;
inline constexpr HidUsage kHidSensorRelativeOrientation = 0x20008E;
inline constexpr HidUsage kHidSensorGeomagneticOrientation = 0x2000C1;
inline constexpr HidUsage kHidSensorTimestamp = 0x200529;

struct HidSensorOrientationOptions {
  // The order of the four quaternion values in the report, as letters: "xyzw" (the HID Sensor
  // Usages document's order and the default) or any other permutation of w, x, y, z.
  std::string component_order = "xyzw";
  // The input report to read: -1 = the first one that holds an orientation quaternion; 0 for
  // a device without report IDs; 1..255 otherwise.
  int report_id = -1;
  // Hand out q* instead of q (for a device whose quaternion rotates world into sensor frame).
  bool conjugate = false;
  // Accepted |‖q‖ − 1|, on top of 4 steps of the field's resolution (10^unit_exponent).
  double norm_tolerance = 0.05;
  // Seconds per timestamp count when the Timestamp field declares no time unit (HID unit
  // 0x1001 = seconds); multiplied by 10^unit_exponent as well. Default 1 µs.
  double timestamp_count_s = 1e-6;
};

// One numeric field slot in a report: where it is and how to scale it.
struct HidValueSlot {
  std::uint32_t bit_offset = 0;  // after the report ID byte
  std::uint32_t bit_size = 0;    // 1..64
  bool is_signed = false;
  std::int64_t logical_min = 0;  // the range is checked only when min < max
  std::int64_t logical_max = 0;
  int unit_exponent = 0;
};

// Where the orientation sits in the device's reports, resolved from its report descriptor.
struct HidOrientationLayout {
  bool uses_report_ids = false;
  std::uint8_t report_id = 0;
  std::size_t report_bytes = 0;              // the whole report, ID byte included
  std::array<HidValueSlot, 4> values{};      // the quaternion's four values in report order
  std::array<int, 4> component{0, 1, 2, 3};  // value k is component[k] of (w, x, y, z)
  std::optional<HidValueSlot> timestamp;
  double timestamp_unit_s = 1e-6;            // seconds per timestamp count (exponent included)
};

// The layout of the orientation quaternion in `descriptor`. Throws std::invalid_argument with a
// message that says what is missing (no quaternion field under an orientation collection, a
// quaternion field of fewer than four values or wider than 64 bits, a bad component_order or
// report_id).
HidOrientationLayout resolve_hid_orientation_layout(const HidReportDescriptor& descriptor,
                                                    const HidSensorOrientationOptions& options = {});

std::unique_ptr<HidReportDecoder> make_hid_sensor_orientation_decoder(const HidOrientationLayout& layout,
                                                                      const HidSensorOrientationOptions& options = {});

// The registry entry: name, description, options (report_id, component_order, conjugate,
// timestamp_count_s), and the factory that resolves each opened device's descriptor.
extern const HidDecoderEntry kHidSensorDecoder;
// The options as the configuration gives them. Throws OptionError for a bad one.
HidSensorOrientationOptions hid_sensor_options(const OptionMap& options);

// One input report as the device would send it: q (posefair's w, x, y, z; conjugated first if
// options.conjugate) scaled by 10^-unit_exponent, rounded and clamped to each value's logical
// range, in the layout's component order; the timestamp's raw counts if the layout has one;
// every other bit 0. For round-trip tests and the uhid test device.
std::vector<std::uint8_t> encode_hid_orientation_report(const HidOrientationLayout& layout, const Quat& q,
                                                        std::optional<std::uint64_t> timestamp_counts = std::nullopt,
                                                        bool conjugate = false);

}  // namespace posefair::drivers
