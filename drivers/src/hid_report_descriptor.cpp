// USB HID report descriptor parser (hid_report_descriptor.hpp).
//
// Reference documents
// - USB Implementers' Forum, "Device Class Definition for Human Interface Devices (HID)",
//   version 1.11 (27 June 2001): 5.6 (Reports: fields packed LSB first, the Report ID byte),
//   6.2.2 (Report Descriptor): 6.2.2.2 short items (prefix bSize/bType/bTag, bSize 3 = four
//   data bytes), 6.2.2.3 long items (prefix 0xFE, no long item tags are defined), 6.2.2.4/5 main
//   items (Input 0x80, Output 0x90, Feature 0xB0, Collection 0xA0, End Collection 0xC0, the
//   data bits), 6.2.2.6 collections, 6.2.2.7 global items (Usage Page .. Pop, and the remarks:
//   a usage page is concatenated with the usages at the main item; Logical Minimum/Maximum are
//   signed; Unit Exponent), 6.2.2.8 local items (Usage, Usage Minimum/Maximum; a four-byte usage
//   carries its own page, an "extended usage"), 8.4 (Report ID 0 reserved).
// - Linux drivers/hid/hid-core.c (hid_parser_global, hid_parser_local, hid_parser_main) for the
//   interpretations that real devices rely on and that the specification leaves implicit; noted
//   below where they are taken over.
//
// Choices
// - Usage page: short (1- or 2-byte) usages are combined with the usage page that is current at
//   the main item, as 6.2.2.7 says (so a Usage Page item after the usages still applies to them;
//   Linux does the same since 5.1, hid_concatenate_last_usage_page). Four-byte usages keep their
//   own page.
// - Logical/Physical Maximum: the data is read signed when the minimum is negative and unsigned
//   otherwise (0x25 0xFF with minimum 0 is 255, as Linux and every host treats it: devices
//   write one-byte 255 maxima that way). Decided at the main item, so the order of the two
//   items does not matter.
// - Unit Exponent: a value 0..15 is the 4-bit two's complement nibble of HID 1.11's table
//   (0x0E = -2, 0x08 = -8); anything else is the item's signed value (0x55 0xFE = -2), as Linux
//   reads it. Sensor descriptors use the nibble form.
// - Stricter than the specification where a wrong layout would silently misplace every value:
//   data items before the first Report ID of a descriptor that uses IDs, Report ID 0, unknown
//   main or global tags, an unmatched End Collection, Pop without Push, a descriptor ending in
//   a collection, and a usage minimum without its maximum are errors. Unknown local tags and
//   Delimiter sets are ignored (Linux ignores them too). Long items are skipped.
// - Limits, so that no input can make the parser allocate without bound: Report Size <= 256
//   (Linux's limit), Report Count <= 65535, a report <= 16384 bytes (Linux's HID_MAX_BUFFER_SIZE),
//   16 nested Push, 64 nested collections, 4096 collections, 4096 main items, 65536 usages.
#include "posefair/drivers/hid_report_descriptor.hpp"

#include <algorithm>
#include <array>
#include <cstdio>
#include <utility>

namespace posefair::drivers {
namespace {

constexpr std::uint32_t kMaxReportSize = 256;
constexpr std::uint32_t kMaxReportCount = 65535;
constexpr std::uint64_t kMaxReportBits = 16384ull * 8;
constexpr std::size_t kMaxPush = 16;
constexpr std::size_t kMaxDepth = 64;
constexpr std::size_t kMaxCollections = 4096;
constexpr std::size_t kMaxFields = 4096;
constexpr std::size_t kMaxUsages = 65536;

// An item's data as read, before the main item resolves it.
struct RawValue {
  std::uint32_t data = 0;
  unsigned size = 0;  // bytes: 0, 1, 2, 4
};

std::int64_t sign_extend(std::uint32_t data, unsigned size) {
  switch (size) {
    case 1: return static_cast<std::int8_t>(data);
    case 2: return static_cast<std::int16_t>(data);
    case 4: return static_cast<std::int32_t>(data);
    default: return 0;
  }
}

std::int64_t resolve_max(const RawValue& max, std::int64_t min) {
  return min < 0 ? sign_extend(max.data, max.size) : static_cast<std::int64_t>(max.data);
}

struct Globals {
  std::uint16_t usage_page = 0;
  std::int64_t logical_min = 0;
  RawValue logical_max;
  std::int64_t physical_min = 0;
  RawValue physical_max;
  int unit_exponent = 0;
  std::uint32_t unit = 0;
  std::uint32_t report_size = 0;
  std::uint8_t report_id = 0;
  std::uint32_t report_count = 0;
};

struct LocalUsage {
  std::uint32_t value = 0;
  bool extended = false;  // four-byte usage: carries its page
};

const char* code_text(HidDescriptorErrorCode c) {
  switch (c) {
    case HidDescriptorErrorCode::TruncatedItem: return "item data runs past the end of the descriptor";
    case HidDescriptorErrorCode::ReservedItemType: return "reserved item type 3";
    case HidDescriptorErrorCode::UnknownMainTag: return "unknown main item tag";
    case HidDescriptorErrorCode::UnknownGlobalTag: return "unknown global item tag";
    case HidDescriptorErrorCode::ReportIdZero: return "Report ID 0 is reserved";
    case HidDescriptorErrorCode::ReportIdTooLarge: return "Report ID above 255";
    case HidDescriptorErrorCode::ReportSizeTooLarge: return "Report Size above 256 bits";
    case HidDescriptorErrorCode::ReportCountTooLarge: return "Report Count above 65535";
    case HidDescriptorErrorCode::ReportTooLong: return "report longer than 16384 bytes";
    case HidDescriptorErrorCode::MissingReportId: return "data items outside any Report ID in a descriptor that uses Report IDs";
    case HidDescriptorErrorCode::UsageRangeInvalid: return "usage maximum below minimum, on another page, or too many usages";
    case HidDescriptorErrorCode::UsageRangeIncomplete: return "usage minimum without maximum (or the reverse)";
    case HidDescriptorErrorCode::PopWithoutPush: return "Pop without Push";
    case HidDescriptorErrorCode::PushStackOverflow: return "more than 16 nested Push items";
    case HidDescriptorErrorCode::EndCollectionWithoutCollection: return "End Collection without Collection";
    case HidDescriptorErrorCode::CollectionTooDeep: return "more than 64 nested collections";
    case HidDescriptorErrorCode::UnclosedCollection: return "descriptor ends inside a collection";
    case HidDescriptorErrorCode::TooManyCollections: return "more than 4096 collections";
    case HidDescriptorErrorCode::TooManyFields: return "more than 4096 main items";
    case HidDescriptorErrorCode::Empty: return "empty descriptor";
  }
  return "?";
}

HidDescriptorError make_error(HidDescriptorErrorCode code, std::size_t offset) {
  char buf[200];
  std::snprintf(buf, sizeof buf, "HID report descriptor, byte %zu: %s", offset, code_text(code));
  return {code, offset, buf};
}

class Parser {
 public:
  explicit Parser(std::span<const std::uint8_t> bytes) : bytes_(bytes) {}

  std::variant<HidReportDescriptor, HidDescriptorError> run() {
    if (bytes_.empty()) return make_error(HidDescriptorErrorCode::Empty, 0);
    std::size_t i = 0;
    while (i < bytes_.size()) {
      const std::uint8_t prefix = bytes_[i];
      if (prefix == 0xFE) {  // long item: bDataSize, bLongItemTag, data
        if (bytes_.size() - i < 3 || bytes_.size() - i - 3 < bytes_[i + 1])
          return make_error(HidDescriptorErrorCode::TruncatedItem, i);
        i += 3 + bytes_[i + 1];
        continue;
      }
      static constexpr std::array<unsigned, 4> kSizes = {0, 1, 2, 4};
      const unsigned size = kSizes[prefix & 3];
      if (bytes_.size() - i - 1 < size) return make_error(HidDescriptorErrorCode::TruncatedItem, i);
      std::uint32_t data = 0;
      for (unsigned k = 0; k < size; ++k) data |= static_cast<std::uint32_t>(bytes_[i + 1 + k]) << (8 * k);
      const unsigned type = (prefix >> 2) & 3;
      const unsigned tag = prefix >> 4;
      std::optional<HidDescriptorErrorCode> err;
      switch (type) {
        case 0: err = main_item(tag, data); break;
        case 1: err = global_item(tag, {data, size}); break;
        case 2: err = local_item(tag, {data, size}); break;
        default: err = HidDescriptorErrorCode::ReservedItemType; break;
      }
      if (err) return make_error(*err, i);
      i += 1 + size;
    }
    if (!open_.empty()) return make_error(HidDescriptorErrorCode::UnclosedCollection, bytes_.size());
    return std::move(out_);
  }

 private:
  HidUsage resolve(const LocalUsage& u) const {
    return u.extended ? u.value : hid_usage(g_.usage_page, static_cast<std::uint16_t>(u.value));
  }

  void clear_locals() {
    usages_.clear();
    usage_min_.reset();
    usage_max_.reset();
  }

  // Expands a complete usage min/max pair into usages_.
  std::optional<HidDescriptorErrorCode> expand_range() {
    if (!usage_min_ || !usage_max_) return std::nullopt;
    const LocalUsage lo = *usage_min_, hi = *usage_max_;
    usage_min_.reset();
    usage_max_.reset();
    // A pair of short items is resolved at the main item; check it with the current page now
    // and again there (resolve()).
    const HidUsage a = resolve(lo), b = resolve(hi);
    if ((a >> 16) != (b >> 16) || b < a) return HidDescriptorErrorCode::UsageRangeInvalid;
    const std::size_t n = static_cast<std::size_t>(b - a) + 1;
    if (n > kMaxUsages - std::min(kMaxUsages, usage_total_ + usages_.size())) return HidDescriptorErrorCode::UsageRangeInvalid;
    for (std::size_t k = 0; k < n; ++k) usages_.push_back({lo.extended ? lo.value + static_cast<std::uint32_t>(k) : ((lo.value & 0xFFFF) + static_cast<std::uint32_t>(k)), lo.extended});
    return std::nullopt;
  }

  std::optional<HidDescriptorErrorCode> main_item(unsigned tag, std::uint32_t data) {
    if (usage_min_.has_value() != usage_max_.has_value()) return HidDescriptorErrorCode::UsageRangeIncomplete;
    std::optional<HidDescriptorErrorCode> err;
    switch (tag) {
      case 0x8: err = data_item(HidReportKind::Input, data); break;
      case 0x9: err = data_item(HidReportKind::Output, data); break;
      case 0xB: err = data_item(HidReportKind::Feature, data); break;
      case 0xA: {
        if (open_.size() >= kMaxDepth) return HidDescriptorErrorCode::CollectionTooDeep;
        if (out_.collections.size() >= kMaxCollections) return HidDescriptorErrorCode::TooManyCollections;
        HidCollection c;
        c.type = static_cast<std::uint8_t>(data);
        c.usage = usages_.empty() ? 0 : resolve(usages_.front());
        c.parent = open_.empty() ? -1 : open_.back();
        out_.collections.push_back(c);
        open_.push_back(static_cast<int>(out_.collections.size() - 1));
        break;
      }
      case 0xC:
        if (open_.empty()) return HidDescriptorErrorCode::EndCollectionWithoutCollection;
        open_.pop_back();
        break;
      default: return HidDescriptorErrorCode::UnknownMainTag;
    }
    clear_locals();
    return err;
  }

  std::optional<HidDescriptorErrorCode> data_item(HidReportKind kind, std::uint32_t data) {
    if (out_.uses_report_ids && g_.report_id == 0) return HidDescriptorErrorCode::MissingReportId;
    if (!out_.uses_report_ids) data_without_id_ = true;
    if (fields_ >= kMaxFields) return HidDescriptorErrorCode::TooManyFields;
    ++fields_;
    auto it = std::find_if(out_.reports.begin(), out_.reports.end(),
                           [&](const HidReport& r) { return r.kind == kind && r.id == g_.report_id; });
    if (it == out_.reports.end()) {
      HidReport r;
      r.kind = kind;
      r.id = g_.report_id;
      out_.reports.push_back(std::move(r));
      it = out_.reports.end() - 1;
    }
    const std::uint64_t bits = static_cast<std::uint64_t>(g_.report_size) * g_.report_count;
    if (it->bit_size + bits > kMaxReportBits) return HidDescriptorErrorCode::ReportTooLong;
    if (bits == 0) return std::nullopt;  // nothing in the report (Linux skips these too)
    HidField f;
    f.bit_offset = it->bit_size;
    f.bit_size = g_.report_size;
    f.count = g_.report_count;
    f.flags = data;
    f.usages.reserve(usages_.size());
    for (const LocalUsage& u : usages_) f.usages.push_back(resolve(u));
    usage_total_ += f.usages.size();
    f.logical_min = g_.logical_min;
    f.logical_max = resolve_max(g_.logical_max, g_.logical_min);
    f.physical_min = g_.physical_min;
    f.physical_max = resolve_max(g_.physical_max, g_.physical_min);
    f.unit = g_.unit;
    f.unit_exponent = g_.unit_exponent;
    f.collection = open_.empty() ? -1 : open_.back();
    it->bit_size += static_cast<std::uint32_t>(bits);
    it->fields.push_back(std::move(f));
    return std::nullopt;
  }

  std::optional<HidDescriptorErrorCode> global_item(unsigned tag, RawValue v) {
    switch (tag) {
      case 0x0: g_.usage_page = static_cast<std::uint16_t>(v.data); break;
      case 0x1: g_.logical_min = sign_extend(v.data, v.size); break;
      case 0x2: g_.logical_max = v; break;
      case 0x3: g_.physical_min = sign_extend(v.data, v.size); break;
      case 0x4: g_.physical_max = v; break;
      case 0x5:
        g_.unit_exponent = v.data <= 15 ? static_cast<int>(v.data >= 8 ? static_cast<int>(v.data) - 16 : static_cast<int>(v.data))
                                        : static_cast<int>(sign_extend(v.data, v.size));
        break;
      case 0x6: g_.unit = v.data; break;
      case 0x7:
        if (v.data > kMaxReportSize) return HidDescriptorErrorCode::ReportSizeTooLarge;
        g_.report_size = v.data;
        break;
      case 0x8:
        if (v.data == 0) return HidDescriptorErrorCode::ReportIdZero;
        if (v.data > 255) return HidDescriptorErrorCode::ReportIdTooLarge;
        if (data_without_id_) return HidDescriptorErrorCode::MissingReportId;
        g_.report_id = static_cast<std::uint8_t>(v.data);
        out_.uses_report_ids = true;
        break;
      case 0x9:
        if (v.data > kMaxReportCount) return HidDescriptorErrorCode::ReportCountTooLarge;
        g_.report_count = v.data;
        break;
      case 0xA:
        if (stack_.size() >= kMaxPush) return HidDescriptorErrorCode::PushStackOverflow;
        stack_.push_back(g_);
        break;
      case 0xB:
        if (stack_.empty()) return HidDescriptorErrorCode::PopWithoutPush;
        g_ = stack_.back();
        stack_.pop_back();
        break;
      default: return HidDescriptorErrorCode::UnknownGlobalTag;
    }
    return std::nullopt;
  }

  std::optional<HidDescriptorErrorCode> local_item(unsigned tag, RawValue v) {
    const LocalUsage u{v.data, v.size == 4};
    switch (tag) {
      case 0x0:
        if (usage_total_ + usages_.size() >= kMaxUsages) return HidDescriptorErrorCode::UsageRangeInvalid;
        usages_.push_back(u);
        return std::nullopt;
      case 0x1: usage_min_ = u; return expand_range();
      case 0x2: usage_max_ = u; return expand_range();
      default: return std::nullopt;  // designators, strings, delimiters, reserved: no effect on layout
    }
  }

  std::span<const std::uint8_t> bytes_;
  HidReportDescriptor out_;
  Globals g_;
  std::vector<Globals> stack_;
  std::vector<LocalUsage> usages_;
  std::optional<LocalUsage> usage_min_, usage_max_;
  std::vector<int> open_;
  std::size_t fields_ = 0;
  std::size_t usage_total_ = 0;
  bool data_without_id_ = false;
};

}  // namespace

HidUsage HidField::usage_of(std::uint32_t index) const {
  if (usages.empty()) return 0;
  return usages[std::min<std::size_t>(index, usages.size() - 1)];
}

const HidReport* HidReportDescriptor::find(HidReportKind kind, std::uint8_t id) const {
  for (const HidReport& r : reports)
    if (r.kind == kind && r.id == id) return &r;
  return nullptr;
}

bool HidReportDescriptor::within(int collection_index, HidUsage usage) const {
  // Parents always precede their children, so the walk ends.
  for (int c = collection_index; c >= 0 && c < static_cast<int>(collections.size()); c = collections[static_cast<std::size_t>(c)].parent)
    if (collections[static_cast<std::size_t>(c)].usage == usage) return true;
  return false;
}

std::variant<HidReportDescriptor, HidDescriptorError> parse_hid_report_descriptor(std::span<const std::uint8_t> bytes) {
  return Parser(bytes).run();
}

std::optional<std::uint64_t> hid_read_bits(std::span<const std::uint8_t> data, std::uint32_t bit_offset, std::uint32_t bit_size) {
  if (bit_size == 0 || bit_size > 64) return std::nullopt;
  const std::uint64_t end = static_cast<std::uint64_t>(bit_offset) + bit_size;
  if ((end + 7) / 8 > data.size()) return std::nullopt;
  const std::size_t first = bit_offset / 8;
  const unsigned shift = bit_offset % 8;
  const std::size_t last = static_cast<std::size_t>((end + 7) / 8);  // one past the last byte
  std::uint64_t lo = 0;
  const std::size_t n = std::min<std::size_t>(8, last - first);
  for (std::size_t k = 0; k < n; ++k) lo |= static_cast<std::uint64_t>(data[first + k]) << (8 * k);
  std::uint64_t v = lo >> shift;
  if (last - first > 8) v |= static_cast<std::uint64_t>(data[first + 8]) << (64 - shift);  // shift > 0 here
  return bit_size == 64 ? v : v & ((std::uint64_t{1} << bit_size) - 1);
}

bool hid_write_bits(std::span<std::uint8_t> data, std::uint32_t bit_offset, std::uint32_t bit_size, std::uint64_t value) {
  if (bit_size == 0 || bit_size > 64) return false;
  const std::uint64_t end = static_cast<std::uint64_t>(bit_offset) + bit_size;
  if ((end + 7) / 8 > data.size()) return false;
  for (std::uint32_t b = 0; b < bit_size; ++b) {
    const std::uint64_t at = static_cast<std::uint64_t>(bit_offset) + b;
    const auto mask = static_cast<std::uint8_t>(1u << (at % 8));
    if ((value >> b) & 1)
      data[at / 8] |= mask;
    else
      data[at / 8] &= static_cast<std::uint8_t>(~mask);
  }
  return true;
}

std::optional<std::int64_t> hid_field_value(std::span<const std::uint8_t> data, const HidField& field, std::uint32_t index) {
  if (index >= field.count || field.bit_size > 64) return std::nullopt;
  const std::uint64_t offset = field.bit_offset + static_cast<std::uint64_t>(index) * field.bit_size;
  if (offset > 0xFFFFFFFFull) return std::nullopt;
  const std::optional<std::uint64_t> raw = hid_read_bits(data, static_cast<std::uint32_t>(offset), field.bit_size);
  if (!raw) return std::nullopt;
  if (field.is_signed() && field.bit_size < 64 && ((*raw >> (field.bit_size - 1)) & 1))
    return static_cast<std::int64_t>(*raw | ~((std::uint64_t{1} << field.bit_size) - 1));
  return static_cast<std::int64_t>(*raw);
}

}  // namespace posefair::drivers
