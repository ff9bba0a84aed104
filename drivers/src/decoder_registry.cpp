// The decoder registry: one line per protocol (decoder.hpp), in the manner of gpsd's driver
// table. A new protocol is one <protocol>_decoder.cpp (with its DecoderEntry) plus one line here.

#include "posefair/drivers/bno08x_rvc_decoder.hpp"
#include "posefair/drivers/decoder.hpp"
#include "posefair/drivers/posefair_serial_decoder.hpp"
#include "posefair/core/registry_lookup.hpp"
#include "posefair/drivers/vectornav_decoder.hpp"
#include "posefair/drivers/witmotion_decoder.hpp"
#include "posefair/drivers/xsens_decoder.hpp"
#include "posefair/drivers/yost_decoder.hpp"

namespace posefair::drivers {
namespace {

// Sorted by name.
const DecoderEntry* const kDecoders[] = {
    &kBno08xRvcDecoder,
    &kPosefairSerialDecoder,
    &kVectorNavDecoder,
    &kWitMotionDecoder,
    &kXsensDecoder,
    &kYostDecoder,
};

}  // namespace

std::span<const DecoderEntry* const> decoder_entries() { return kDecoders; }

const DecoderEntry* find_decoder(std::string_view protocol) { return find_entry<DecoderEntry>(kDecoders, protocol); }

std::unique_ptr<Decoder> make_decoder(std::string_view protocol, const OptionMap& options) {
  const DecoderEntry* e = find_decoder(protocol);
  return e ? e->make(options) : nullptr;
}

std::vector<std::string> decoder_protocols() { return entry_names<DecoderEntry>(kDecoders); }

}  // namespace posefair::drivers
