// The CAN decoder registry: one line per protocol (can_decoder.hpp), as decoder_registry.cpp
// is for the serial ones. A new protocol is one <protocol>_decoder.cpp (with its CanDecoderEntry) plus one line here.
#include <charconv>
#include <stdexcept>
#include <string>

#include "posefair/drivers/can_decoder.hpp"
#include "posefair/drivers/dronecan_ahrs_decoder.hpp"
#include "posefair/drivers/posefair_can_decoder.hpp"
#include "posefair/core/registry_lookup.hpp"
#include "posefair/drivers/xsens_can_decoder.hpp"

namespace posefair::drivers {
namespace {

// Sorted by name.
const CanDecoderEntry* const kCanDecoders[] = {
    &kDroneCanAhrsDecoder,
    &kPosefairCanDecoder,
    &kXsensCanDecoder,
};

}  // namespace

std::span<const CanDecoderEntry* const> can_decoder_entries() { return kCanDecoders; }

const CanDecoderEntry* find_can_decoder(std::string_view protocol) { return find_entry<CanDecoderEntry>(kCanDecoders, protocol); }

std::unique_ptr<CanDecoder> make_can_decoder(std::string_view protocol, const OptionMap& options) {
  const CanDecoderEntry* e = find_can_decoder(protocol);
  return e ? e->make(options) : nullptr;
}

std::vector<std::string> can_decoder_protocols() { return entry_names<CanDecoderEntry>(kCanDecoders); }

std::uint32_t parse_can_id_option(std::string_view option, std::string_view text, std::uint32_t max) {
  std::string_view digits = text;
  int base = 10;
  if (digits.size() > 2 && digits[0] == '0' && (digits[1] == 'x' || digits[1] == 'X')) {
    digits.remove_prefix(2);
    base = 16;
  }
  std::uint64_t v = 0;
  const auto [end, ec] = std::from_chars(digits.data(), digits.data() + digits.size(), v, base);
  if (digits.empty() || ec != std::errc() || end != digits.data() + digits.size() || v > max)
    throw OptionError(std::string(option), "\"" + std::string(text) + "\" is not an identifier 0 .. " + std::to_string(max) +
                                               " (decimal or 0x hex)");
  return static_cast<std::uint32_t>(v);
}

bool parse_can_id_format_option(std::string_view option, std::string_view text) {
  if (text == "standard") return false;
  if (text == "extended") return true;
  throw OptionError(std::string(option), "\"" + std::string(text) + "\" is not \"standard\" or \"extended\"");
}

}  // namespace posefair::drivers
