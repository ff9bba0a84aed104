// HID Sensor orientation quaternion decoder: protocol name "hid-sensor".
//
// Reference documents
// - USB-IF HID Usage Tables review request HUTRR39 ("HID Sensor Usages", 2011; since then in
//   the HID Usage Tables, Sensors page 0x20): the sensor type collections Device Orientation
//   0x8A, Relative Orientation 0x8E and Geomagnetic Orientation 0xC1 (under category 0x80
//   Orientation), Data Field: Quaternion 0x0483, "A matrix of 4 values (x, y, z and w, all
//   ranging in value from -1.0 to 1.0) that represent rotation in space about a unit vector.
//   No units are specified and scaling is by the Unit Exponent usage." (the description as
//   quoted in Vuzix' M400C SDK, Sensors.kt), and Data Field: Timestamp 0x0529.
// - Linux include/linux/hid-sensor-ids.h (HID_USAGE_SENSOR_DEVICE_ORIENTATION 0x20008A,
//   HID_USAGE_SENSOR_ORIENT_QUATERNION 0x200483, HID_USAGE_SENSOR_TIME_TIMESTAMP 0x200529) and
//   drivers/iio/orientation/hid-sensor-rotation.c, which reads the quaternion as one field of
//   four values and hands them on in report order; the IIO ABI documents that order as
//   "x y z w" (in_rot_quaternion_raw).
// - Device Class Definition for HID 1.11 (hid_report_descriptor.cpp): report sizes, logical
//   range, unit exponent.
//
// What is read: the first Input field (or four consecutive one-value fields) whose usage is
// 0x200483 and that lies inside one of the three orientation sensor collections, in the report
// chosen by report_id. Its values are raw · 10^unit_exponent (a 16-bit field with unit
// exponent 0x0E = -2 carries hundredths; 32-bit fields with exponent 0x08 = -8, as the ST
// firmware in tests/support/hid_sensor_descriptor.hpp sends them, carry 1e-8 steps); signed
// iff the logical minimum is negative. Report sizes of 1..64 bits are read (8, 16 and 32 in
// practice).
//
// Choices where the documents are silent
// - Component order: x, y, z, w as the usage table describes it, configurable
//   (component_order), because firmware authors are known to put w first.
// - Frame: the usage table does not say whether q rotates device into world coordinates or the
//   reverse; posefair takes it as device→world (its own convention, as Windows' orientation
//   sensor presents it) and `conjugate` flips it.
// - A value outside a declared logical range (min < max) makes the report malformed: HID 1.11
//   6.2.2.7 says such values are to be ignored as out of range (null).
// - Norm: a quaternion whose norm differs from 1 by more than norm_tolerance + 4 steps of the
//   field's resolution, or is not finite, is malformed; otherwise it is normalised.
// - Timestamp: used when the same report carries a 0x200529 field of at most 64 bits. Unit
//   0x1001 (SI linear, seconds) gives 10^unit_exponent s per count; without a unit the counts
//   are timestamp_count_s (1 µs by default) · 10^unit_exponent. Unsigned timestamps narrower
//   than 64 bits are unwrapped forward-only (a device restart looks like a rollover; reset()
//   starts afresh).
#include "posefair/drivers/hid_sensor_orientation_decoder.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <utility>
#include <variant>
#include <stdexcept>
#include <string>

namespace posefair::drivers {
namespace {

bool is_orientation_collection(const HidReportDescriptor& d, int collection) {
  return d.within(collection, kHidSensorDeviceOrientation) || d.within(collection, kHidSensorRelativeOrientation) ||
         d.within(collection, kHidSensorGeomagneticOrientation);
}

HidValueSlot slot_of(const HidField& f, std::uint32_t index) {
  HidValueSlot s;
  s.bit_offset = f.bit_offset + index * f.bit_size;
  s.bit_size = f.bit_size;
  s.is_signed = f.is_signed();
  s.logical_min = f.logical_min;
  s.logical_max = f.logical_max;
  s.unit_exponent = f.unit_exponent;
  return s;
}

bool is_data_variable(const HidField& f) { return (f.flags & kHidConstant) == 0 && (f.flags & kHidVariable) != 0; }

// The four quaternion slots of `report`, if it has them.
std::optional<std::array<HidValueSlot, 4>> quaternion_slots(const HidReportDescriptor& d, const HidReport& report, std::string& why) {
  const auto& fields = report.fields;
  for (std::size_t i = 0; i < fields.size(); ++i) {
    const HidField& f = fields[i];
    if (!is_data_variable(f) || f.usage_of(0) != kHidSensorQuaternion || !is_orientation_collection(d, f.collection)) continue;
    if (f.bit_size > 64) {
      why = "its quaternion field is " + std::to_string(f.bit_size) + " bits wide (at most 64 are read)";
      return std::nullopt;
    }
    std::array<HidValueSlot, 4> s{};
    if (f.count >= 4) {
      for (std::uint32_t k = 0; k < 4; ++k) s[k] = slot_of(f, k);
      return s;
    }
    // Four one-value fields with the quaternion usage, one after the other.
    std::size_t got = 0;
    for (std::size_t j = i; j < fields.size() && got < 4; ++j) {
      const HidField& g = fields[j];
      if (!is_data_variable(g) || g.usage_of(0) != kHidSensorQuaternion || g.bit_size > 64) break;
      for (std::uint32_t k = 0; k < g.count && got < 4; ++k) s[got++] = slot_of(g, k);
    }
    if (got == 4) return s;
    why = "its quaternion field has " + std::to_string(got) + " values, not 4";
    return std::nullopt;
  }
  return std::nullopt;
}

std::array<int, 4> parse_order(const std::string& order) {
  std::array<int, 4> component{};
  bool seen[4] = {false, false, false, false};
  if (order.size() != 4) throw std::invalid_argument("hid-sensor component_order \"" + order + "\": four letters w, x, y, z expected");
  for (std::size_t k = 0; k < 4; ++k) {
    const std::size_t c = std::string("wxyz").find(order[k]);
    if (c == std::string::npos || seen[c])
      throw std::invalid_argument("hid-sensor component_order \"" + order + "\": each of w, x, y, z exactly once expected");
    seen[c] = true;
    component[k] = static_cast<int>(c);
  }
  return component;
}

double pow10(int e) { return std::pow(10.0, e); }

std::optional<double> slot_value(std::span<const std::uint8_t> data, const HidValueSlot& s, double scale) {
  const std::optional<std::uint64_t> bits = hid_read_bits(data, s.bit_offset, s.bit_size);
  if (!bits) return std::nullopt;
  std::int64_t raw = static_cast<std::int64_t>(*bits);
  if (s.is_signed && s.bit_size < 64 && ((*bits >> (s.bit_size - 1)) & 1))
    raw = static_cast<std::int64_t>(*bits | ~((std::uint64_t{1} << s.bit_size) - 1));
  if (s.logical_min < s.logical_max && (raw < s.logical_min || raw > s.logical_max)) return std::nullopt;
  return static_cast<double>(raw) * scale;
}

class HidSensorOrientationDecoder final : public HidReportDecoder {
 public:
  HidSensorOrientationDecoder(const HidOrientationLayout& layout, const HidSensorOrientationOptions& options)
      : layout_(layout), conjugate_(options.conjugate) {
    double worst_step = 0.0;
    for (std::size_t k = 0; k < 4; ++k) {
      scale_[k] = pow10(layout.values[k].unit_exponent);
      worst_step = std::max(worst_step, scale_[k]);
    }
    tolerance_ = options.norm_tolerance + 4.0 * worst_step;
    if (layout.timestamp) {
      const HidValueSlot& t = *layout.timestamp;
      wrap_mask_ = (!t.is_signed && t.bit_size < 64) ? (std::uint64_t{1} << t.bit_size) - 1 : ~std::uint64_t{0};
    }
    need_bytes_ = layout.report_bytes;
  }

  std::string_view protocol() const override { return "hid-sensor"; }

  void decode(std::span<const std::uint8_t> report, DecodedSink& sink) override {
    counters_.bytes += report.size();
    if (layout_.uses_report_ids) {
      if (report.empty() || report[0] != layout_.report_id) {
        ++counters_.ignored_frames;
        return;
      }
      report = report.subspan(1);
    }
    if (report.size() + (layout_.uses_report_ids ? 1 : 0) < need_bytes_) {
      ++counters_.malformed;
      return;
    }
    ++counters_.frames;
    DecodedSample s;
    if (layout_.timestamp) {
      const HidValueSlot& t = *layout_.timestamp;
      const std::optional<std::uint64_t> bits = hid_read_bits(report, t.bit_offset, t.bit_size);
      if (bits) {  // always, the length was checked
        std::uint64_t counts = *bits;
        if (wrap_mask_ != ~std::uint64_t{0}) {
          total_ = have_time_ ? total_ + ((counts - last_) & wrap_mask_) : counts;
          have_time_ = true;
          last_ = counts;
          counts = total_;
        }
        s.device_time = static_cast<double>(counts) * layout_.timestamp_unit_s;
        s.flags |= kHasDeviceTime;
      }
    }
    double c[4] = {0, 0, 0, 0};  // w, x, y, z
    for (std::size_t k = 0; k < 4; ++k) {
      const std::optional<double> v = slot_value(report, layout_.values[k], scale_[k]);
      if (!v) {
        ++counters_.malformed;
        return;
      }
      c[layout_.component[k]] = *v;
    }
    const Quat q(c[0], c[1], c[2], c[3]);
    const double n = q.norm();
    if (!std::isfinite(n) || !(std::abs(n - 1.0) <= tolerance_)) {
      ++counters_.malformed;
      return;
    }
    s.orientation = Quat(q.coeffs() / n);
    if (conjugate_) s.orientation = s.orientation.conjugate();
    ++counters_.samples;
    sink.on_sample(s);
  }

  void reset() override { have_time_ = false; }

 private:
  HidOrientationLayout layout_;
  bool conjugate_;
  std::array<double, 4> scale_{};
  double tolerance_ = 0.0;
  std::size_t need_bytes_ = 0;
  std::uint64_t wrap_mask_ = ~std::uint64_t{0};
  bool have_time_ = false;
  std::uint64_t last_ = 0;
  std::uint64_t total_ = 0;
};

}  // namespace

HidOrientationLayout resolve_hid_orientation_layout(const HidReportDescriptor& descriptor, const HidSensorOrientationOptions& options) {
  HidOrientationLayout layout;
  layout.component = parse_order(options.component_order);
  if (options.report_id < -1 || options.report_id > 255)
    throw std::invalid_argument("hid-sensor report_id " + std::to_string(options.report_id) + ": -1 (any) or 0..255 expected");
  if (!(options.timestamp_count_s > 0.0) || !std::isfinite(options.timestamp_count_s))
    throw std::invalid_argument("hid-sensor timestamp_count_s must be a positive number of seconds");
  if (!(options.norm_tolerance >= 0.0) || !std::isfinite(options.norm_tolerance))
    throw std::invalid_argument("hid-sensor norm_tolerance must be a finite number >= 0");
  std::string why;
  for (const HidReport& r : descriptor.reports) {
    if (r.kind != HidReportKind::Input) continue;
    if (options.report_id >= 0 && r.id != options.report_id) continue;
    std::string report_why;
    const auto slots = quaternion_slots(descriptor, r, report_why);
    if (!slots) {
      if (!report_why.empty()) why = "input report " + std::to_string(r.id) + ": " + report_why;
      continue;
    }
    layout.uses_report_ids = descriptor.uses_report_ids;
    layout.report_id = r.id;
    layout.report_bytes = r.byte_size(descriptor.uses_report_ids);
    layout.values = *slots;
    for (const HidField& f : r.fields) {
      if ((f.flags & kHidConstant) || f.usage_of(0) != kHidSensorTimestamp || f.bit_size > 64) continue;
      layout.timestamp = slot_of(f, 0);
      const double unit = f.unit == 0x1001 ? 1.0 : options.timestamp_count_s;
      layout.timestamp_unit_s = unit * pow10(f.unit_exponent);
      break;
    }
    return layout;
  }
  std::string where = options.report_id >= 0 ? "input report " + std::to_string(options.report_id) : "any input report";
  throw std::invalid_argument("hid-sensor: no orientation quaternion (usage 0x200483 in a Device, Relative or Geomagnetic "
                              "Orientation collection) in " + where + (why.empty() ? "" : "; " + why));
}

std::unique_ptr<HidReportDecoder> make_hid_sensor_orientation_decoder(const HidOrientationLayout& layout,
                                                                      const HidSensorOrientationOptions& options) {
  return std::make_unique<HidSensorOrientationDecoder>(layout, options);
}

namespace {

constexpr OptionSpec kOptions[] = {
    {"report_id", OptionType::Integer, "", "the input report to read (0: a device without report IDs); absent: the first with a quaternion"},
    {"component_order", OptionType::String, "xyzw", "the order of the quaternion's four values in the report"},
    {"conjugate", OptionType::Boolean, "false", "hand out q* (for a device whose quaternion rotates world into sensor)"},
    {"timestamp_count_s", OptionType::Float, "1e-6", "seconds per timestamp count when the Timestamp field declares no unit"},
};

std::string number_text(double v) {
  char buf[40];
  std::snprintf(buf, sizeof buf, "%g", v);
  return buf;
}

// Resolves each opened device's descriptor with the configured options.
class HidSensorFactory final : public HidDecoderFactory {
 public:
  explicit HidSensorFactory(HidSensorOrientationOptions options) : options_(std::move(options)) {}
  std::unique_ptr<HidReportDecoder> make(std::span<const std::uint8_t> descriptor, std::string& what) const override {
    auto parsed = parse_hid_report_descriptor(descriptor);
    if (const auto* error = std::get_if<HidDescriptorError>(&parsed)) throw std::invalid_argument(error->message);
    const HidOrientationLayout layout = resolve_hid_orientation_layout(std::get<HidReportDescriptor>(parsed), options_);
    what = "input report " + std::to_string(layout.report_id) + " of " + std::to_string(layout.report_bytes) + " bytes" +
           (layout.timestamp ? " with a timestamp" : "");
    return make_hid_sensor_orientation_decoder(layout, options_);
  }

 private:
  HidSensorOrientationOptions options_;
};

std::unique_ptr<HidDecoderFactory> configure_hid_sensor(const OptionMap& options) {
  return std::make_unique<HidSensorFactory>(hid_sensor_options(options));
}

}  // namespace

const HidDecoderEntry kHidSensorDecoder{"hid-sensor",
                                        "HID Sensor usage page orientation sensors: the quaternion field, from the report descriptor",
                                        kOptions, configure_hid_sensor};

HidSensorOrientationOptions hid_sensor_options(const OptionMap& options) {
  const OptionReader read(kOptions, options);
  HidSensorOrientationOptions o;
  // Absent: the first input report with an orientation quaternion; 0: a device without report IDs.
  if (read.has("report_id")) o.report_id = static_cast<int>(read.integer("report_id", 0, 255));
  o.component_order = read.text("component_order");
  std::string sorted = o.component_order;
  std::sort(sorted.begin(), sorted.end());
  if (sorted != "wxyz")
    throw OptionError("component_order", "must be the letters w, x, y, z each once in report order, e.g. \"xyzw\" or \"wxyz\", got '" +
                                             o.component_order + "'");
  o.conjugate = read.boolean("conjugate");
  o.timestamp_count_s = read.real("timestamp_count_s");
  if (!(o.timestamp_count_s > 0.0) || !std::isfinite(o.timestamp_count_s))
    throw OptionError("timestamp_count_s", "out of range: must be > 0, got " + number_text(o.timestamp_count_s));
  return o;
}

std::vector<std::uint8_t> encode_hid_orientation_report(const HidOrientationLayout& layout, const Quat& q_in,
                                                        std::optional<std::uint64_t> timestamp_counts, bool conjugate) {
  std::vector<std::uint8_t> out(layout.report_bytes, 0);
  std::span<std::uint8_t> data(out);
  if (layout.uses_report_ids && !out.empty()) {
    out[0] = layout.report_id;
    data = data.subspan(1);
  }
  const Quat q = conjugate ? q_in.conjugate() : q_in;
  const double wxyz[4] = {q.w(), q.x(), q.y(), q.z()};
  for (std::size_t k = 0; k < 4; ++k) {
    const HidValueSlot& s = layout.values[k];
    double raw = std::round(wxyz[layout.component[k]] / pow10(s.unit_exponent));
    if (s.logical_min < s.logical_max)
      raw = std::clamp(raw, static_cast<double>(s.logical_min), static_cast<double>(s.logical_max));
    raw = std::isfinite(raw) ? std::clamp(raw, -9.2e18, 9.2e18) : 0.0;  // a defined conversion below
    hid_write_bits(data, s.bit_offset, s.bit_size, static_cast<std::uint64_t>(static_cast<std::int64_t>(raw)));
  }
  if (layout.timestamp && timestamp_counts)
    hid_write_bits(data, layout.timestamp->bit_offset, layout.timestamp->bit_size, *timestamp_counts);
  return out;
}

}  // namespace posefair::drivers
