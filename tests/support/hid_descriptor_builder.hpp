#pragma once
// Writing HID report descriptors item by item (HID 1.11, 6.2.2.2 short items, each value in the
// fewest bytes that hold it), for the HID tests, fuzz corpus and benchmarks, and a builder of HID
// Sensor orientation descriptors of any report size, exponent and report ID (the uhid test
// device can use it for the 8- and 16-bit variants the genuine descriptor does not cover).
#include <cstdint>
#include <optional>
#include <vector>

namespace posefair::testing {

class HidDescriptorBuilder {
 public:
  // Item types (bType).
  static constexpr std::uint8_t kMain = 0, kGlobal = 1, kLocal = 2;

  // One short item with `value` in 1, 2 or 4 bytes: the fewest that hold it as a signed value
  // (is_signed) or an unsigned one; `bytes` forces a size (0, 1, 2 or 4).
  HidDescriptorBuilder& item(std::uint8_t type, std::uint8_t tag, std::int64_t value, bool is_signed = false, int bytes = -1) {
    int n = bytes;
    if (n < 0) {
      if (is_signed)
        n = (value >= -128 && value <= 127) ? 1 : (value >= -32768 && value <= 32767) ? 2 : 4;
      else
        n = value <= 0xFF ? 1 : value <= 0xFFFF ? 2 : 4;
    }
    const std::uint8_t size_code = n == 0 ? 0 : n == 1 ? 1 : n == 2 ? 2 : 3;
    out.push_back(static_cast<std::uint8_t>(tag << 4 | type << 2 | size_code));
    for (int k = 0; k < n; ++k) out.push_back(static_cast<std::uint8_t>(static_cast<std::uint64_t>(value) >> (8 * k)));
    return *this;
  }

  HidDescriptorBuilder& usage_page(std::uint16_t page) { return item(kGlobal, 0x0, page); }
  HidDescriptorBuilder& logical_min(std::int64_t v) {
    min_signed_ = v < 0;
    return item(kGlobal, 0x1, v, true);
  }
  // Written signed when the last logical minimum was negative (the reading rule).
  HidDescriptorBuilder& logical_max(std::int64_t v) { return item(kGlobal, 0x2, v, min_signed_ || v < 0); }
  HidDescriptorBuilder& unit_exponent(int e) { return item(kGlobal, 0x5, e & 0xF); }  // the 4-bit nibble form
  HidDescriptorBuilder& unit(std::uint32_t u) { return item(kGlobal, 0x6, u); }
  HidDescriptorBuilder& report_size(std::uint32_t bits) { return item(kGlobal, 0x7, bits); }
  HidDescriptorBuilder& report_id(std::uint8_t id) { return item(kGlobal, 0x8, id); }
  HidDescriptorBuilder& report_count(std::uint32_t n) { return item(kGlobal, 0x9, n); }
  HidDescriptorBuilder& push() { return item(kGlobal, 0xA, 0, false, 0); }
  HidDescriptorBuilder& pop() { return item(kGlobal, 0xB, 0, false, 0); }
  HidDescriptorBuilder& usage(std::uint16_t id) { return item(kLocal, 0x0, id); }
  HidDescriptorBuilder& usage_extended(std::uint32_t page_and_id) { return item(kLocal, 0x0, page_and_id, false, 4); }
  HidDescriptorBuilder& usage_min(std::uint16_t id) { return item(kLocal, 0x1, id); }
  HidDescriptorBuilder& usage_max(std::uint16_t id) { return item(kLocal, 0x2, id); }
  HidDescriptorBuilder& input(std::uint32_t flags) { return item(kMain, 0x8, flags); }
  HidDescriptorBuilder& output(std::uint32_t flags) { return item(kMain, 0x9, flags); }
  HidDescriptorBuilder& feature(std::uint32_t flags) { return item(kMain, 0xB, flags); }
  HidDescriptorBuilder& collection(std::uint8_t type) { return item(kMain, 0xA, type); }
  HidDescriptorBuilder& end_collection() { return item(kMain, 0xC, 0, false, 0); }

  std::vector<std::uint8_t> out;

 private:
  bool min_signed_ = false;
};

// A HID Sensor Device Orientation collection (Application) whose input report holds the
// sensor state (8 bits), the quaternion as four `bits`-bit signed values (logical range
// ±(2^(bits-1) − 1), unit exponent `exponent`) and, if asked, a Timestamp 0x0529 of
// `timestamp_bits` unsigned bits with unit `timestamp_unit` (0: none) and exponent
// `timestamp_exponent`. report_id 0: no report IDs.
inline std::vector<std::uint8_t> hid_sensor_orientation_descriptor(std::uint32_t bits, int exponent, std::uint8_t report_id,
                                                                   std::optional<std::uint32_t> timestamp_bits = std::nullopt,
                                                                   std::uint32_t timestamp_unit = 0, int timestamp_exponent = 0) {
  HidDescriptorBuilder b;
  const std::int64_t max = bits >= 64 ? INT64_MAX : (std::int64_t{1} << (bits - 1)) - 1;
  b.usage_page(0x20).usage(0x8A).collection(0x01);
  if (report_id != 0) b.report_id(report_id);
  b.usage(0x0201).logical_min(0).logical_max(6).report_size(8).report_count(1).input(0x02);  // sensor state
  b.usage(0x0483).logical_min(-max).logical_max(max).report_size(bits).report_count(4).unit_exponent(exponent).input(0x02);
  if (timestamp_bits) {
    b.usage(0x0529).logical_min(0).logical_max(*timestamp_bits >= 32 ? 0x7FFFFFFF : 0xFFFF);
    b.report_size(*timestamp_bits).report_count(1).unit(timestamp_unit).unit_exponent(timestamp_exponent).input(0x02);
  }
  b.end_collection();
  return b.out;
}

}  // namespace posefair::testing
