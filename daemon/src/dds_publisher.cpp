// [[output]] encoding = "dds": each stream published with Eclipse Cyclone DDS (Debian
// cyclonedds-dev 0.10) as ROS 2's geometry_msgs/msg/PoseStamped, so `ros2 topic echo` and any
// ROS 2 node read it without ROS on this host:
//   - topic rt/<prefix>/<stream name>/pose (ROS 2's "rt/" prefix for topics; the ROS name is
//     /<prefix>/<stream>/pose);
//   - type geometry_msgs::msg::dds_::PoseStamped_ (idl/pose_stamped.idl, every struct @final);
//   - classic CDR (XCDR1), as ROS 2's rmw layers write it;
//   - header.stamp: the pose's sample time; header.frame_id from the config;
//   - QoS: reliable with keep-last 10 (ROS 2's default) or best effort with depth 5 (its
//     sensor-data profile), volatile.
// Discovery is DDS's own (SPDP multicast on the default domain 0, or `domain_id`), so it works
// with no Cyclone configuration file on one host and across a LAN. The participant is created at
// the first pose, on the thread publishing it, so `posefaird --check` and config parsing start no
// network traffic. Poses are in posefair's frame, which is ROS's (REP 103): no axes change.
#include <dds/dds.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "pose_stamped.h"
#include "posefair/daemon/output_encoder.hpp"

namespace posefair::daemon {
namespace {

struct Topic {
  std::uint32_t stream;
  std::string name;  // rt/<prefix>/<stream>/pose
  dds_entity_t writer = 0;
};

class DdsPublisher final : public OutputEncoder {
 public:
  DdsPublisher(std::vector<Topic> topics, std::uint32_t domain, bool reliable, std::string frame_id)
      : topics_(std::move(topics)), domain_(domain), reliable_(reliable), frame_id_(std::move(frame_id)) {}
  ~DdsPublisher() override {
    if (participant_ > 0) dds_delete(participant_);  // and its topics and writers
  }
  std::string_view name() const override { return "dds"; }
  std::size_t encode(const PoseMessage&, std::span<std::uint8_t>) const override { return 0; }
  bool delivers() const override { return true; }

  bool deliver(const PoseMessage& m) const override {
    std::call_once(opened_, [this] { open(); });  // the streams' threads may get here at once
    if (participant_ <= 0) return false;
    const auto t = std::find_if(topics_.begin(), topics_.end(), [&](const Topic& x) { return x.stream == m.stream; });
    if (t == topics_.end() || t->writer <= 0) return false;
    geometry_msgs_msg_dds__PoseStamped_ s{};
    const double stamp = std::isfinite(m.sample_time) ? m.sample_time : 0.0;
    const double sec = std::floor(stamp);
    s.header.stamp.sec = static_cast<std::int32_t>(sec);
    s.header.stamp.nanosec = static_cast<std::uint32_t>(std::min(999'999'999.0, std::round((stamp - sec) * 1e9)));
    s.header.frame_id = const_cast<char*>(frame_id_.c_str());  // only read by dds_write
    const Vec3 p = m.position.value_or(Vec3::Zero());
    s.pose.position = {p.x(), p.y(), p.z()};
    s.pose.orientation = {m.orientation.x(), m.orientation.y(), m.orientation.z(), m.orientation.w()};
    return dds_write(t->writer, &s) >= 0;
  }

 private:
  // The participant, one topic and writer per stream. A failure (e.g. no usable network
  // interface) leaves participant_ negative: every pose then counts as a failed send.
  void open() const {
    participant_ = dds_create_participant(domain_, nullptr, nullptr);
    if (participant_ < 0) return;
    dds_qos_t* qos = dds_create_qos();
    if (reliable_) {
      dds_qset_reliability(qos, DDS_RELIABILITY_RELIABLE, DDS_MSECS(100));
      dds_qset_history(qos, DDS_HISTORY_KEEP_LAST, 10);
    } else {
      dds_qset_reliability(qos, DDS_RELIABILITY_BEST_EFFORT, 0);
      dds_qset_history(qos, DDS_HISTORY_KEEP_LAST, 5);
    }
    const dds_data_representation_id_t classic_cdr[] = {DDS_DATA_REPRESENTATION_XCDR1};
    dds_qset_data_representation(qos, 1, classic_cdr);
    for (Topic& t : topics_) {
      const dds_entity_t topic = dds_create_topic(participant_, &geometry_msgs_msg_dds__PoseStamped__desc, t.name.c_str(), qos, nullptr);
      if (topic > 0) t.writer = dds_create_writer(participant_, topic, qos, nullptr);
    }
    dds_delete_qos(qos);
  }

  mutable std::vector<Topic> topics_;
  std::uint32_t domain_;
  bool reliable_;
  std::string frame_id_;
  mutable std::once_flag opened_;
  mutable dds_entity_t participant_ = 0;
};

// A ROS 2 name token: letters, digits and underscores, not starting with a digit, no "__".
bool valid_token(std::string_view s) {
  if (s.empty() || std::isdigit(static_cast<unsigned char>(s.front()))) return false;
  if (s.find("__") != std::string_view::npos) return false;
  return std::all_of(s.begin(), s.end(), [](char c) { return std::isalnum(static_cast<unsigned char>(c)) || c == '_'; });
}
// A namespace: tokens separated by single slashes (no leading, trailing or double slash).
bool valid_namespace(std::string_view s) {
  if (s.empty()) return false;
  for (std::size_t start = 0;;) {
    const std::size_t slash = s.find('/', start);
    if (!valid_token(s.substr(start, slash - start))) return false;
    if (slash == std::string_view::npos) return true;
    start = slash + 1;
  }
}

constexpr std::string_view kQos[] = {"reliable", "best-effort"};
constexpr posefair::OptionSpec kDdsOptions[] = {
    {"domain_id", posefair::OptionType::Integer, "0", "the DDS domain (ROS_DOMAIN_ID), 0-232"},
    {"prefix", posefair::OptionType::String, "posefair", "the topics' namespace: rt/<prefix>/<stream name>/pose"},
    {"frame_id", posefair::OptionType::String, "world", "header.frame_id of every pose"},
    {"qos", posefair::OptionType::String, "reliable",
     "\"reliable\" (keep last 10, ROS 2's default) or \"best-effort\" (depth 5, its sensor-data profile)", kQos},
};

std::shared_ptr<const OutputEncoder> make_dds(const posefair::OptionMap& options, std::span<const OutputStream> streams) {
  const posefair::OptionReader r(kDdsOptions, options);
  const auto domain = static_cast<std::uint32_t>(r.integer("domain_id", 0, 232));
  const std::string prefix = r.text("prefix");
  if (!valid_namespace(prefix))
    throw posefair::OptionError("prefix", "'" + prefix + "' is not a ROS 2 namespace: tokens of letters, digits and '_' "
                                          "(not starting with a digit, no \"__\") separated by single '/', no leading or trailing '/'");
  const bool reliable = r.choice("qos") == 0;
  std::vector<Topic> topics;
  for (const OutputStream& s : streams) {
    if (!valid_token(s.name))
      throw posefair::OptionError("streams", "stream " + std::to_string(s.id) + "'s name '" + std::string(s.name) +
                                                 "' cannot be a ROS 2 topic name token (letters, digits and '_', not starting with a digit, no \"__\"): "
                                                 "rename the [[stream]] for a dds output");
    std::string topic = "rt/" + prefix + "/" + std::string(s.name) + "/pose";
    if (topic.size() > 255)
      throw posefair::OptionError("prefix", "the topic " + topic + " is longer than DDS's 255 characters");
    topics.push_back({s.id, std::move(topic)});
  }
  return std::make_shared<const DdsPublisher>(std::move(topics), domain, reliable, r.text("frame_id"));
}

}  // namespace

// Registered in output_encoder_registry.cpp when the build found Cyclone DDS.
const OutputEncoderEntry& dds_output_encoding() {
  static const OutputEncoderEntry entry{
      "dds", "ROS 2 geometry_msgs/PoseStamped over DDS (Cyclone DDS): topic rt/<prefix>/<stream>/pose", kDdsOptions,
      make_dds, 0, true};
  return entry;
}

}  // namespace posefair::daemon
