// The output encodings posefaird can publish (daemon/output_encoder.hpp). One line each: the
// function that returns the encoding's entry, defined in the encoding's own file.
#include "posefair/daemon/output_encoder.hpp"

#include "posefair/core/registry_lookup.hpp"

namespace posefair::daemon {

const OutputEncoderEntry& binary_output_encoding();      // wire_protocol.cpp: wire protocol v1
const OutputEncoderEntry& json_lines_output_encoding();  // json_lines.cpp: JSON lines
const OutputEncoderEntry& opentrack_output_encoding();   // opentrack_encoder.cpp: opentrack UDP
const OutputEncoderEntry& freed_output_encoding();       // freed_encoder.cpp: FreeD D1
const OutputEncoderEntry& vmc_output_encoding();         // vmc_encoder.cpp: VMC over OSC
const OutputEncoderEntry& vrchat_output_encoding();      // vrchat_encoder.cpp: VRChat OSC trackers
#ifdef POSEFAIR_WITH_DDS
const OutputEncoderEntry& dds_output_encoding();         // dds_publisher.cpp: ROS 2 PoseStamped over DDS
#endif

std::span<const OutputEncoderEntry* const> output_encoder_entries() {
  static const OutputEncoderEntry* const entries[] = {
      &binary_output_encoding(),
      &json_lines_output_encoding(),
      &opentrack_output_encoding(),
      &freed_output_encoding(),
      &vmc_output_encoding(),
      &vrchat_output_encoding(),
#ifdef POSEFAIR_WITH_DDS  // a build with Cyclone DDS (daemon/CMakeLists.txt)
      &dds_output_encoding(),
#endif
  };
  return entries;
}

const OutputEncoderEntry* find_output_encoder(std::string_view name) {
  return posefair::find_entry(output_encoder_entries(), name);
}

std::vector<std::string_view> output_encoder_names() {
  std::vector<std::string_view> names;
  for (const OutputEncoderEntry* e : output_encoder_entries()) names.push_back(e->name);
  return names;
}

std::shared_ptr<const OutputEncoder> default_output_encoder() { return output_encoder_entries().front()->make({}, {}); }

}  // namespace posefair::daemon
