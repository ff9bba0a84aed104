#pragma once
// HID devices that send their quaternion in a vendor-defined input report (usage page 0xFF00..,
// or any report whose descriptor does not say what the bytes are): the layout comes from the
// configuration. drivers/src/hid_vendor_layout_decoder.cpp says how values are read. Protocol
// name: "hid-vendor".
#include <array>
#include <cstdint>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "posefair/core/sample.hpp"
#include "posefair/core/options.hpp"
#include "posefair/drivers/hid_report_decoder.hpp"

namespace posefair::drivers {

enum class HidVendorType : std::uint8_t { Int16, Int32, Float32, Float64 };

struct HidVendorLayout {
  // -1: the device's reports carry no report ID byte; 1..255: the ID (first byte of each report).
  int report_id = -1;
  // Data bytes after the ID byte; 0 = just what the components need. Shorter reports are
  // malformed, longer ones are read as far as needed.
  std::uint32_t report_length = 0;
  HidVendorType type = HidVendorType::Int16;
  bool big_endian = false;
  // Offset of each of the four values in the report's data (after the ID byte), in bits, in the
  // order they appear in the report (a configuration in bytes gives byte · 8). Little-endian
  // values may start at any bit (HID packs LSB first); big-endian ones must be byte-aligned.
  std::array<std::uint32_t, 4> offset_bits{0, 16, 32, 48};
  // true: the report holds w x y z; false: x y z w.
  bool w_first = true;
  // value = raw · scale (also for float types); e.g. 1/16384 for Q14 int16.
  double scale = 1.0 / 16384.0;
  // Accepted |‖q‖ − 1| before normalising.
  double norm_tolerance = 0.05;
};

// A layout that cannot be read. field() names the offending layout field ("report_id",
// "offset_bits[2]", "scale", ...); what() is the whole message. As an OptionError, key() is the
// configuration key to blame (hid_vendor_layout(OptionMap) gives offsets[3] for offset_bits[2]),
// else the field.
class HidVendorLayoutError : public OptionError {
 public:
  HidVendorLayoutError(std::string field, const std::string& message)
      : OptionError(field, "hid-vendor layout: " + field + ": " + message, {}, "hid-vendor layout: " + field + ": " + message),
        field_(std::move(field)) {}
  // A problem blamed on configuration key `key`, in the words `message`.
  HidVendorLayoutError(std::string field, std::string key, const std::string& message)
      : OptionError(std::move(key), message, {}, "hid-vendor layout: " + field + ": " + message), field_(std::move(field)) {}
  // The same error blamed on configuration key `key`: message() is e.what().
  HidVendorLayoutError(const HidVendorLayoutError& e, std::string key)
      : OptionError(std::move(key), e.what(), {}, e.what()), field_(e.field()) {}
  const std::string& field() const { return field_; }

 private:
  std::string field_;
};

// Throws HidVendorLayoutError for the first bad field (components overlapping or running past
// report_length, misaligned big-endian offsets, report_id outside -1 and 1..255, a scale that is
// zero or not finite, a negative or non-finite norm_tolerance).
void validate_hid_vendor_layout(const HidVendorLayout& layout);

// Validates, then builds the decoder.
std::unique_ptr<HidReportDecoder> make_hid_vendor_layout_decoder(const HidVendorLayout& layout);

// The registry entry: name, description, options (report_id, report_length, value_type,
// byte_order, offsets or offsets_bits, order, scale), factory.
extern const HidDecoderEntry kHidVendorDecoder;
// The layout the configuration's options describe, validated. Throws HidVendorLayoutError (an
// OptionError) naming the configuration key for a bad one.
HidVendorLayout hid_vendor_layout(const OptionMap& options);

// Bytes each value takes (2, 4, 4, 8).
std::uint32_t hid_vendor_type_bytes(HidVendorType type);

// One report in `layout` carrying q (w, x, y, z) divided by scale (rounded and saturated for the
// integer types); unused bytes 0. For round-trip tests and the uhid test device.
std::vector<std::uint8_t> encode_hid_vendor_report(const HidVendorLayout& layout, const Quat& q);

}  // namespace posefair::drivers
