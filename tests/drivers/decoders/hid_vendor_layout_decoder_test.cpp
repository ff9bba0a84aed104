// The vendor HID report layout decoder (drivers/src/hid_vendor_layout_decoder.cpp): reports
// written by hand, every type and byte order through encode/decode, unaligned little-endian
// offsets, w-first and w-last, validation errors naming the field, and 10 MB of random reports.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <random>
#include <string>
#include <vector>

#include "../../support/decoder_testing.hpp"
#include "posefair/drivers/hid_vendor_layout_decoder.hpp"

namespace posefair::drivers::hid_vendor_layout_decoder_test {
namespace {

using namespace ::posefair::testing;
using Bytes = std::vector<std::uint8_t>;

Decoded decode_reports(HidReportDecoder& d, const std::vector<Bytes>& reports) {
  Collector sink;
  for (const Bytes& r : reports) d.decode(r, sink);
  return {std::move(sink.samples), d.counters()};
}

double angle_between(const Quat& a, const Quat& b) { return 2.0 * std::asin(std::min(1.0, (a.conjugate() * b).vec().norm())); }

TEST(HidVendorLayout, Int16Q14LittleEndianWFirstByHand) {
  HidVendorLayout l;  // report ID 0x05, int16 LE, Q14, w x y z at bytes 2, 4, 6, 8 (bytes 0-1: a counter)
  l.report_id = 5;
  l.report_length = 12;
  l.offset_bits = {16, 32, 48, 64};
  auto d = make_hid_vendor_layout_decoder(l);
  // w = 0.5 (0x2000), x = -0.5 (0xE000), y = 0.5, z = -0.5
  const Decoded out = decode_reports(*d, {hex("05 07 00 00 20 00 E0 00 20 00 E0 AA BB CC")});
  ASSERT_EQ(out.samples.size(), 1u);
  EXPECT_DOUBLE_EQ(out.samples[0].orientation.w(), 0.5);
  EXPECT_DOUBLE_EQ(out.samples[0].orientation.x(), -0.5);
  EXPECT_DOUBLE_EQ(out.samples[0].orientation.y(), 0.5);
  EXPECT_DOUBLE_EQ(out.samples[0].orientation.z(), -0.5);
  EXPECT_EQ(encode_hid_vendor_report(l, Quat(0.5, -0.5, 0.5, -0.5)), hex("05 00 00 00 20 00 E0 00 20 00 E0 00 00"));
}

TEST(HidVendorLayout, Float32BigEndianWLastByHand) {
  HidVendorLayout l;  // no report IDs, float32 BE, x y z w from byte 0
  l.type = HidVendorType::Float32;
  l.big_endian = true;
  l.w_first = false;
  l.scale = 1.0;
  l.offset_bits = {0, 32, 64, 96};
  auto d = make_hid_vendor_layout_decoder(l);
  // x = 0, y = 0, z = 0.6 (0x3F19999A), w = 0.8 (0x3F4CCCCD)
  const Decoded out = decode_reports(*d, {hex("00000000 00000000 3F19999A 3F4CCCCD")});
  ASSERT_EQ(out.samples.size(), 1u);
  EXPECT_NEAR(out.samples[0].orientation.z(), 0.6, 1e-7);
  EXPECT_NEAR(out.samples[0].orientation.w(), 0.8, 1e-7);
}

TEST(HidVendorLayout, EveryTypeAndByteOrderRoundTrips) {
  std::mt19937_64 rng(4);
  struct Case {
    HidVendorType type;
    double scale;
    double max_angle;
  };
  for (const Case c : {Case{HidVendorType::Int16, 1.0 / 16384, 3e-4}, Case{HidVendorType::Int32, 1.0 / (1 << 30), 1e-8},
                       Case{HidVendorType::Float32, 1.0, 1e-6}, Case{HidVendorType::Float64, 1.0, 1e-12},
                       Case{HidVendorType::Float32, 0.001, 1e-6}})
    for (const bool big : {false, true})
      for (const bool w_first : {true, false})
        for (const int id : {-1, 9}) {
          HidVendorLayout l;
          l.type = c.type;
          l.scale = c.scale;
          l.big_endian = big;
          l.w_first = w_first;
          l.report_id = id;
          const std::uint32_t w = 8 * hid_vendor_type_bytes(c.type);
          l.offset_bits = {3 * w + 24, 8, 2 * w + 24, w + 8};  // out of order, with gaps, byte-aligned
          auto d = make_hid_vendor_layout_decoder(l);
          Collector sink;
          for (int i = 0; i < 300; ++i) {
            const Quat q = random_unit_quaternion(rng);
            const Bytes r = encode_hid_vendor_report(l, q);
            d->decode(r, sink);
            ASSERT_EQ(sink.samples.size(), static_cast<std::size_t>(i + 1));
            ASSERT_LT(angle_between(sink.samples.back().orientation, q), c.max_angle) << static_cast<int>(c.type) << big << w_first;
          }
        }
}

TEST(HidVendorLayout, UnalignedLittleEndianOffsets) {
  HidVendorLayout l;
  l.offset_bits = {3, 19, 35, 51};  // int16 values shifted by 3 bits, HID's LSB-first packing
  auto d = make_hid_vendor_layout_decoder(l);
  const Quat q = zyx(10, 20, 30);
  const Bytes r = encode_hid_vendor_report(l, q);
  EXPECT_EQ(r.size(), 9u);  // 67 bits
  const Decoded out = decode_reports(*d, {r});
  ASSERT_EQ(out.samples.size(), 1u);
  EXPECT_LT(angle_between(out.samples[0].orientation, q), 3e-4);
  // The same bits by hand: w = 1 (0x4000) at bit 3 is 0x4000 << 3 = 0x20000: bytes 00 00 02.
  HidVendorLayout one = l;
  const Bytes identity = encode_hid_vendor_report(one, Quat::Identity());
  EXPECT_EQ(identity, hex("00 00 02 00 00 00 00 00 00"));
}

TEST(HidVendorLayout, MalformedAndForeignReports) {
  HidVendorLayout l;
  l.report_id = 2;
  auto d = make_hid_vendor_layout_decoder(l);
  const Decoded out = decode_reports(*d, {
                                             hex("02 00 40 00 00 00 00 00 00"),  // identity
                                             hex("02 00 40 00 00 00 00 00"),     // a byte short
                                             hex("03 00 40 00 00 00 00 00 00"),  // another report
                                             hex("02 00 00 00 00 00 00 00 00"),  // zero
                                             hex("02 00 30 00 00 00 00 00 00"),  // norm 0.75
                                         });
  EXPECT_EQ(out.samples.size(), 1u);
  EXPECT_EQ(out.counters.frames, 3u);
  EXPECT_EQ(out.counters.malformed, 3u);
  EXPECT_EQ(out.counters.ignored_frames, 1u);
  // NaN in a float layout.
  HidVendorLayout f;
  f.type = HidVendorType::Float32;
  f.scale = 1.0;
  f.offset_bits = {0, 32, 64, 96};
  auto df = make_hid_vendor_layout_decoder(f);
  EXPECT_EQ(decode_reports(*df, {hex("0000C07F 00000000 00000000 00000000")}).counters.malformed, 1u);
}

TEST(HidVendorLayout, ValidationErrorsNameTheField) {
  const auto field_of = [](const HidVendorLayout& l) {
    try {
      validate_hid_vendor_layout(l);
    } catch (const HidVendorLayoutError& e) {
      EXPECT_NE(std::string(e.what()).find(e.field()), std::string::npos);
      return e.field();
    }
    return std::string("(valid)");
  };
  HidVendorLayout l;
  EXPECT_EQ(field_of(l), "(valid)");
  for (const int id : {0, -2, 256}) {
    HidVendorLayout b = l;
    b.report_id = id;
    EXPECT_EQ(field_of(b), "report_id") << id;
  }
  HidVendorLayout overlap = l;
  overlap.offset_bits = {0, 16, 40, 32};  // value 3 (bits 32..47) overlaps value 2 (40..55)
  EXPECT_EQ(field_of(overlap), "offset_bits[3]");
  HidVendorLayout past = l;
  past.report_length = 8;
  past.offset_bits = {0, 16, 32, 50};
  EXPECT_EQ(field_of(past), "offset_bits[3]");
  HidVendorLayout misaligned = l;
  misaligned.big_endian = true;
  misaligned.offset_bits = {0, 16, 33, 56};
  EXPECT_EQ(field_of(misaligned), "offset_bits[2]");
  HidVendorLayout huge = l;
  huge.offset_bits = {0, 16, 32, 16384 * 8};
  EXPECT_EQ(field_of(huge), "offset_bits[3]");
  HidVendorLayout long_report = l;
  long_report.report_length = 20000;
  EXPECT_EQ(field_of(long_report), "report_length");
  for (const double s : {0.0, std::nan(""), static_cast<double>(INFINITY)}) {
    HidVendorLayout b = l;
    b.scale = s;
    EXPECT_EQ(field_of(b), "scale") << s;
  }
  HidVendorLayout tol = l;
  tol.norm_tolerance = -1;
  EXPECT_EQ(field_of(tol), "norm_tolerance");
  EXPECT_THROW(make_hid_vendor_layout_decoder(overlap), HidVendorLayoutError);
  try {
    validate_hid_vendor_layout(past);
  } catch (const HidVendorLayoutError& e) {
    EXPECT_EQ(std::string(e.what()), "hid-vendor layout: offset_bits[3]: the value at bit 50 ends at bit 66, past report_length 8 bytes");
  }
}

TEST(HidVendorLayout, TenMegabytesOfRandomReportsNeverCrash) {
  std::mt19937_64 rng(6);
  HidVendorLayout a;  // int16 LE with ID
  a.report_id = 1;
  HidVendorLayout b;  // float64 BE, no ID
  b.type = HidVendorType::Float64;
  b.big_endian = true;
  b.scale = 1.0;
  b.offset_bits = {0, 64, 128, 192};
  HidVendorLayout c;  // int32 LE unaligned
  c.type = HidVendorType::Int32;
  c.scale = 1.0 / (1 << 30);
  c.offset_bits = {1, 33, 65, 97};
  std::size_t bytes = 0;
  for (const HidVendorLayout& l : {a, b, c}) {
    auto d = make_hid_vendor_layout_decoder(l);
    Collector sink;
    std::uniform_int_distribution<std::size_t> length(0, 40);
    for (std::size_t done = 0; done < 3'400'000;) {
      Bytes r = random_bytes(length(rng), rng);
      if (!r.empty() && l.report_id > 0 && rng() % 2) r[0] = static_cast<std::uint8_t>(l.report_id);
      done += r.size();
      d->decode(r, sink);
    }
    expect_unit_quaternions(sink.samples);
    bytes += d->counters().bytes;
  }
  EXPECT_GE(bytes, 10'000'000u);
}

}  // namespace
}  // namespace posefair::drivers::hid_vendor_layout_decoder_test
