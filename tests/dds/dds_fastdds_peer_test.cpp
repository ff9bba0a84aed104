// The dds encoding received by an implementation posefair did not write: a Fast DDS 2.9
// (Debian libfastrtps) DataReader with the type fastddsgen -typeros2 generated from a ROS
// user's IDL (ros2_pose_stamped.idl), as a ROS 2 node on rmw_fastrtps would read
// /posefair/<stream>/pose. posefair's side is its registered dds encoder (Cyclone DDS).
//
// ctest runs this program inside a network namespace of its own with only the loopback
// interface up (in_loopback_netns.sh), so DDS discovery never leaves it.
#include <gtest/gtest.h>

#include <signal.h>

#include <chrono>
#include <cmath>
#include <fstream>
#include <numbers>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include <fastdds/dds/domain/DomainParticipant.hpp>
#include <fastdds/dds/domain/DomainParticipantFactory.hpp>
#include <fastdds/dds/subscriber/DataReader.hpp>
#include <fastdds/dds/subscriber/SampleInfo.hpp>
#include <fastdds/dds/subscriber/Subscriber.hpp>
#include <fastdds/dds/subscriber/qos/DataReaderQos.hpp>
#include <fastdds/dds/topic/TypeSupport.hpp>

#include "../protocol/subprocess.hpp"
#include "posefair/daemon/output_encoder.hpp"
#include "ros2_pose_stampedPubSubTypes.h"

namespace posefair::daemon {
namespace {

using namespace std::chrono_literals;
namespace fdds = eprosima::fastdds::dds;

// A Fast DDS participant reading one PoseStamped topic.
class FastDdsReader {
 public:
  FastDdsReader(std::uint32_t domain, const std::string& topic_name, bool reliable) : type_(new geometry_msgs::msg::PoseStampedPubSubType()) {
    participant_ = fdds::DomainParticipantFactory::get_instance()->create_participant(domain, fdds::PARTICIPANT_QOS_DEFAULT);
    if (participant_ == nullptr) throw std::runtime_error("Fast DDS: no participant");
    type_.register_type(participant_);
    topic_ = participant_->create_topic(topic_name, type_.get_type_name(), fdds::TOPIC_QOS_DEFAULT);
    subscriber_ = participant_->create_subscriber(fdds::SUBSCRIBER_QOS_DEFAULT);
    fdds::DataReaderQos qos = fdds::DATAREADER_QOS_DEFAULT;
    qos.reliability().kind = reliable ? fdds::RELIABLE_RELIABILITY_QOS : fdds::BEST_EFFORT_RELIABILITY_QOS;
    reader_ = subscriber_->create_datareader(topic_, qos);
    if (reader_ == nullptr) throw std::runtime_error("Fast DDS: no reader");
  }
  ~FastDdsReader() {
    participant_->delete_contained_entities();
    fdds::DomainParticipantFactory::get_instance()->delete_participant(participant_);
  }
  std::optional<geometry_msgs::msg::PoseStamped> take() {
    geometry_msgs::msg::PoseStamped sample;
    fdds::SampleInfo info;
    if (reader_->take_next_sample(&sample, &info) == eprosima::fastrtps::types::ReturnCode_t::RETCODE_OK && info.valid_data) return sample;
    return std::nullopt;
  }
  std::string type_name() const { return type_.get_type_name(); }

 private:
  fdds::TypeSupport type_;
  fdds::DomainParticipant* participant_ = nullptr;
  fdds::Topic* topic_ = nullptr;
  fdds::Subscriber* subscriber_ = nullptr;
  fdds::DataReader* reader_ = nullptr;
};

// Publishes m through posefair's dds encoder every 20 ms until the reader has a sample (DDS
// discovery takes a moment) or 20 s have passed.
std::optional<geometry_msgs::msg::PoseStamped> publish_until_read(const OutputEncoder& dds, FastDdsReader& reader, const PoseMessage& m) {
  const auto deadline = std::chrono::steady_clock::now() + 20s;
  while (std::chrono::steady_clock::now() < deadline) {
    EXPECT_TRUE(dds.deliver(m));
    std::this_thread::sleep_for(20ms);
    if (auto s = reader.take()) return s;
  }
  return std::nullopt;
}

PoseMessage turned_left_at_a_place() {
  PoseMessage m;
  m.stream = 4;
  m.sample_time = 1700000000.25;
  m.orientation = Quat(Eigen::AngleAxisd(std::numbers::pi / 2, Vec3::UnitZ()));  // 90° to the left
  m.position = Vec3(1.5, -0.25, 0.75);
  return m;
}

void expect_pose(const geometry_msgs::msg::PoseStamped& s, const std::string& frame_id) {
  EXPECT_EQ(s.header().frame_id(), frame_id);
  EXPECT_EQ(s.header().stamp().sec(), 1700000000);
  EXPECT_EQ(s.header().stamp().nanosec(), 250000000u);
  EXPECT_EQ(s.pose().position().x(), 1.5);
  EXPECT_EQ(s.pose().position().y(), -0.25);
  EXPECT_EQ(s.pose().position().z(), 0.75);
  // ROS's frame is posefair's (REP 103): a left turn is +90° about z.
  EXPECT_NEAR(s.pose().orientation().x(), 0.0, 1e-15);
  EXPECT_NEAR(s.pose().orientation().y(), 0.0, 1e-15);
  EXPECT_NEAR(s.pose().orientation().z(), std::sqrt(0.5), 1e-15);
  EXPECT_NEAR(s.pose().orientation().w(), std::sqrt(0.5), 1e-15);
}

TEST(DdsFastddsPeer, ReadsTheReliablePoseStampedTopicWithRosNames) {
  const OutputEncoderEntry* entry = find_output_encoder("dds");
  ASSERT_NE(entry, nullptr);
  const std::vector<OutputStream> streams = {{4, "head"}};
  const auto dds = entry->make({{"frame_id", std::string("map")}}, streams);
  FastDdsReader reader(0, "rt/posefair/head/pose", true);
  EXPECT_EQ(reader.type_name(), "geometry_msgs::msg::dds_::PoseStamped_");
  const auto s = publish_until_read(*dds, reader, turned_left_at_a_place());
  ASSERT_TRUE(s) << "Fast DDS received nothing on rt/posefair/head/pose in 20 s";
  expect_pose(*s, "map");
}

TEST(DdsFastddsPeer, ReadsABestEffortTopicOnAnotherDomainAndPrefix) {
  const std::vector<OutputStream> streams = {{4, "wrist_left"}};
  const auto dds = find_output_encoder("dds")->make(
      {{"domain_id", std::int64_t{7}}, {"prefix", std::string("rig/a")}, {"qos", std::string("best-effort")}}, streams);
  FastDdsReader reader(7, "rt/rig/a/wrist_left/pose", false);
  const auto s = publish_until_read(*dds, reader, turned_left_at_a_place());
  ASSERT_TRUE(s) << "Fast DDS received nothing on rt/rig/a/wrist_left/pose in 20 s";
  expect_pose(*s, "world");
}

// posefaird itself, from a config with no Cyclone configuration anywhere: a synthetic stream
// named "chest" on a dds output, read by Fast DDS as /posefair/chest/pose.
TEST(DdsFastddsPeer, PosefairdPublishesAStreamFromItsConfig) {
  testing::TempDir dir;
  const std::string config = (dir / "dds.toml").string();
  {
    std::ofstream f(config);
    f << "[daemon]\nexit_when_sources_end = true\n[logging]\nstatus_interval = 0\n\n"
         "[[stream]]\nid = 9\nname = \"chest\"\n"
         "driver = { type = \"synthetic\", rate_hz = 100.0, duration = 8.0, with_position = true }\n\n"
         "[[output]]\nencoding = \"dds\"\nframe_id = \"odom\"\n";
  }
  FastDdsReader reader(0, "rt/posefair/chest/pose", true);
  testing::Subprocess d({POSEFAIR_BINARY_DIR "/daemon/posefaird", "-c", config, "--log-target", "stderr"}, dir / "out", dir / "err");
  std::vector<geometry_msgs::msg::PoseStamped> got;
  const auto deadline = std::chrono::steady_clock::now() + 20s;
  while (got.size() < 50 && std::chrono::steady_clock::now() < deadline) {
    if (auto s = reader.take())
      got.push_back(*s);
    else
      std::this_thread::sleep_for(5ms);
  }
  d.send_signal(SIGTERM);
  EXPECT_TRUE(d.wait(20s).has_value()) << d.err();
  ASSERT_GE(got.size(), 50u) << d.err();
  for (const auto& s : got) {
    EXPECT_EQ(s.header().frame_id(), "odom");
    const auto& q = s.pose().orientation();
    EXPECT_NEAR(q.x() * q.x() + q.y() * q.y() + q.z() * q.z() + q.w() * q.w(), 1.0, 1e-9);
  }
  // Stamps are the poses' sample times: increasing.
  for (std::size_t i = 1; i < got.size(); ++i) {
    const double a = got[i - 1].header().stamp().sec() + 1e-9 * got[i - 1].header().stamp().nanosec();
    const double b = got[i].header().stamp().sec() + 1e-9 * got[i].header().stamp().nanosec();
    EXPECT_GT(b, a) << i;
  }
}

// A topic that is not a ROS 2 name is a config error: posefaird --check exits 78 with
// file:line:key, for the prefix and for a stream's name.
TEST(DdsEncoding, PosefairdRefusesAnInvalidTopicWithFileLineAndKey) {
  testing::TempDir dir;
  struct Row {
    std::string toml, where;
  };
  const std::string stream = "[[stream]]\nid = 1\nname = \"%\"\ndriver = { type = \"synthetic\" }\n";
  auto with_name = [&](const std::string& name) { return stream.substr(0, stream.find('%')) + name + stream.substr(stream.find('%') + 1); };
  const Row rows[] = {
      {with_name("head") + "[[output]]\nencoding = \"dds\"\nprefix = \"rig//a\"\n", ":7:10: output[1].prefix: "},
      {with_name("left-hand") + "[[output]]\nencoding = \"dds\"\n", ":5:1: output[1].streams: "},
      {with_name("head") + "[[output]]\nencoding = \"dds\"\ndestinations = [\"127.0.0.1\"]\n", ":7:16: output[1].destinations: "},
  };
  int n = 0;
  for (const Row& row : rows) {
    const std::string config = (dir / ("bad" + std::to_string(++n) + ".toml")).string();
    std::ofstream(config) << row.toml;
    testing::Subprocess d({POSEFAIR_BINARY_DIR "/daemon/posefaird", "--check", "-c", config}, dir / "out", dir / "err");
    EXPECT_EQ(d.wait(20s), 78) << d.err();
    EXPECT_NE(d.err().find(config + row.where), std::string::npos) << d.err();
  }
}

TEST(DdsEncoding, RefusesNamesThatAreNotRosTopics) {
  auto refused = [](const posefair::OptionMap& o, std::string_view stream) -> std::string {
    const std::vector<OutputStream> streams = {{1, stream}};
    try {
      (void)find_output_encoder("dds")->make(o, streams);
    } catch (const posefair::OptionError& e) {
      return e.key();
    }
    return "accepted";
  };
  EXPECT_EQ(refused({}, "head"), "accepted");
  EXPECT_EQ(refused({{"prefix", std::string("a/b_c")}}, "head"), "accepted");
  EXPECT_EQ(refused({}, "left-hand"), "streams");
  EXPECT_EQ(refused({}, "2nd"), "streams");
  EXPECT_EQ(refused({{"prefix", std::string("/posefair")}}, "head"), "prefix");
  EXPECT_EQ(refused({{"prefix", std::string("a//b")}}, "head"), "prefix");
  EXPECT_EQ(refused({{"prefix", std::string("a__b")}}, "head"), "prefix");
  EXPECT_EQ(refused({{"domain_id", std::int64_t{233}}}, "head"), "domain_id");
}

}  // namespace
}  // namespace posefair::daemon
