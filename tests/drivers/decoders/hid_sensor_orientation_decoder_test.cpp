// The HID Sensor orientation decoder (drivers/src/hid_sensor_orientation_decoder.cpp): the
// genuine ST descriptor and a report written by hand from its layout, 8/16/32-bit variants with
// their unit exponents, component order, logical range, timestamps with rollover, report IDs,
// layout errors, encode/decode round trips and 10 MB of random reports.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <random>
#include <stdexcept>
#include <string>
#include <variant>
#include <vector>

#include "../../support/decoder_testing.hpp"
#include "../../support/hid_descriptor_builder.hpp"
#include "../../support/hid_sensor_descriptor.hpp"
#include "posefair/drivers/hid_sensor_orientation_decoder.hpp"

namespace posefair::drivers::hid_sensor_orientation_decoder_test {
namespace {

using namespace ::posefair::testing;
using Bytes = std::vector<std::uint8_t>;

HidReportDescriptor parse(const Bytes& bytes) {
  auto r = parse_hid_report_descriptor(bytes);
  if (const auto* e = std::get_if<HidDescriptorError>(&r)) throw std::runtime_error(e->message);
  return std::get<HidReportDescriptor>(std::move(r));
}

HidOrientationLayout st_layout(const HidSensorOrientationOptions& o = {}) {
  return resolve_hid_orientation_layout(parse(Bytes(kStImuOrientationDescriptor.begin(), kStImuOrientationDescriptor.end())), o);
}

Decoded decode_reports(HidReportDecoder& d, const std::vector<Bytes>& reports) {
  Collector sink;
  for (const Bytes& r : reports) d.decode(r, sink);
  return {std::move(sink.samples), d.counters()};
}

// The rotation angle between a and b (asin form: accurate for small angles).
double angle_between(const Quat& a, const Quat& b) { return 2.0 * std::asin(std::min(1.0, (a.conjugate() * b).vec().norm())); }

TEST(HidSensorOrientation, GenuineDescriptorLayout) {
  const HidOrientationLayout l = st_layout();
  EXPECT_TRUE(l.uses_report_ids);
  EXPECT_EQ(l.report_id, kStImuOrientationReportId);
  EXPECT_EQ(l.report_bytes, kStImuOrientationReportBytes);
  for (std::uint32_t k = 0; k < 4; ++k) {
    EXPECT_EQ(l.values[k].bit_offset, 16 + 32 * k);
    EXPECT_EQ(l.values[k].bit_size, 32u);
    EXPECT_TRUE(l.values[k].is_signed);
    EXPECT_EQ(l.values[k].unit_exponent, -8);
  }
  EXPECT_EQ(l.component, (std::array<int, 4>{1, 2, 3, 0}));  // x y z w
  EXPECT_FALSE(l.timestamp);
}

TEST(HidSensorOrientation, HandWrittenReportOfTheGenuineDevice) {
  // Report 8: state 1 (Ready), event 3 (Data Updated), x = 0.5, y = -0.5, z = 0.5, w = 0.5 in
  // counts of 1e-8 (50000000 = 0x02FAF080, little-endian), magnetometer accuracy 2.
  const Bytes report = hex("08 01 03  80 F0 FA 02  80 0F 05 FD  80 F0 FA 02  80 F0 FA 02  02");
  ASSERT_EQ(report.size(), kStImuOrientationReportBytes);
  auto d = make_hid_sensor_orientation_decoder(st_layout());
  const Decoded out = decode_reports(*d, {report});
  ASSERT_EQ(out.samples.size(), 1u);
  const Quat q = out.samples[0].orientation;
  EXPECT_DOUBLE_EQ(q.w(), 0.5);
  EXPECT_DOUBLE_EQ(q.x(), 0.5);
  EXPECT_DOUBLE_EQ(q.y(), -0.5);
  EXPECT_DOUBLE_EQ(q.z(), 0.5);
  EXPECT_EQ(out.samples[0].flags, 0u);
  EXPECT_EQ(out.counters.frames, 1u);
  EXPECT_EQ(out.counters.bytes, 20u);
  // The encoder writes the same bytes, except the state, event and accuracy it leaves 0.
  Bytes expected = report;
  expected[1] = expected[2] = expected[19] = 0;
  EXPECT_EQ(encode_hid_orientation_report(st_layout(), Quat(0.5, 0.5, -0.5, 0.5)), expected);
}

TEST(HidSensorOrientation, ComponentOrderIsConfigurable) {
  const Bytes report = hex("08 01 03  80 F0 FA 02  80 0F 05 FD  80 F0 FA 02  80 0F 05 FD  02");  // 0.5 -0.5 0.5 -0.5
  HidSensorOrientationOptions o;
  o.component_order = "wxyz";
  auto d = make_hid_sensor_orientation_decoder(st_layout(o), o);
  const Decoded out = decode_reports(*d, {report});
  ASSERT_EQ(out.samples.size(), 1u);
  EXPECT_TRUE(out.samples[0].orientation.coeffs().isApprox(Eigen::Vector4d(-0.5, 0.5, -0.5, 0.5), 1e-12));  // x y z w
  auto xyzw = make_hid_sensor_orientation_decoder(st_layout());
  EXPECT_TRUE(decode_reports(*xyzw, {report}).samples[0].orientation.coeffs().isApprox(Eigen::Vector4d(0.5, -0.5, 0.5, -0.5), 1e-12));
  for (const char* bad : {"xyz", "xyzz", "abcd", "wxyzw"}) {
    o.component_order = bad;
    EXPECT_THROW(st_layout(o), std::invalid_argument) << bad;
  }
}

TEST(HidSensorOrientation, SixteenBitsWithExponentMinusTwo) {
  // Unit exponent 0x0E = -2: counts of 0.01. 90° about z: w = z = 0.71 (rounded), x = y = 0.
  const HidReportDescriptor desc = parse(hid_sensor_orientation_descriptor(16, -2, 3));
  const HidOrientationLayout l = resolve_hid_orientation_layout(desc);
  EXPECT_EQ(l.report_bytes, 1u + 1 + 8);
  EXPECT_EQ(l.values[0].unit_exponent, -2);
  const Bytes report = hex("03 01  00 00  00 00  47 00  47 00");  // x 0, y 0, z 71, w 71
  auto d = make_hid_sensor_orientation_decoder(l);
  const Decoded out = decode_reports(*d, {report});
  ASSERT_EQ(out.samples.size(), 1u);
  EXPECT_NEAR(out.samples[0].orientation.w(), std::sqrt(0.5), 1e-12);  // normalised
  EXPECT_NEAR(out.samples[0].orientation.z(), std::sqrt(0.5), 1e-12);
  // Negative counts: x = -0.71 (0xFFB9).
  const Decoded neg = decode_reports(*d, {hex("03 01  B9 FF  00 00  00 00  47 00")});
  ASSERT_EQ(neg.samples.size(), 1u);
  EXPECT_NEAR(neg.samples[0].orientation.x(), -std::sqrt(0.5), 1e-12);
}

TEST(HidSensorOrientation, EightAndThirtyTwoBitRoundTrips) {
  std::mt19937_64 rng(21);
  struct Variant {
    std::uint32_t bits;
    int exponent;
    double max_angle;  // rad, from the rounding of each component to one count
  };
  for (const Variant v : {Variant{8, -2, 0.05}, Variant{16, -4, 5e-4}, Variant{32, -8, 5e-8}, Variant{16, -2, 0.05}}) {
    const HidOrientationLayout l = resolve_hid_orientation_layout(parse(hid_sensor_orientation_descriptor(v.bits, v.exponent, 0)));
    EXPECT_FALSE(l.uses_report_ids);
    auto d = make_hid_sensor_orientation_decoder(l);
    Collector sink;
    for (int i = 0; i < 2000; ++i) {
      const Quat q = random_unit_quaternion(rng);
      d->decode(encode_hid_orientation_report(l, q), sink);
      ASSERT_EQ(sink.samples.size(), static_cast<std::size_t>(i + 1)) << v.bits;
      ASSERT_LT(angle_between(sink.samples.back().orientation, q), v.max_angle) << v.bits;
    }
    EXPECT_EQ(d->counters().malformed, 0u);
  }
}

TEST(HidSensorOrientation, ConjugateOption) {
  HidSensorOrientationOptions o;
  o.conjugate = true;
  const HidOrientationLayout l = st_layout(o);
  auto d = make_hid_sensor_orientation_decoder(l, o);
  const Quat q = zyx(30, -20, 10);
  // A device that sends q* (world→sensor): encoded as such, decoded back to q.
  const Decoded out = decode_reports(*d, {encode_hid_orientation_report(l, q, std::nullopt, true)});
  ASSERT_EQ(out.samples.size(), 1u);
  EXPECT_LT(angle_between(out.samples[0].orientation, q), 1e-7);
  EXPECT_GT(angle_between(out.samples[0].orientation, q.conjugate()), 0.1);
}

TEST(HidSensorOrientation, OutOfRangeZeroAndShortReportsAreMalformed) {
  HidDescriptorBuilder b;
  b.usage_page(0x20).usage(0x8A).collection(1).report_id(1);
  b.usage(0x0483).logical_min(-100).logical_max(100).report_size(8).report_count(4).unit_exponent(-2).input(0x02);
  b.end_collection();
  const HidOrientationLayout l = resolve_hid_orientation_layout(parse(b.out));
  auto d = make_hid_sensor_orientation_decoder(l);
  const Decoded out = decode_reports(*d, {
                                             hex("01 00 00 00 64"),     // w = 1.00: fine
                                             hex("01 00 00 00 65"),     // 1.01 > logical max 100
                                             hex("01 00 00 00 00"),     // zero quaternion
                                             hex("01 00 00 00"),        // one byte short
                                             hex("01 00 00 00 64 FF"),  // longer: read as far as needed
                                             hex("02 00 00 00 64"),     // another report ID
                                             hex(""),                   // nothing
                                             hex("01 3C 00 00 3C"),     // norm 0.85: off by more than 0.05 + 4 steps
                                         });
  EXPECT_EQ(out.samples.size(), 2u);
  EXPECT_EQ(out.counters.frames, 5u);
  EXPECT_EQ(out.counters.malformed, 4u);
  EXPECT_EQ(out.counters.ignored_frames, 2u);
  EXPECT_EQ(out.counters.samples, 2u);
}

TEST(HidSensorOrientation, UnsignedRangesAreReadUnsigned) {
  // A descriptor that declares 0..65535 (as some hobby firmware does) gets its values unsigned:
  // 0xFFFF is 65535 counts, not -1, and the report is malformed rather than silently wrong.
  HidDescriptorBuilder b;
  b.usage_page(0x20).usage(0x8A).collection(1);
  b.usage(0x0483).logical_min(0).logical_max(65535).report_size(16).report_count(4).unit_exponent(-4).input(0x02);
  b.end_collection();
  const HidOrientationLayout l = resolve_hid_orientation_layout(parse(b.out));
  EXPECT_FALSE(l.values[0].is_signed);
  auto d = make_hid_sensor_orientation_decoder(l);
  const Decoded out = decode_reports(*d, {hex("FF FF 00 00 00 00 10 27"), hex("00 00 00 00 00 00 10 27")});
  ASSERT_EQ(out.samples.size(), 1u);  // the second: w = 10000 · 1e-4 = 1
  EXPECT_EQ(out.counters.malformed, 1u);
}

TEST(HidSensorOrientation, TimestampInSecondsUnitAndWithout) {
  // Unit 0x1001 (seconds), exponent -6: microseconds; 32-bit unsigned, unwrapped at 2^32.
  const HidOrientationLayout l = resolve_hid_orientation_layout(parse(hid_sensor_orientation_descriptor(16, -4, 2, 32, 0x1001, -6)));
  ASSERT_TRUE(l.timestamp);
  EXPECT_DOUBLE_EQ(l.timestamp_unit_s, 1e-6);
  auto d = make_hid_sensor_orientation_decoder(l);
  Collector sink;
  const std::uint64_t ticks[] = {4294967000ull, 4294967295ull, 100ull, 5000ull};
  for (const std::uint64_t t : ticks) d->decode(encode_hid_orientation_report(l, Quat::Identity(), t), sink);
  ASSERT_EQ(sink.samples.size(), 4u);
  EXPECT_EQ(sink.samples[0].flags, static_cast<std::uint32_t>(kHasDeviceTime));
  EXPECT_NEAR(sink.samples[0].device_time, 4294.967000, 1e-9);
  EXPECT_NEAR(sink.samples[1].device_time, 4294.967295, 1e-9);
  EXPECT_NEAR(sink.samples[2].device_time, 4294.967296 + 100e-6, 1e-9);  // rolled over
  EXPECT_NEAR(sink.samples[3].device_time, 4294.967296 + 5000e-6, 1e-9);
  d->reset();
  d->decode(encode_hid_orientation_report(l, Quat::Identity(), 7), sink);
  EXPECT_NEAR(sink.samples.back().device_time, 7e-6, 1e-12);
  // No unit: counts of timestamp_count_s (1 µs by default) times 10^exponent.
  HidSensorOrientationOptions o;
  o.timestamp_count_s = 1e-3;
  const HidOrientationLayout ms = resolve_hid_orientation_layout(parse(hid_sensor_orientation_descriptor(16, -4, 2, 64, 0, 0)), o);
  ASSERT_TRUE(ms.timestamp);
  EXPECT_DOUBLE_EQ(ms.timestamp_unit_s, 1e-3);
  EXPECT_EQ(ms.timestamp->bit_size, 64u);
  auto dm = make_hid_sensor_orientation_decoder(ms, o);
  Collector s2;
  dm->decode(encode_hid_orientation_report(ms, Quat::Identity(), 123456789012ull), s2);
  ASSERT_EQ(s2.samples.size(), 1u);
  EXPECT_NEAR(s2.samples[0].device_time, 123456789.012, 1e-3);
}

TEST(HidSensorOrientation, LayoutErrorsSayWhatIsMissing) {
  const auto message = [](const Bytes& desc, const HidSensorOrientationOptions& o = {}) {
    try {
      resolve_hid_orientation_layout(parse(desc), o);
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string("(no error)");
  };
  // A quaternion outside any orientation collection (an accelerometer 0x73 here).
  HidDescriptorBuilder outside;
  outside.usage_page(0x20).usage(0x73).collection(1);
  outside.usage(0x0483).logical_min(-127).logical_max(127).report_size(8).report_count(4).input(0x02).end_collection();
  EXPECT_NE(message(outside.out).find("no orientation quaternion"), std::string::npos) << message(outside.out);
  // Three values only.
  HidDescriptorBuilder three;
  three.usage_page(0x20).usage(0x8A).collection(1);
  three.usage(0x0483).logical_min(-127).logical_max(127).report_size(8).report_count(3).input(0x02).end_collection();
  EXPECT_NE(message(three.out).find("3 values, not 4"), std::string::npos) << message(three.out);
  // A quaternion only in a feature report (the genuine descriptor's modifiers) is not read.
  HidDescriptorBuilder feature;
  feature.usage_page(0x20).usage(0x8A).collection(1);
  feature.usage(0x0483).logical_min(-127).logical_max(127).report_size(8).report_count(4).feature(0x02).end_collection();
  EXPECT_NE(message(feature.out).find("no orientation quaternion"), std::string::npos);
  // Asking for a report that does not hold it.
  HidSensorOrientationOptions o;
  o.report_id = 7;
  const Bytes st(kStImuOrientationDescriptor.begin(), kStImuOrientationDescriptor.end());
  EXPECT_NE(message(st, o).find("input report 7"), std::string::npos) << message(st, o);
  o.report_id = 300;
  EXPECT_NE(message(st, o).find("report_id 300"), std::string::npos);
  // Four one-value fields in a row are one quaternion; Relative Orientation counts too.
  HidDescriptorBuilder split;
  split.usage_page(0x20).usage(0x8E).collection(1);
  split.logical_min(-127).logical_max(127).report_size(8).report_count(1);
  for (int k = 0; k < 4; ++k) split.usage(0x0483).input(0x02);
  split.end_collection();
  const HidOrientationLayout l = resolve_hid_orientation_layout(parse(split.out));
  EXPECT_EQ(l.values[3].bit_offset, 24u);
}

TEST(HidSensorOrientation, TenMegabytesOfRandomReportsNeverCrash) {
  std::mt19937_64 rng(8);
  const HidOrientationLayout layouts[] = {st_layout(),
                                          resolve_hid_orientation_layout(parse(hid_sensor_orientation_descriptor(16, -2, 0))),
                                          resolve_hid_orientation_layout(parse(hid_sensor_orientation_descriptor(8, -2, 5, 32, 0x1001, -6)))};
  std::size_t total = 0;
  for (const HidOrientationLayout& l : layouts) {
    auto d = make_hid_sensor_orientation_decoder(l);
    Collector sink;
    std::uniform_int_distribution<std::size_t> length(0, 2 * l.report_bytes);
    std::size_t reports = 0;
    for (std::size_t done = 0; done < 3'400'000; ++reports) {
      Bytes r = random_bytes(length(rng), rng);
      if (!r.empty() && l.uses_report_ids && rng() % 2) r[0] = l.report_id;  // half of them the right ID
      done += r.size();
      d->decode(r, sink);
      sink.samples.clear();
    }
    total += d->counters().bytes;
    const DecoderCounters& c = d->counters();
    EXPECT_EQ(c.frames + c.ignored_frames + (c.malformed - (c.frames - c.samples)), reports);
    EXPECT_EQ(c.bad_checksum + c.resyncs + c.skipped_bytes, 0u);
  }
  EXPECT_GE(total, 10'000'000u);
}

TEST(HidSensorOrientation, SamplesOfRandomReportsAreUnitQuaternions) {
  std::mt19937_64 rng(12);
  // 8-bit values with exponent -2 accept many random reports (norm within 0.09 of 1).
  const HidOrientationLayout l = resolve_hid_orientation_layout(parse(hid_sensor_orientation_descriptor(8, -1, 0)));
  auto d = make_hid_sensor_orientation_decoder(l);
  Collector sink;
  for (int i = 0; i < 200000; ++i) d->decode(random_bytes(l.report_bytes, rng), sink);
  EXPECT_GT(sink.samples.size(), 0u);
  expect_unit_quaternions(sink.samples);
}

}  // namespace
}  // namespace posefair::drivers::hid_sensor_orientation_decoder_test
