// posefaird's TOML configuration (docs/config.md): every key of a full config lands in its
// DaemonConfig field, the example configs load, and malformed configs are refused with the
// file, line and key of the problem.
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <string>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "../support/test_files.hpp"
#include "posefair/daemon/config.hpp"
#include "posefair/drivers/can_decoder.hpp"
#include "posefair/drivers/decoder.hpp"
#include "posefair/drivers/hid_sensor_orientation_decoder.hpp"
#include "posefair/drivers/hid_vendor_layout_decoder.hpp"
#include "posefair/drivers/replay_driver.hpp"

namespace posefair::daemon {
namespace {

using ::testing::HasSubstr;
using ::testing::StartsWith;

// A decoder option as the configuration handed it on (text options arrive as text).
std::string option_text(const posefair::OptionMap& options, const std::string& key) {
  const auto it = options.find(key);
  return it == options.end() ? std::string("(absent)") : std::get<std::string>(it->second);
}

// An expected message with the registries' lists in place of {can-protocols} ("a, b") and
// {hid-protocols} ("'a', 'b'"), so that a new protocol changes no row.
std::vector<std::string> encoding_names() {
  std::vector<std::string> names;
  for (std::string_view n : output_encoder_names()) names.emplace_back(n);
  return names;
}

std::string with_registry_lists(std::string text) {
  const auto join = [](const std::vector<std::string>& names, bool quoted) {
    std::string list;
    for (const std::string& n : names) list += (list.empty() ? "" : ", ") + (quoted ? "'" + n + "'" : n);
    return list;
  };
  for (const auto& [placeholder, list] : {std::pair{std::string("{can-protocols}"), join(drivers::can_decoder_protocols(), false)},
                                          std::pair{std::string("{hid-protocols}"), join(drivers::hid_decoder_protocols(), true)},
                                          std::pair{std::string("{encodings}"), join(encoding_names(), true)}})
    for (std::size_t at = text.find(placeholder); at != std::string::npos; at = text.find(placeholder)) text.replace(at, placeholder.size(), list);
  return text;
}

const std::filesystem::path kSourceDir = POSEFAIR_SOURCE_DIR;

void write_file(const std::filesystem::path& p, const std::string& text) {
  std::filesystem::create_directories(p.parent_path());
  std::ofstream out(p, std::ios::binary);
  out << text;
  ASSERT_TRUE(out.good()) << p;
}

Endpoint endpoint(const std::string& text) {
  const auto e = Endpoint::parse(text);
  EXPECT_TRUE(e.has_value()) << text;
  return e.value_or(Endpoint{});
}

// Every key, most of them away from their defaults.
constexpr const char* kFullConfig = R"toml(
[daemon]
exit_when_sources_end = true
session_id = 4000000000

[logging]
level = "debug"
target = "journald"
status_interval = 15        # an integer where a float is expected

[engine]
window = 48
lag = 3
order = 3
smoothing = 500
epsilon_r = 0.04            # rotation angle; the engine gets half of it
epsilon_t = 0.5
gap = 0.5
unit_tolerance = 0.05
rate_hz = 200
noise_time = 4              # the adaptation's time constants (s) and margin
motion_span = 0.5
motion_margin = 3
rest_threshold = 3          # 0: never at rest
rest_memory = 2.5           # s; 0: the window's smoothing at rest
prediction_check = false    # the noise estimate as it reads, unchecked
outlier_threshold = 10      # multiples of the median distance from the prediction; 0: off

[[stream]]
id = 7
name = "replayed"
ring_capacity = 256
overflow = "drop-newest"
[stream.driver]
type = "replay"
path = "data/poses.csv"
timing = "fast"
speed = 2.5
schedule = "receive-time"
loop = true
rounds = 3
format = "csv"
csv_prefix = "gt_"
skip_missing = true
source_stream = 9
[stream.engine]
cutoff_hz = 10              # overrides [engine]'s smoothing; rate_hz from [engine]
lag = 1
solver = "gauss-newton"
iterations = 3
continuity = 0.5
bound = "window"
motion_time = 0.2           # noise_time and motion_span stay [engine]'s
motion_margin = 1.5

[[stream]]
id = 8
name = "generated"
[stream.driver]
type = "synthetic"
rate_hz = 1000
duration = 30
rotation_noise = 0.02
with_position = true
seed = 42
[stream.engine]
solver = "sweeps"
iterations = 4
lambda_r = 0.2
lambda_t = 0.6
variant = "printed"
smoothing_r = 50            # smoothing_t stays [engine]'s 500

[[stream]]
id = 9
name = "defaults"
driver = { type = "synthetic" }

[[output]]
encoding = "json"
destinations = ["127.0.0.1", "[::1]:6000", "239.255.0.1:5800"]
ttl = 4
interface = "lo"
loopback = false
streams = [8, 7]
angular_velocity = true

[[output]]
destinations = ["10.0.0.2:5701"]

[recorder]
path = "rec/out.pflog"
max_file_bytes = 1048576
flush_interval = 0.5
overwrite = true
sync = false
ring_capacity = 8192
)toml";

TEST(Config, AFullConfigFillsEveryField) {
  testing::ScratchDir dir("posefair-config-");
  write_file(dir / "data/poses.csv", "t,qw,qx,qy,qz\n0,1,0,0,0\n");
  std::filesystem::create_directories(dir / "rec");
  const std::filesystem::path file = dir / "cfg.toml";
  const DaemonConfig c = parse_config(kFullConfig, file);

  EXPECT_EQ(c.source_file, file);
  EXPECT_TRUE(c.daemon.exit_when_sources_end);
  EXPECT_EQ(c.daemon.session_id, std::optional<std::uint32_t>(4000000000u));
  EXPECT_EQ(c.logging.level, "debug");
  EXPECT_EQ(c.logging.target, LogTarget::Journald);
  EXPECT_EQ(c.logging.status_interval, 15.0);

  ASSERT_EQ(c.streams.size(), 3u);
  {
    const StreamConfig& s = c.streams[0];
    EXPECT_EQ(s.id, 7u);
    EXPECT_EQ(s.name, "replayed");
    EXPECT_EQ(s.ring_capacity, 256u);
    EXPECT_EQ(s.overflow, OverflowPolicy::DropNewest);
    ASSERT_EQ(s.driver.type, DriverType::Replay);
    const ReplaySourceConfig& r = s.driver.replay;
    EXPECT_EQ(r.path, dir.path() / "data" / "poses.csv");  // against the config's directory
    EXPECT_TRUE(r.path.is_absolute());
    EXPECT_EQ(r.options.timing, drivers::ReplayTiming::AsFastAsPossible);
    EXPECT_EQ(r.options.speed, 2.5);
    EXPECT_EQ(r.options.schedule, drivers::ReplaySchedule::ReceiveTime);
    EXPECT_TRUE(r.options.loop);
    EXPECT_EQ(r.options.max_rounds, 3u);
    EXPECT_EQ(r.options.stream_id, 7u);
    EXPECT_EQ(r.options.pose.format, std::optional<formats::PoseFormat>(formats::PoseFormat::Csv));
    EXPECT_EQ(r.options.pose.csv_prefix, std::optional<std::string>("gt_"));
    EXPECT_TRUE(r.options.pose.skip_missing);
    EXPECT_EQ(r.options.pose.bvh_joint, "");
    EXPECT_EQ(r.source_stream, std::optional<std::uint32_t>(9u));

    const WindowConfig& e = s.engine;
    EXPECT_EQ(e.window, 48);
    EXPECT_EQ(e.lag, 1);
    EXPECT_EQ(e.order, 3);
    EXPECT_EQ(e.solver, WindowSolver::GaussNewton);
    EXPECT_EQ(e.iterations, 3);
    EXPECT_DOUBLE_EQ(e.smoothing_r.value_or(-1.0), smoothing_for_cutoff(10.0, 200.0, 3));
    EXPECT_DOUBLE_EQ(e.smoothing_t.value_or(-1.0), smoothing_for_cutoff(10.0, 200.0, 3));
    EXPECT_EQ(e.continuity, 0.5);
    EXPECT_EQ(e.lambda_r, WindowConfig{}.lambda_r);
    EXPECT_EQ(e.lambda_t, WindowConfig{}.lambda_t);
    EXPECT_EQ(e.variant, OperatorVariant::Corrected);
    EXPECT_DOUBLE_EQ(e.epsilon_r, 0.02);  // half of the 0.04 rad rotation angle
    EXPECT_EQ(e.epsilon_t, 0.5);
    EXPECT_EQ(e.bound, BoundPolicy::Window);
    EXPECT_EQ(e.gate.gap_threshold, 0.5);
    EXPECT_EQ(e.gate.unit_tolerance, 0.05);
    EXPECT_EQ(e.adaptation.noise_time_s, 4.0);
    EXPECT_EQ(e.adaptation.motion_time_s, 0.2);
    EXPECT_EQ(e.adaptation.motion_span_s, 0.5);
    EXPECT_EQ(e.adaptation.motion_margin, 1.5);
    EXPECT_EQ(e.adaptation.rest_threshold, 3.0);
    EXPECT_EQ(e.adaptation.rest_memory_s, 2.5);
    EXPECT_FALSE(e.adaptation.prediction_check);
    EXPECT_EQ(e.outlier_threshold, 10.0);
  }
  {
    const StreamConfig& s = c.streams[1];
    EXPECT_EQ(s.id, 8u);
    EXPECT_EQ(s.name, "generated");
    ASSERT_EQ(s.driver.type, DriverType::Synthetic);
    const SyntheticSourceConfig& g = s.driver.synthetic;
    EXPECT_EQ(g.rate_hz, 1000.0);
    EXPECT_EQ(g.duration, 30.0);
    EXPECT_EQ(g.rotation_noise, 0.02);
    EXPECT_TRUE(g.with_position);
    EXPECT_EQ(g.seed, 42u);
    const WindowConfig& e = s.engine;
    EXPECT_EQ(e.window, 48);
    EXPECT_EQ(e.lag, 3);
    EXPECT_EQ(e.order, 3);
    EXPECT_EQ(e.solver, WindowSolver::DampedSweeps);
    EXPECT_EQ(e.iterations, 4);
    EXPECT_EQ(e.smoothing_r.value_or(-1.0), 50.0);
    EXPECT_EQ(e.smoothing_t.value_or(-1.0), 500.0);
    EXPECT_EQ(e.continuity, 0.0);
    EXPECT_EQ(e.lambda_r, 0.2);
    EXPECT_EQ(e.lambda_t, 0.6);
    EXPECT_EQ(e.variant, OperatorVariant::Printed);
    EXPECT_DOUBLE_EQ(e.epsilon_r, 0.02);
    EXPECT_EQ(e.bound, BoundPolicy::Sample);
  }
  {
    // Only [engine] and the defaults.
    const StreamConfig& s = c.streams[2];
    EXPECT_EQ(s.id, 9u);
    EXPECT_EQ(s.ring_capacity, 1024u);
    EXPECT_EQ(s.overflow, OverflowPolicy::DropOldest);
    ASSERT_EQ(s.driver.type, DriverType::Synthetic);
    const SyntheticSourceConfig g = s.driver.synthetic;
    EXPECT_EQ(g.rate_hz, 100.0);
    EXPECT_EQ(g.duration, 0.0);
    EXPECT_EQ(g.rotation_noise, 0.01);
    EXPECT_FALSE(g.with_position);
    EXPECT_EQ(g.seed, 1u);
    const WindowConfig& e = s.engine;
    EXPECT_EQ(e.window, 48);
    EXPECT_EQ(e.lag, 3);
    EXPECT_EQ(e.order, 3);
    EXPECT_EQ(e.solver, WindowSolver::Linear);
    EXPECT_EQ(e.iterations, 1);
    EXPECT_EQ(e.smoothing_r.value_or(-1.0), 500.0);
    EXPECT_EQ(e.smoothing_t.value_or(-1.0), 500.0);
    EXPECT_DOUBLE_EQ(e.epsilon_r, 0.02);
    EXPECT_EQ(e.epsilon_t, 0.5);
    EXPECT_EQ(e.gate.gap_threshold, 0.5);
    EXPECT_EQ(e.gate.unit_tolerance, 0.05);
    EXPECT_EQ(e.adaptation.noise_time_s, 4.0);
    EXPECT_EQ(e.adaptation.motion_time_s, AdaptationSettings{}.motion_time_s);
    EXPECT_EQ(e.adaptation.motion_span_s, 0.5);
    EXPECT_EQ(e.adaptation.motion_margin, 3.0);
  }

  ASSERT_EQ(c.outputs.size(), 2u);
  {
    const OutputConfig& o = c.outputs[0];
    EXPECT_EQ(o.encoder->name(), "json");
    ASSERT_EQ(o.destinations.size(), 3u);
    EXPECT_EQ(o.destinations[0], endpoint("127.0.0.1:5700"));  // the default port
    EXPECT_EQ(o.destinations[1], endpoint("[::1]:6000"));
    EXPECT_EQ(o.destinations[2], endpoint("239.255.0.1:5800"));
    EXPECT_EQ(o.send.multicast_ttl, 4);
    EXPECT_EQ(o.send.interface.name_or_address, "lo");
    EXPECT_FALSE(o.send.multicast_loopback);
    EXPECT_EQ(o.streams, (std::vector<std::uint32_t>{8, 7}));
    EXPECT_TRUE(o.angular_velocity);
  }
  {
    const OutputConfig& o = c.outputs[1];
    EXPECT_EQ(o.encoder->name(), "binary");
    ASSERT_EQ(o.destinations.size(), 1u);
    EXPECT_EQ(o.destinations[0], endpoint("10.0.0.2:5701"));
    EXPECT_EQ(o.send.multicast_ttl, 1);
    EXPECT_EQ(o.send.interface.name_or_address, "");
    EXPECT_TRUE(o.send.multicast_loopback);
    EXPECT_TRUE(o.streams.empty());
    EXPECT_FALSE(o.angular_velocity);
  }

  EXPECT_TRUE(c.recorder.enabled);  // the table is there
  EXPECT_EQ(c.recorder.path, dir.path() / "rec" / "out.pflog");
  EXPECT_EQ(c.recorder.max_file_bytes, 1048576u);
  EXPECT_EQ(c.recorder.flush_interval, 0.5);
  EXPECT_TRUE(c.recorder.overwrite);
  EXPECT_FALSE(c.recorder.sync);
  EXPECT_EQ(c.recorder.ring_capacity, 8192u);

  // load_config reads the same from the file, and resolves against the file's directory,
  // not the working directory.
  write_file(file, kFullConfig);
  const DaemonConfig loaded = load_config(file);
  EXPECT_EQ(loaded.source_file, file);
  EXPECT_EQ(loaded.streams.at(0).driver.replay.path, dir.path() / "data" / "poses.csv");
  EXPECT_EQ(loaded.recorder.path, dir.path() / "rec" / "out.pflog");
}

// [daemon] fair_on, publish_on, spin_us, wake, cpu_affinity; [[stream]] busy_poll; [[output]]
// sendmmsg (docs/config.md; measured in docs/benchmarks.md, "Latency by stage").
TEST(Config, TheLatencyKeysChooseHowTheThreadsHandOver) {
  const DaemonConfig c = parse_config(R"toml(
[daemon]
fair_on = "engine"
publish_on = "publisher"
spin_us = 40
wake = "per-sample"
cpu_affinity = [1, 0]
[[stream]]
id = 1
name = "a"
busy_poll = true
driver = { type = "synthetic" }
[[stream]]
id = 2
name = "b"
driver = { type = "synthetic" }
[[output]]
destinations = ["127.0.0.1:5700", "127.0.0.1:5701"]
sendmmsg = false
)toml",
                                      "/nonexistent/latency.toml");
  EXPECT_EQ(c.daemon.fair_on, FairThread::Engine);
  EXPECT_EQ(c.daemon.publish_on, PublishThread::Publisher);
  EXPECT_EQ(c.daemon.spin_us, 40);
  EXPECT_FALSE(c.daemon.wake_per_batch);
  EXPECT_EQ(c.daemon.cpu_affinity, (std::vector<int>{1, 0}));
  ASSERT_EQ(c.streams.size(), 2u);
  EXPECT_TRUE(c.streams[0].busy_poll);
  EXPECT_FALSE(c.streams[1].busy_poll);
  ASSERT_EQ(c.outputs.size(), 1u);
  EXPECT_FALSE(c.outputs[0].send.sendmmsg);

  const DaemonConfig d = parse_config("[[stream]]\nid = 1\nname = \"a\"\ndriver = { type = \"synthetic\" }\n"
                                      "[[output]]\ndestinations = [\"127.0.0.1:5700\"]\n",
                                      "/nonexistent/defaults.toml");
  const DaemonSettings defaults;
  EXPECT_EQ(d.daemon.fair_on, FairThread::Driver);
  EXPECT_EQ(d.daemon.publish_on, defaults.publish_on);
  EXPECT_EQ(d.daemon.spin_us, defaults.spin_us);
  EXPECT_TRUE(d.daemon.wake_per_batch);
  EXPECT_TRUE(d.daemon.cpu_affinity.empty());
  EXPECT_FALSE(d.streams[0].busy_poll);
  EXPECT_TRUE(d.outputs[0].send.sendmmsg);
}

TEST(Config, AMinimalConfigGetsEveryDefault) {
  const DaemonConfig c = parse_config(R"toml(
[[stream]]
id = 0
name = "s"
driver = { type = "synthetic" }
)toml",
                                      "/nonexistent/minimal.toml");
  EXPECT_FALSE(c.daemon.exit_when_sources_end);
  EXPECT_FALSE(c.daemon.session_id.has_value());
  EXPECT_EQ(c.logging.level, "info");
  EXPECT_EQ(c.logging.target, LogTarget::Auto);
  EXPECT_EQ(c.logging.status_interval, 60.0);
  EXPECT_TRUE(c.outputs.empty());
  EXPECT_FALSE(c.recorder.enabled);
  ASSERT_EQ(c.streams.size(), 1u);
  const WindowConfig d;
  const WindowConfig& e = c.streams[0].engine;
  EXPECT_EQ(e.window, d.window);
  EXPECT_EQ(e.lag, d.lag);
  EXPECT_EQ(e.order, d.order);
  EXPECT_EQ(e.solver, d.solver);
  EXPECT_EQ(e.iterations, d.iterations);
  EXPECT_EQ(e.smoothing_r, d.smoothing_r);  // unset: adapted to the stream
  EXPECT_EQ(e.smoothing_t, d.smoothing_t);
  EXPECT_EQ(e.cutoff_hz, d.cutoff_hz);
  EXPECT_EQ(e.window_s, d.window_s);
  EXPECT_EQ(e.horizon_s, d.horizon_s);
  EXPECT_EQ(e.continuity, d.continuity);
  EXPECT_EQ(e.lambda_r, d.lambda_r);
  EXPECT_EQ(e.lambda_t, d.lambda_t);
  EXPECT_EQ(e.variant, d.variant);
  EXPECT_EQ(e.epsilon_r, d.epsilon_r);
  EXPECT_EQ(e.epsilon_t, d.epsilon_t);
  EXPECT_EQ(e.bound, d.bound);
  EXPECT_EQ(e.gate.gap_threshold, d.gate.gap_threshold);
  EXPECT_EQ(e.gate.unit_tolerance, d.gate.unit_tolerance);
  EXPECT_EQ(e.adaptation.noise_time_s, d.adaptation.noise_time_s);
  EXPECT_EQ(e.adaptation.motion_time_s, d.adaptation.motion_time_s);
  EXPECT_EQ(e.adaptation.motion_span_s, d.adaptation.motion_span_s);
  EXPECT_EQ(e.adaptation.motion_margin, d.adaptation.motion_margin);
}

TEST(Config, ASerialSourceFillsEveryField) {
  const std::vector<std::string> protocols = drivers::decoder_protocols();
  ASSERT_FALSE(protocols.empty()) << "a serial source needs a registered decoder (drivers/src/decoder_registry.cpp)";
  const std::string protocol = protocols.front();
  std::string text = R"toml(
[[stream]]
id = 1
name = "by-usb"
[stream.driver]
type = "serial"
usb = "1A86:7523"
serial_number = "A50285BI"
baud = 921600
data_bits = 7
parity = "even"
stop_bits = 2
flow_control = "rtscts"
protocol = "@"
time_source = "device"
reconnect_min = 0.5
reconnect_max = 10

[[stream]]
id = 2
name = "by-path"
driver = { type = "serial", device = "/dev/serial/by-id/usb-FTDI_imu-if00-port0", protocol = "@" }
)toml";
  for (std::size_t at = text.find('@'); at != std::string::npos; at = text.find('@')) text.replace(at, 1, protocol);
  const bool witmotion = std::find(protocols.begin(), protocols.end(), "witmotion") != protocols.end();
  if (witmotion) {
    text += R"toml(
[[stream]]
id = 3
name = "wit"
driver = { type = "serial", device = "/dev/ttyUSB1", protocol = "witmotion", witmotion_scalar = "last" }
)toml";
  }
  const DaemonConfig c = parse_config(text, "/nonexistent/serial.toml");
  ASSERT_EQ(c.streams.size(), witmotion ? 3u : 2u);

  ASSERT_EQ(c.streams[0].driver.type, DriverType::Serial);
  const SerialSourceConfig& a = c.streams[0].driver.serial;
  EXPECT_TRUE(a.port.device.empty());
  ASSERT_TRUE(a.port.usb.has_value());
  EXPECT_EQ(a.port.usb->vid, 0x1a86);
  EXPECT_EQ(a.port.usb->pid, 0x7523);
  EXPECT_EQ(a.port.usb_serial, "A50285BI");
  EXPECT_EQ(a.settings.baud, 921600);
  EXPECT_EQ(a.settings.data_bits, 7);
  EXPECT_EQ(a.settings.parity, drivers::Parity::Even);
  EXPECT_EQ(a.settings.stop_bits, 2);
  EXPECT_EQ(a.settings.flow_control, drivers::FlowControl::RtsCts);
  EXPECT_EQ(a.protocol, protocol);
  EXPECT_EQ(a.time_source, drivers::TimeSource::Device);
  EXPECT_EQ(a.reconnect_min, 0.5);
  EXPECT_EQ(a.reconnect_max, 10.0);

  // Every default.
  ASSERT_EQ(c.streams[1].driver.type, DriverType::Serial);
  const SerialSourceConfig& b = c.streams[1].driver.serial;
  EXPECT_EQ(b.port.device, "/dev/serial/by-id/usb-FTDI_imu-if00-port0");
  EXPECT_FALSE(b.port.usb.has_value());
  EXPECT_EQ(b.port.usb_serial, "");
  const drivers::SerialSettings d;
  EXPECT_EQ(b.settings.baud, 115200);
  EXPECT_EQ(b.settings.data_bits, d.data_bits);
  EXPECT_EQ(b.settings.parity, drivers::Parity::None);
  EXPECT_EQ(b.settings.stop_bits, 1);
  EXPECT_EQ(b.settings.flow_control, drivers::FlowControl::None);
  EXPECT_EQ(b.time_source, drivers::TimeSource::Auto);
  EXPECT_EQ(b.reconnect_min, 0.1);
  EXPECT_EQ(b.reconnect_max, 5.0);
  EXPECT_FALSE(b.decoder.contains("witmotion_scalar"));  // the decoder's default
  // No rate from a serial driver: the engine keeps its defaults.
  EXPECT_EQ(c.streams[1].engine.window, WindowConfig{}.window);

  if (witmotion) {
    EXPECT_EQ(option_text(c.streams[2].driver.serial.decoder, "witmotion_scalar"), "last");
  }
}

TEST(Config, DecoderOptionsReachTheirDecoderAsTextOrNumber) {
  const DaemonConfig c = parse_config(R"([[stream]]
id = 1
name = "vn"
driver = { type = "serial", device = "/dev/ttyUSB0", protocol = "vectornav", vectornav_unchecked = "accept" }
[[stream]]
id = 2
name = "yost"
driver = { type = "serial", device = "/dev/ttyUSB1", protocol = "yost", yost_header = 0x4F, yost_data_length = 16 }
)", "/virtual/options.toml");
  EXPECT_EQ(option_text(c.streams[0].driver.serial.decoder, "vectornav_unchecked"), "accept");
  EXPECT_EQ(option_text(c.streams[1].driver.serial.decoder, "yost_header"), "79");
  EXPECT_EQ(option_text(c.streams[1].driver.serial.decoder, "yost_data_length"), "16");
}

TEST(Config, HidSourcesOfBothProtocolsAreParsed) {
  const DaemonConfig c = parse_config(R"([[stream]]
id = 1
name = "st"
[stream.driver]
type = "hid"
usb = "0483:5750"
serial_number = "2053386B5650"
protocol = "hid-sensor"
component_order = "wxyz"
report_id = 8
conjugate = true
timestamp_count_s = 1e-3
time_source = "receive"
reconnect_min = 0.5
reconnect_max = 10
[[stream]]
id = 2
name = "vendor"
driver = { type = "hid", device = "/dev/hidraw3", protocol = "hid-vendor", report_id = 2, report_length = 20, value_type = "float32", byte_order = "big", offsets = [4, 8, 12, 16], order = "w-last", scale = 2.0 }
[[stream]]
id = 3
name = "bits"
driver = { type = "hid", device = "/dev/hidraw4", protocol = "hid-vendor", offsets_bits = [4, 20, 36, 52] }
)", "/virtual/hid.toml");
  ASSERT_EQ(c.streams.size(), 3u);
  ASSERT_EQ(c.streams[0].driver.type, DriverType::Hid);
  const HidSourceConfig& a = c.streams[0].driver.hid;
  ASSERT_TRUE(a.device.usb);
  EXPECT_EQ(a.device.usb->vid, 0x0483);
  EXPECT_EQ(a.device.usb->pid, 0x5750);
  EXPECT_EQ(a.device.serial, "2053386B5650");
  EXPECT_EQ(a.device.device, "");
  EXPECT_EQ(a.protocol, "hid-sensor");
  const drivers::HidSensorOrientationOptions as = drivers::hid_sensor_options(a.decoder);
  EXPECT_EQ(as.component_order, "wxyz");
  EXPECT_EQ(as.report_id, 8);
  EXPECT_TRUE(as.conjugate);
  EXPECT_EQ(as.timestamp_count_s, 1e-3);
  EXPECT_EQ(a.time_source, drivers::TimeSource::Receive);
  EXPECT_EQ(a.reconnect_min, 0.5);
  EXPECT_EQ(a.reconnect_max, 10.0);

  const HidSourceConfig& b = c.streams[1].driver.hid;
  EXPECT_EQ(b.device.device, "/dev/hidraw3");
  EXPECT_FALSE(b.device.usb);
  EXPECT_EQ(b.protocol, "hid-vendor");
  const drivers::HidVendorLayout bv = drivers::hid_vendor_layout(b.decoder);
  EXPECT_EQ(bv.report_id, 2);
  EXPECT_EQ(bv.report_length, 20u);
  EXPECT_EQ(bv.type, drivers::HidVendorType::Float32);
  EXPECT_TRUE(bv.big_endian);
  EXPECT_EQ(bv.offset_bits, (std::array<std::uint32_t, 4>{32, 64, 96, 128}));
  EXPECT_FALSE(bv.w_first);
  EXPECT_EQ(bv.scale, 2.0);
  EXPECT_EQ(b.time_source, drivers::TimeSource::Auto);

  const HidSourceConfig& d = c.streams[2].driver.hid;
  const drivers::HidVendorLayout dv = drivers::hid_vendor_layout(d.decoder);
  EXPECT_EQ(dv.report_id, -1);  // the default: no report ID byte
  EXPECT_EQ(dv.type, drivers::HidVendorType::Int16);
  EXPECT_EQ(dv.offset_bits, (std::array<std::uint32_t, 4>{4, 20, 36, 52}));
  EXPECT_TRUE(dv.w_first);
  EXPECT_EQ(dv.scale, 1.0 / 16384.0);
}

TEST(Config, SocketCanSourcesAndCandumpReplaysTakeTheirKeys) {
  testing::ScratchDir dir("posefair-config-");
  write_file(dir / "bus.log", "(1.000000) can0 021#7FFF000000000000\n");
  const DaemonConfig c = parse_config(R"toml(
[[stream]]
id = 1
name = "glove"
driver = { type = "socketcan", interface = "can0", protocol = "posefair-can", posefair_base_id = 0x204, posefair_id_format = "extended", fd = true, time_source = "receive", reconnect_min = 0.2, reconnect_max = 2.0 }
[[stream]]
id = 2
name = "mti"
driver = { type = "socketcan", interface = "vcan1", protocol = "xsens-can", xsens_quaternion_id = "0x121", xsens_sample_time_unit = "1us" }
[[stream]]
id = 3
name = "ahrs"
driver = { type = "socketcan", interface = "can1", protocol = "dronecan-ahrs", dronecan_node_id = 42 }
[[stream]]
id = 4
name = "recorded"
driver = { type = "replay", candump = "bus.log", interface = "can0", protocol = "xsens-can", timing = "fast", time_source = "device" }
)toml", dir / "cfg.toml");
  ASSERT_EQ(c.streams.size(), 4u);
  ASSERT_EQ(c.streams[0].driver.type, DriverType::SocketCan);
  const SocketCanSourceConfig& a = c.streams[0].driver.socketcan;
  EXPECT_EQ(a.interface, "can0");
  EXPECT_EQ(a.protocol, "posefair-can");
  EXPECT_EQ(option_text(a.decoder, "posefair_base_id"), "516");
  EXPECT_EQ(option_text(a.decoder, "posefair_id_format"), "extended");
  EXPECT_TRUE(a.fd);
  EXPECT_EQ(a.time_source, drivers::TimeSource::Receive);
  EXPECT_EQ(a.reconnect_min, 0.2);
  EXPECT_EQ(a.reconnect_max, 2.0);
  const SocketCanSourceConfig& b = c.streams[1].driver.socketcan;
  EXPECT_EQ(option_text(b.decoder, "xsens_quaternion_id"), "0x121");
  EXPECT_EQ(option_text(b.decoder, "xsens_sample_time_unit"), "1us");
  EXPECT_FALSE(b.fd);
  EXPECT_EQ(b.reconnect_min, 0.1);
  EXPECT_EQ(b.reconnect_max, 5.0);
  EXPECT_EQ(option_text(c.streams[2].driver.socketcan.decoder, "dronecan_node_id"), "42");
  ASSERT_EQ(c.streams[3].driver.type, DriverType::Replay);
  const ReplaySourceConfig& r = c.streams[3].driver.replay;
  EXPECT_EQ(r.candump, dir / "bus.log");
  EXPECT_TRUE(r.path.empty());
  EXPECT_EQ(r.can.interface, "can0");
  EXPECT_EQ(r.can.protocol, "xsens-can");
  EXPECT_EQ(r.can.time_source, drivers::TimeSource::Device);
  EXPECT_EQ(r.options.timing, drivers::ReplayTiming::AsFastAsPossible);
  EXPECT_EQ(r.options.stream_id, 4u);
}

TEST(Config, TheSplineTableSetsBridgingAndResampling) {
  const DaemonConfig c = parse_config(R"toml(
[[stream]]
id = 1
name = "plain"
driver = { type = "synthetic" }

[[stream]]
id = 2
name = "display"
driver = { type = "synthetic" }
[stream.spline]
publish_rate_hz = 90.0
bridge_gap = 0.15
order = 3
manifold = "lie-group"
velocity = "central"
)toml",
                                      "spline.toml");
  ASSERT_EQ(c.streams.size(), 2u);
  EXPECT_FALSE(c.streams[0].spline.resampling());
  EXPECT_FALSE(c.streams[0].spline.bridging());
  const SplineConfig& s = c.streams[1].spline;
  EXPECT_TRUE(s.resampling());
  EXPECT_TRUE(s.bridging());
  EXPECT_EQ(s.publish_rate_hz, 90.0);
  EXPECT_EQ(s.bridge_gap, 0.15);
  EXPECT_EQ(s.spline.order, 3);
  EXPECT_EQ(s.spline.manifold, geometric_splines::OrientationManifold::LieGroup);
  EXPECT_EQ(s.spline.velocity.estimator, geometric_splines::KnotVelocityEstimator::CentralDifference);
}

TEST(Config, TheFusionTableNamesAnEstimatorAndItsOptions) {
  const DaemonConfig c = parse_config(R"toml(
[[stream]]
id = 1
name = "poses"
driver = { type = "synthetic" }

[[stream]]
id = 2
name = "imu"
driver = { type = "synthetic" }
[stream.fusion]
estimator = "madgwick"
beta = 0.05
magnetometer = false

[[stream]]
id = 3
name = "imu-default"
driver = { type = "synthetic" }
fusion = { tau_acc = 4 }
)toml",
                                      "fusion.toml");
  ASSERT_EQ(c.streams.size(), 3u);
  EXPECT_FALSE(c.streams[0].fusion.has_value());
  ASSERT_TRUE(c.streams[1].fusion.has_value());
  EXPECT_EQ(c.streams[1].fusion->estimator, "madgwick");
  EXPECT_EQ(std::get<double>(c.streams[1].fusion->options.at("beta")), 0.05);
  EXPECT_EQ(std::get<bool>(c.streams[1].fusion->options.at("magnetometer")), false);
  ASSERT_TRUE(c.streams[2].fusion.has_value());
  EXPECT_EQ(c.streams[2].fusion->estimator, "vqf");  // the registry's first
  EXPECT_EQ(std::get<double>(c.streams[2].fusion->options.at("tau_acc")), 4.0);  // an integer taken as a float
}

// [stream.engine] gyro_stream names another stream; the pair keeps the stream's gyro keys, and
// a source with a fusion stage (a raw IMU) keeps its own gyro aiding off.
TEST(Config, AGyroStreamNamesAnotherStreamOnTheBody) {
  posefair::testing::ScratchDir dir("posefair-config-");
  write_file(dir / "optical.tum", "0 0 0 0 0 0 0 1\n");
  const DaemonConfig c = parse_config(R"toml(
[[stream]]
id = 1
name = "optical"
driver = { type = "replay", path = "optical.tum" }
[stream.engine]
gyro_stream = "imu"
gyro_mounting = [90, 0, 0]
gyro_time_offset = 0.004

[[stream]]
id = 2
name = "imu"
driver = { type = "serial", device = "/dev/ttyUSB0", protocol = "xsens" }
fusion = { magnetometer = false }
)toml",
                                      dir / "paired.toml");
  ASSERT_EQ(c.streams.size(), 2u);
  EXPECT_EQ(c.streams[0].gyro_stream, "imu");
  EXPECT_TRUE(c.streams[0].engine.gyro.enabled);
  EXPECT_DOUBLE_EQ(c.streams[0].engine.gyro.time_offset_s, 0.004);
  EXPECT_LT(so3::rotation_angle(c.streams[0].engine.gyro.mounting, so3::from_rotation_vector(Vec3(0, 0, M_PI / 2))), 1e-9);
  EXPECT_EQ(c.streams[1].gyro_stream, "");
  EXPECT_FALSE(c.streams[1].engine.gyro.enabled);
}

TEST(Config, PoseInterpolationIsTheSplineUnlessMatrixLerpIsChosen) {
  const DaemonConfig c = parse_config(R"toml(
[[stream]]
id = 1
name = "default"
driver = { type = "synthetic" }
spline = { publish_rate_hz = 90.0 }

[[stream]]
id = 2
name = "explicit"
driver = { type = "synthetic" }
spline = { publish_rate_hz = 90.0, order = 1, pose_interpolation = "spline" }

[[stream]]
id = 3
name = "matrix"
driver = { type = "synthetic" }
spline = { publish_rate_hz = 90.0, bridge_gap = 0.1, pose_interpolation = "matrix-lerp" }
)toml",
                                      "lerp.toml");
  ASSERT_EQ(c.streams.size(), 3u);
  EXPECT_EQ(c.streams[0].spline.pose_interpolation, PoseInterpolation::Spline);
  EXPECT_EQ(c.streams[1].spline.pose_interpolation, PoseInterpolation::Spline);
  EXPECT_EQ(c.streams[1].spline.spline.order, 1);
  EXPECT_EQ(c.streams[2].spline.pose_interpolation, PoseInterpolation::MatrixLerp);
  EXPECT_TRUE(c.streams[2].spline.bridging());
}

TEST(Config, TheGpioTableSetsTheDataReadyAndOutputLines) {
  const DaemonConfig c = parse_config(R"toml(
[[stream]]
id = 1
name = "plain"
driver = { type = "synthetic" }

[[stream]]
id = 2
name = "imu"
driver = { type = "synthetic", rate_hz = 200.0 }
[stream.gpio]
chip = "gpio-sim.0-node0"
data_ready_line = 17
edge = "falling"
bias = "pull-up"
tolerance_min = 0.0005
tolerance_max = 0.004
output_line = "SCOPE"
output_mode = "heartbeat"
heartbeat_hz = 50

[[stream]]
id = 3
name = "out-only"
driver = { type = "synthetic" }
gpio = { chip = "/dev/gpiochip1", output_line = 2 }
)toml",
                                      "gpio.toml");
  ASSERT_EQ(c.streams.size(), 3u);
  EXPECT_FALSE(c.streams[0].gpio.has_value());
  ASSERT_TRUE(c.streams[1].gpio.has_value());
  const GpioConfig& g = *c.streams[1].gpio;
  EXPECT_EQ(g.chip, "gpio-sim.0-node0");
  ASSERT_TRUE(g.data_ready.has_value());
  EXPECT_EQ(g.data_ready->offset, 17u);
  EXPECT_EQ(g.edge, drivers::GpioEdge::Falling);
  EXPECT_EQ(g.bias, drivers::GpioBias::PullUp);
  EXPECT_EQ(g.pairing.tolerance_min, 0.0005);
  EXPECT_EQ(g.pairing.tolerance_max, 0.004);
  ASSERT_TRUE(g.output.has_value());
  EXPECT_FALSE(g.output->offset.has_value());
  EXPECT_EQ(g.output->name, "SCOPE");
  EXPECT_EQ(g.output_mode, drivers::GpioOutputMode::Heartbeat);
  EXPECT_EQ(g.heartbeat_hz, 50.0);
  ASSERT_TRUE(c.streams[2].gpio.has_value());
  const GpioConfig& o = *c.streams[2].gpio;
  EXPECT_FALSE(o.data_ready.has_value());
  EXPECT_EQ(o.output->offset, 2u);
  EXPECT_EQ(o.output_mode, drivers::GpioOutputMode::PerPose);
  // Defaults of the input line: rising edge, bias as it is, the pairer's window.
  EXPECT_EQ(o.edge, drivers::GpioEdge::Rising);
  EXPECT_EQ(o.bias, drivers::GpioBias::AsIs);
  EXPECT_EQ(o.pairing.tolerance_max, drivers::EdgePairingOptions{}.tolerance_max);
}

TEST(Config, TheGpioLinesTakeTheDeviceDriversReconnectKeys) {
  const DaemonConfig c = parse_config(R"toml(
[[stream]]
id = 1
name = "imu"
driver = { type = "synthetic" }
[stream.gpio]
chip = "gpiochip0"
data_ready_line = 3
reconnect_min = 0.05
reconnect_max = 1.5

[[stream]]
id = 2
name = "scope"
driver = { type = "synthetic" }
gpio = { chip = "gpiochip0", output_line = 4 }
)toml",
                                      "gpio.toml");
  ASSERT_EQ(c.streams.size(), 2u);
  EXPECT_EQ(c.streams[0].gpio->reconnect_min, 0.05);
  EXPECT_EQ(c.streams[0].gpio->reconnect_max, 1.5);
  // Unset: the GPIO lines' default, 0.1 s doubling to 2 s.
  EXPECT_EQ(c.streams[1].gpio->reconnect_min, 0.1);
  EXPECT_EQ(c.streams[1].gpio->reconnect_max, 2.0);
  try {
    parse_config("[[stream]]\nid = 1\nname = \"a\"\ndriver = { type = \"synthetic\" }\n[stream.gpio]\nchip = \"gpiochip0\"\n"
                 "output_line = 4\nreconnect_min = 0.5\nreconnect_max = 0.2\n",
                 "cfg.toml");
    FAIL() << "accepted";
  } catch (const ConfigError& e) {
    EXPECT_EQ(e.key(), "stream[1].gpio.reconnect_max");
    EXPECT_EQ(e.line(), 9u);
    EXPECT_EQ(e.message(), "must be >= reconnect_min (0.5 s), got 0.2");
  }
}

TEST(Config, TheMostSpecificTableDecidesTheSmoothing) {
  testing::ScratchDir dir("posefair-config-");
  write_file(dir / "poses.csv", "t,qw,qx,qy,qz\n0,1,0,0,0\n");
  const DaemonConfig c = parse_config(R"toml(
[engine]
order = 3
cutoff_hz = 5
rate_hz = 100

[[stream]]                 # smoothing here replaces [engine]'s cutoff_hz for both
id = 1
name = "a"
driver = { type = "replay", path = "poses.csv" }
engine = { smoothing = 300 }

[[stream]]                 # smoothing_t replaces only the translational half
id = 2
name = "b"
driver = { type = "replay", path = "poses.csv" }
engine = { smoothing_t = 300 }

[[stream]]                 # [engine]'s cutoff at [engine]'s rate
id = 3
name = "c"
driver = { type = "replay", path = "poses.csv" }

[[stream]]                 # a synthetic driver's rate comes before [engine]'s
id = 4
name = "d"
driver = { type = "synthetic", rate_hz = 400 }

[[stream]]                 # the stream's own rate_hz comes first
id = 5
name = "e"
driver = { type = "synthetic", rate_hz = 400 }
engine = { rate_hz = 50 }

[[stream]]                 # its own cutoff_hz and order, at the synthetic driver's default 100 Hz
id = 6
name = "f"
driver = { type = "synthetic" }
engine = { cutoff_hz = 2, order = 2 }
)toml",
                                      dir / "cfg.toml");
  ASSERT_EQ(c.streams.size(), 6u);
  const double at100 = smoothing_for_cutoff(5.0, 100.0, 3);
  EXPECT_EQ(c.streams[0].engine.smoothing_r.value_or(-1.0), 300.0);
  EXPECT_EQ(c.streams[0].engine.smoothing_t.value_or(-1.0), 300.0);
  EXPECT_DOUBLE_EQ(c.streams[1].engine.smoothing_r.value_or(-1.0), at100);
  EXPECT_EQ(c.streams[1].engine.smoothing_t.value_or(-1.0), 300.0);
  EXPECT_DOUBLE_EQ(c.streams[2].engine.smoothing_r.value_or(-1.0), at100);
  EXPECT_DOUBLE_EQ(c.streams[2].engine.smoothing_t.value_or(-1.0), at100);
  EXPECT_DOUBLE_EQ(c.streams[3].engine.smoothing_r.value_or(-1.0), smoothing_for_cutoff(5.0, 400.0, 3));
  EXPECT_DOUBLE_EQ(c.streams[4].engine.smoothing_r.value_or(-1.0), smoothing_for_cutoff(5.0, 50.0, 3));
  EXPECT_DOUBLE_EQ(c.streams[5].engine.smoothing_t.value_or(-1.0), smoothing_for_cutoff(2.0, 100.0, 2));

  // And the other way round: a stream's cutoff_hz replaces [engine]'s smoothing.
  const DaemonConfig d = parse_config(R"toml(
[engine]
smoothing_r = 7
[[stream]]
id = 1
name = "a"
driver = { type = "synthetic", rate_hz = 250 }
engine = { cutoff_hz = 10 }
)toml",
                                      dir / "cfg.toml");
  EXPECT_DOUBLE_EQ(d.streams.at(0).engine.smoothing_r.value_or(-1.0), smoothing_for_cutoff(10.0, 250.0, 2));
  EXPECT_DOUBLE_EQ(d.streams.at(0).engine.smoothing_t.value_or(-1.0), smoothing_for_cutoff(10.0, 250.0, 2));

  // Without a known rate the cutoff goes to the engine, which applies it at the rate it measures.
  const DaemonConfig e = parse_config(R"toml(
[engine]
cutoff_hz = 8
[[stream]]
id = 1
name = "a"
driver = { type = "replay", path = "poses.csv" }
)toml",
                                      dir / "cfg.toml");
  EXPECT_EQ(e.streams.at(0).engine.cutoff_hz, std::optional<double>(8.0));
  EXPECT_FALSE(e.streams.at(0).engine.smoothing_r.has_value());
  EXPECT_EQ(e.streams.at(0).engine.rate_hz, 0.0);
}

TEST(Config, OutputsOfTheSameOptionlessEncodingShareOneEncoder) {
  // The encoder is built once at load; the publisher encodes each pose once per encoder object.
  const DaemonConfig c = parse_config(R"([[stream]]
id = 1
name = "a"
driver = { type = "synthetic" }
[[output]]
destinations = ["127.0.0.1:5700"]
[[output]]
encoding = "binary"
destinations = ["127.0.0.1:5701"]
[[output]]
encoding = "json"
destinations = ["127.0.0.1:5702"]
)", "/virtual/shared-encoder.toml");
  ASSERT_EQ(c.outputs.size(), 3u);
  EXPECT_EQ(c.outputs[0].encoder, c.outputs[1].encoder);
  EXPECT_EQ(c.outputs[2].encoder->name(), "json");
  EXPECT_NE(c.outputs[0].encoder, c.outputs[2].encoder);
}

TEST(Config, TheExampleConfigsLoad) {
  for (const char* name : {"config/minimal.toml", "config/robot.toml", "config/vr-rig.toml", "config/clients.toml",
                           "data/demo/posefaird.toml"}) {
    SCOPED_TRACE(name);
    try {
      const DaemonConfig c = load_config(kSourceDir / name);
      EXPECT_FALSE(c.streams.empty());
    } catch (const ConfigError& e) {
      ADD_FAILURE() << e.what();
    }
  }
}

TEST(Config, TheRos2ExampleLoadsWhenTheBuildHasDds) {
  // A build without Cyclone DDS has no dds encoding (docs/outputs.md): then the file is refused
  // at its encoding key, like any unknown encoding.
  try {
    const DaemonConfig c = load_config(kSourceDir / "config/ros2.toml");
    ASSERT_NE(find_output_encoder("dds"), nullptr);
    ASSERT_EQ(c.outputs.size(), 1u);
    EXPECT_EQ(c.outputs[0].encoder->name(), "dds");
    EXPECT_TRUE(c.outputs[0].destinations.empty());
  } catch (const ConfigError& e) {
    EXPECT_EQ(find_output_encoder("dds"), nullptr) << e.what();
    EXPECT_EQ(e.key(), "output[1].encoding") << e.what();
  }
}

TEST(Config, TheClientExampleSetsFramesRatesAndEncodings) {
  const DaemonConfig c = load_config(kSourceDir / "config/clients.toml");
  ASSERT_EQ(c.streams.size(), 3u);
  EXPECT_TRUE(c.streams[0].frame.mounting.isApprox(Quat(0, 0, 0, 1), 1e-12) ||
              c.streams[0].frame.mounting.isApprox(Quat(0, 0, 0, -1), 1e-12));  // 180° about z
  EXPECT_TRUE(c.streams[1].frame.identity());
  ASSERT_EQ(c.outputs.size(), 4u);
  const char* names[] = {"opentrack", "freed", "vmc", "vrchat"};
  const double rates[] = {250, 50, 60, 90};
  const std::uint16_t ports[] = {4242, 40000, 39539, 9000};
  for (std::size_t i = 0; i < 4; ++i) {
    EXPECT_EQ(c.outputs[i].encoder->name(), names[i]);
    EXPECT_EQ(c.outputs[i].max_rate_hz, rates[i]);
    EXPECT_EQ(c.outputs[i].destinations.at(0).port(), ports[i]) << names[i];
  }
}

TEST(Config, TheDemoConfigReplaysTheBundledExcerpt) {
  const DaemonConfig c = load_config(kSourceDir / "data/demo/posefaird.toml");
  EXPECT_TRUE(c.daemon.exit_when_sources_end);
  ASSERT_EQ(c.streams.size(), 1u);
  const StreamConfig& s = c.streams[0];
  EXPECT_EQ(s.id, 1u);
  EXPECT_EQ(s.name, "broad07");
  ASSERT_EQ(s.driver.type, DriverType::Replay);
  EXPECT_TRUE(std::filesystem::equivalent(s.driver.replay.path, kSourceDir / "data/demo/broad-07-excerpt.csv"));
  EXPECT_EQ(s.driver.replay.options.timing, drivers::ReplayTiming::Original);
  EXPECT_EQ(s.driver.replay.options.speed, 1.0);
  // The engine's defaults: adapted smoothing, a time-span window, at the recording's rate.
  const WindowConfig defaults;
  EXPECT_EQ(s.engine.order, defaults.order);
  EXPECT_EQ(s.engine.window, 0);
  EXPECT_EQ(s.engine.lag, 0);
  EXPECT_FALSE(s.engine.smoothing_r.has_value());
  EXPECT_FALSE(s.engine.cutoff_hz.has_value());
  EXPECT_EQ(s.engine.rate_hz, 285.7);
  EXPECT_DOUBLE_EQ(s.engine.epsilon_r, 0.01);
  EXPECT_DOUBLE_EQ(s.engine.epsilon_t, 0.002);
  ASSERT_EQ(c.outputs.size(), 1u);
  EXPECT_EQ(c.outputs[0].encoder->name(), "binary");
  ASSERT_EQ(c.outputs[0].destinations.size(), 1u);
  EXPECT_EQ(c.outputs[0].destinations[0], endpoint("127.0.0.1:5700"));
  // The replay driver reads the file with the options as configured.
  const drivers::ReplayDriver replay(s.driver.replay.path, s.driver.replay.options);
  EXPECT_EQ(replay.samples().size(), 2000u);
  EXPECT_EQ(replay.samples().front().stream_id, 1u);
}

TEST(Config, SubscriptionAndControlTables) {
  testing::ScratchDir dir("posefair-config-");
  write_file(dir.path() / "psk", "000102030405060708090a0b0c0d0e0f101112131415161718191a1b1c1d1e1f\n");
  const DaemonConfig c = parse_config(R"([[stream]]
id = 1
name = "a"
driver = { type = "synthetic" }
[subscription]
listen = "[::1]"
allow = ["192.168.10.0/24", "fd00::/8", "10.1.2.3"]
max_subscribers = 8
max_per_address = 2
rate_per_source = 5
burst_per_source = 3
source_table = 1024
max_lease = 120
psk_file = "psk"
[control]
socket = "ctl.sock"
mode = 0o600
group = "root"
)",
                                      dir.path() / "cfg.toml");
  ASSERT_TRUE(c.subscription);
  const SubscriptionSettings& s = *c.subscription;
  EXPECT_EQ(s.listen.to_string(), "[::1]:5710");
  ASSERT_EQ(s.allow.ranges().size(), 3u);
  EXPECT_EQ(s.allow.ranges()[2].to_string(), "10.1.2.3/32");
  EXPECT_EQ(s.max_subscribers, 8u);
  EXPECT_EQ(s.max_per_address, 2u);
  EXPECT_EQ(s.rate_per_source, 5.0);
  EXPECT_EQ(s.burst_per_source, 3.0);
  EXPECT_EQ(s.source_table, 1024u);
  EXPECT_EQ(s.max_lease, 120.0);
  ASSERT_TRUE(s.psk);
  EXPECT_EQ((*s.psk)[31], 0x1f);
  ASSERT_TRUE(c.control);
  EXPECT_EQ(c.control->path, dir.path() / "ctl.sock");
  EXPECT_EQ(c.control->mode, 0600u);
  EXPECT_EQ(c.control->group, "root");
  // Defaults: loopback only; and both off unless their table is there (or enabled = false).
  const DaemonConfig d = parse_config("[[stream]]\nid = 1\nname = \"a\"\ndriver = { type = \"synthetic\" }\n"
                                      "[subscription]\n[control]\n",
                                      dir.path() / "cfg.toml");
  EXPECT_EQ(d.subscription->listen.to_string(), "127.0.0.1:5710");
  EXPECT_TRUE(d.subscription->allow.allows(*Endpoint::parse("127.0.0.1:1")));
  EXPECT_FALSE(d.subscription->allow.allows(*Endpoint::parse("192.168.1.1:1")));
  EXPECT_EQ(d.control->path, "/run/posefaird/control");
  EXPECT_EQ(d.control->mode, 0660u);
  const DaemonConfig off = parse_config("[[stream]]\nid = 1\nname = \"a\"\ndriver = { type = \"synthetic\" }\n"
                                        "[subscription]\nenabled = false\n",
                                        dir.path() / "cfg.toml");
  EXPECT_FALSE(off.subscription);
  EXPECT_FALSE(off.control);
}

struct BadConfig {
  const char* name;
  const char* toml;
  const char* expected;  // a substring of what()
  std::uint32_t line;    // 0: the message carries no line
};

// Files in the scratch directory the rows may name: poses.csv, walk.bvh, imu.pflog (contents unread).
const std::vector<BadConfig> kBadConfigs = {
    {"syntax error", R"([[stream]]
id = = 1
)", "Error while parsing", 2},
    {"unknown top-level key", R"([[stream]]
id = 1
name = "a"
driver = { type = "synthetic" }
[loging]
level = "info"
)", "loging: unknown key (did you mean 'logging'?)", 5},
    {"unknown key in [engine]", R"([engine]
windw = 16
[[stream]]
id = 1
name = "a"
driver = { type = "synthetic" }
)", "engine.windw: unknown key (did you mean 'window'?)", 2},
    {"unknown key without a near one", R"([[stream]]
id = 1
name = "a"
driver = { type = "synthetic" }
colour = "red"
)", "stream[1].colour: unknown key", 5},
    {"wrong type", R"([[stream]]
id = 1
name = 5
driver = { type = "synthetic" }
)", "stream[1].name: expected a string, got an integer", 3},
    {"float for integer", R"([engine]
window = 32.0
[[stream]]
id = 1
name = "a"
driver = { type = "synthetic" }
)", "engine.window: expected an integer, got a float", 2},
    {"window out of range", R"([engine]
window = 5000
[[stream]]
id = 1
name = "a"
driver = { type = "synthetic" }
)", "engine.window: out of range: must be in [2, 4096], got 5000", 2},
    {"lag not below window", R"([[stream]]
id = 1
name = "a"
driver = { type = "synthetic" }
[stream.engine]
window = 16
lag = 16
)", "stream[1].engine.lag: lag must be in [0, window-1] = [0, 15], got 16", 7},
    {"order 4", R"([engine]
order = 4
[[stream]]
id = 1
name = "a"
driver = { type = "synthetic" }
)", "engine.order: must be 2 or 3, got 4", 2},
    {"window too small for the order, from [engine]", R"([engine]
order = 3
window = 3
[[stream]]
id = 1
name = "a"
driver = { type = "synthetic" }
)", "engine.window: window must hold 4 to 4096 samples for order 3, got 3 (for stream[1] 'a')", 3},
    {"unknown solver", R"([[stream]]
id = 1
name = "a"
driver = { type = "synthetic" }
engine = { solver = "newton" }
)", "stream[1].engine.solver: expected one of 'linear', 'gauss-newton', 'sweeps', got 'newton'", 5},
    {"duplicate stream id", R"([[stream]]
id = 1
name = "a"
driver = { type = "synthetic" }
[[stream]]
id = 1
name = "b"
driver = { type = "synthetic" }
)", "stream[2].id: duplicate stream id 1 (also stream[1])", 6},
    {"duplicate stream name", R"([[stream]]
id = 1
name = "a"
driver = { type = "synthetic" }
[[stream]]
id = 2
name = "a"
driver = { type = "synthetic" }
)", "stream[2].name: duplicate stream name 'a' (also stream[1])", 7},
    {"empty name", R"([[stream]]
id = 1
name = ""
driver = { type = "synthetic" }
)", "stream[1].name: must not be empty", 3},
    {"missing id", R"([daemon]
exit_when_sources_end = true

[[stream]]
name = "a"
driver = { type = "synthetic" }
)", "stream[1].id: missing required key", 4},
    {"missing driver", R"([[stream]]
id = 1
name = "a"
)", "stream[1].driver: missing required key", 1},
    {"unknown driver type", R"([[stream]]
id = 1
name = "a"
[stream.driver]
type = "modbus"
)", "stream[1].driver.type: expected one of 'replay', 'synthetic', 'serial', 'socketcan', 'hid', got 'modbus'", 5},
    {"replay key on a synthetic driver", R"([[stream]]
id = 1
name = "a"
driver = { type = "synthetic", path = "poses.csv" }
)", "stream[1].driver.path: unknown key for driver type synthetic (it belongs to type replay)", 4},
    {"nonexistent replay path", R"([[stream]]
id = 1
name = "a"
[stream.driver]
type = "replay"
path = "no-such-file.csv"
)", "stream[1].driver.path: no such file", 6},
    {"BVH without a joint", R"([[stream]]
id = 1
name = "a"
[stream.driver]
type = "replay"
path = "walk.bvh"
)", "stream[1].driver.joint: missing required key", 4},
    {"negative speed", R"([[stream]]
id = 1
name = "a"
[stream.driver]
type = "replay"
path = "poses.csv"
speed = -1
)", "stream[1].driver.speed: out of range: must be > 0, got -1", 7},
    {"synthetic rate too high", R"([[stream]]
id = 1
name = "a"
driver = { type = "synthetic", rate_hz = 200000 }
)", "stream[1].driver.rate_hz: out of range: must be in (0, 100000], got 200000", 4},
    {"bad destination", R"([[stream]]
id = 1
name = "a"
driver = { type = "synthetic" }
[[output]]
destinations = ["127.0.0.1", "localhost:5700"]
)", "output[1].destinations[2]: not a destination: 'localhost:5700'", 6},
    {"no destinations", R"([[stream]]
id = 1
name = "a"
driver = { type = "synthetic" }
[[output]]
destinations = []
)", "output[1].destinations: must list at least one destination", 6},
    {"output naming an unknown stream", R"([[stream]]
id = 1
name = "a"
driver = { type = "synthetic" }
[[output]]
destinations = ["127.0.0.1"]
streams = [1, 5]
)", "output[1].streams[2]: no [[stream]] has id 5", 7},
    {"ring capacity not a power of two", R"([[stream]]
id = 1
name = "a"
ring_capacity = 1000
driver = { type = "synthetic" }
)", "stream[1].ring_capacity: must be a power of two in [2, 1048576], got 1000", 4},
    {"ttl 300", R"([[stream]]
id = 1
name = "a"
driver = { type = "synthetic" }
[[output]]
destinations = ["239.255.0.1"]
ttl = 300
)", "output[1].ttl: out of range: must be in [0, 255], got 300", 7},
    {"unknown encoding", R"([[stream]]
id = 1
name = "a"
driver = { type = "synthetic" }
[[output]]
encoding = "jsn"
destinations = ["127.0.0.1"]
)", "output[1].encoding: expected one of {encodings}, got 'jsn' (did you mean 'json'?)", 6},
    {"vrchat tracker out of range", R"([[stream]]
id = 1
name = "a"
driver = { type = "synthetic" }
[[output]]
encoding = "vrchat"
destinations = ["127.0.0.1"]
trackers = [9]
)", "output[1].trackers[1]: '9' is not a VRChat tracker: expected \"1\" to \"8\" or \"head\"", 8},
    {"vmc bone that is not a Unity bone", R"([[stream]]
id = 1
name = "a"
driver = { type = "synthetic" }
[[stream]]
id = 2
name = "b"
driver = { type = "synthetic" }
[[output]]
encoding = "vmc"
destinations = ["127.0.0.1"]
bones = ["Head",
         "LeftPalm"]
)", "output[1].bones[2]: 'LeftPalm' is not a Unity HumanBodyBones name", 13},
    {"vmc bones fewer than the streams", R"([[stream]]
id = 1
name = "a"
driver = { type = "synthetic" }
[[stream]]
id = 2
name = "b"
driver = { type = "synthetic" }
[[output]]
encoding = "vmc"
destinations = ["127.0.0.1"]
streams = [2, 1]
bones = ["Head"]
)", "output[1].bones: names 1 bones for the 2 streams the output carries", 13},
    {"a vrchat key on an opentrack output", R"([[stream]]
id = 1
name = "a"
driver = { type = "synthetic" }
[[output]]
encoding = "opentrack"
destinations = ["127.0.0.1"]
trackers = [1]
)", "output[1].trackers: only for encoding 'vrchat'", 8},
    {"freed zoom beyond 24 bits", R"([[stream]]
id = 1
name = "a"
driver = { type = "synthetic" }
[[output]]
encoding = "freed"
destinations = ["127.0.0.1"]
zoom = 16777216
)", "output[1].zoom: out of range: must be in [0, 16777215], got 16777216", 8},
    {"max_rate_hz zero", R"([[stream]]
id = 1
name = "a"
driver = { type = "synthetic" }
[[output]]
destinations = ["127.0.0.1"]
max_rate_hz = 0
)", "output[1].max_rate_hz: out of range: must be > 0, got 0", 7},
    {"mounting of two numbers", R"([[stream]]
id = 1
name = "a"
mounting = [90, 0]
driver = { type = "synthetic" }
)", "stream[1].mounting: expected [yaw, pitch, roll] in degrees or a quaternion [w, x, y, z], got 2 numbers", 4},
    {"world a quaternion of norm 2", R"([[stream]]
id = 1
name = "a"
world = [2, 0, 0, 0]
driver = { type = "synthetic" }
)", "stream[1].world: a quaternion must have norm 1 (within 1e-3), got 2", 4},
    {"mounting angle not a number", R"([[stream]]
id = 1
name = "a"
mounting = [90, "left", 0]
driver = { type = "synthetic" }
)", "stream[1].mounting[2]: expected a number, got a string", 4},
    {"misspelt output key", R"([[stream]]
id = 1
name = "a"
driver = { type = "synthetic" }
[[output]]
destinations = ["127.0.0.1"]
ttll = 2
)", "output[1].ttll: unknown key (did you mean 'ttl'?)", 7},
    {"bad overflow policy", R"([[stream]]
id = 1
name = "a"
overflow = "drop-all"
driver = { type = "synthetic" }
)", "stream[1].overflow: expected one of 'drop-oldest', 'drop-newest', got 'drop-all'", 4},
    {"no [[stream]] at all", R"([daemon]
exit_when_sources_end = true
)", "stream: missing required key: at least one [[stream]] table is needed", 0},
    {"[stream] instead of [[stream]]", R"([stream]
id = 1
)", "stream: expected an array of tables ([[stream]]), got a table", 1},
    {"horizon with a lag", R"([[stream]]
id = 1
name = "a"
driver = { type = "synthetic", rate_hz = 100 }
[stream.engine]
lag = 2
horizon = 0.02
)", "stream[1].engine.horizon: a horizon (prediction) needs lag 0", 7},
    {"horizon with an epsilon bound", R"([engine]
epsilon_r = 0.05
horizon = 0.02
[[stream]]
id = 1
name = "a"
driver = { type = "synthetic", rate_hz = 100 }
)", "engine.horizon: a horizon (prediction) cannot be combined with an epsilon bound", 3},
    {"gyro_aided not a boolean", R"([engine]
gyro_aided = "yes"
[[stream]]
id = 1
name = "a"
driver = { type = "synthetic", rate_hz = 100 }
)", "engine.gyro_aided: expected a boolean, got a string", 2},
    {"gyro_estimate_offset not a boolean", R"([[stream]]
id = 1
name = "a"
driver = { type = "synthetic", rate_hz = 100 }
engine = { gyro_estimate_offset = 1 }
)", "stream[1].engine.gyro_estimate_offset: expected a boolean, got an integer", 5},
    {"prediction_check not a boolean", R"([[stream]]
id = 1
name = "a"
driver = { type = "synthetic", rate_hz = 100 }
engine = { prediction_check = "off" }
)", "stream[1].engine.prediction_check: expected a boolean, got a string", 5},
    {"gyro_time_offset out of range", R"([engine]
gyro_time_offset = 0.2
[[stream]]
id = 1
name = "a"
driver = { type = "synthetic", rate_hz = 100 }
)", "engine.gyro_time_offset: out of range: must be in [-0.05, 0.05], got 0.2", 2},
    {"gyro_time_offset not a number", R"([engine]
gyro_time_offset = "4ms"
[[stream]]
id = 1
name = "a"
driver = { type = "synthetic", rate_hz = 100 }
)", "engine.gyro_time_offset: expected a number, got a string", 2},
    {"gyro_mounting not a rotation", R"([engine]
gyro_mounting = [0, 90]
[[stream]]
id = 1
name = "a"
driver = { type = "synthetic", rate_hz = 100 }
)", "engine.gyro_mounting: ", 2},
    {"gyro_stream naming no stream", R"([[stream]]
id = 1
name = "optical"
driver = { type = "replay", path = "poses.csv" }
engine = { gyro_stream = "imu" }
[[stream]]
id = 2
name = "imu2"
driver = { type = "replay", path = "imu.pflog" }
)", "stream[1].engine.gyro_stream: no stream named 'imu' (streams: 'optical', 'imu2')", 5},
    {"gyro_stream naming its own stream", R"([[stream]]
id = 1
name = "optical"
driver = { type = "replay", path = "poses.csv" }
[stream.engine]
gyro_stream = "optical"
)", "stream[1].engine.gyro_stream: names this stream itself", 6},
    {"gyro_stream naming a synthetic stream", R"([[stream]]
id = 1
name = "optical"
driver = { type = "replay", path = "poses.csv" }
[stream.engine]
gyro_stream = "gen"
[[stream]]
id = 2
name = "gen"
driver = { type = "synthetic", rate_hz = 1000 }
)", "stream[1].engine.gyro_stream: stream 'gen' (stream[2]) has no gyroscope: a synthetic source", 6},
    {"gyro_stream naming a pose file replay", R"([[stream]]
id = 1
name = "optical"
driver = { type = "replay", path = "imu.pflog" }
[[stream]]
id = 2
name = "other"
driver = { type = "replay", path = "poses.csv" }
[stream.engine]
gyro_stream = "optical"
[[stream]]
id = 3
name = "third"
driver = { type = "replay", path = "imu.pflog" }
engine = { gyro_stream = "other" }
)", "stream[3].engine.gyro_stream: stream 'other' (stream[2]) has no gyroscope: it replays a pose file (poses.csv)", 15},
    {"gyro_stream cycle", R"([[stream]]
id = 1
name = "a"
driver = { type = "replay", path = "imu.pflog" }
engine = { gyro_stream = "b" }
[[stream]]
id = 2
name = "b"
driver = { type = "replay", path = "imu.pflog" }
engine = { gyro_stream = "a" }
)", "stream[1].engine.gyro_stream: forms a cycle of gyro_stream: 'a' -> 'b' -> 'a'", 5},
    {"gyro_stream in [engine]", R"([engine]
gyro_stream = "imu"
[[stream]]
id = 1
name = "imu"
driver = { type = "replay", path = "imu.pflog" }
)", "engine.gyro_stream: only in [stream.engine]", 2},
    {"gyro_stream not a string", R"([[stream]]
id = 1
name = "a"
driver = { type = "replay", path = "poses.csv" }
engine = { gyro_stream = 2 }
)", "stream[1].engine.gyro_stream: expected a string, got an integer", 5},
    {"gyro_stream with gyro aiding off", R"([engine]
gyro_aided = false
[[stream]]
id = 1
name = "optical"
driver = { type = "replay", path = "poses.csv" }
engine = { gyro_stream = "imu" }
[[stream]]
id = 2
name = "imu"
driver = { type = "replay", path = "imu.pflog" }
)", "stream[1].engine.gyro_stream: needs gyro-aided fairing, which gyro_aided = false turns off", 7},
    {"gyro_stream with a horizon", R"([[stream]]
id = 1
name = "optical"
driver = { type = "replay", path = "poses.csv" }
engine = { gyro_stream = "imu", horizon = 0.02 }
[[stream]]
id = 2
name = "imu"
driver = { type = "replay", path = "imu.pflog" }
)", "stream[1].engine.gyro_stream: gyro-aided fairing needs the linear solver and no horizon", 5},
    {"window_time out of range", R"([engine]
window_time = 0
[[stream]]
id = 1
name = "a"
driver = { type = "synthetic", rate_hz = 100 }
)", "engine.window_time: out of range: must be in (0, 60], got 0", 2},
    {"noise_time zero", R"([engine]
noise_time = 0
[[stream]]
id = 1
name = "a"
driver = { type = "synthetic", rate_hz = 100 }
)", "engine.noise_time: out of range: must be in (0, 600], got 0", 2},
    {"motion_span too long", R"([[stream]]
id = 1
name = "a"
driver = { type = "synthetic", rate_hz = 100 }
[stream.engine]
motion_span = 601
)", "stream[1].engine.motion_span: out of range: must be in (0, 600], got 601", 6},
    {"motion_time not a number", R"([engine]
motion_time = "fast"
[[stream]]
id = 1
name = "a"
driver = { type = "synthetic", rate_hz = 100 }
)", "engine.motion_time: expected a number, got a string", 2},
    {"negative motion_margin", R"([[stream]]
id = 1
name = "a"
driver = { type = "synthetic", rate_hz = 100 }
engine = { motion_margin = -1 }
)", "stream[1].engine.motion_margin: out of range: must be in (0, 100], got -1", 5},
    {"negative rest_threshold", R"([[stream]]
id = 1
name = "a"
driver = { type = "synthetic", rate_hz = 100 }
engine = { rest_threshold = -0.5 }
)", "stream[1].engine.rest_threshold: out of range: must be in [0, 100], got -0.5", 5},
    {"rest_memory over ten minutes", R"([[stream]]
id = 1
name = "a"
driver = { type = "synthetic", rate_hz = 100 }
engine = { rest_memory = 601 }
)", "stream[1].engine.rest_memory: out of range: must be in [0, 600], got 601", 5},
    {"negative outlier_threshold", R"([[stream]]
id = 1
name = "a"
driver = { type = "synthetic", rate_hz = 100 }
engine = { outlier_threshold = -1 }
)", "stream[1].engine.outlier_threshold: out of range: must be in [0, 1000], got -1", 5},
    {"continuity with adapted smoothing", R"([engine]
window = 32
continuity = 1
[[stream]]
id = 1
name = "a"
driver = { type = "replay", path = "poses.csv" }
)", "engine.continuity: continuity needs fixed smoothing", 3},
    {"cutoff_hz above half the rate", R"([[stream]]
id = 1
name = "a"
driver = { type = "synthetic", rate_hz = 100 }
engine = { cutoff_hz = 60 }
)", "stream[1].engine.cutoff_hz: must be below half the sample rate", 5},
    {"cutoff_hz and smoothing in one table", R"([engine]
smoothing = 10
rate_hz = 100
cutoff_hz = 5
[[stream]]
id = 1
name = "a"
driver = { type = "synthetic" }
)", "engine.cutoff_hz: cannot be given together with engine.smoothing (line 2)", 4},
    {"unstable continuity", R"([[stream]]
id = 1
name = "a"
driver = { type = "synthetic" }
[stream.engine]
order = 3
window = 32
lag = 0
smoothing = 100
continuity = 10
)", "stream[1].engine.continuity: continuity 10.000000 with smoothing 100.000000, window 32 and lag 0 makes the output recursion unstable", 10},
    {"window bound with the linear solver", R"([[stream]]
id = 1
name = "a"
driver = { type = "synthetic" }
engine = { bound = "window" }
)", "stream[1].engine.bound: the window bound policy needs an iterative solver", 5},
    {"zero epsilon_r", R"([engine]
epsilon_r = 0
[[stream]]
id = 1
name = "a"
driver = { type = "synthetic" }
)", "engine.epsilon_r: out of range: must be > 0, got 0", 2},
    {"recorder with a nonexistent directory", R"([[stream]]
id = 1
name = "a"
driver = { type = "synthetic" }
[recorder]
path = "nowhere/rec.pflog"
)", "recorder.path: no such directory", 6},
    {"recorder without a path", R"([[stream]]
id = 1
name = "a"
driver = { type = "synthetic" }

[recorder]
sync = false
)", "recorder.path: missing required key", 6},
    {"subscription: listen not an address", R"([[stream]]
id = 1
name = "a"
driver = { type = "synthetic" }
[subscription]
listen = "localhost:5710"
)", "subscription.listen: not a local address: 'localhost:5710'", 6},
    {"subscription: allow not a CIDR range", R"([[stream]]
id = 1
name = "a"
driver = { type = "synthetic" }
[subscription]
allow = ["127.0.0.0/8", "10.0.0.0/40"]
)", "subscription.allow[2]: not a CIDR range: '10.0.0.0/40'", 6},
    {"subscription: cap of 0", R"([[stream]]
id = 1
name = "a"
driver = { type = "synthetic" }
[subscription]
max_subscribers = 0
)", "subscription.max_subscribers: out of range: must be in [1, 4096], got 0", 6},
    {"subscription: rate 0", R"([[stream]]
id = 1
name = "a"
driver = { type = "synthetic" }
[subscription]
rate_per_source = 0
)", "subscription.rate_per_source: out of range", 6},
    {"subscription: unknown key", R"([[stream]]
id = 1
name = "a"
driver = { type = "synthetic" }
[subscription]
max_leases = 10
)", "subscription.max_leases: unknown key (did you mean 'max_lease'?)", 6},
    {"subscription: missing key file", R"([[stream]]
id = 1
name = "a"
driver = { type = "synthetic" }
[subscription]
psk_file = "no-such.key"
)", "subscription.psk_file: cannot read ", 6},
    {"subscription: a key file without a key", R"([[stream]]
id = 1
name = "a"
driver = { type = "synthetic" }
[subscription]
psk_file = "poses.csv"
)", "does not hold a key: expected 64 hex digits (32 bytes)", 6},
    {"control: mode open to others", R"([[stream]]
id = 1
name = "a"
driver = { type = "synthetic" }
[control]
mode = 0o666
)", "control.mode: must give others no access", 6},
    {"control: empty socket path", R"([[stream]]
id = 1
name = "a"
driver = { type = "synthetic" }
[control]
socket = ""
)", "control.socket: must not be empty", 6},
    {"session id out of range", R"([daemon]
session_id = -1
[[stream]]
id = 1
name = "a"
driver = { type = "synthetic" }
)", "daemon.session_id: out of range: must be in [0, 4294967295], got -1", 2},
    {"log level typo", R"([logging]
level = "warning"
[[stream]]
id = 1
name = "a"
driver = { type = "synthetic" }
)", "logging.level: expected one of 'trace', 'debug', 'info', 'warn', 'error', 'critical', 'off', got 'warning'", 2},
    {"serial: unknown protocol", R"([[stream]]
id = 1
name = "a"
[stream.driver]
type = "serial"
device = "/dev/ttyUSB0"
protocol = "nope"
)", "stream[1].driver.protocol: unknown protocol 'nope' (known: ", 7},
    {"serial: witmotion_scalar with another protocol", R"([[stream]]
id = 1
name = "a"
[stream.driver]
type = "serial"
device = "/dev/ttyUSB0"
protocol = "yost"
witmotion_scalar = "last"
)", "stream[1].driver.witmotion_scalar: only for protocol 'witmotion' (this source's protocol is 'yost')", 8},
    {"serial: vectornav_unchecked with another protocol", R"([[stream]]
id = 1
name = "a"
driver = { type = "serial", device = "/dev/ttyUSB0", protocol = "xsens", vectornav_unchecked = "accept" }
)", "stream[1].driver.vectornav_unchecked: only for protocol 'vectornav' (this source's protocol is 'xsens')", 4},
    {"serial: a yost header without the checksum bit, judged by the decoder", R"([[stream]]
id = 1
name = "a"
[stream.driver]
type = "serial"
device = "/dev/ttyUSB0"
protocol = "yost"
yost_header = 1
)", "stream[1].driver.yost_header: ", 8},
    {"serial: dtrdsr flow control does not exist on Linux", R"([[stream]]
id = 1
name = "a"
[stream.driver]
type = "serial"
device = "/dev/ttyUSB0"
flow_control = "dtrdsr"
protocol = "posefair"
)", "stream[1].driver.flow_control: Linux has no DTR/DSR flow control", 7},
    {"serial: baud 0", R"([[stream]]
id = 1
name = "a"
[stream.driver]
type = "serial"
device = "/dev/ttyUSB0"
baud = 0
protocol = "witmotion"
)", "stream[1].driver.baud: out of range: must be in [50, 12000000], got 0", 7},
    {"serial: baud as a string", R"([[stream]]
id = 1
name = "a"
driver = { type = "serial", device = "/dev/ttyUSB0", baud = "115200", protocol = "witmotion" }
)", "stream[1].driver.baud: expected an integer, got a string", 4},
    {"serial: bad usb id", R"([[stream]]
id = 1
name = "a"
[stream.driver]
type = "serial"
usb = "1a86-7523"
protocol = "witmotion"
)", "stream[1].driver.usb: not a USB id: '1a86-7523'; expected VID:PID in hexadecimal, e.g. '1a86:7523'", 6},
    {"serial: usb id too long", R"([[stream]]
id = 1
name = "a"
driver = { type = "serial", usb = "1a86:75230", protocol = "witmotion" }
)", "stream[1].driver.usb: not a USB id: '1a86:75230'", 4},
    {"serial: device and usb", R"([[stream]]
id = 1
name = "a"
[stream.driver]
type = "serial"
device = "/dev/ttyUSB0"
usb = "1a86:7523"
protocol = "witmotion"
)", "stream[1].driver.usb: give either device or usb, not both (device is set at line 6)", 7},
    {"serial: neither device nor usb", R"([[stream]]
id = 1
name = "a"
[stream.driver]
type = "serial"
protocol = "witmotion"
)", "stream[1].driver.device: missing required key: device (a path) or usb (\"VID:PID\")", 4},
    {"serial: relative device path", R"([[stream]]
id = 1
name = "a"
driver = { type = "serial", device = "ttyUSB0", protocol = "witmotion" }
)", "stream[1].driver.device: must be an absolute path", 4},
    {"serial: serial_number without usb", R"([[stream]]
id = 1
name = "a"
[stream.driver]
type = "serial"
device = "/dev/ttyUSB0"
serial_number = "A50285BI"
protocol = "witmotion"
)", "stream[1].driver.serial_number: only with usb", 7},
    {"serial: protocol missing", R"([[stream]]
id = 1
name = "a"
[stream.driver]
type = "serial"
device = "/dev/ttyUSB0"
)", "stream[1].driver.protocol: missing required key", 4},
    {"serial: stop bits 3", R"([[stream]]
id = 1
name = "a"
driver = { type = "serial", device = "/dev/ttyUSB0", stop_bits = 3, protocol = "witmotion" }
)", "stream[1].driver.stop_bits: must be 1 or 2, got 3", 4},
    {"serial: parity typo", R"([[stream]]
id = 1
name = "a"
driver = { type = "serial", device = "/dev/ttyUSB0", parity = "Even", protocol = "witmotion" }
)", "stream[1].driver.parity: expected one of 'none', 'odd', 'even', 'mark', 'space', got 'Even' (did you mean 'even'?)", 4},
    {"serial: reconnect_max below reconnect_min", R"([[stream]]
id = 1
name = "a"
[stream.driver]
type = "serial"
device = "/dev/ttyUSB0"
protocol = "witmotion"
reconnect_min = 2
reconnect_max = 1
)", "stream[1].driver.reconnect_max: must be >= reconnect_min (2 s), got 1", 9},
    {"serial: a synthetic key", R"([[stream]]
id = 1
name = "a"
[stream.driver]
type = "serial"
device = "/dev/ttyUSB0"
rate_hz = 100
protocol = "witmotion"
)", "stream[1].driver.rate_hz: unknown key for driver type serial (it belongs to type synthetic)", 7},
    {"replay: a serial key", R"([[stream]]
id = 1
name = "a"
[stream.driver]
type = "replay"
path = "poses.csv"
baud = 115200
)", "stream[1].driver.baud: unknown key for driver type replay (it belongs to type serial)", 7},
    {"serial: time source typo", R"([[stream]]
id = 1
name = "a"
driver = { type = "serial", device = "/dev/ttyUSB0", time_source = "devise", protocol = "witmotion" }
)", "stream[1].driver.time_source: expected one of 'auto', 'receive', 'device', got 'devise' (did you mean 'device'?)", 4},
    {"hid: neither device nor usb", R"([[stream]]
id = 1
name = "a"
[stream.driver]
type = "hid"
protocol = "hid-sensor"
)", "stream[1].driver.device: missing required key: device (a path) or usb (\"VID:PID\")", 4},
    {"hid: relative device path", R"([[stream]]
id = 1
name = "a"
driver = { type = "hid", device = "hidraw0", protocol = "hid-sensor" }
)", "stream[1].driver.device: must be an absolute path, e.g. '/dev/hidraw0', got 'hidraw0'", 4},
    {"hid: bad usb id", R"([[stream]]
id = 1
name = "a"
driver = { type = "hid", usb = "0483-5750", protocol = "hid-sensor" }
)", "stream[1].driver.usb: not a USB id: '0483-5750'", 4},
    {"hid: serial_number without usb", R"([[stream]]
id = 1
name = "a"
driver = { type = "hid", device = "/dev/hidraw0", serial_number = "X", protocol = "hid-sensor" }
)", "stream[1].driver.serial_number: only with usb", 4},
    {"hid: protocol missing", R"([[stream]]
id = 1
name = "a"
[stream.driver]
type = "hid"
device = "/dev/hidraw0"
)", "stream[1].driver.protocol: missing required key", 4},
    {"hid: a serial protocol", R"([[stream]]
id = 1
name = "a"
driver = { type = "hid", device = "/dev/hidraw0", protocol = "witmotion" }
)", "stream[1].driver.protocol: expected one of {hid-protocols}, got 'witmotion'", 4},
    {"hid: component_order not a permutation", R"([[stream]]
id = 1
name = "a"
driver = { type = "hid", device = "/dev/hidraw0", protocol = "hid-sensor", component_order = "xyzx" }
)", "stream[1].driver.component_order: must be the letters w, x, y, z each once in report order", 4},
    {"hid: sensor report_id above 255", R"([[stream]]
id = 1
name = "a"
driver = { type = "hid", device = "/dev/hidraw0", protocol = "hid-sensor", report_id = 256 }
)", "stream[1].driver.report_id: out of range: must be in [0, 255], got 256", 4},
    {"hid: timestamp_count_s of 0", R"([[stream]]
id = 1
name = "a"
driver = { type = "hid", device = "/dev/hidraw0", protocol = "hid-sensor", timestamp_count_s = 0 }
)", "stream[1].driver.timestamp_count_s: out of range: must be > 0, got 0", 4},
    {"hid: a vendor key with hid-sensor", R"([[stream]]
id = 1
name = "a"
[stream.driver]
type = "hid"
device = "/dev/hidraw0"
protocol = "hid-sensor"
scale = 0.001
)", "stream[1].driver.scale: only for protocol \"hid-vendor\" (this source's protocol is 'hid-sensor')", 8},
    {"hid: a sensor key with hid-vendor", R"([[stream]]
id = 1
name = "a"
driver = { type = "hid", device = "/dev/hidraw0", protocol = "hid-vendor", offsets = [0, 2, 4, 6], conjugate = true }
)", "stream[1].driver.conjugate: only for protocol \"hid-sensor\"", 4},
    {"hid: vendor without offsets", R"([[stream]]
id = 1
name = "a"
[stream.driver]
type = "hid"
device = "/dev/hidraw0"
protocol = "hid-vendor"
)", "stream[1].driver.offsets: missing required key: offsets (four byte offsets) or offsets_bits", 4},
    {"hid: vendor offsets and offsets_bits", R"([[stream]]
id = 1
name = "a"
[stream.driver]
type = "hid"
device = "/dev/hidraw0"
protocol = "hid-vendor"
offsets = [0, 2, 4, 6]
offsets_bits = [0, 16, 32, 48]
)", "stream[1].driver.offsets_bits: give either offsets (bytes) or offsets_bits, not both (offsets is set at line 8)", 9},
    {"hid: vendor three offsets", R"([[stream]]
id = 1
name = "a"
driver = { type = "hid", device = "/dev/hidraw0", protocol = "hid-vendor", offsets = [0, 2, 4] }
)", "stream[1].driver.offsets: expected an array of four offsets", 4},
    {"hid: vendor overlapping offsets, judged by the layout", R"([[stream]]
id = 1
name = "a"
[stream.driver]
type = "hid"
device = "/dev/hidraw0"
protocol = "hid-vendor"
value_type = "int32"
offsets = [0, 4, 8, 10]
)", "stream[1].driver.offsets[4]: hid-vendor layout: offset_bits[3]: the value at bit 80 overlaps value 2 at bit 64 (32 bits each)", 9},
    {"hid: vendor offset past report_length", R"([[stream]]
id = 1
name = "a"
[stream.driver]
type = "hid"
device = "/dev/hidraw0"
protocol = "hid-vendor"
report_length = 7
offsets = [0, 2, 4, 6]
)", "stream[1].driver.offsets[4]: hid-vendor layout: offset_bits[3]: the value at bit 48 ends at bit 64, past report_length 7 bytes", 9},
    {"hid: vendor report_id 0", R"([[stream]]
id = 1
name = "a"
driver = { type = "hid", device = "/dev/hidraw0", protocol = "hid-vendor", report_id = 0, offsets = [0, 2, 4, 6] }
)", "stream[1].driver.report_id: 0 is reserved by HID", 4},
    {"hid: vendor scale 0", R"([[stream]]
id = 1
name = "a"
driver = { type = "hid", device = "/dev/hidraw0", protocol = "hid-vendor", offsets = [0, 2, 4, 6], scale = 0 }
)", "stream[1].driver.scale: must not be 0", 4},
    {"hid: vendor value type typo", R"([[stream]]
id = 1
name = "a"
driver = { type = "hid", device = "/dev/hidraw0", protocol = "hid-vendor", offsets = [0, 2, 4, 6], value_type = "int8" }
)", "stream[1].driver.value_type: expected one of 'int16', 'int32', 'float32', 'float64', got 'int8'", 4},
    {"hid: a serial key", R"([[stream]]
id = 1
name = "a"
driver = { type = "hid", device = "/dev/hidraw0", protocol = "hid-sensor", baud = 9600 }
)", "stream[1].driver.baud: unknown key for driver type hid (it belongs to type serial)", 4},
    {"hid: reconnect_max below reconnect_min", R"([[stream]]
id = 1
name = "a"
driver = { type = "hid", device = "/dev/hidraw0", protocol = "hid-sensor", reconnect_min = 2, reconnect_max = 1 }
)", "stream[1].driver.reconnect_max: must be >= reconnect_min (2 s), got 1", 4},
    {"fusion: unknown estimator", R"([[stream]]
id = 1
name = "a"
driver = { type = "synthetic" }
[stream.fusion]
estimator = "kalman"
)", "stream[1].fusion.estimator: expected one of 'vqf', 'madgwick', 'mahony', got 'kalman'", 6},
    {"fusion: another estimator's option", R"([[stream]]
id = 1
name = "a"
driver = { type = "synthetic" }
[stream.fusion]
estimator = "vqf"
beta = 0.1
)", "stream[1].fusion.beta: only for estimator 'madgwick'", 7},
    {"fusion: a value the estimator refuses", R"([[stream]]
id = 1
name = "a"
driver = { type = "synthetic" }
[stream.fusion]
tau_acc = 0.0
)", "stream[1].fusion.tau_acc: must be positive", 6},
    {"fusion: wrong type", R"([[stream]]
id = 1
name = "a"
driver = { type = "synthetic" }
fusion = { magnetometer = "yes" }
)", "stream[1].fusion.magnetometer: ", 5},
    {"fusion: unknown key", R"([[stream]]
id = 1
name = "a"
driver = { type = "synthetic" }
[stream.fusion]
estimater = "vqf"
)", "stream[1].fusion.estimater: unknown key", 6},
    {"spline: a rate of zero", R"([[stream]]
id = 1
name = "a"
driver = { type = "synthetic" }
[stream.spline]
publish_rate_hz = 0.0
)", "stream[1].spline.publish_rate_hz: ", 6},
    {"spline: the fit estimate is not offered live", R"([[stream]]
id = 1
name = "a"
driver = { type = "synthetic" }
[stream.spline]
bridge_gap = 0.1
velocity = "fit"
)", "stream[1].spline.velocity: expected one of 'bessel', 'central', got 'fit'", 7},
    {"spline: order out of range", R"([[stream]]
id = 1
name = "a"
driver = { type = "synthetic" }
spline = { order = 9 }
)", "stream[1].spline.order: ", 5},
    {"spline: unknown key", R"([[stream]]
id = 1
name = "a"
driver = { type = "synthetic" }
[stream.spline]
rate_hz = 90.0
)", "stream[1].spline.rate_hz: unknown key", 6},
    {"spline: pose_interpolation typo", R"([[stream]]
id = 1
name = "a"
driver = { type = "synthetic" }
[stream.spline]
publish_rate_hz = 90.0
pose_interpolation = "matrix"
)", "stream[1].spline.pose_interpolation: expected one of 'spline', 'matrix-lerp', got 'matrix'", 7},
    {"spline: matrix-lerp with an order", R"([[stream]]
id = 1
name = "a"
driver = { type = "synthetic" }
[stream.spline]
publish_rate_hz = 90.0
order = 1
pose_interpolation = "matrix-lerp"
)", "stream[1].spline.order: has no meaning with pose_interpolation = 'matrix-lerp'", 7},
    {"spline: matrix-lerp with a velocity estimate", R"([[stream]]
id = 1
name = "a"
driver = { type = "synthetic" }
spline = { bridge_gap = 0.1, pose_interpolation = "matrix-lerp", velocity = "central" }
)", "stream[1].spline.velocity: has no meaning with pose_interpolation = 'matrix-lerp'", 5},
    {"gpio: no chip", R"([[stream]]
id = 1
name = "a"
driver = { type = "synthetic" }
[stream.gpio]
data_ready_line = 17
)", "stream[1].gpio.chip: missing required key", 5},
    {"gpio: no line at all", R"([[stream]]
id = 1
name = "a"
driver = { type = "synthetic" }
[stream.gpio]
chip = "gpiochip0"
)", "stream[1].gpio.data_ready_line: missing required key: give data_ready_line, output_line or both", 5},
    {"gpio: a line that is neither offset nor name", R"([[stream]]
id = 1
name = "a"
driver = { type = "synthetic" }
[stream.gpio]
chip = "gpiochip0"
data_ready_line = 1.5
)", "stream[1].gpio.data_ready_line: expected a line offset (integer) or a line name (string), got a float", 7},
    {"gpio: unknown edge", R"([[stream]]
id = 1
name = "a"
driver = { type = "synthetic" }
[stream.gpio]
chip = "gpiochip0"
data_ready_line = 3
edge = "raising"
)", "stream[1].gpio.edge: expected one of 'rising', 'falling', got 'raising' (did you mean 'rising'?)", 8},
    {"gpio: unknown bias", R"([[stream]]
id = 1
name = "a"
driver = { type = "synthetic" }
[stream.gpio]
chip = "gpiochip0"
data_ready_line = 3
bias = "pullup"
)", "stream[1].gpio.bias: expected one of 'as-is', 'pull-up', 'pull-down', 'disabled', got 'pullup'", 8},
    {"gpio: tolerance_max below tolerance_min", R"([[stream]]
id = 1
name = "a"
driver = { type = "synthetic" }
[stream.gpio]
chip = "gpiochip0"
data_ready_line = 3
tolerance_min = 0.004
tolerance_max = 0.002
)", "stream[1].gpio.tolerance_max: GPIO edge pairing: need 0 <= tolerance_min <= tolerance_max", 9},
    {"gpio: negative tolerance", R"([[stream]]
id = 1
name = "a"
driver = { type = "synthetic" }
[stream.gpio]
chip = "gpiochip0"
data_ready_line = 3
tolerance_min = -0.001
)", "stream[1].gpio.tolerance_min: out of range: must be in [0, 10]", 8},
    {"gpio: window wider than the sample period", R"([[stream]]
id = 1
name = "a"
driver = { type = "synthetic", rate_hz = 400.0 }
[stream.gpio]
chip = "gpiochip0"
data_ready_line = 3
tolerance_max = 0.003
)", "stream[1].gpio.tolerance_max: the pairing window (tolerance_max - tolerance_min = 0.003 s) must be narrower than the sample period 1/400 Hz (rate from stream[1].driver.rate_hz)", 8},
    {"gpio: the same line in and out", R"([[stream]]
id = 1
name = "a"
driver = { type = "synthetic" }
[stream.gpio]
chip = "gpiochip0"
data_ready_line = "DRDY"
output_line = "DRDY"
)", "stream[1].gpio.output_line: is the data_ready_line too", 8},
    {"gpio: heartbeat rate without heartbeat mode", R"([[stream]]
id = 1
name = "a"
driver = { type = "synthetic" }
[stream.gpio]
chip = "gpiochip0"
output_line = 4
heartbeat_hz = 10.0
)", "stream[1].gpio.heartbeat_hz: needs output_mode = 'heartbeat'", 8},
    {"gpio: heartbeat rate of zero", R"([[stream]]
id = 1
name = "a"
driver = { type = "synthetic" }
[stream.gpio]
chip = "gpiochip0"
output_line = 4
output_mode = "heartbeat"
heartbeat_hz = 0
)", "stream[1].gpio.heartbeat_hz: out of range: must be in (0, 10000], got 0", 9},
    {"gpio: output mode without an output line", R"([[stream]]
id = 1
name = "a"
driver = { type = "synthetic" }
[stream.gpio]
chip = "gpiochip0"
data_ready_line = 3
output_mode = "per-pose"
)", "stream[1].gpio.output_mode: needs output_line", 8},
    {"gpio: edge without a data-ready line", R"([[stream]]
id = 1
name = "a"
driver = { type = "synthetic" }
[stream.gpio]
chip = "gpiochip0"
output_line = 4
edge = "falling"
)", "stream[1].gpio.edge: needs data_ready_line", 8},
    {"gpio: unknown key", R"([[stream]]
id = 1
name = "a"
driver = { type = "synthetic" }
[stream.gpio]
chip = "gpiochip0"
data_ready_line = 3
toleranse_max = 0.002
)", "stream[1].gpio.toleranse_max: unknown key (did you mean 'tolerance_max'?)", 8},
    {"socketcan: unknown protocol", R"([[stream]]
id = 1
name = "a"
driver = { type = "socketcan", interface = "can0", protocol = "xsens" }
)", "stream[1].driver.protocol: unknown CAN protocol 'xsens' (known: {can-protocols})", 4},
    {"socketcan: a bad identifier, judged by the decoder", R"([[stream]]
id = 1
name = "a"
[stream.driver]
type = "socketcan"
interface = "can0"
protocol = "posefair-can"
posefair_base_id = "0x2G0"
)", "stream[1].driver.posefair_base_id: ", 8},
    {"socketcan: an option of another protocol", R"([[stream]]
id = 1
name = "a"
driver = { type = "socketcan", interface = "can0", protocol = "posefair-can", dronecan_node_id = 42 }
)", "stream[1].driver.dronecan_node_id: only for protocol 'dronecan-ahrs' (this source's protocol is 'posefair-can')", 4},
    {"socketcan: interface missing", R"([[stream]]
id = 1
name = "a"
[stream.driver]
type = "socketcan"
protocol = "xsens-can"
)", "stream[1].driver.interface: missing required key", 4},
    {"socketcan: interface name too long", R"([[stream]]
id = 1
name = "a"
driver = { type = "socketcan", interface = "can0-on-the-left-arm", protocol = "xsens-can" }
)", "stream[1].driver.interface: an interface name has at most 15 characters", 4},
    {"socketcan: fd as a string", R"([[stream]]
id = 1
name = "a"
driver = { type = "socketcan", interface = "can0", protocol = "xsens-can", fd = "yes" }
)", "stream[1].driver.fd: expected a boolean, got a string", 4},
    {"socketcan: a serial key", R"([[stream]]
id = 1
name = "a"
driver = { type = "socketcan", interface = "can0", protocol = "xsens-can", baud = 1000000 }
)", "stream[1].driver.baud: unknown key for driver type socketcan (it belongs to type serial)", 4},
    {"socketcan: reconnect_max below reconnect_min", R"([[stream]]
id = 1
name = "a"
driver = { type = "socketcan", interface = "can0", protocol = "xsens-can", reconnect_min = 2, reconnect_max = 1 }
)", "stream[1].driver.reconnect_max: must be >= reconnect_min (2 s), got 1", 4},
    {"socketcan: a bad dronecan node id", R"([[stream]]
id = 1
name = "a"
driver = { type = "socketcan", interface = "can0", protocol = "dronecan-ahrs", dronecan_node_id = 200 }
)", "stream[1].driver.dronecan_node_id: ", 4},
    {"candump replay: also a path", R"([[stream]]
id = 1
name = "a"
[stream.driver]
type = "replay"
candump = "bus.log"
path = "poses.csv"
protocol = "xsens-can"
)", "stream[1].driver.path: not for a candump log (candump is set at line 6)", 7},
    {"candump replay: no such file", R"([[stream]]
id = 1
name = "a"
driver = { type = "replay", candump = "missing.log", protocol = "xsens-can" }
)", "stream[1].driver.candump: no such file: ", 4},
    {"candump replay: protocol missing", R"([[stream]]
id = 1
name = "a"
driver = { type = "replay", candump = "bus.log", interface = "can0" }
)", "stream[1].driver.protocol: missing required key", 4},
    {"candump replay: unknown protocol", R"([[stream]]
id = 1
name = "a"
driver = { type = "replay", candump = "bus.log", protocol = "posefair-cam" }
)", "stream[1].driver.protocol: unknown CAN protocol 'posefair-cam' (known: {can-protocols}) (did you mean 'posefair-can'?)", 4},
    {"replay: a CAN protocol without candump", R"([[stream]]
id = 1
name = "a"
driver = { type = "replay", path = "poses.csv", protocol = "xsens-can" }
)", "stream[1].driver.protocol: only for a candump log (key candump)", 4},
    {"candump replay: fd is the live driver's", R"([[stream]]
id = 1
name = "a"
driver = { type = "replay", candump = "bus.log", protocol = "xsens-can", fd = true }
)", "stream[1].driver.fd: unknown key for driver type replay (it belongs to type socketcan)", 4},
    {"fair_on: not a thread that fairs", R"([daemon]
fair_on = "publisher"
[[stream]]
id = 1
name = "a"
driver = { type = "synthetic" }
)", "daemon.fair_on", 2},
    {"publish_on: not a thread", R"([daemon]
publish_on = "driver"
[[stream]]
id = 1
name = "a"
driver = { type = "synthetic" }
)", "daemon.publish_on", 2},
    {"spin_us: out of range", R"([daemon]
spin_us = 20000
[[stream]]
id = 1
name = "a"
driver = { type = "synthetic" }
)", "daemon.spin_us", 2},
    {"wake: unknown", R"([daemon]
wake = "per-stream"
[[stream]]
id = 1
name = "a"
driver = { type = "synthetic" }
)", "daemon.wake", 2},
    {"cpu_affinity: a CPU twice", R"([daemon]
cpu_affinity = [1, 1]
[[stream]]
id = 1
name = "a"
driver = { type = "synthetic" }
)", "daemon.cpu_affinity[2]: CPU 1 is listed twice", 2},
    {"cpu_affinity: not an array", R"([daemon]
cpu_affinity = 1
[[stream]]
id = 1
name = "a"
driver = { type = "synthetic" }
)", "daemon.cpu_affinity: expected an array of CPU numbers", 2},
    {"busy_poll: not a bool", R"([[stream]]
id = 1
name = "a"
busy_poll = 1
driver = { type = "synthetic" }
)", "stream[1].busy_poll", 4},
    {"a table that is not one", R"(daemon = 5
[[stream]]
id = 1
name = "a"
driver = { type = "synthetic" }
)", "daemon: expected a table ([daemon]), got an integer", 1},
};

TEST(Config, MalformedConfigsAreRefusedWithFileLineAndKey) {
  testing::ScratchDir dir("posefair-config-");
  write_file(dir / "poses.csv", "t,qw,qx,qy,qz\n0,1,0,0,0\n");
  write_file(dir / "walk.bvh", "");
  write_file(dir / "bus.log", "(1.000000) can0 021#7FFF000000000000\n");
  write_file(dir / "imu.pflog", "");  // a sample log by its name (contents unread)
  const std::filesystem::path file = dir / "cfg.toml";
  EXPECT_GE(kBadConfigs.size(), 25u);
  for (const BadConfig& bad : kBadConfigs) {
    SCOPED_TRACE(bad.name);
    try {
      parse_config(bad.toml, file);
      ADD_FAILURE() << "accepted";
    } catch (const ConfigError& e) {
      const std::string what = e.what();
      EXPECT_THAT(what, HasSubstr(with_registry_lists(bad.expected)));
      EXPECT_EQ(e.file(), file.string());
      EXPECT_EQ(e.line(), bad.line) << what;
      if (bad.line > 0) {
        EXPECT_THAT(what, StartsWith(file.string() + ":" + std::to_string(bad.line) + ":")) << what;
        EXPECT_GT(e.column(), 0u) << what;
      } else {
        EXPECT_THAT(what, StartsWith(file.string() + ": ")) << what;
      }
    } catch (const std::exception& e) {
      ADD_FAILURE() << "not a ConfigError: " << e.what();
    }
  }
}

TEST(Config, TheMessageIsFileLineColumnKeyMessage) {
  try {
    parse_config(R"toml(
[[stream]]
id = 1
name = "a"
driver = { type = "synthetic" }

[[stream]]
id = 2
driver = { type = "synthetic" }
)toml",
                 "cfg.toml");
    FAIL() << "accepted";
  } catch (const ConfigError& e) {
    EXPECT_STREQ(e.what(), "cfg.toml:7:1: stream[2].name: missing required key");
    EXPECT_EQ(e.file(), "cfg.toml");
    EXPECT_EQ(e.line(), 7u);
    EXPECT_EQ(e.column(), 1u);
    EXPECT_EQ(e.key(), "stream[2].name");
    EXPECT_EQ(e.message(), "missing required key");
  }
  try {
    parse_config("[[stream]]\nid = 1\nname = \"a\"\ndriver = { type = \"synthetic\" }\n[engine]\n  lagg = 2\n", "cfg.toml");
    FAIL() << "accepted";
  } catch (const ConfigError& e) {
    EXPECT_STREQ(e.what(), "cfg.toml:6:3: engine.lagg: unknown key (did you mean 'lag'?)");
  }
}

TEST(Config, AMissingFileCannotBeRead) {
  testing::ScratchDir dir("posefair-config-");
  const std::filesystem::path file = dir / "absent.toml";
  try {
    load_config(file);
    FAIL() << "loaded";
  } catch (const ConfigError& e) {
    EXPECT_STREQ(e.what(), (file.string() + ": cannot read: No such file or directory").c_str());
    EXPECT_EQ(e.line(), 0u);
    EXPECT_EQ(e.key(), "");
  }
}

}  // namespace
}  // namespace posefair::daemon
