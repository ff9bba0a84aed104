// The HID decoder registry: one line per protocol (hid_report_decoder.hpp), as
// decoder_registry.cpp is for the serial ones. A new protocol is one <protocol>_decoder.cpp
// (with its HidDecoderEntry) plus one line here.

#include "posefair/drivers/hid_report_decoder.hpp"
#include "posefair/drivers/hid_sensor_orientation_decoder.hpp"
#include "posefair/drivers/hid_vendor_layout_decoder.hpp"
#include "posefair/core/registry_lookup.hpp"

namespace posefair::drivers {
namespace {

// Sorted by name.
const HidDecoderEntry* const kHidDecoders[] = {
    &kHidSensorDecoder,
    &kHidVendorDecoder,
};

}  // namespace

std::span<const HidDecoderEntry* const> hid_decoder_entries() { return kHidDecoders; }

const HidDecoderEntry* find_hid_decoder(std::string_view protocol) { return find_entry<HidDecoderEntry>(kHidDecoders, protocol); }

std::unique_ptr<HidDecoderFactory> configure_hid_decoder(std::string_view protocol, const OptionMap& options) {
  const HidDecoderEntry* e = find_hid_decoder(protocol);
  return e ? e->configure(options) : nullptr;
}

std::vector<std::string> hid_decoder_protocols() { return entry_names<HidDecoderEntry>(kHidDecoders); }

}  // namespace posefair::drivers
