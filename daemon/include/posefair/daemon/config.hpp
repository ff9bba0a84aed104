#pragma once
// posefaird's configuration: what a TOML file (docs/config.md) says, validated whole before
// anything runs. load_config() either returns a complete DaemonConfig or throws ConfigError
// naming the file, the line and the key; the daemon exits 78 (EX_CONFIG) on it at start and
// keeps the running configuration on it at SIGHUP. Unknown keys are errors.
//
// Relative paths in a config (replay sources, the recording) are resolved against the
// directory of the config file, so a config and its data can move together.
#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "posefair/core/error.hpp"
#include "posefair/core/fairing_window.hpp"
#include "posefair/core/pose_spline.hpp"
#include "posefair/core/rigid_pose_lerp.hpp"
#include "posefair/daemon/client_frames.hpp"
#include "posefair/daemon/output_encoder.hpp"
#include "posefair/daemon/overflow_policy.hpp"
#include "posefair/daemon/subscription_handler.hpp"
#include "posefair/daemon/udp_socket.hpp"
#include "posefair/daemon/wire_protocol.hpp"
#include "posefair/drivers/can_decoder.hpp"
#include "posefair/drivers/decoder.hpp"
#include "posefair/drivers/hidraw_driver.hpp"
#include "posefair/drivers/gpio_data_ready.hpp"
#include "posefair/drivers/gpio_output_line.hpp"
#include "posefair/drivers/replay_driver.hpp"
#include "posefair/drivers/serial_port.hpp"
#include "posefair/drivers/time_base.hpp"

namespace posefair::daemon {

// "<file>:<line>:<column>: <key>: <message>" (line and column omitted when unknown, e.g. a
// missing required key is reported at its table's line). `key` is the dotted TOML path,
// e.g. "stream[2].engine.window" (array elements numbered from 1 as a user counts them).
// An Error of kind Config (exit 78); the file, position and key are data, not just text.
class ConfigError : public Error {
 public:
  ConfigError(std::string file, std::uint32_t line, std::uint32_t column, std::string key, std::string message);
  const std::string& file() const noexcept { return file_; }
  std::uint32_t line() const noexcept { return line_; }      // 0 = unknown
  std::uint32_t column() const noexcept { return column_; }  // 0 = unknown
  const std::string& message() const noexcept { return message_; }

 private:
  std::string file_;
  std::uint32_t line_;
  std::uint32_t column_;
  std::string message_;
};

enum class LogTarget { Auto, Stderr, Journald };  // Auto: journald when JOURNAL_STREAM says stderr is the journal

struct LoggingConfig {
  std::string level = "info";  // spdlog level: trace, debug, info, warn, error, critical, off
  LogTarget target = LogTarget::Auto;
  double status_interval = 60.0;  // s between counter lines in the log (0: only on SIGUSR1 and exit)
};

enum class PublishThread { Publisher, Engine };
enum class FairThread { Engine, Driver };

struct DaemonSettings {
  // Exit (status 0) once every driver has ended and every pose is out, e.g. a replay without
  // loop. Off for a service: a finished source then just idles.
  bool exit_when_sources_end = false;
  // Fixed session id for the wire protocol; unset = random at start (the normal case).
  std::optional<std::uint32_t> session_id;
  // SCHED_FIFO priority (1..99) for the engine and publisher threads, so samples are faired
  // and sent ahead of other work; 0 = normal scheduling. Needs CAP_SYS_NICE or an RLIMIT_RTPRIO
  // at least this high (the unit sets LimitRTPRIO); refused, it is logged and the daemon runs on.
  int realtime_priority = 0;
  // How the pipeline's real-time threads hand work on (docs/operations.md, "Threads and memory"; measured
  // side by side in docs/benchmarks.md, "Latency by stage"):
  // which thread sends the faired poses: a publisher thread of its own, or the engine thread
  // right after fairing (no second hop).
  PublishThread publish_on = PublishThread::Engine;
  // which thread fairs the samples: the engine thread, woken by the drivers, or the driver
  // thread that handed the sample over, while no other thread is fairing (no wake at all).
  FairThread fair_on = FairThread::Driver;
  // Bounded adaptive spin (µs) of the engine and publisher threads before they park; 0: park at once.
  int spin_us = 50;
  // One FUTEX_WAKE per sleep of the woken thread (true), or one per notify while it sleeps.
  bool wake_per_batch = true;
  // CPUs the engine and publisher threads are pinned to (sched_setaffinity); empty: any.
  std::vector<int> cpu_affinity;
};

// [stream.driver] with type = "socketcan": trackers on a CAN bus (drivers/socketcan_driver.hpp),
// a raw CAN socket on a named interface, its frames decoded by a CAN protocol decoder. The
// interface need not exist at load: the driver waits for it. Also what a candump replay
// shares with it (interface, protocol, decoder options, time_source).
struct SocketCanSourceConfig {
  std::string interface;              // e.g. "can0"; for a candump replay empty = every interface
  std::string protocol;               // one of drivers::can_decoder_protocols()
  posefair::OptionMap decoder;         // the options given that the protocol declares
  bool fd = false;                    // also receive CAN FD frames
  drivers::TimeSource time_source = drivers::TimeSource::Auto;
  double reconnect_min = 0.1;         // s
  double reconnect_max = 5.0;         // s, >= reconnect_min
};

// [stream.driver] with type = "replay": the simulated device backend.
struct ReplaySourceConfig {
  std::filesystem::path path;          // absolute after loading (resolved against the config's directory)
  drivers::ReplayOptions options;      // timing, speed, schedule, loop, rounds, pose file format ...
  // Sample logs hold several streams: which recorded stream id to play (its samples get this
  // stream's id). Unset: the log must hold exactly one stream. Pose files: ignored.
  std::optional<std::uint32_t> source_stream;
  // A candump log (key `candump`, instead of `path`): absolute after loading, its frames decoded
  // by `can` (interface, protocol and options; reconnect_* and fd unused). Empty: not one.
  std::filesystem::path candump;
  SocketCanSourceConfig can;
};

// [stream.driver] with type = "synthetic": smooth motion plus bounded noise at a fixed rate,
// generated live (core/synthetic_motion), for demos, soak tests and the latency benchmark.
struct SyntheticSourceConfig {
  double rate_hz = 100.0;
  double duration = 0.0;       // s; 0 = until stopped
  double rotation_noise = 0.01;  // rad (dist on S³)
  bool with_position = false;
  std::uint64_t seed = 1;
  double phase = 0.0;  // [0, 1): the first sample comes this fraction of a period after start
};

// [stream.driver] with type = "serial": a device on a serial port (drivers/serial_driver.hpp),
// opened by path or by USB id, its bytes decoded by a registered protocol decoder. The device
// need not exist at load: the driver waits for it (and for its return after an unplug).
struct SerialSourceConfig {
  drivers::SerialPortSpec port;       // device (absolute path) or usb (+ serial_number)
  drivers::SerialSettings settings;   // baud, data_bits, parity, stop_bits, flow_control
  std::string protocol;               // one of drivers::decoder_protocols()
  posefair::OptionMap decoder;         // the options given that the protocol declares
  drivers::TimeSource time_source = drivers::TimeSource::Auto;
  double reconnect_min = 0.1;         // s
  double reconnect_max = 5.0;         // s, >= reconnect_min
};

// [stream.driver] with type = "hid": a HID device through hidraw (drivers/hidraw_driver.hpp),
// opened by path or by USB id, its reports read by a registered HID decoder. The
// device need not exist at load: the driver waits for it.
struct HidSourceConfig {
  drivers::HidDeviceSpec device;                 // device (absolute path) or usb (+ serial_number)
  std::string protocol;                          // one of drivers::hid_decoder_protocols()
  posefair::OptionMap decoder;                    // the options given that the protocol declares
  drivers::TimeSource time_source = drivers::TimeSource::Auto;
  double reconnect_min = 0.1;                    // s
  double reconnect_max = 5.0;                    // s, >= reconnect_min
};

enum class DriverType { Replay, Synthetic, Serial, SocketCan, Hid };

struct DriverConfig {
  DriverType type = DriverType::Replay;
  ReplaySourceConfig replay;        // type == Replay
  SyntheticSourceConfig synthetic;  // type == Synthetic
  SerialSourceConfig serial;        // type == Serial
  HidSourceConfig hid;              // type == Hid
  SocketCanSourceConfig socketcan;  // type == SocketCan
};

// [stream.spline]: the geometric spline around the fairing window (docs/splines.md, "In the
// daemon"). Both parts are off unless their key is given.
struct SplineConfig {
  double publish_rate_hz = 0.0;  // > 0: publish on a fixed grid at this rate instead of every faired pose
  double bridge_gap = 0.0;       // s, > 0: fill input gaps up to this long on the spline
  geometric_splines::PoseSplineOptions spline;  // order, manifold, knot velocity estimate
  // "spline" (the spline above, rotation and position separately) or "matrix-lerp" (Alexa's
  // lerp of the 4x4 transform between the two neighbouring samples; refuses the spline's keys)
  PoseInterpolation pose_interpolation = PoseInterpolation::Spline;
  bool resampling() const { return publish_rate_hz > 0.0; }
  bool bridging() const { return bridge_gap > 0.0; }
};

// [stream.gpio]: a data-ready input line whose edges time the stream's samples, and/or an
// output line toggled per published pose or as a heartbeat (docs/hid-gpio.md, "GPIO").
struct GpioConfig {
  std::string chip;                                // "gpiochip0", a path or a label
  std::optional<drivers::GpioLineRef> data_ready;  // data_ready_line
  drivers::GpioEdge edge = drivers::GpioEdge::Rising;
  drivers::GpioBias bias = drivers::GpioBias::AsIs;
  drivers::EdgePairingOptions pairing;             // tolerance_min, tolerance_max
  std::optional<drivers::GpioLineRef> output;      // output_line
  drivers::GpioOutputMode output_mode = drivers::GpioOutputMode::PerPose;
  double heartbeat_hz = 1.0;
  double reconnect_min = 0.1;  // s: the backoff between requests of either line
  double reconnect_max = 2.0;  // s, >= reconnect_min
};

// [stream.fusion] (docs/fusion.md): the stream's raw inertial samples (kNoOrientation) become
// orientation samples, on the engine thread, before the fairing engine.
struct FusionConfig {
  std::string estimator = "vqf";  // a registered orientation estimator
  posefair::OptionMap options;    // its options, type-checked and accepted by it at load
};

struct StreamConfig {
  std::uint32_t id = 0;           // unique; the wire protocol's stream id
  bool busy_poll = false;         // the engine never parks while this stream's driver runs
  std::string name;               // unique, non-empty; for logs, STATUS= and the recording's stream table
  DriverConfig driver;
  std::uint32_t ring_capacity = 1024;  // samples; a power of two, 2 .. 1048576
  OverflowPolicy overflow = OverflowPolicy::DropOldest;
  // The engine: [engine] defaults with this stream's [stream.engine] overrides applied, already
  // validated (posefair::validate) and in the engine's units (epsilon_r as dist on S³, i.e.
  // half the rotation angle given in the file; smoothing from cutoff_hz when that was given).
  WindowConfig engine;
  // [stream.engine] gyro_stream: the name of another stream on the same body whose gyroscope
  // readings this stream's samples get for gyro-aided fairing (gyro_pairing.hpp); empty: none.
  std::string gyro_stream;
  SplineConfig spline;
  std::optional<GpioConfig> gpio;
  std::optional<FusionConfig> fusion;
  // `mounting` and `world`: corrections applied to every published pose of the stream, before
  // any encoding (client_frames.hpp, docs/outputs.md).
  StreamFrame frame;
};

struct OutputConfig {
  // `encoding` (a registered name; default "binary") built with its options, once, at load.
  std::shared_ptr<const OutputEncoder> encoder = default_output_encoder();
  std::vector<Endpoint> destinations;              // unicast and multicast, IPv4 and IPv6; at least one
  SendOptions send;                                // ttl (default 1), interface, loopback
  std::vector<std::uint32_t> streams;              // the streams this output carries; empty = all
  bool angular_velocity = false;  // include the body rate between consecutive emitted poses
  double max_rate_hz = 0.0;       // > 0: at most this many poses a second per stream; 0 = every pose
};

struct RecorderConfig {
  bool enabled = false;
  std::filesystem::path path;          // absolute after loading
  std::uint64_t max_file_bytes = 0;    // rotation; 0 = never
  double flush_interval = 1.0;         // s
  bool overwrite = false;              // false: refuse to start when the file exists
  bool sync = true;                    // fdatasync after each flush
  std::uint32_t ring_capacity = 4096;  // per stream, samples waiting for the recorder thread
};

// [control]: the operators' Unix socket (`posefair ctl`, docs/operations.md). Access is by the
// socket file's mode and group.
struct ControlSocketConfig {
  std::filesystem::path path = "/run/posefaird/control";
  std::uint32_t mode = 0660;
  std::string group;  // empty: the daemon's own group
};

struct DaemonConfig {
  std::filesystem::path source_file;  // the file this was loaded from
  DaemonSettings daemon;
  LoggingConfig logging;
  std::vector<StreamConfig> streams;  // at least one
  std::vector<OutputConfig> outputs;  // may be empty (recording only)
  RecorderConfig recorder;
  std::optional<SubscriptionSettings> subscription;  // [subscription]: clients sign up on a UDP port
  std::optional<ControlSocketConfig> control;        // [control]: the Unix socket for posefair ctl
};

// Parses and validates a config file. Throws ConfigError (never anything else) for an
// unreadable file, a TOML syntax error, an unknown key, a value of the wrong type or out of
// range, a missing required key, duplicate stream ids or names, an output naming an unknown
// stream, an engine combination posefair::validate refuses, a replay source that does not
// exist, or a serial source naming an unknown protocol.
DaemonConfig load_config(const std::filesystem::path& file);

// The same from a string (tests); `file` names it in messages and anchors relative paths.
DaemonConfig parse_config(std::string_view text, const std::filesystem::path& file);

}  // namespace posefair::daemon
