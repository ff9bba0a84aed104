// The decoder registry: one line per protocol (decoder.hpp), in the manner of gpsd's driver
// table. A new protocol is one <protocol>_decoder.cpp plus one line here.
#include <algorithm>
#include <stdexcept>

#include "posefair/drivers/bno08x_rvc_decoder.hpp"
#include "posefair/drivers/decoder.hpp"
#include "posefair/drivers/posefair_serial_decoder.hpp"
#include "posefair/drivers/vectornav_decoder.hpp"
#include "posefair/drivers/witmotion_decoder.hpp"
#include "posefair/drivers/xsens_decoder.hpp"
#include "posefair/drivers/yost_decoder.hpp"

namespace posefair::drivers {
namespace {

struct Entry {
  std::string_view name;
  std::unique_ptr<Decoder> (*make)(const DecoderOptions&);
};

constexpr Entry kDecoders[] = {
    {"bno08x-rvc", make_bno08x_rvc_decoder},
    {"posefair", make_posefair_serial_decoder},
    {"vectornav", make_vectornav_decoder},
    {"xsens", make_xsens_decoder},
    {"witmotion", make_witmotion_decoder},
    {"yost", make_yost_decoder},
};

}  // namespace

std::unique_ptr<Decoder> make_decoder(std::string_view protocol, const DecoderOptions& options) {
  for (const Entry& e : kDecoders)
    if (e.make && e.name == protocol) return e.make(options);
  return nullptr;
}

std::vector<std::string> decoder_protocols() {
  std::vector<std::string> names;
  for (const Entry& e : kDecoders)
    if (e.make) names.emplace_back(e.name);
  std::sort(names.begin(), names.end());
  return names;
}

}  // namespace posefair::drivers
