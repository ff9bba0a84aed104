// Vendor-defined HID report layout decoder: protocol name "hid-vendor".
//
// Reference: there is none by nature: the layout is the vendor's (read it from the device's
// documentation, or from its report descriptor and a few captured reports, e.g. with
// `hid-recorder` or /sys/kernel/debug/hid/*/events). What posefair assumes:
// - The report as hidraw returns it: the report ID byte first when the device uses report IDs
//   (report_id 1..255), then the data; offsets count from the first data byte. Report ID 0 is
//   reserved by HID 1.11 (8.4) and never sent.
// - Four values of one type (int16, int32 two's complement; float32, float64 IEEE 754) in one
//   byte order, at the configured bit offsets, in the order w x y z (w_first) or x y z w.
//   Little-endian values may start at any bit (HID's LSB-first packing), big-endian ones on
//   byte boundaries only (a big-endian value split across a bit offset has no single reading).
// - value = raw · scale. A quaternion that is not finite, or whose norm is further than
//   norm_tolerance from 1, makes the report malformed; otherwise it is normalised. The
//   direction is taken as sensor→world (posefair's convention).
#include "posefair/drivers/hid_vendor_layout_decoder.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "posefair/drivers/hid_report_descriptor.hpp"

namespace posefair::drivers {
namespace {

constexpr std::uint32_t kMaxReportLength = 16384;

std::uint32_t bits_of(HidVendorType t) { return 8 * hid_vendor_type_bytes(t); }

// The raw bits of a value (its width from the type), in host order.
std::optional<std::uint64_t> read_raw(std::span<const std::uint8_t> data, std::uint32_t offset_bits, HidVendorType t, bool big_endian) {
  const std::uint32_t width = bits_of(t);
  if (!big_endian) return hid_read_bits(data, offset_bits, width);
  const std::size_t first = offset_bits / 8, n = width / 8;
  if (first + n > data.size()) return std::nullopt;
  std::uint64_t v = 0;
  for (std::size_t k = 0; k < n; ++k) v = v << 8 | data[first + k];
  return v;
}

double to_value(std::uint64_t raw, HidVendorType t) {
  switch (t) {
    case HidVendorType::Int16: return static_cast<std::int16_t>(static_cast<std::uint16_t>(raw));
    case HidVendorType::Int32: return static_cast<std::int32_t>(static_cast<std::uint32_t>(raw));
    case HidVendorType::Float32: return std::bit_cast<float>(static_cast<std::uint32_t>(raw));
    case HidVendorType::Float64: return std::bit_cast<double>(raw);
  }
  return 0.0;
}

std::uint64_t from_value(double v, HidVendorType t) {
  const auto saturate = [](double x, double lo, double hi) { return std::isfinite(x) ? std::clamp(std::round(x), lo, hi) : 0.0; };
  switch (t) {
    case HidVendorType::Int16:
      return static_cast<std::uint16_t>(static_cast<std::int16_t>(saturate(v, -32768.0, 32767.0)));
    case HidVendorType::Int32:
      return static_cast<std::uint32_t>(static_cast<std::int32_t>(saturate(v, -2147483648.0, 2147483647.0)));
    case HidVendorType::Float32:  // (a double beyond float's range converts to ±inf, not by an undefined cast)
      return std::bit_cast<std::uint32_t>(std::abs(v) <= 3.4028234663852886e38 || !std::isfinite(v)
                                              ? static_cast<float>(v)
                                              : std::copysign(std::numeric_limits<float>::infinity(), static_cast<float>(v > 0 ? 1 : -1)));
    case HidVendorType::Float64: return std::bit_cast<std::uint64_t>(v);
  }
  return 0;
}

std::uint32_t needed_bytes(const HidVendorLayout& l) {
  std::uint64_t end = 0;
  for (const std::uint32_t off : l.offset_bits) end = std::max<std::uint64_t>(end, static_cast<std::uint64_t>(off) + bits_of(l.type));
  return std::max(l.report_length, static_cast<std::uint32_t>((end + 7) / 8));
}

class HidVendorLayoutDecoder final : public HidReportDecoder {
 public:
  explicit HidVendorLayoutDecoder(const HidVendorLayout& layout) : layout_(layout), need_(needed_bytes(layout)) {}

  std::string_view protocol() const override { return "hid-vendor"; }

  void decode(std::span<const std::uint8_t> report, DecodedSink& sink) override {
    counters_.bytes += report.size();
    if (layout_.report_id >= 0) {
      if (report.empty() || report[0] != layout_.report_id) {
        ++counters_.ignored_frames;
        return;
      }
      report = report.subspan(1);
    }
    if (report.size() < need_) {
      ++counters_.malformed;
      return;
    }
    ++counters_.frames;
    double v[4];
    for (std::size_t k = 0; k < 4; ++k)
      v[k] = to_value(*read_raw(report, layout_.offset_bits[k], layout_.type, layout_.big_endian), layout_.type) * layout_.scale;
    const Quat q = layout_.w_first ? Quat(v[0], v[1], v[2], v[3]) : Quat(v[3], v[0], v[1], v[2]);
    const double n = q.norm();
    if (!std::isfinite(n) || !(std::abs(n - 1.0) <= layout_.norm_tolerance)) {
      ++counters_.malformed;
      return;
    }
    DecodedSample s;
    s.orientation = Quat(q.coeffs() / n);
    ++counters_.samples;
    sink.on_sample(s);
  }

  void reset() override {}

 private:
  HidVendorLayout layout_;
  std::uint32_t need_;
};

}  // namespace

std::uint32_t hid_vendor_type_bytes(HidVendorType type) {
  switch (type) {
    case HidVendorType::Int16: return 2;
    case HidVendorType::Int32:
    case HidVendorType::Float32: return 4;
    case HidVendorType::Float64: return 8;
  }
  return 0;
}

void validate_hid_vendor_layout(const HidVendorLayout& l) {
  if (l.report_id < -1 || l.report_id == 0 || l.report_id > 255)
    throw HidVendorLayoutError("report_id", std::to_string(l.report_id) + " is neither -1 (no report IDs) nor 1..255");
  if (l.report_length > kMaxReportLength)
    throw HidVendorLayoutError("report_length", std::to_string(l.report_length) + " bytes is above HID's 16384");
  if (hid_vendor_type_bytes(l.type) == 0) throw HidVendorLayoutError("type", "unknown value type");
  const std::uint32_t width = bits_of(l.type);
  for (std::size_t k = 0; k < 4; ++k) {
    const std::string name = "offset_bits[" + std::to_string(k) + "]";
    const std::uint64_t off = l.offset_bits[k], end = off + width;
    if (l.big_endian && off % 8 != 0)
      throw HidVendorLayoutError(name, std::to_string(off) + " is not a byte boundary (big-endian values start at bit 8*n)");
    if (end > static_cast<std::uint64_t>(kMaxReportLength) * 8)
      throw HidVendorLayoutError(name, std::to_string(off) + " lies past the largest HID report (16384 bytes)");
    if (l.report_length > 0 && end > static_cast<std::uint64_t>(l.report_length) * 8)
      throw HidVendorLayoutError(name, "the value at bit " + std::to_string(off) + " ends at bit " + std::to_string(end) +
                                           ", past report_length " + std::to_string(l.report_length) + " bytes");
    for (std::size_t j = 0; j < k; ++j) {
      const std::uint64_t o = l.offset_bits[j];
      if (off < o + width && o < end)
        throw HidVendorLayoutError(name, "the value at bit " + std::to_string(off) + " overlaps value " + std::to_string(j) +
                                             " at bit " + std::to_string(o) + " (" + std::to_string(width) + " bits each)");
    }
  }
  if (!std::isfinite(l.scale) || l.scale == 0.0) throw HidVendorLayoutError("scale", "must be a finite number other than 0");
  if (!(l.norm_tolerance >= 0.0) || !std::isfinite(l.norm_tolerance))
    throw HidVendorLayoutError("norm_tolerance", "must be a finite number >= 0");
}

std::unique_ptr<HidReportDecoder> make_hid_vendor_layout_decoder(const HidVendorLayout& layout) {
  validate_hid_vendor_layout(layout);
  return std::make_unique<HidVendorLayoutDecoder>(layout);
}

namespace {

constexpr std::string_view kValueTypes[] = {"int16", "int32", "float32", "float64"};
constexpr std::string_view kByteOrders[] = {"little", "big"};
constexpr std::string_view kOrders[] = {"w-first", "w-last"};
constexpr OptionSpec kOptions[] = {
    {"report_id", OptionType::Integer, "-1", "the report ID (1..255, the first byte of each report), or -1: no report IDs"},
    {"report_length", OptionType::Integer, "0", "data bytes after the ID byte; 0: just what the values need"},
    {"value_type", OptionType::String, "int16", "the type of the four values", kValueTypes},
    {"byte_order", OptionType::String, "little", "the values' byte order", kByteOrders},
    {"offsets", OptionType::IntegerArray, "", "the four values' byte offsets after the ID byte, in report order (or offsets_bits)"},
    {"offsets_bits", OptionType::IntegerArray, "", "the same in bits (little-endian values may start at any bit)"},
    {"order", OptionType::String, "w-first", "w-first (w x y z) or w-last (x y z w)", kOrders},
    {"scale", OptionType::Float, "0.00006103515625", "value = raw * scale (the default 1/16384 is Q14)"},
};

// The configured layout; the same decoder for every device opened.
class HidVendorFactory final : public HidDecoderFactory {
 public:
  explicit HidVendorFactory(const HidVendorLayout& layout) : layout_(layout) {}
  std::unique_ptr<HidReportDecoder> make(std::span<const std::uint8_t> descriptor, std::string& what) const override {
    what = "descriptor of " + std::to_string(descriptor.size()) + " bytes";
    return make_hid_vendor_layout_decoder(layout_);
  }

 private:
  HidVendorLayout layout_;
};

std::unique_ptr<HidDecoderFactory> configure_hid_vendor(const OptionMap& options) {
  return std::make_unique<HidVendorFactory>(hid_vendor_layout(options));
}

}  // namespace

const HidDecoderEntry kHidVendorDecoder{"hid-vendor", "a quaternion at configured offsets of a vendor-defined input report",
                                        kOptions, configure_hid_vendor};

HidVendorLayout hid_vendor_layout(const OptionMap& options) {
  const OptionReader read(kOptions, options);
  HidVendorLayout l;
  l.report_id = static_cast<int>(read.integer("report_id", -1, 255));
  if (l.report_id == 0)
    throw HidVendorLayoutError("report_id", "report_id",
                               "0 is reserved by HID: give the report's ID (1..255), or -1 for a device without report IDs");
  l.report_length = static_cast<std::uint32_t>(read.integer("report_length", 0, kMaxReportLength));
  constexpr HidVendorType kTypes[] = {HidVendorType::Int16, HidVendorType::Int32, HidVendorType::Float32, HidVendorType::Float64};
  l.type = kTypes[read.choice("value_type")];
  l.big_endian = read.choice("byte_order") == 1;
  l.w_first = read.choice("order") == 0;
  l.scale = read.real("scale");
  if (!std::isfinite(l.scale)) throw OptionError("scale", "must be a finite number");
  if (l.scale == 0.0) throw OptionError("scale", "must not be 0 (value = raw * scale)");
  const bool bytes = read.has("offsets");
  if (bytes && read.has("offsets_bits"))
    throw OptionError("offsets_bits", "give either offsets (bytes) or offsets_bits, not both", "offsets");
  if (!bytes && !read.has("offsets_bits"))
    throw OptionError("offsets", "missing required key: offsets (four byte offsets) or offsets_bits");
  const std::string key = bytes ? "offsets" : "offsets_bits";
  const std::vector<std::int64_t> offsets = read.integers(key);
  if (offsets.size() != 4) throw OptionError(key, "expected an array of four offsets (the values in report order), e.g. [0, 2, 4, 6]");
  const std::uint32_t unit = bytes ? 8 : 1;
  const std::int64_t max = std::int64_t{kMaxReportLength} * 8 / unit;
  for (std::size_t k = 0; k < 4; ++k) {
    if (offsets[k] < 0 || offsets[k] > max)
      throw OptionError(key + "[" + std::to_string(k + 1) + "]", "out of range: must be in [0, " + std::to_string(max) +
                                                                   "], got " + std::to_string(offsets[k]));
    l.offset_bits[k] = static_cast<std::uint32_t>(offsets[k]) * unit;
  }
  try {
    validate_hid_vendor_layout(l);
  } catch (const HidVendorLayoutError& e) {
    const std::string& f = e.field();
    if (f.starts_with("offset_bits[")) throw HidVendorLayoutError(e, key + "[" + std::to_string(f[12] - '0' + 1) + "]");
    throw;  // its field is the key (report_id, report_length, scale)
  }
  return l;
}

std::vector<std::uint8_t> encode_hid_vendor_report(const HidVendorLayout& l, const Quat& q) {
  const std::uint32_t data_bytes = needed_bytes(l);
  const std::size_t id = l.report_id >= 0 ? 1 : 0;
  std::vector<std::uint8_t> out(id + data_bytes, 0);
  if (id) out[0] = static_cast<std::uint8_t>(l.report_id);
  std::span<std::uint8_t> data = std::span<std::uint8_t>(out).subspan(id);
  const double wxyz[4] = {q.w(), q.x(), q.y(), q.z()};
  const double report_order[4] = {l.w_first ? wxyz[0] : wxyz[1], l.w_first ? wxyz[1] : wxyz[2], l.w_first ? wxyz[2] : wxyz[3],
                                  l.w_first ? wxyz[3] : wxyz[0]};
  const std::uint32_t n = hid_vendor_type_bytes(l.type);
  for (std::size_t k = 0; k < 4; ++k) {
    const std::uint64_t raw = from_value(report_order[k] / l.scale, l.type);
    if (!l.big_endian) {
      hid_write_bits(data, l.offset_bits[k], 8 * n, raw);
    } else {
      const std::size_t first = l.offset_bits[k] / 8;
      for (std::uint32_t b = 0; b < n; ++b) data[first + b] = static_cast<std::uint8_t>(raw >> (8 * (n - 1 - b)));
    }
  }
  return out;
}

}  // namespace posefair::drivers
