// [[output]] encoding = "vmc": the Virtual Motion Capture protocol (OSC over UDP), as VSeeFace,
// VMC, Unity's uOSC-based receivers and VTuber tools read it. One bundle per pose:
//   /VMC/Ext/Root/Pos  s "root" fff px py pz ffff qx qy qz qw   (the stream mapped to "Root"), or
//   /VMC/Ext/Bone/Pos  s <bone> fff px py pz ffff qx qy qz qw   (a Unity HumanBodyBones name),
//   /VMC/Ext/OK        i 1                                       (a model is loaded),
//   /VMC/Ext/T         f <sample time, s>.
// Positions and rotations in Unity's frame (client_frames.hpp: left-handed, y up, metres); a
// stream without a position sends 0, 0, 0. The bundle is built by liblo (osc_bundle.hpp), which
// allocates per message: a convenience encoding like JSON lines, not the allocation-free path.
#include <algorithm>
#include <array>
#include <memory>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "osc_bundle.hpp"
#include "posefair/daemon/client_frames.hpp"
#include "posefair/daemon/output_encoder.hpp"

namespace posefair::daemon {
namespace {

// UnityEngine.HumanBodyBones, every bone but LastBone, in Unity's order.
constexpr std::array<std::string_view, 55> kHumanBodyBones = {
    "Hips", "LeftUpperLeg", "RightUpperLeg", "LeftLowerLeg", "RightLowerLeg", "LeftFoot", "RightFoot", "Spine", "Chest",
    "Neck", "Head", "LeftShoulder", "RightShoulder", "LeftUpperArm", "RightUpperArm", "LeftLowerArm", "RightLowerArm",
    "LeftHand", "RightHand", "LeftToes", "RightToes", "LeftEye", "RightEye", "Jaw", "LeftThumbProximal",
    "LeftThumbIntermediate", "LeftThumbDistal", "LeftIndexProximal", "LeftIndexIntermediate", "LeftIndexDistal",
    "LeftMiddleProximal", "LeftMiddleIntermediate", "LeftMiddleDistal", "LeftRingProximal", "LeftRingIntermediate",
    "LeftRingDistal", "LeftLittleProximal", "LeftLittleIntermediate", "LeftLittleDistal", "RightThumbProximal",
    "RightThumbIntermediate", "RightThumbDistal", "RightIndexProximal", "RightIndexIntermediate", "RightIndexDistal",
    "RightMiddleProximal", "RightMiddleIntermediate", "RightMiddleDistal", "RightRingProximal", "RightRingIntermediate",
    "RightRingDistal", "RightLittleProximal", "RightLittleIntermediate", "RightLittleDistal", "UpperChest"};
constexpr std::string_view kRoot = "Root";  // not a bone: the avatar's root transform

struct Target {
  std::uint32_t stream;
  bool root;
  std::string bone;
};

class VmcEncoder final : public OutputEncoder {
 public:
  explicit VmcEncoder(std::vector<Target> targets) : targets_(std::move(targets)) {}
  std::string_view name() const override { return "vmc"; }
  std::size_t encode(const PoseMessage& m, std::span<std::uint8_t> out) const override {
    const auto t = std::find_if(targets_.begin(), targets_.end(), [&](const Target& x) { return x.stream == m.stream; });
    const bool root = t == targets_.end() || t->root;
    const Vec3 p = unity_position(m.position.value_or(Vec3::Zero()));
    const Quat q = unity_rotation(m.orientation);
    OscBundle b;
    b.add(root ? "/VMC/Ext/Root/Pos" : "/VMC/Ext/Bone/Pos", root ? "root" : t->bone.c_str(),
          {float(p.x()), float(p.y()), float(p.z()), float(q.x()), float(q.y()), float(q.z()), float(q.w())});
    b.add("/VMC/Ext/OK", std::int32_t{1});
    b.add("/VMC/Ext/T", nullptr, {float(m.sample_time)});
    return b.serialise(out);
  }

 private:
  std::vector<Target> targets_;
};

constexpr posefair::OptionSpec kVmcOptions[] = {
    {"bones", posefair::OptionType::StringArray, "",
     "one per stream the output carries, in its order: a Unity HumanBodyBones name (e.g. \"Head\", \"LeftHand\") or "
     "\"Root\" (default: \"Root\" for an output of one stream)"},
};

std::shared_ptr<const OutputEncoder> make_vmc(const posefair::OptionMap& options, std::span<const OutputStream> streams) {
  const posefair::OptionReader r(kVmcOptions, options);
  std::vector<Target> targets;
  if (!r.has("bones")) {
    if (streams.size() > 1)
      throw posefair::OptionError("bones", "missing: the output carries " + std::to_string(streams.size()) +
                                               " streams, so name a bone (or \"Root\") for each, in the order of `streams`");
    for (const OutputStream& s : streams) targets.push_back({s.id, true, {}});
    return std::make_shared<const VmcEncoder>(std::move(targets));
  }
  const std::vector<std::string> bones = r.strings("bones");
  if (bones.size() != streams.size())
    throw posefair::OptionError("bones", "names " + std::to_string(bones.size()) + " bones for the " +
                                             std::to_string(streams.size()) + " streams the output carries (one each, in the order of `streams`)");
  for (std::size_t i = 0; i < bones.size(); ++i) {
    const std::string key = "bones[" + std::to_string(i + 1) + "]";
    const bool root = bones[i] == kRoot;
    if (!root && std::find(kHumanBodyBones.begin(), kHumanBodyBones.end(), bones[i]) == kHumanBodyBones.end())
      throw posefair::OptionError(key, "'" + bones[i] + "' is not a Unity HumanBodyBones name (e.g. Hips, Spine, Head, LeftHand, RightFoot) nor \"Root\"");
    for (std::size_t j = 0; j < i; ++j)
      if (bones[j] == bones[i]) throw posefair::OptionError(key, "'" + bones[i] + "' is already given to another stream");
    targets.push_back({streams[i].id, root, bones[i]});
  }
  return std::make_shared<const VmcEncoder>(std::move(targets));
}

}  // namespace

// Registered in output_encoder_registry.cpp.
const OutputEncoderEntry& vmc_output_encoding() {
  static const OutputEncoderEntry entry{
      "vmc", "VMC protocol over OSC (VSeeFace, Unity VMC receivers): root or bone position and rotation, Unity frame",
      kVmcOptions, make_vmc, 39539};
  return entry;
}

}  // namespace posefair::daemon
