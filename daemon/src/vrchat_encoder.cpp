// [[output]] encoding = "vrchat": VRChat's OSC trackers (docs.vrchat.com, "OSC Trackers"). One
// OSC bundle per pose, built by liblo (osc_bundle.hpp), to the stream's tracker:
//   /tracking/trackers/<1..8|head>/position  fff  x y z      (Unity frame, metres; only with a position)
//   /tracking/trackers/<1..8|head>/rotation  fff  x y z      (Unity Euler degrees, applied Z, X, Y)
// client_frames.hpp holds the Unity frame and its Euler angles. Like vmc, liblo allocates per
// message: not the allocation-free path.
#include <algorithm>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "osc_bundle.hpp"
#include "posefair/daemon/client_frames.hpp"
#include "posefair/daemon/output_encoder.hpp"

namespace posefair::daemon {
namespace {

struct Tracker {
  std::uint32_t stream;
  std::string position_path, rotation_path;
};

class VrchatEncoder final : public OutputEncoder {
 public:
  explicit VrchatEncoder(std::vector<Tracker> trackers) : trackers_(std::move(trackers)) {}
  std::string_view name() const override { return "vrchat"; }
  std::size_t encode(const PoseMessage& m, std::span<std::uint8_t> out) const override {
    auto t = std::find_if(trackers_.begin(), trackers_.end(), [&](const Tracker& x) { return x.stream == m.stream; });
    if (t == trackers_.end()) t = trackers_.begin();  // not carried (never asked by the publisher)
    OscBundle b;
    if (t == trackers_.end()) return b.serialise(out);
    if (m.position) {
      const Vec3 p = unity_position(*m.position);
      b.add(t->position_path.c_str(), nullptr, {float(p.x()), float(p.y()), float(p.z())});
    }
    const std::array<double, 3> e = unity_euler_zxy(unity_rotation(m.orientation));
    b.add(t->rotation_path.c_str(), nullptr, {float(e[0]), float(e[1]), float(e[2])});
    return b.serialise(out);
  }

 private:
  std::vector<Tracker> trackers_;
};

constexpr posefair::OptionSpec kVrchatOptions[] = {
    {"trackers", posefair::OptionType::StringArray, "",
     "one per stream the output carries, in its order: \"1\" to \"8\" or \"head\" (default: 1, 2, ... in order)"},
};

std::shared_ptr<const OutputEncoder> make_vrchat(const posefair::OptionMap& options, std::span<const OutputStream> streams) {
  const posefair::OptionReader r(kVrchatOptions, options);
  std::vector<std::string> names;
  if (r.has("trackers")) {
    names = r.strings("trackers");
    if (names.size() != streams.size())
      throw posefair::OptionError("trackers", "names " + std::to_string(names.size()) + " trackers for the " +
                                                  std::to_string(streams.size()) + " streams the output carries (one each, in the order of `streams`)");
  } else {
    if (streams.size() > 8)
      throw posefair::OptionError("trackers", "missing: the output carries " + std::to_string(streams.size()) +
                                                  " streams and VRChat takes trackers 1 to 8 and head; list the streams and their trackers");
    for (std::size_t i = 0; i < streams.size(); ++i) names.push_back(std::to_string(i + 1));
  }
  std::vector<Tracker> trackers;
  for (std::size_t i = 0; i < names.size(); ++i) {
    const std::string key = "trackers[" + std::to_string(i + 1) + "]";
    const std::string& n = names[i];
    const bool valid = n == "head" || (n.size() == 1 && n[0] >= '1' && n[0] <= '8');
    if (!valid) throw posefair::OptionError(key, "'" + n + "' is not a VRChat tracker: expected \"1\" to \"8\" or \"head\"");
    for (std::size_t j = 0; j < i; ++j)
      if (names[j] == n) throw posefair::OptionError(key, "tracker '" + n + "' is already given to another stream");
    const std::string base = "/tracking/trackers/" + n;
    trackers.push_back({streams[i].id, base + "/position", base + "/rotation"});
  }
  return std::make_shared<const VrchatEncoder>(std::move(trackers));
}

}  // namespace

// Registered in output_encoder_registry.cpp.
const OutputEncoderEntry& vrchat_output_encoding() {
  static const OutputEncoderEntry entry{
      "vrchat", "VRChat OSC trackers: /tracking/trackers/{1..8|head}/position and /rotation, Unity frame",
      kVrchatOptions, make_vrchat, 9000};
  return entry;
}

}  // namespace posefair::daemon
