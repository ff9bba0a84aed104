// [[output]] encoding = "freed": the FreeD D1 message (camera position/orientation), as camera
// tracking and virtual-production systems receive it over UDP. Layout from the free-d
// installation manual (Vinten, appendix A and B), 29 bytes:
//   0 0xD1 | 1 camera id | 2 pan | 5 tilt | 8 roll | 11 X | 14 Y | 17 Z (height) | 20 zoom |
//   23 focus | 26 two spare bytes (0) | 28 checksum = (0x40 - sum of bytes 0..27) mod 256
// Angles and positions are 24-bit two's-complement big-endian: angles in 1/32768 degree
// (pan clockwise from above, tilt up, roll clockwise seen from behind: client_frames.hpp's
// yaw negated, pitch and roll), positions in 1/64 mm (X right, Y forward, Z up). Zoom and
// focus are 24-bit values from the config (a tracker has no lens).
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "posefair/daemon/client_frames.hpp"
#include "posefair/daemon/output_encoder.hpp"

namespace posefair::daemon {
namespace {

constexpr std::size_t kFreedSize = 29;
constexpr std::int64_t kMax24 = 0x7FFFFF, kMin24 = -0x800000;

// v in units of 1/scale, rounded and held to the 24-bit range (a position beyond ±131 m, an
// angle beyond ±256° cannot be written; non-finite is 0).
void put_be24(std::uint8_t* out, double v, double scale) {
  const double scaled = std::isfinite(v) ? std::round(v * scale) : 0.0;
  const auto n = static_cast<std::int64_t>(std::clamp(scaled, double(kMin24), double(kMax24)));
  const auto u = static_cast<std::uint32_t>(n) & 0xFFFFFFu;
  out[0] = static_cast<std::uint8_t>(u >> 16);
  out[1] = static_cast<std::uint8_t>(u >> 8);
  out[2] = static_cast<std::uint8_t>(u);
}

void put_be24_unsigned(std::uint8_t* out, std::uint32_t u) {
  out[0] = static_cast<std::uint8_t>(u >> 16);
  out[1] = static_cast<std::uint8_t>(u >> 8);
  out[2] = static_cast<std::uint8_t>(u);
}

class FreedEncoder final : public OutputEncoder {
 public:
  // camera_ids: per carried stream id (pairs id -> camera id); fixed: one camera id for all.
  FreedEncoder(std::vector<std::pair<std::uint32_t, std::uint8_t>> camera_ids, std::uint32_t zoom, std::uint32_t focus)
      : camera_ids_(std::move(camera_ids)), zoom_(zoom), focus_(focus) {}
  std::string_view name() const override { return "freed"; }
  std::size_t encode(const PoseMessage& m, std::span<std::uint8_t> out) const override {
    if (out.size() < kFreedSize) throw std::length_error("freed: output buffer too small");
    std::uint8_t* b = out.data();
    b[0] = 0xD1;
    b[1] = camera_id(m.stream);
    const HeadAngles a = head_angles(m.orientation);
    put_be24(b + 2, -a.yaw, 32768.0);
    put_be24(b + 5, a.pitch, 32768.0);
    put_be24(b + 8, a.roll, 32768.0);
    const Vec3 p = m.position.value_or(Vec3::Zero());
    put_be24(b + 11, -p.y() * 1000.0, 64.0);  // X: right
    put_be24(b + 14, p.x() * 1000.0, 64.0);   // Y: forward
    put_be24(b + 17, p.z() * 1000.0, 64.0);   // Z: up
    put_be24_unsigned(b + 20, zoom_);
    put_be24_unsigned(b + 23, focus_);
    b[26] = b[27] = 0;
    unsigned sum = 0;
    for (std::size_t i = 0; i < kFreedSize - 1; ++i) sum += b[i];
    b[28] = static_cast<std::uint8_t>((0x40u - sum) & 0xFFu);
    return kFreedSize;
  }

 private:
  std::uint8_t camera_id(std::uint32_t stream) const {
    for (const auto& [id, camera] : camera_ids_)
      if (id == stream) return camera;
    return static_cast<std::uint8_t>(stream);  // not carried (never asked by the publisher)
  }
  std::vector<std::pair<std::uint32_t, std::uint8_t>> camera_ids_;
  std::uint32_t zoom_, focus_;
};

constexpr posefair::OptionSpec kFreedOptions[] = {
    {"camera_id", posefair::OptionType::Integer, "",
     "the D1 camera id, 0-255, for an output of one stream (default: each stream's id, which must be 0-255)"},
    {"zoom", posefair::OptionType::Integer, "0", "the lens zoom value sent, 0-16777215 (24 bits)"},
    {"focus", posefair::OptionType::Integer, "0", "the lens focus value sent, 0-16777215 (24 bits)"},
};

std::shared_ptr<const OutputEncoder> make_freed(const posefair::OptionMap& options, std::span<const OutputStream> streams) {
  const posefair::OptionReader r(kFreedOptions, options);
  std::vector<std::pair<std::uint32_t, std::uint8_t>> cameras;
  if (r.has("camera_id")) {
    const auto id = static_cast<std::uint8_t>(r.integer("camera_id", 0, 255));
    if (streams.size() > 1)
      throw posefair::OptionError("camera_id", "names one camera, but the output carries " + std::to_string(streams.size()) +
                                                   " streams; list one stream in `streams`, or leave camera_id out (each stream's id is its camera id)");
    for (const OutputStream& s : streams) cameras.emplace_back(s.id, id);
  } else {
    for (const OutputStream& s : streams) {
      if (s.id > 255)
        throw posefair::OptionError("camera_id", "stream " + std::to_string(s.id) + " ('" + std::string(s.name) +
                                                     "') has an id above 255, which a D1 camera id cannot hold: set camera_id");
      cameras.emplace_back(s.id, static_cast<std::uint8_t>(s.id));
    }
  }
  const auto zoom = static_cast<std::uint32_t>(r.integer("zoom", 0, 0xFFFFFF));
  const auto focus = static_cast<std::uint32_t>(r.integer("focus", 0, 0xFFFFFF));
  return std::make_shared<const FreedEncoder>(std::move(cameras), zoom, focus);
}

}  // namespace

// Registered in output_encoder_registry.cpp.
const OutputEncoderEntry& freed_output_encoding() {
  static const OutputEncoderEntry entry{
      "freed", "FreeD D1 camera tracking message (29 bytes): pan, tilt, roll, x, y, z, zoom, focus", kFreedOptions,
      make_freed, 40000};
  return entry;
}

}  // namespace posefair::daemon
