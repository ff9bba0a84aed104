#pragma once
// USB HID report descriptors (Device Class Definition for HID 1.11, section 6.2.2): the parser
// that turns the bytes a device returns for its report descriptor (hidraw: HIDIOCGRDESC, uhid:
// UHID_CREATE2.rd_data) into the fields of each report, and the reader of one field's value
// out of a report. Pure: no I/O. drivers/src/hid_report_descriptor.cpp says which rules of the
// specification it follows and where it is stricter.
#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <variant>
#include <vector>

namespace posefair::drivers {

// A 32-bit usage: usage page in the high 16 bits, usage id in the low 16 (e.g. 0x00200483,
// Sensors page, Data Field: Quaternion).
using HidUsage = std::uint32_t;
constexpr HidUsage hid_usage(std::uint16_t page, std::uint16_t id) { return static_cast<HidUsage>(page) << 16 | id; }

enum class HidReportKind : std::uint8_t { Input, Output, Feature };

// Main item data bits (HID 1.11, 6.2.2.4/6.2.2.5), for HidField::flags.
inline constexpr std::uint32_t kHidConstant = 1u << 0;  // 0: Data
inline constexpr std::uint32_t kHidVariable = 1u << 1;  // 0: Array
inline constexpr std::uint32_t kHidRelative = 1u << 2;  // 0: Absolute
inline constexpr std::uint32_t kHidNullState = 1u << 6;

struct HidCollection {
  std::uint8_t type = 0;   // 0 Physical, 1 Application, 2 Logical, 3 Report, ...
  HidUsage usage = 0;      // the first usage declared before it (0 if none)
  int parent = -1;         // index into HidReportDescriptor::collections, -1 at top level
};

// One Input, Output or Feature main item: `count` values of `bit_size` bits each, packed from
// `bit_offset` on. Offsets count from the first bit after the report ID byte (bit 0 = the least
// significant bit of that byte; HID packs fields little-endian, LSB first).
struct HidField {
  std::uint32_t bit_offset = 0;
  std::uint32_t bit_size = 0;
  std::uint32_t count = 0;
  std::uint32_t flags = 0;            // main item data (kHidConstant, kHidVariable, ...)
  std::vector<HidUsage> usages;       // as declared (usage min/max expanded); may be empty
  std::int64_t logical_min = 0;
  std::int64_t logical_max = 0;
  std::int64_t physical_min = 0;
  std::int64_t physical_max = 0;
  std::uint32_t unit = 0;             // the Unit item's raw value (system and exponents by nibble)
  int unit_exponent = 0;              // value = raw · 10^unit_exponent (in the unit)
  int collection = -1;                // innermost enclosing collection, -1 if none

  // Values are two's complement iff the logical minimum is negative (HID 1.11, 6.2.2.7).
  bool is_signed() const { return logical_min < 0; }
  // The usage of value `index` of a Variable field: the index-th usage, the last one repeated
  // when there are fewer usages than values; 0 when there are none.
  HidUsage usage_of(std::uint32_t index) const;
};

struct HidReport {
  HidReportKind kind = HidReportKind::Input;
  std::uint8_t id = 0;           // 0 when the descriptor declares no report IDs
  std::uint32_t bit_size = 0;    // sum of the fields, without the report ID byte
  std::vector<HidField> fields;  // in descriptor order
  // Bytes of this report as hidraw returns it: the ID byte (when IDs are used) + the data.
  std::size_t byte_size(bool with_id) const { return (with_id ? 1 : 0) + (bit_size + 7) / 8; }
};

struct HidReportDescriptor {
  bool uses_report_ids = false;  // a Report ID item appeared: every report starts with its ID byte
  std::vector<HidCollection> collections;
  std::vector<HidReport> reports;  // one per (kind, id), in order of first appearance

  const HidReport* find(HidReportKind kind, std::uint8_t id) const;
  // True when collection `index` or one of its ancestors has usage `usage`.
  bool within(int collection_index, HidUsage usage) const;
};

enum class HidDescriptorErrorCode {
  TruncatedItem,          // the item's data runs past the end of the descriptor
  ReservedItemType,       // short item of type 3 (reserved)
  UnknownMainTag,
  UnknownGlobalTag,
  ReportIdZero,           // Report ID 0 is reserved
  ReportIdTooLarge,       // Report ID above 255
  ReportSizeTooLarge,     // Report Size above 256 bits
  ReportCountTooLarge,    // Report Count above 65535 values
  ReportTooLong,          // a report longer than 16384 bytes
  MissingReportId,        // data items before the first Report ID of a descriptor that uses IDs
  UsageRangeInvalid,      // usage maximum below minimum, or min/max on different pages, or too many usages
  UsageRangeIncomplete,   // a usage minimum without maximum (or the reverse) at a main item
  PopWithoutPush,
  PushStackOverflow,      // more than 16 nested Push items
  EndCollectionWithoutCollection,
  CollectionTooDeep,      // more than 64 nested collections
  UnclosedCollection,     // the descriptor ends inside a collection
  TooManyCollections,     // more than 4096 collections
  TooManyFields,          // more than 4096 main items
  Empty,                  // no bytes at all
};

struct HidDescriptorError {
  HidDescriptorErrorCode code = HidDescriptorErrorCode::Empty;
  std::size_t offset = 0;  // byte offset of the offending item's prefix
  // e.g. "HID report descriptor, byte 17: Report Size 300 above 256 bits".
  std::string message;
};

// Parses a whole report descriptor. Never throws for any input (except std::bad_alloc) and
// never reads outside `bytes`; a malformed descriptor gives a HidDescriptorError.
std::variant<HidReportDescriptor, HidDescriptorError> parse_hid_report_descriptor(std::span<const std::uint8_t> bytes);

// Value `index` of `field` from a report's data (after the ID byte): the field's bits, sign-
// extended when the field is signed. nullopt when the data is too short or the field is wider
// than 64 bits.
std::optional<std::int64_t> hid_field_value(std::span<const std::uint8_t> data, const HidField& field, std::uint32_t index);

// The raw bits of `bit_size` (1..64) bits at `bit_offset`, LSB first; nullopt when out of data.
std::optional<std::uint64_t> hid_read_bits(std::span<const std::uint8_t> data, std::uint32_t bit_offset, std::uint32_t bit_size);
// Writes the low `bit_size` bits of `value` at `bit_offset`, LSB first (the encoders' inverse);
// false when out of data.
bool hid_write_bits(std::span<std::uint8_t> data, std::uint32_t bit_offset, std::uint32_t bit_size, std::uint64_t value);

}  // namespace posefair::drivers
