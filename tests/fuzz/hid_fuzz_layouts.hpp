#pragma once
// What the HID fuzz targets share: the report layouts the HID Sensor target picks from by the
// input's first byte (the genuine ST descriptor and built 8/16/32-bit variants with and without
// report IDs and timestamps), and the cutting of the rest of the input into reports (each
// report's length is the byte before it, modulo twice the layout's report size plus one, so
// that short, exact and long reports all occur).
#include <cstddef>
#include <cstdint>
#include <span>
#include <variant>
#include <vector>

#include "../support/hid_descriptor_builder.hpp"
#include "../support/hid_sensor_descriptor.hpp"
#include "posefair/drivers/hid_sensor_orientation_decoder.hpp"

namespace posefair::testing {

inline std::vector<drivers::HidOrientationLayout> hid_fuzz_layouts() {
  const std::vector<std::vector<std::uint8_t>> descriptors = {
      {kStImuOrientationDescriptor.begin(), kStImuOrientationDescriptor.end()},
      hid_sensor_orientation_descriptor(16, -2, 3),
      hid_sensor_orientation_descriptor(8, -2, 0, 32, 0x1001, -6),
      hid_sensor_orientation_descriptor(32, -8, 9, 64, 0, 0),
  };
  std::vector<drivers::HidOrientationLayout> layouts;
  for (const auto& d : descriptors)
    layouts.push_back(drivers::resolve_hid_orientation_layout(std::get<drivers::HidReportDescriptor>(drivers::parse_hid_report_descriptor(d))));
  return layouts;
}

// The reports in `data`: [length byte][that many bytes] ..., lengths taken modulo max_length + 1.
inline std::vector<std::span<const std::uint8_t>> hid_fuzz_reports(std::span<const std::uint8_t> data, std::size_t max_length) {
  std::vector<std::span<const std::uint8_t>> reports;
  std::size_t i = 0;
  while (i < data.size()) {
    const std::size_t n = std::min<std::size_t>(data[i] % (max_length + 1), data.size() - i - 1);
    reports.push_back(data.subspan(i + 1, n));
    i += 1 + n;
  }
  return reports;
}

}  // namespace posefair::testing
