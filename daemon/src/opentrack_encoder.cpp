// [[output]] encoding = "opentrack": what opentrack's "UDP over network" input reads, one 48-byte
// datagram per pose: six little-endian IEEE-754 doubles, x, y, z in centimetres, then yaw,
// pitch, roll in degrees (opentrack's own UDP output writes the same six doubles). The axes
// and signs are client_frames.hpp's: x right, y up, z back; yaw positive to the left, pitch
// positive up, roll positive leaning right. A stream without a position sends 0, 0, 0.
// opentrack would pass a NaN to games unchecked: a non-finite value is sent as 0.
#include <bit>
#include <cmath>
#include <cstdint>
#include <memory>
#include <stdexcept>

#include "posefair/daemon/client_frames.hpp"
#include "posefair/daemon/output_encoder.hpp"

namespace posefair::daemon {
namespace {

constexpr std::size_t kOpentrackSize = 48;

void put_le_double(std::uint8_t* out, double v) {
  const auto bits = std::bit_cast<std::uint64_t>(std::isfinite(v) ? v : 0.0);
  for (int i = 0; i < 8; ++i) out[i] = static_cast<std::uint8_t>(bits >> (8 * i));
}

class OpentrackEncoder final : public OutputEncoder {
 public:
  std::string_view name() const override { return "opentrack"; }
  std::size_t encode(const PoseMessage& m, std::span<std::uint8_t> out) const override {
    if (out.size() < kOpentrackSize) throw std::length_error("opentrack: output buffer too small");
    const Vec3 cm = m.position ? opentrack_position_cm(*m.position) : Vec3::Zero();
    const HeadAngles a = head_angles(m.orientation);
    const double values[6] = {cm.x(), cm.y(), cm.z(), a.yaw, a.pitch, a.roll};
    for (int i = 0; i < 6; ++i) put_le_double(out.data() + 8 * i, values[i]);
    return kOpentrackSize;
  }
};

}  // namespace

// Registered in output_encoder_registry.cpp. No options: every opentrack output shares one encoder.
const OutputEncoderEntry& opentrack_output_encoding() {
  static const OutputEncoderEntry entry{
      "opentrack", "opentrack's \"UDP over network\" input: x, y, z (cm), yaw, pitch, roll (degrees) as 6 doubles", {},
      [](const posefair::OptionMap& options, std::span<const OutputStream>) -> std::shared_ptr<const OutputEncoder> {
        (void)posefair::OptionReader({}, options);  // it reads none: refuses any
        static const auto encoder = std::make_shared<const OpentrackEncoder>();
        return encoder;
      },
      4242};
  return entry;
}

}  // namespace posefair::daemon
