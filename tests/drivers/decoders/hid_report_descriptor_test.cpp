// The HID report descriptor parser (drivers/src/hid_report_descriptor.cpp): byte-exact
// descriptors from documents, every error with its byte offset, the reading rules (usage
// pages, extended usages, signed ranges, unit exponent nibbles, push/pop, report IDs), round
// trips of built descriptors, the bit reader and writer, and 10 MB of random bytes.
//
// Byte-exact descriptors used here:
// - HID 1.11, Appendix B.1 (boot keyboard) and B.2 (boot mouse): the report descriptors the
//   specification gives for the boot protocol devices.
// - tests/support/hid_sensor_descriptor.hpp: the Device Orientation collection of an ST IMU
//   firmware's descriptor (its comment names the source).
#include <gtest/gtest.h>

#include <cstdint>
#include <cstdio>
#include <map>
#include <random>
#include <string>
#include <variant>
#include <vector>

#include "../../support/decoder_testing.hpp"
#include "../../support/hid_descriptor_builder.hpp"
#include "../../support/hid_sensor_descriptor.hpp"
#include "posefair/drivers/hid_report_descriptor.hpp"

namespace posefair::drivers::hid_report_descriptor_test {
namespace {

using namespace ::posefair::testing;
using Bytes = std::vector<std::uint8_t>;
using Code = HidDescriptorErrorCode;

HidReportDescriptor parse_ok(const Bytes& bytes) {
  auto r = parse_hid_report_descriptor(bytes);
  if (const auto* e = std::get_if<HidDescriptorError>(&r)) {
    ADD_FAILURE() << e->message;
    return {};
  }
  return std::get<HidReportDescriptor>(std::move(r));
}

HidDescriptorError parse_error(const Bytes& bytes) {
  auto r = parse_hid_report_descriptor(bytes);
  if (const auto* e = std::get_if<HidDescriptorError>(&r)) return *e;
  ADD_FAILURE() << "parsed, an error was expected";
  return {};
}

// HID 1.11 Appendix B.2, the boot mouse.
const Bytes kBootMouse = hex(
    "05 01 09 02 A1 01 09 01 A1 00 05 09 19 01 29 03 15 00 25 01 95 03 75 01 81 02 95 01 75 05 81 01"
    " 05 01 09 30 09 31 15 81 25 7F 75 08 95 02 81 06 C0 C0");
// HID 1.11 Appendix B.1, the boot keyboard.
const Bytes kBootKeyboard = hex(
    "05 01 09 06 A1 01 05 07 19 E0 29 E7 15 00 25 01 75 01 95 08 81 02 95 01 75 08 81 01 95 05 75 01"
    " 05 08 19 01 29 05 91 02 95 01 75 03 91 01 95 06 75 08 15 00 25 65 05 07 19 00 29 65 81 00 C0");

TEST(HidReportDescriptor, BootMouseFromTheSpecification) {
  ASSERT_EQ(kBootMouse.size(), 50u);
  const HidReportDescriptor d = parse_ok(kBootMouse);
  EXPECT_FALSE(d.uses_report_ids);
  ASSERT_EQ(d.collections.size(), 2u);
  EXPECT_EQ(d.collections[0].type, 1);  // Application
  EXPECT_EQ(d.collections[0].usage, 0x00010002u);
  EXPECT_EQ(d.collections[1].type, 0);  // Physical (Pointer)
  EXPECT_EQ(d.collections[1].usage, 0x00010001u);
  EXPECT_EQ(d.collections[1].parent, 0);
  ASSERT_EQ(d.reports.size(), 1u);
  const HidReport& r = d.reports[0];
  EXPECT_EQ(r.kind, HidReportKind::Input);
  EXPECT_EQ(r.id, 0);
  EXPECT_EQ(r.bit_size, 24u);
  EXPECT_EQ(r.byte_size(false), 3u);
  ASSERT_EQ(r.fields.size(), 3u);
  const HidField& buttons = r.fields[0];
  EXPECT_EQ(buttons.bit_offset, 0u);
  EXPECT_EQ(buttons.bit_size, 1u);
  EXPECT_EQ(buttons.count, 3u);
  EXPECT_EQ(buttons.flags, kHidVariable);
  EXPECT_EQ(buttons.usages, (std::vector<HidUsage>{0x00090001, 0x00090002, 0x00090003}));
  EXPECT_EQ(buttons.logical_max, 1);
  EXPECT_EQ(r.fields[1].bit_offset, 3u);  // 5 bits of padding
  EXPECT_EQ(r.fields[1].bit_size, 5u);
  EXPECT_EQ(r.fields[1].flags, kHidConstant);
  const HidField& xy = r.fields[2];
  EXPECT_EQ(xy.bit_offset, 8u);
  EXPECT_EQ(xy.count, 2u);
  EXPECT_EQ(xy.flags, kHidVariable | kHidRelative);
  EXPECT_EQ(xy.logical_min, -127);
  EXPECT_EQ(xy.logical_max, 127);
  EXPECT_EQ(xy.usage_of(0), 0x00010030u);
  EXPECT_EQ(xy.usage_of(1), 0x00010031u);
  EXPECT_EQ(xy.collection, 1);
  EXPECT_TRUE(d.within(xy.collection, 0x00010002));
  // A report: button 1 and 3, x = -3, y = +5.
  const Bytes report = hex("05 FD 05");
  EXPECT_EQ(*hid_field_value(report, buttons, 0), 1);
  EXPECT_EQ(*hid_field_value(report, buttons, 1), 0);
  EXPECT_EQ(*hid_field_value(report, buttons, 2), 1);
  EXPECT_EQ(*hid_field_value(report, xy, 0), -3);
  EXPECT_EQ(*hid_field_value(report, xy, 1), 5);
  EXPECT_FALSE(hid_field_value(report, xy, 2));                   // past the field
  EXPECT_FALSE(hid_field_value(hex("05 FD"), xy, 1));             // past the data
}

TEST(HidReportDescriptor, BootKeyboardFromTheSpecification) {
  ASSERT_EQ(kBootKeyboard.size(), 63u);
  const HidReportDescriptor d = parse_ok(kBootKeyboard);
  const HidReport* in = d.find(HidReportKind::Input, 0);
  const HidReport* out = d.find(HidReportKind::Output, 0);
  ASSERT_TRUE(in && out);
  EXPECT_EQ(in->bit_size, 64u);
  EXPECT_EQ(out->bit_size, 8u);
  ASSERT_EQ(in->fields.size(), 3u);
  EXPECT_EQ(in->fields[0].usages.size(), 8u);
  EXPECT_EQ(in->fields[0].usages.front(), 0x000700E0u);
  EXPECT_EQ(in->fields[0].usages.back(), 0x000700E7u);
  const HidField& keys = in->fields[2];
  EXPECT_EQ(keys.bit_offset, 16u);
  EXPECT_EQ(keys.bit_size, 8u);
  EXPECT_EQ(keys.count, 6u);
  EXPECT_EQ(keys.flags, 0u);  // Data, Array
  EXPECT_EQ(keys.logical_max, 101);
  EXPECT_EQ(keys.usages.size(), 102u);
  ASSERT_EQ(out->fields.size(), 2u);
  EXPECT_EQ(out->fields[0].usages, (std::vector<HidUsage>{0x80001, 0x80002, 0x80003, 0x80004, 0x80005}));
  EXPECT_EQ(out->fields[1].bit_offset, 5u);
}

TEST(HidReportDescriptor, GenuineSensorOrientationDescriptor) {
  const Bytes bytes(kStImuOrientationDescriptor.begin(), kStImuOrientationDescriptor.end());
  const HidReportDescriptor d = parse_ok(bytes);
  EXPECT_TRUE(d.uses_report_ids);
  ASSERT_FALSE(d.collections.empty());
  EXPECT_EQ(d.collections[0].usage, 0x0020008Au);
  EXPECT_EQ(d.collections[0].type, 0);
  const HidReport* in = d.find(HidReportKind::Input, kStImuOrientationReportId);
  ASSERT_NE(in, nullptr);
  EXPECT_EQ(in->byte_size(true), kStImuOrientationReportBytes);
  ASSERT_EQ(in->fields.size(), 4u);
  const HidField& q = in->fields[2];
  EXPECT_EQ(q.usages, (std::vector<HidUsage>{0x00200483}));
  EXPECT_EQ(q.bit_offset, 16u);
  EXPECT_EQ(q.bit_size, 32u);
  EXPECT_EQ(q.count, 4u);
  EXPECT_EQ(q.logical_min, -2147483647);
  EXPECT_EQ(q.logical_max, 2147483647);
  EXPECT_EQ(q.unit_exponent, -8);
  EXPECT_TRUE(d.within(q.collection, 0x0020008A));
  EXPECT_EQ(in->fields[3].usages.size(), 3u);   // magnetometer accuracy selectors
  EXPECT_EQ(in->fields[3].bit_offset, 144u);
  const HidReport* feature = d.find(HidReportKind::Feature, 7);
  ASSERT_NE(feature, nullptr);
  EXPECT_EQ(feature->bit_size, 112u);
  ASSERT_EQ(feature->fields.size(), 8u);
  EXPECT_EQ(feature->fields[4].flags, kHidConstant | kHidVariable);  // report interval
  EXPECT_EQ(feature->fields[4].logical_max, 16777215);
  const HidField& sensitivity = feature->fields[5];  // 0x1483: one-byte-signed 0xFF with minimum 0 = 255
  EXPECT_EQ(sensitivity.usage_of(0), 0x00201483u);
  EXPECT_EQ(sensitivity.logical_max, 255);
  EXPECT_EQ(sensitivity.unit_exponent, -2);
  EXPECT_EQ(feature->fields[6].logical_min, -32767);
  EXPECT_EQ(feature->fields[6].unit_exponent, 1);
  EXPECT_EQ(d.find(HidReportKind::Input, 7), nullptr);
}

// ---- the reading rules ----

TEST(HidReportDescriptor, UsagePageAtTheMainItemAndExtendedUsages) {
  HidDescriptorBuilder b;
  // A short usage declared before its page; an extended usage that carries another page.
  b.usage(0x30).usage_extended(0x00200483).usage_page(0x01).report_size(8).report_count(2).input(0x02);
  const HidReportDescriptor d = parse_ok(b.out);
  EXPECT_EQ(d.reports[0].fields[0].usages, (std::vector<HidUsage>{0x00010030, 0x00200483}));
}

TEST(HidReportDescriptor, LogicalRangeSignRule) {
  // 25 FF with minimum 0 is 255; with minimum -1 it is -1; 26 FF 00 is 255 either way.
  EXPECT_EQ(parse_ok(hex("15 00 25 FF 75 08 95 01 81 02")).reports[0].fields[0].logical_max, 255);
  EXPECT_EQ(parse_ok(hex("15 FF 25 FF 75 08 95 01 81 02")).reports[0].fields[0].logical_max, -1);
  EXPECT_EQ(parse_ok(hex("15 81 26 FF 00 75 08 95 01 81 02")).reports[0].fields[0].logical_max, 255);
  // The maximum before the minimum: decided at the main item.
  EXPECT_EQ(parse_ok(hex("25 FF 15 FF 75 08 95 01 81 02")).reports[0].fields[0].logical_max, -1);
  // Unsigned field values are not sign-extended, signed ones are.
  const HidField u = parse_ok(hex("15 00 26 FF 00 75 08 95 01 81 02")).reports[0].fields[0];
  const HidField s = parse_ok(hex("15 81 25 7F 75 08 95 01 81 02")).reports[0].fields[0];
  EXPECT_EQ(*hid_field_value(hex("FE"), u, 0), 254);
  EXPECT_EQ(*hid_field_value(hex("FE"), s, 0), -2);
}

TEST(HidReportDescriptor, UnitExponentNibbleAndFullForms) {
  const auto exponent = [](const std::string& item) {
    return parse_ok(hex(item + " 75 08 95 01 81 02")).reports[0].fields[0].unit_exponent;
  };
  EXPECT_EQ(exponent("55 0E"), -2);
  EXPECT_EQ(exponent("55 08"), -8);
  EXPECT_EQ(exponent("55 0F"), -1);
  EXPECT_EQ(exponent("55 07"), 7);
  EXPECT_EQ(exponent("55 00"), 0);
  EXPECT_EQ(exponent("55 FE"), -2);     // one-byte signed (Linux reads it so too)
  EXPECT_EQ(exponent("56 FD FF"), -3);  // two-byte signed
}

TEST(HidReportDescriptor, PushPopRestoresGlobals) {
  HidDescriptorBuilder b;
  b.report_size(8).report_count(2).logical_min(-5).logical_max(5).push();
  b.report_size(16).report_count(1).logical_min(0).logical_max(1000).input(0x02);
  b.pop().input(0x02);
  const HidReportDescriptor d = parse_ok(b.out);
  const auto& f = d.reports[0].fields;
  ASSERT_EQ(f.size(), 2u);
  EXPECT_EQ(f[0].bit_size, 16u);
  EXPECT_EQ(f[0].logical_max, 1000);
  EXPECT_EQ(f[1].bit_offset, 16u);
  EXPECT_EQ(f[1].bit_size, 8u);
  EXPECT_EQ(f[1].count, 2u);
  EXPECT_EQ(f[1].logical_min, -5);
  EXPECT_EQ(f[1].logical_max, 5);
}

TEST(HidReportDescriptor, ReportIdsSeparateReports) {
  HidDescriptorBuilder b;
  b.report_size(8).report_count(3).report_id(1).input(0x02).report_id(2).report_count(5).input(0x02).report_id(1).input(0x02);
  const HidReportDescriptor d = parse_ok(b.out);
  EXPECT_TRUE(d.uses_report_ids);
  ASSERT_EQ(d.reports.size(), 2u);
  EXPECT_EQ(d.find(HidReportKind::Input, 1)->bit_size, 8u * 8);  // 3 + 5 values
  EXPECT_EQ(d.find(HidReportKind::Input, 1)->fields[1].bit_offset, 24u);
  EXPECT_EQ(d.find(HidReportKind::Input, 2)->bit_size, 40u);
  EXPECT_EQ(d.find(HidReportKind::Input, 2)->byte_size(true), 6u);
}

TEST(HidReportDescriptor, LongItemsAreSkipped) {
  const HidReportDescriptor d = parse_ok(cat({hex("FE 02 10 AA BB"), kBootMouse}));
  EXPECT_EQ(d.reports[0].bit_size, 24u);
}

TEST(HidReportDescriptor, ZeroSizedMainItemsAddNothing) {
  const HidReportDescriptor d = parse_ok(hex("75 00 95 04 81 02 75 08 95 01 81 02"));
  ASSERT_EQ(d.reports[0].fields.size(), 1u);
  EXPECT_EQ(d.reports[0].fields[0].bit_offset, 0u);
}

// ---- errors, each with its byte offset ----

struct ErrorCase {
  const char* bytes;
  Code code;
  std::size_t offset;
};

TEST(HidReportDescriptor, MalformedDescriptorsGiveTypedErrorsWithOffsets) {
  const ErrorCase cases[] = {
      {"", Code::Empty, 0},
      {"75 08 26 FF", Code::TruncatedItem, 2},
      {"75 08 27 FF FF", Code::TruncatedItem, 2},
      {"FE 05 10 AA", Code::TruncatedItem, 0},
      {"75 08 0C", Code::ReservedItemType, 2},
      {"75 08 00", Code::UnknownMainTag, 2},
      {"75 08 C4", Code::UnknownGlobalTag, 2},
      {"85 00", Code::ReportIdZero, 0},
      {"86 00 01", Code::ReportIdTooLarge, 0},
      {"76 01 01", Code::ReportSizeTooLarge, 0},
      {"97 00 00 01 00", Code::ReportCountTooLarge, 0},
      {"75 FF 96 FF FF 81 02", Code::ReportTooLong, 5},
      {"75 08 95 01 81 02 85 01", Code::MissingReportId, 6},
      {"A4 85 01 B4 75 08 95 01 81 02", Code::MissingReportId, 8},  // Pop brings back "no ID"
      {"B4", Code::PopWithoutPush, 0},
      {"C0", Code::EndCollectionWithoutCollection, 0},
      {"A1 01 A1 00 C0", Code::UnclosedCollection, 5},
      {"19 05 29 03 81 02", Code::UsageRangeInvalid, 2},
      {"19 01 75 08 95 01 81 02", Code::UsageRangeIncomplete, 6},
      {"1B 01 00 20 00 2B 05 00 01 00 81 02", Code::UsageRangeInvalid, 5},  // different pages
  };
  for (const ErrorCase& c : cases) {
    const Bytes bytes = hex(c.bytes);
    const HidDescriptorError e = parse_error(bytes);
    EXPECT_EQ(e.code, c.code) << c.bytes << ": " << e.message;
    EXPECT_EQ(e.offset, c.offset) << c.bytes << ": " << e.message;
    EXPECT_NE(e.message.find("byte " + std::to_string(c.offset)), std::string::npos) << e.message;
  }
}

TEST(HidReportDescriptor, NestingLimits) {
  Bytes deep;
  for (int i = 0; i < 65; ++i) deep.insert(deep.end(), {0xA1, 0x00});
  EXPECT_EQ(parse_error(deep).code, Code::CollectionTooDeep);
  EXPECT_EQ(parse_error(deep).offset, 128u);
  const Bytes pushes(17, 0xA4);
  EXPECT_EQ(parse_error(pushes).code, Code::PushStackOverflow);
  EXPECT_EQ(parse_error(pushes).offset, 16u);
  // 64 levels are fine.
  Bytes ok(deep.begin(), deep.begin() + 128);
  ok.insert(ok.end(), 64, 0xC0);
  EXPECT_EQ(parse_ok(ok).collections.size(), 64u);
}

// ---- round trips of built descriptors ----

TEST(HidReportDescriptor, RandomBuiltDescriptorsParseToWhatWasBuilt) {
  std::mt19937_64 rng(11);
  for (int trial = 0; trial < 300; ++trial) {
    struct Built {
      std::uint32_t size, count;
      std::int64_t min, max;
      int exponent;
      std::uint16_t usage;
      std::uint8_t id;
    };
    std::vector<Built> built;
    HidDescriptorBuilder b;
    const bool ids = rng() % 2;
    b.usage_page(0x20).usage(0x8A).collection(1);
    const int n = 1 + static_cast<int>(rng() % 8);
    for (int i = 0; i < n; ++i) {
      Built f{};
      f.size = 1 + static_cast<std::uint32_t>(rng() % 64);
      f.count = 1 + static_cast<std::uint32_t>(rng() % 5);
      f.min = -static_cast<std::int64_t>(rng() % 100000);
      f.max = static_cast<std::int64_t>(rng() % 100000);
      f.exponent = static_cast<int>(rng() % 16) - 8;
      f.usage = static_cast<std::uint16_t>(rng());
      f.id = ids ? static_cast<std::uint8_t>(1 + rng() % 3) : 0;
      if (ids) b.report_id(f.id);
      b.usage(f.usage).logical_min(f.min).logical_max(f.max).report_size(f.size).report_count(f.count).unit_exponent(f.exponent);
      b.input(0x02);
      built.push_back(f);
    }
    b.end_collection();
    const HidReportDescriptor d = parse_ok(b.out);
    std::map<std::uint8_t, std::uint32_t> offsets;
    std::map<std::uint8_t, std::size_t> index;
    for (const Built& f : built) {
      const HidReport* r = d.find(HidReportKind::Input, f.id);
      ASSERT_NE(r, nullptr);
      const HidField& g = r->fields.at(index[f.id]++);
      EXPECT_EQ(g.bit_offset, offsets[f.id]);
      EXPECT_EQ(g.bit_size, f.size);
      EXPECT_EQ(g.count, f.count);
      EXPECT_EQ(g.logical_min, f.min);
      EXPECT_EQ(g.logical_max, f.max);
      EXPECT_EQ(g.unit_exponent, f.exponent);
      EXPECT_EQ(g.usage_of(0), hid_usage(0x20, f.usage));
      EXPECT_TRUE(d.within(g.collection, 0x0020008A));
      offsets[f.id] += f.size * f.count;
    }
  }
}

TEST(HidReportDescriptor, BitsWrittenAreTheBitsRead) {
  std::mt19937_64 rng(5);
  for (int trial = 0; trial < 20000; ++trial) {
    Bytes data(12);
    for (auto& x : data) x = static_cast<std::uint8_t>(rng());
    const Bytes before = data;
    const auto size = static_cast<std::uint32_t>(1 + rng() % 64);
    const auto offset = static_cast<std::uint32_t>(rng() % (96 - size + 1));
    const std::uint64_t value = rng();
    ASSERT_TRUE(hid_write_bits(data, offset, size, value));
    const std::uint64_t mask = size == 64 ? ~0ull : (1ull << size) - 1;
    ASSERT_EQ(*hid_read_bits(data, offset, size), value & mask) << offset << " " << size;
    // Every other bit unchanged, and the read agrees with a bit-by-bit reference.
    for (std::uint32_t bit = 0; bit < 96; ++bit) {
      const bool inside = bit >= offset && bit < offset + size;
      const int now = (data[bit / 8] >> (bit % 8)) & 1, was = (before[bit / 8] >> (bit % 8)) & 1;
      if (inside)
        ASSERT_EQ(now, static_cast<int>((value >> (bit - offset)) & 1));
      else
        ASSERT_EQ(now, was);
    }
    ASSERT_FALSE(hid_read_bits(data, 96 - size + 1, size));
  }
  EXPECT_FALSE(hid_read_bits(Bytes(16), 0, 65));
  EXPECT_FALSE(hid_read_bits(Bytes(16), 0, 0));
}

// ---- random and mutated input ----

TEST(HidReportDescriptor, TenMegabytesOfRandomBytesNeverCrash) {
  std::mt19937_64 rng(3);
  std::uniform_int_distribution<std::size_t> length(1, 4096);
  std::size_t parsed = 0, errors = 0;
  for (std::size_t done = 0; done < 10'000'000;) {
    const Bytes bytes = random_bytes(length(rng), rng);
    done += bytes.size();
    auto r = parse_hid_report_descriptor(bytes);
    if (const auto* e = std::get_if<HidDescriptorError>(&r)) {
      ++errors;
      ASSERT_LE(e->offset, bytes.size());
    } else {
      ++parsed;
    }
  }
  EXPECT_GT(errors, 0u);
  std::printf("random descriptors: %zu parsed, %zu refused\n", parsed, errors);
}

TEST(HidReportDescriptor, MutatedGenuineDescriptorsParseOrFailAtAnItem) {
  const Bytes genuine(kStImuOrientationDescriptor.begin(), kStImuOrientationDescriptor.end());
  std::mt19937_64 rng(9);
  for (int trial = 0; trial < 20000; ++trial) {
    Bytes m = genuine;
    const int edits = 1 + static_cast<int>(rng() % 4);
    for (int k = 0; k < edits; ++k) m[rng() % m.size()] = static_cast<std::uint8_t>(rng());
    if (rng() % 4 == 0) m.resize(rng() % m.size());
    auto r = parse_hid_report_descriptor(m);
    if (const auto* d = std::get_if<HidReportDescriptor>(&r)) {
      for (const HidReport& rep : d->reports) {
        std::uint32_t end = 0;
        for (const HidField& f : rep.fields) {
          ASSERT_EQ(f.bit_offset, end);  // fields tile the report
          end += f.bit_size * f.count;
        }
        ASSERT_EQ(end, rep.bit_size);
      }
    } else {
      ASSERT_LE(std::get<HidDescriptorError>(r).offset, m.size());
    }
  }
}

}  // namespace
}  // namespace posefair::drivers::hid_report_descriptor_test
