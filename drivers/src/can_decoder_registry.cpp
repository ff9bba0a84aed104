// The CAN decoder registry: one line per protocol (can_decoder.hpp), as decoder_registry.cpp
// is for the serial ones. A new protocol is one <protocol>_decoder.cpp plus one line here.
#include <algorithm>
#include <charconv>
#include <stdexcept>
#include <string>

#include "posefair/drivers/can_decoder.hpp"
#include "posefair/drivers/dronecan_ahrs_decoder.hpp"
#include "posefair/drivers/posefair_can_decoder.hpp"
#include "posefair/drivers/xsens_can_decoder.hpp"

namespace posefair::drivers {
namespace {

struct Entry {
  std::string_view name;
  std::unique_ptr<CanDecoder> (*make)(const CanDecoderOptions&);
};

constexpr Entry kCanDecoders[] = {
    {"dronecan-ahrs", make_dronecan_ahrs_decoder},
    {"posefair-can", make_posefair_can_decoder},
    {"xsens-can", make_xsens_can_decoder},
};

}  // namespace

std::unique_ptr<CanDecoder> make_can_decoder(std::string_view protocol, const CanDecoderOptions& options) {
  for (const Entry& e : kCanDecoders)
    if (e.name == protocol) return e.make(options);
  return nullptr;
}

std::vector<std::string> can_decoder_protocols() {
  std::vector<std::string> names;
  for (const Entry& e : kCanDecoders) names.emplace_back(e.name);
  std::sort(names.begin(), names.end());
  return names;
}

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
    throw std::invalid_argument(std::string(option) + ": \"" + std::string(text) + "\" is not an identifier 0 .. " +
                                std::to_string(max) + " (decimal or 0x hex)");
  return static_cast<std::uint32_t>(v);
}

bool parse_can_id_format_option(std::string_view option, std::string_view text) {
  if (text == "standard") return false;
  if (text == "extended") return true;
  throw std::invalid_argument(std::string(option) + ": \"" + std::string(text) + "\" is not \"standard\" or \"extended\"");
}

}  // namespace posefair::drivers
