// The output encodings posefaird can publish (daemon/output_encoder.hpp). One line each: the
// function that returns the encoder, defined in the encoding's own file.
#include "posefair/daemon/output_encoder.hpp"

#include <algorithm>

namespace posefair::daemon {

const OutputEncoder& binary_output_encoder();      // wire_protocol.cpp: wire protocol v1
const OutputEncoder& json_lines_output_encoder();  // json_lines.cpp: JSON lines

std::span<const OutputEncoder* const> output_encoders() {
  static const OutputEncoder* const encoders[] = {
      &binary_output_encoder(),
      &json_lines_output_encoder(),
  };
  return encoders;
}

const OutputEncoder* find_output_encoder(std::string_view name) {
  const auto all = output_encoders();
  const auto it = std::find_if(all.begin(), all.end(), [&](const OutputEncoder* e) { return e->name() == name; });
  return it == all.end() ? nullptr : *it;
}

std::vector<std::string_view> output_encoder_names() {
  std::vector<std::string_view> names;
  for (const OutputEncoder* e : output_encoders()) names.push_back(e->name());
  return names;
}

}  // namespace posefair::daemon
