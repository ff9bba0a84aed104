#include "posefair/daemon/driver_factory.hpp"

#include <spdlog/spdlog.h>

#include <stdexcept>
#include <utility>

#include "posefair/drivers/candump_replay.hpp"
#include "posefair/drivers/driver_log.hpp"
#include "posefair/drivers/hidraw_driver.hpp"
#include "posefair/drivers/replay_driver.hpp"
#include "posefair/drivers/serial_driver.hpp"
#include "posefair/drivers/socketcan_driver.hpp"
#include "posefair/drivers/synthetic_driver.hpp"

namespace posefair::daemon {
namespace {

// A candump log decoded into samples up front (candump_replay.hpp), then played like any
// replay. Malformed lines are skipped and reported as warnings (the first few by line number).
MadeDriver make_candump_replay(const StreamConfig& stream) {
  const ReplaySourceConfig& rc = stream.driver.replay;
  drivers::ReplayOptions options = rc.options;
  options.stream_id = stream.id;
  const std::string where = "stream '" + stream.name + "': candump " + rc.candump.string() + ": ";
  drivers::CandumpReplayOptions co;
  co.protocol = rc.can.protocol;
  co.decoder = rc.can.decoder;
  co.interface = rc.can.interface;
  co.stream_id = stream.id;
  co.time_source = rc.can.time_source;
  MadeDriver made;
  made.source = "replay:" + rc.candump.string() + " (" + rc.can.protocol + ")";
  try {
    drivers::CandumpReplay decoded = drivers::decode_candump_file(rc.candump, co);
    constexpr std::size_t kShown = 5;
    const std::string file = "candump " + rc.candump.string() + ": ";  // the pipeline adds the stream
    for (std::size_t i = 0; i < decoded.problems.size() && i < kShown; ++i)
      made.warnings.push_back(file + "line " + std::to_string(decoded.problems[i].line) + ": " +
                              decoded.problems[i].message + " (skipped)");
    if (decoded.problems.size() > kShown)
      made.warnings.push_back(file + std::to_string(decoded.problems.size() - kShown) + " more malformed lines skipped");
    if (decoded.samples.empty())
      throw std::runtime_error(where + "no samples decoded (" + std::to_string(decoded.frame_counters.received) +
                               " frames of " + (co.interface.empty() ? std::string("any interface") : co.interface) +
                               ", " + std::to_string(decoded.frame_counters.foreign) + " with other ids, " +
                               std::to_string(decoded.other_interfaces) + " of other interfaces)");
    made.driver = std::make_unique<drivers::ReplayDriver>(std::move(decoded.samples), options, made.source);
  } catch (const formats::CandumpFileError& e) {
    throw std::runtime_error(where + e.what());
  } catch (const std::invalid_argument& e) {
    throw std::runtime_error(where + e.what());
  }
  return made;
}

MadeDriver make_replay(const StreamConfig& stream) {
  const ReplaySourceConfig& rc = stream.driver.replay;
  if (!rc.candump.empty()) return make_candump_replay(stream);
  drivers::ReplayOptions options = rc.options;
  options.stream_id = stream.id;
  const std::string where = "stream '" + stream.name + "': replay " + rc.path.string() + ": ";
  MadeDriver made;
  made.source = "replay:" + rc.path.string();
  try {
    drivers::ReplayDriver loaded(rc.path, options);
    made.warnings = loaded.warnings();
    // A sample log can hold several streams: keep the one asked for and give it this id.
    std::vector<std::uint32_t> ids;
    for (const formats::StreamInfo& info : loaded.streams()) ids.push_back(info.id);
    std::uint32_t wanted = stream.id;
    if (rc.source_stream) {
      wanted = *rc.source_stream;
    } else if (ids.size() == 1) {
      wanted = ids[0];
    } else {
      throw std::runtime_error(where + "the log holds " + std::to_string(ids.size()) +
                               " streams; choose one with source_stream");
    }
    std::vector<Sample> samples;
    samples.reserve(loaded.samples().size());
    for (Sample s : loaded.samples()) {
      if (s.stream_id != wanted) continue;
      s.stream_id = stream.id;
      samples.push_back(s);
    }
    if (samples.empty()) throw std::runtime_error(where + "no samples of stream " + std::to_string(wanted));
    if (rc.source_stream) made.source += " stream " + std::to_string(wanted);
    made.driver = std::make_unique<drivers::ReplayDriver>(std::move(samples), options, made.source);
  } catch (const formats::SampleLogError& e) {
    throw std::runtime_error(where + e.what());
  } catch (const formats::PoseFileError& e) {
    throw std::runtime_error(where + e.what());
  } catch (const std::invalid_argument& e) {
    throw std::runtime_error(where + e.what());
  }
  return made;
}

MadeDriver make_synthetic(const StreamConfig& stream) {
  const SyntheticSourceConfig& sc = stream.driver.synthetic;
  drivers::SyntheticOptions o;
  o.rate_hz = sc.rate_hz;
  o.duration = sc.duration;
  o.rotation_noise = sc.rotation_noise;
  o.with_position = sc.with_position;
  o.seed = sc.seed;
  o.phase = sc.phase;
  o.stream_id = stream.id;
  MadeDriver made;
  try {
    made.driver = std::make_unique<drivers::SyntheticDriver>(o);
  } catch (const std::invalid_argument& e) {
    throw std::runtime_error("stream '" + stream.name + "': " + e.what());
  }
  made.source = std::string(made.driver->name());
  return made;
}

// A device driver's state changes (opened, lost, reopened) go to the daemon's log, from the
// driver's thread: a few lines per connection, never per sample.
drivers::DriverLog to_spdlog(const std::string& stream_name) {
  return [prefix = "stream '" + stream_name + "': "](drivers::LogLevel level, std::string_view message) {
    spdlog::level::level_enum l = spdlog::level::info;
    switch (level) {
      case drivers::LogLevel::Debug: l = spdlog::level::debug; break;
      case drivers::LogLevel::Info: l = spdlog::level::info; break;
      case drivers::LogLevel::Warn: l = spdlog::level::warn; break;
      case drivers::LogLevel::Error: l = spdlog::level::err; break;
    }
    spdlog::log(l, "{}{}", prefix, message);
  };
}

// A device driver (serial, SocketCAN, hidraw) from its options and its source's config: the
// backoff and time source as configured, log lines to spdlog under the stream's name, `source`
// naming it in logs and in the recording's stream table, and a refused option naming the stream.
template <class Driver, class Options, class SourceConfig>
MadeDriver make_device_driver(const StreamConfig& stream, const SourceConfig& config, Options o, std::string source) {
  o.stream_id = stream.id;
  o.reconnect_min = config.reconnect_min;
  o.reconnect_max = config.reconnect_max;
  o.time_source = config.time_source;
  o.log = to_spdlog(stream.name);
  o.name = source;
  MadeDriver made;
  made.source = std::move(source);
  try {
    made.driver = std::make_unique<Driver>(std::move(o));
  } catch (const std::invalid_argument& e) {
    throw std::runtime_error("stream '" + stream.name + "': " + e.what());
  }
  return made;
}

MadeDriver make_serial(const StreamConfig& stream) {
  const SerialSourceConfig& sc = stream.driver.serial;
  drivers::SerialDriverOptions o;
  o.port = sc.port;
  o.settings = sc.settings;
  o.protocol = sc.protocol;
  o.decoder_options = sc.decoder;
  return make_device_driver<drivers::SerialDriver>(stream, sc, std::move(o),
                                                   "serial:" + sc.port.describe() + " (" + sc.protocol + ")");
}

MadeDriver make_hid(const StreamConfig& stream) {
  const HidSourceConfig& hc = stream.driver.hid;
  drivers::HidrawDriverOptions o;
  o.device = hc.device;
  o.protocol = hc.protocol;
  o.decoder_options = hc.decoder;
  return make_device_driver<drivers::HidrawDriver>(stream, hc, std::move(o),
                                                   "hid:" + hc.device.describe() + " (" + hc.protocol + ")");
}

MadeDriver make_socketcan(const StreamConfig& stream) {
  const SocketCanSourceConfig& sc = stream.driver.socketcan;
  drivers::SocketCanDriverOptions o;
  o.interface = sc.interface;
  o.protocol = sc.protocol;
  o.decoder_options = sc.decoder;
  o.fd = sc.fd;
  return make_device_driver<drivers::SocketCanDriver>(stream, sc, std::move(o),
                                                      "socketcan:" + sc.interface + " (" + sc.protocol + ")");
}

}  // namespace

MadeDriver make_driver(const StreamConfig& stream) {
  switch (stream.driver.type) {
    case DriverType::Replay:
      return make_replay(stream);
    case DriverType::Synthetic:
      return make_synthetic(stream);
    case DriverType::Serial:
      return make_serial(stream);
    case DriverType::SocketCan:
      return make_socketcan(stream);
    case DriverType::Hid:
      return make_hid(stream);
  }
  throw std::logic_error("make_driver: unknown driver type");
}

MadeGpioLines make_gpio_lines(const StreamConfig& stream, drivers::SampleSink& next) {
  MadeGpioLines made;
  if (!stream.gpio) return made;
  const GpioConfig& g = *stream.gpio;
  try {
    if (g.data_ready) {
      drivers::GpioDataReadyOptions o;
      o.chip = g.chip;
      o.line = *g.data_ready;
      o.edge = g.edge;
      o.bias = g.bias;
      o.pairing = g.pairing;
      o.reconnect_min = g.reconnect_min;
      o.reconnect_max = g.reconnect_max;
      o.consumer = "posefaird:" + stream.name;
      o.log = to_spdlog(stream.name);
      made.data_ready = std::make_unique<drivers::GpioDataReadySink>(std::move(o), next);
    }
    if (g.output) {
      drivers::GpioOutputOptions o;
      o.chip = g.chip;
      o.line = *g.output;
      o.mode = g.output_mode;
      o.heartbeat_hz = g.heartbeat_hz;
      o.reconnect_min = g.reconnect_min;
      o.reconnect_max = g.reconnect_max;
      o.consumer = "posefaird:" + stream.name + ":out";
      o.log = to_spdlog(stream.name);
      made.output = std::make_unique<drivers::GpioOutputLine>(std::move(o));
    }
  } catch (const std::invalid_argument& e) {
    throw std::runtime_error("stream '" + stream.name + "': " + e.what());
  }
  return made;
}

}  // namespace posefair::daemon
