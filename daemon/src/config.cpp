// posefaird's TOML configuration (docs/config.md): toml++ parses, this file checks every key
// (type, range, cross-references) and builds a DaemonConfig, or throws ConfigError naming the
// file, line, column and dotted key of the first problem.
#include "posefair/daemon/config.hpp"

#include <sched.h>

#include <toml++/toml.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <initializer_list>
#include <limits>
#include <map>
#include <memory>
#include <span>
#include <string_view>
#include <utility>

#include "posefair/core/engine_setting.hpp"
#include "posefair/core/orientation_estimator.hpp"
#include "posefair/core/sample_gate.hpp"
#include "posefair/daemon/output_encoder.hpp"
#include "posefair/daemon/wire_protocol.hpp"
#include "posefair/drivers/can_decoder.hpp"
#include "posefair/drivers/decoder.hpp"
#include "posefair/core/options.hpp"
#include "posefair/drivers/hid_report_decoder.hpp"
#include "posefair/formats/pose_file.hpp"

namespace posefair::daemon {
namespace {

std::string format_what(const std::string& file, std::uint32_t line, std::uint32_t column, const std::string& key,
                        const std::string& message) {
  std::string s = file;
  if (line > 0) {
    s += ':' + std::to_string(line);
    if (column > 0) s += ':' + std::to_string(column);
  }
  s += ": ";
  if (!key.empty()) s += key + ": ";
  return s + message;
}

}  // namespace

ConfigError::ConfigError(std::string file, std::uint32_t line, std::uint32_t column, std::string key,
                         std::string message)
    : Error(ErrorKind::Config, format_what(file, line, column, key, message), key),
      file_(std::move(file)),
      line_(line),
      column_(column),
      message_(std::move(message)) {}

namespace {

constexpr std::int64_t kMaxU32 = std::numeric_limits<std::uint32_t>::max();
constexpr std::int64_t kMaxI64 = std::numeric_limits<std::int64_t>::max();
constexpr std::int64_t kMaxRingCapacity = 1 << 20;

std::string number(double v) {
  char buf[40];
  std::snprintf(buf, sizeof buf, "%g", v);
  return buf;
}

std::string in_quotes(std::string_view s) { return "'" + std::string(s) + "'"; }

std::string join_key(const std::string& prefix, std::string_view key) {
  return prefix.empty() ? std::string(key) : prefix + "." + std::string(key);
}

std::string element_key(const std::string& prefix, std::size_t index0) {
  return prefix + "[" + std::to_string(index0 + 1) + "]";
}

std::string_view type_name(toml::node_type t) {
  switch (t) {
    case toml::node_type::table: return "a table";
    case toml::node_type::array: return "an array";
    case toml::node_type::string: return "a string";
    case toml::node_type::integer: return "an integer";
    case toml::node_type::floating_point: return "a float";
    case toml::node_type::boolean: return "a boolean";
    case toml::node_type::date: return "a date";
    case toml::node_type::time: return "a time";
    case toml::node_type::date_time: return "a date-time";
    case toml::node_type::none: break;
  }
  return "nothing";
}

// Levenshtein distance (small strings: keys).
std::size_t edit_distance(std::string_view a, std::string_view b) {
  std::vector<std::size_t> row(b.size() + 1);
  for (std::size_t j = 0; j <= b.size(); ++j) row[j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i) {
    std::size_t diagonal = row[0];
    row[0] = i;
    for (std::size_t j = 1; j <= b.size(); ++j) {
      const std::size_t above = row[j];
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, diagonal + (a[i - 1] == b[j - 1] ? 0 : 1)});
      diagonal = above;
    }
  }
  return row[b.size()];
}

// " (did you mean 'x'?)" for the nearest candidate within edit distance 2, else "".
std::string suggestion(std::string_view word, std::span<const std::string_view> candidates) {
  std::string_view best;
  std::size_t best_distance = 3;
  for (std::string_view c : candidates) {
    const std::size_t d = edit_distance(word, c);
    if (d < best_distance) {
      best_distance = d;
      best = c;
    }
  }
  return best.empty() ? std::string() : " (did you mean " + in_quotes(best) + "?)";
}

bool before(const toml::source_position& a, const toml::source_position& b) {
  return a.line != b.line ? a.line < b.line : a.column < b.column;
}

constexpr std::string_view kRootKeys[] = {"daemon", "logging", "engine", "stream", "output", "recorder", "subscription", "control"};
constexpr std::string_view kSubscriptionKeys[] = {"enabled", "listen", "allow", "max_subscribers", "max_per_address",
                                                  "rate_per_source", "burst_per_source", "source_table",
                                                  "max_lease", "psk_file"};
constexpr std::string_view kControlKeys[] = {"enabled", "socket", "mode", "group"};
constexpr std::string_view kDaemonKeys[] = {"exit_when_sources_end", "session_id", "realtime_priority", "publish_on", "fair_on",
                                            "spin_us",               "wake",       "cpu_affinity"};
constexpr std::string_view kLoggingKeys[] = {"level", "target", "status_interval"};
constexpr std::string_view kEngineKeys[] = {
    "window",   "window_time", "max_window", "lag", "horizon", "order", "solver", "iterations", "smoothing", "smoothing_r",
    "smoothing_t", "cutoff_hz", "rate_hz", "noise_time", "motion_time", "motion_span", "motion_margin", "rest_threshold", "rest_memory", "prediction_check", "continuity",
    "lambda_r", "lambda_t", "variant",
    "epsilon_r", "epsilon_t", "bound",  "gap",       "gap_intervals", "unit_tolerance", "outlier_threshold", "gyro_aided", "gyro_time_offset",
    "gyro_estimate_offset", "gyro_mounting", "gyro_stream"};
constexpr std::string_view kStreamKeys[] = {"id",     "name", "ring_capacity", "overflow", "driver", "engine",
                                            "spline", "gpio", "fusion",        "mounting", "world",  "busy_poll"};
constexpr std::string_view kGpioKeys[] = {"chip",          "data_ready_line", "edge",        "bias",         "tolerance_min",
                                          "tolerance_max", "output_line",     "output_mode", "heartbeat_hz", "reconnect_min",
                                          "reconnect_max"};
constexpr std::string_view kSplineKeys[] = {"publish_rate_hz", "bridge_gap", "order", "manifold", "velocity", "pose_interpolation"};
// Each [stream.driver] type's own keys; a device type also takes the keys its protocols declare
// (ProtocolKind below), which this file does not name.
constexpr std::string_view kReplayKeys[] = {"type",   "path",   "timing",     "speed",        "schedule",     "loop",
                                            "rounds", "format", "joint",      "csv_prefix",   "skip_missing", "source_stream",
                                            // a candump log (docs/can-devices.md), with a CAN protocol's keys
                                            "candump", "interface", "protocol", "time_source"};
constexpr std::string_view kSyntheticKeys[] = {"type", "rate_hz", "duration", "rotation_noise", "with_position", "seed", "phase"};
constexpr std::string_view kSerialKeys[] = {"type",          "device",       "usb",          "serial_number", "baud",
                                            "data_bits",     "parity",       "stop_bits",    "flow_control",  "protocol",
                                            "time_source",   "reconnect_min", "reconnect_max"};
constexpr std::string_view kHidKeys[] = {"type",        "device",        "usb",          "serial_number", "protocol",
                                         "time_source", "reconnect_min", "reconnect_max"};
constexpr std::string_view kSocketCanKeys[] = {"type", "interface", "protocol", "fd", "time_source", "reconnect_min",
                                               "reconnect_max"};

// One registry of device protocols (serial, CAN or HID), or the output encodings, as the
// configuration sees it: names and the options each declares (core/options.hpp). The
// wording of its errors is the kind's own, as it always was.
struct ProtocolInfo {
  std::string_view name;
  std::span<const posefair::OptionSpec> options;
};
struct ProtocolKind {
  std::string_view what;  // "unknown <what> 'x' (known: ...)"
  bool closed_set;        // an unknown name is refused as a choice: "expected one of ..., got 'x'"
  char owner_quote;       // how "only for protocol X" quotes X
  std::vector<ProtocolInfo> protocols;  // sorted by name
  std::string_view key = "protocol";  // the key that names the entry
  std::string_view holder = "source";  // "this <holder>'s <key> is ..."

  const ProtocolInfo* find(std::string_view name) const {
    for (const ProtocolInfo& p : protocols)
      if (p.name == name) return &p;
    return nullptr;
  }
  // The first protocol other than `except` that declares `key`, or nullptr.
  const ProtocolInfo* owner_of(std::string_view key, std::string_view except) const {
    for (const ProtocolInfo& p : protocols)
      if (p.name != except && posefair::find_option(p.options, key) != nullptr) return &p;
    return nullptr;
  }
  std::vector<std::string_view> names() const {
    std::vector<std::string_view> n;
    for (const ProtocolInfo& p : protocols) n.push_back(p.name);
    return n;
  }
  // Every key some protocol declares, once each.
  std::vector<std::string_view> all_keys() const {
    std::vector<std::string_view> keys;
    for (const ProtocolInfo& p : protocols)
      for (const posefair::OptionSpec& o : p.options)
        if (std::find(keys.begin(), keys.end(), o.name) == keys.end()) keys.push_back(o.name);
    return keys;
  }
};

template <class Entry>
std::vector<ProtocolInfo> protocol_infos(std::span<const Entry* const> entries) {
  std::vector<ProtocolInfo> infos;
  for (const Entry* e : entries) infos.push_back({e->name, e->options});
  std::sort(infos.begin(), infos.end(), [](const ProtocolInfo& a, const ProtocolInfo& b) { return a.name < b.name; });
  return infos;
}
const ProtocolKind& serial_protocols() {
  static const ProtocolKind kind{"protocol", false, '\'', protocol_infos(drivers::decoder_entries())};
  return kind;
}
const ProtocolKind& can_protocols() {
  static const ProtocolKind kind{"CAN protocol", false, '\'', protocol_infos(drivers::can_decoder_entries())};
  return kind;
}
const ProtocolKind& hid_protocols() {
  static const ProtocolKind kind{"HID protocol", true, '"', protocol_infos(drivers::hid_decoder_entries())};
  return kind;
}
const ProtocolKind& output_encodings() {
  static const ProtocolKind kind{"encoding", true, '\'', protocol_infos(output_encoder_entries()), "encoding", "output"};
  return kind;
}
const ProtocolKind& orientation_estimators() {
  static const ProtocolKind kind{"estimator", true, '\'', protocol_infos(posefair::orientation_estimator_entries()),
                                 "estimator", "fusion stage"};
  return kind;
}

// Each [stream.driver] type: its own keys, and the protocols whose keys it also takes.
struct DriverKind {
  DriverType type;
  std::string_view name;
  std::span<const std::string_view> own_keys;
  const ProtocolKind* protocols;  // nullptr: none
  std::vector<std::string_view> keys;  // own_keys and every key of `protocols`
};
const std::vector<DriverKind>& driver_kinds() {
  static const std::vector<DriverKind> kinds = [] {
    std::vector<DriverKind> k{
        {DriverType::Replay, "replay", kReplayKeys, &can_protocols(), {}},
        {DriverType::Synthetic, "synthetic", kSyntheticKeys, nullptr, {}},
        {DriverType::Serial, "serial", kSerialKeys, &serial_protocols(), {}},
        {DriverType::SocketCan, "socketcan", kSocketCanKeys, &can_protocols(), {}},
        {DriverType::Hid, "hid", kHidKeys, &hid_protocols(), {}},
    };
    for (DriverKind& d : k) {
      d.keys.assign(d.own_keys.begin(), d.own_keys.end());
      if (d.protocols == nullptr) continue;
      for (std::string_view key : d.protocols->all_keys())
        if (std::find(d.keys.begin(), d.keys.end(), key) == d.keys.end()) d.keys.push_back(key);
    }
    return k;
  }();
  return kinds;
}

// The first option a table gave for its protocol or encoding, for errors without a key.
struct OptionsGiven {
  const toml::node* first_option = nullptr;
  std::string first_option_key;
};
// The protocol a device source named and the options it gave, for check_protocol.
struct ProtocolGiven : OptionsGiven {
  const toml::node* node = nullptr;  // the protocol key
  std::string name;
};

constexpr std::string_view kOutputKeys[] = {"encoding", "destinations", "ttl",          "interface",
                                            "loopback", "streams",      "angular_velocity", "max_rate_hz", "sendmmsg"};
constexpr std::string_view kRecorderKeys[] = {"path",  "enabled", "max_file_bytes", "flush_interval",
                                              "overwrite", "sync", "ring_capacity"};

// A float's allowed range: [lo, hi] with either end open; infinities only when allow_inf.
struct FloatRange {
  double lo = -std::numeric_limits<double>::infinity();
  bool lo_open = false;
  double hi = std::numeric_limits<double>::infinity();
  bool hi_open = false;
  bool allow_inf = false;

  bool contains(double v) const {
    if (std::isnan(v) || (std::isinf(v) && !allow_inf)) return false;
    if (lo_open ? !(v > lo) : !(v >= lo)) return false;
    if (std::isinf(hi)) return true;
    return hi_open ? v < hi : v <= hi;
  }
  std::string describe() const {
    if (std::isinf(hi)) return std::string(lo_open ? "> " : ">= ") + number(lo);
    return std::string(lo_open ? "in (" : "in [") + number(lo) + ", " + number(hi) + (hi_open ? ")" : "]");
  }
};
constexpr FloatRange kPositive{0.0, true};
constexpr FloatRange kNonNegative{0.0, false};
constexpr FloatRange kUnitInterval{0.0, true, 1.0, false};  // (0, 1]

template <typename E>
struct Choice {
  std::string_view text;
  E value;
};

// Where a value was given: its position and dotted key.
struct Where {
  toml::source_position at{};
  std::string key;
};

template <typename T>
struct Given {
  T value;
  Where where;
};

// One engine table ([engine] or [stream.engine]), type- and range-checked key by key.
struct EngineLayer {
  const toml::table* table = nullptr;
  std::string prefix;
  std::optional<Given<int>> window, max_window, lag, order, iterations;
  std::optional<Given<WindowSolver>> solver;
  std::optional<Given<double>> window_time, horizon, smoothing, smoothing_r, smoothing_t, cutoff_hz, rate_hz, continuity, lambda_r,
      lambda_t, epsilon_r, epsilon_t, gap, gap_intervals, unit_tolerance, outlier_threshold;
  // The adaptation's time constants and margin (core/smoothing_adaptation.hpp).
  std::optional<Given<double>> noise_time, motion_time, motion_span, motion_margin, rest_threshold, rest_memory;
  std::optional<Given<OperatorVariant>> variant;
  std::optional<Given<BoundPolicy>> bound;
  // Gyro-aided fairing (core/gyro_aiding.hpp).
  std::optional<Given<bool>> gyro_aided, gyro_estimate_offset;
  std::optional<Given<bool>> prediction_check;  // the adaptation's check by the next measurement
  std::optional<Given<double>> gyro_time_offset;
  std::optional<Given<Quat>> gyro_mounting;
  std::optional<Given<std::string>> gyro_stream;  // [stream.engine] only: the stream whose gyroscope this one gets
};

class Parser {
 public:
  Parser(std::string file, std::filesystem::path base) : file_(std::move(file)), base_(std::move(base)) {}

  DaemonConfig parse(const toml::table& root) {
    DaemonConfig config;
    check_keys(root, "", kRootKeys);
    if (const toml::node* n = root.get("daemon")) config.daemon = parse_daemon(table_of(*n, "daemon", "[daemon]"));
    if (const toml::node* n = root.get("logging")) config.logging = parse_logging(table_of(*n, "logging", "[logging]"));
    EngineLayer global;
    global.prefix = "engine";
    if (const toml::node* n = root.get("engine")) global = parse_engine(table_of(*n, "engine", "[engine]"), "engine");

    const toml::node* streams = root.get("stream");
    if (streams == nullptr) fail(toml::source_position{}, "stream", "missing required key: at least one [[stream]] table is needed");
    const toml::array& stream_array = array_of_tables(*streams, "stream", "[[stream]]");
    if (stream_array.empty()) fail(*streams, "stream", "at least one [[stream]] table is required");
    std::vector<std::optional<Where>> gyro_streams;  // where each stream's gyro_stream was given
    for (std::size_t i = 0; i < stream_array.size(); ++i) {
      config.streams.push_back(parse_stream(stream_array[i], element_key("stream", i), global, config.streams, gyro_streams.emplace_back()));
    }
    check_gyro_streams(config.streams, gyro_streams);

    if (const toml::node* n = root.get("output")) {
      const toml::array& outputs = array_of_tables(*n, "output", "[[output]]");
      for (std::size_t i = 0; i < outputs.size(); ++i)
        config.outputs.push_back(parse_output(outputs[i], element_key("output", i), config.streams));
    }
    if (const toml::node* n = root.get("recorder")) config.recorder = parse_recorder(table_of(*n, "recorder", "[recorder]"));
    if (const toml::node* n = root.get("subscription")) config.subscription = parse_subscription(table_of(*n, "subscription", "[subscription]"));
    if (const toml::node* n = root.get("control")) config.control = parse_control(table_of(*n, "control", "[control]"));
    return config;
  }

 private:
  // --- errors ---
  [[noreturn]] void fail(const toml::source_position& at, const std::string& key, const std::string& message) const {
    throw ConfigError(file_, at.line, at.line > 0 ? at.column : 0, key, message);
  }
  [[noreturn]] void fail(const toml::node& at, const std::string& key, const std::string& message) const {
    fail(at.source().begin, key, message);
  }
  [[noreturn]] void fail(const Where& where, const std::string& message) const { fail(where.at, where.key, message); }
  [[noreturn]] void wrong_type(const toml::node& n, const std::string& key, std::string_view expected) const {
    fail(n, key, "expected " + std::string(expected) + ", got " + std::string(type_name(n.type())));
  }

  // --- structure ---
  // Every key of t must be one of `known`; the first unknown one in file order is reported.
  void check_keys(const toml::table& t, const std::string& prefix, std::span<const std::string_view> known) const {
    const toml::key* first = nullptr;
    for (auto&& [k, v] : t) {
      if (std::find(known.begin(), known.end(), k.str()) != known.end()) continue;
      if (first == nullptr || before(k.source().begin, first->source().begin)) first = &k;
    }
    if (first != nullptr) fail(first->source().begin, join_key(prefix, first->str()), "unknown key" + suggestion(first->str(), known));
  }

  const toml::node& require(const toml::table& t, std::string_view name, const std::string& prefix) const {
    const toml::node* n = t.get(name);
    if (n == nullptr) fail(t.source().begin, join_key(prefix, name), "missing required key");
    return *n;
  }

  const toml::table& table_of(const toml::node& n, const std::string& key, std::string_view header) const {
    if (!n.is_table()) wrong_type(n, key, "a table (" + std::string(header) + ")");
    return *n.as_table();
  }

  const toml::array& array_of_tables(const toml::node& n, const std::string& key, std::string_view header) const {
    if (!n.is_array()) wrong_type(n, key, "an array of tables (" + std::string(header) + ")");
    return *n.as_array();
  }

  // --- values ---
  bool get_bool(const toml::node& n, const std::string& key) const {
    if (!n.is_boolean()) wrong_type(n, key, "a boolean");
    return n.as_boolean()->get();
  }

  std::string get_string(const toml::node& n, const std::string& key) const {
    if (!n.is_string()) wrong_type(n, key, "a string");
    return n.as_string()->get();
  }

  std::string get_nonempty_string(const toml::node& n, const std::string& key) const {
    std::string s = get_string(n, key);
    if (s.empty()) fail(n, key, "must not be empty");
    return s;
  }

  std::int64_t get_int(const toml::node& n, const std::string& key, std::int64_t lo, std::int64_t hi) const {
    if (!n.is_integer()) wrong_type(n, key, "an integer");
    const std::int64_t v = n.as_integer()->get();
    if (v < lo || v > hi) {
      const std::string range = hi == kMaxI64 ? ">= " + std::to_string(lo)
                                              : "in [" + std::to_string(lo) + ", " + std::to_string(hi) + "]";
      fail(n, key, "out of range: must be " + range + ", got " + std::to_string(v));
    }
    return v;
  }

  std::uint32_t get_u32(const toml::node& n, const std::string& key) const {
    return static_cast<std::uint32_t>(get_int(n, key, 0, kMaxU32));
  }

  std::uint32_t get_ring_capacity(const toml::node& n, const std::string& key) const {
    if (!n.is_integer()) wrong_type(n, key, "an integer");
    const std::int64_t v = n.as_integer()->get();
    if (v < 2 || v > kMaxRingCapacity || (v & (v - 1)) != 0)
      fail(n, key, "must be a power of two in [2, 1048576], got " + std::to_string(v));
    return static_cast<std::uint32_t>(v);
  }

  // A float; integers are accepted too (smoothing = 100).
  double get_float(const toml::node& n, const std::string& key, const FloatRange& range) const {
    double v = 0.0;
    if (n.is_floating_point())
      v = n.as_floating_point()->get();
    else if (n.is_integer())
      v = static_cast<double>(n.as_integer()->get());
    else
      wrong_type(n, key, "a number");
    if (!range.contains(v)) fail(n, key, "out of range: must be " + range.describe() + ", got " + number(v));
    return v;
  }

  template <typename E>
  E get_choice(const toml::node& n, const std::string& key, std::initializer_list<Choice<E>> choices) const {
    return get_choice<E>(n, key, std::span<const Choice<E>>(choices.begin(), choices.size()));
  }

  template <typename E>
  E get_choice(const toml::node& n, const std::string& key, std::span<const Choice<E>> choices) const {
    const std::string s = get_string(n, key);
    std::vector<std::string_view> texts;
    for (const Choice<E>& c : choices) {
      if (c.text == s) return c.value;
      texts.push_back(c.text);
    }
    std::string list;
    for (std::string_view t : texts) list += (list.empty() ? "" : ", ") + in_quotes(t);
    fail(n, key, "expected one of " + list + ", got " + in_quotes(s) + suggestion(s, texts));
  }

  Where where(const toml::node& n, const std::string& key) const { return Where{n.source().begin, key}; }

  std::filesystem::path resolve(const std::string& text) const {
    std::filesystem::path p(text);
    if (p.is_relative()) p = base_ / p;
    return p.lexically_normal();
  }

  // --- tables ---
  DaemonSettings parse_daemon(const toml::table& t) const {
    const std::string prefix = "daemon";
    check_keys(t, prefix, kDaemonKeys);
    DaemonSettings d;
    if (const toml::node* n = t.get("exit_when_sources_end")) d.exit_when_sources_end = get_bool(*n, join_key(prefix, "exit_when_sources_end"));
    if (const toml::node* n = t.get("session_id")) d.session_id = get_u32(*n, join_key(prefix, "session_id"));
    if (const toml::node* n = t.get("realtime_priority"))
      d.realtime_priority = static_cast<int>(get_int(*n, join_key(prefix, "realtime_priority"), 0, 99));
    if (const toml::node* n = t.get("publish_on"))
      d.publish_on = get_choice<PublishThread>(*n, join_key(prefix, "publish_on"),
                                               {{"engine", PublishThread::Engine}, {"publisher", PublishThread::Publisher}});
    if (const toml::node* n = t.get("fair_on"))
      d.fair_on = get_choice<FairThread>(*n, join_key(prefix, "fair_on"), {{"engine", FairThread::Engine}, {"driver", FairThread::Driver}});
    if (const toml::node* n = t.get("spin_us")) d.spin_us = static_cast<int>(get_int(*n, join_key(prefix, "spin_us"), 0, 10000));
    if (const toml::node* n = t.get("wake"))
      d.wake_per_batch = get_choice<bool>(*n, join_key(prefix, "wake"), {{"per-batch", true}, {"per-sample", false}});
    if (const toml::node* n = t.get("cpu_affinity")) {
      const std::string key = join_key(prefix, "cpu_affinity");
      if (!n->is_array()) wrong_type(*n, key, "an array of CPU numbers");
      const toml::array& cpus = *n->as_array();
      for (std::size_t i = 0; i < cpus.size(); ++i) {
        const std::string k = element_key(key, i);
        const int cpu = static_cast<int>(get_int(cpus[i], k, 0, CPU_SETSIZE - 1));
        if (std::find(d.cpu_affinity.begin(), d.cpu_affinity.end(), cpu) != d.cpu_affinity.end())
          fail(cpus[i], k, "CPU " + std::to_string(cpu) + " is listed twice");
        d.cpu_affinity.push_back(cpu);
      }
    }
    return d;
  }

  LoggingConfig parse_logging(const toml::table& t) const {
    const std::string prefix = "logging";
    check_keys(t, prefix, kLoggingKeys);
    LoggingConfig l;
    if (const toml::node* n = t.get("level")) {
      l.level = get_choice<std::string_view>(*n, join_key(prefix, "level"),
                                             {{"trace", "trace"}, {"debug", "debug"}, {"info", "info"}, {"warn", "warn"},
                                              {"error", "error"}, {"critical", "critical"}, {"off", "off"}});
    }
    if (const toml::node* n = t.get("target")) {
      l.target = get_choice<LogTarget>(*n, join_key(prefix, "target"),
                                       {{"auto", LogTarget::Auto}, {"stderr", LogTarget::Stderr}, {"journald", LogTarget::Journald}});
    }
    if (const toml::node* n = t.get("status_interval")) l.status_interval = get_float(*n, join_key(prefix, "status_interval"), kNonNegative);
    return l;
  }

  EngineLayer parse_engine(const toml::table& t, const std::string& prefix) const {
    check_keys(t, prefix, kEngineKeys);
    EngineLayer e;
    e.table = &t;
    e.prefix = prefix;
    auto integer = [&](std::string_view name, std::optional<Given<int>>& out, std::int64_t lo, std::int64_t hi) {
      if (const toml::node* n = t.get(name)) {
        const std::string key = join_key(prefix, name);
        out = Given<int>{static_cast<int>(get_int(*n, key, lo, hi)), where(*n, key)};
      }
    };
    auto real = [&](std::string_view name, std::optional<Given<double>>& out, const FloatRange& range) {
      if (const toml::node* n = t.get(name)) {
        const std::string key = join_key(prefix, name);
        out = Given<double>{get_float(*n, key, range), where(*n, key)};
      }
    };
    auto choice = [&](std::string_view name, auto& out, auto choices) {
      if (const toml::node* n = t.get(name)) {
        const std::string key = join_key(prefix, name);
        using E = decltype(out->value);
        out = Given<E>{get_choice<E>(*n, key, choices), where(*n, key)};
      }
    };
    integer("window", e.window, 2, 4096);
    real("window_time", e.window_time, FloatRange{0.0, true, 60.0, false});
    integer("max_window", e.max_window, kMinWindowSamples, 4096);
    integer("lag", e.lag, 0, 4095);
    real("horizon", e.horizon, FloatRange{0.0, false, 1.0, false});
    if (const toml::node* n = t.get("order")) {
      const std::string key = join_key(prefix, "order");
      if (!n->is_integer()) wrong_type(*n, key, "an integer");
      const std::int64_t v = n->as_integer()->get();
      if (v != 2 && v != 3) fail(*n, key, "must be 2 or 3, got " + std::to_string(v));
      e.order = Given<int>{static_cast<int>(v), where(*n, key)};
    }
    choice("solver", e.solver,
           std::initializer_list<Choice<WindowSolver>>{{"linear", WindowSolver::Linear},
                                                       {"gauss-newton", WindowSolver::GaussNewton},
                                                       {"sweeps", WindowSolver::DampedSweeps}});
    integer("iterations", e.iterations, 1, 1000);
    const FloatRange smoothing_range{0.0, true, kMaxSmoothing, false};
    real("smoothing", e.smoothing, smoothing_range);
    real("smoothing_r", e.smoothing_r, smoothing_range);
    real("smoothing_t", e.smoothing_t, smoothing_range);
    real("cutoff_hz", e.cutoff_hz, kPositive);
    real("rate_hz", e.rate_hz, kPositive);
    const FloatRange adaptation_time{0.0, true, kMaxAdaptationTime, false};
    real("noise_time", e.noise_time, adaptation_time);
    real("motion_time", e.motion_time, adaptation_time);
    real("motion_span", e.motion_span, adaptation_time);
    real("motion_margin", e.motion_margin, FloatRange{0.0, true, kMaxMotionMargin, false});
    real("rest_threshold", e.rest_threshold, FloatRange{0.0, false, kMaxRestThreshold, false});
    real("rest_memory", e.rest_memory, FloatRange{0.0, false, kMaxAdaptationTime, false});
    real("continuity", e.continuity, kNonNegative);
    real("lambda_r", e.lambda_r, kUnitInterval);
    real("lambda_t", e.lambda_t, kUnitInterval);
    choice("variant", e.variant,
           std::initializer_list<Choice<OperatorVariant>>{{"corrected", OperatorVariant::Corrected},
                                                          {"printed", OperatorVariant::Printed}});
    FloatRange epsilon_range = kPositive;
    epsilon_range.allow_inf = true;  // inf: no bound (the default)
    real("epsilon_r", e.epsilon_r, epsilon_range);
    real("epsilon_t", e.epsilon_t, epsilon_range);
    choice("bound", e.bound,
           std::initializer_list<Choice<BoundPolicy>>{{"sample", BoundPolicy::Sample}, {"window", BoundPolicy::Window}});
    real("gap", e.gap, kPositive);
    real("gap_intervals", e.gap_intervals, kNonNegative);
    real("unit_tolerance", e.unit_tolerance, FloatRange{0.0, true, 1.0, true});
    real("outlier_threshold", e.outlier_threshold, FloatRange{0.0, false, kMaxOutlierThreshold, false});
    for (auto [name, field] : {std::pair{"gyro_aided", &e.gyro_aided}, std::pair{"gyro_estimate_offset", &e.gyro_estimate_offset},
                               std::pair{"prediction_check", &e.prediction_check}})
      if (const toml::node* n = t.get(name)) {
        const std::string key = join_key(prefix, name);
        *field = Given<bool>{get_bool(*n, key), where(*n, key)};
      }
    const GyroAidingSettings gyro_defaults;
    real("gyro_time_offset", e.gyro_time_offset,
         FloatRange{-gyro_defaults.max_time_offset_s, false, gyro_defaults.max_time_offset_s, false});
    if (const toml::node* n = t.get("gyro_mounting")) {
      const std::string key = join_key(prefix, "gyro_mounting");
      e.gyro_mounting = Given<Quat>{get_rotation(*n, key), where(*n, key)};
    }
    if (const toml::node* n = t.get("gyro_stream")) {
      const std::string key = join_key(prefix, "gyro_stream");
      if (prefix == "engine") fail(*n, key, "only in [stream.engine]: it names the one stream whose gyroscope that stream gets");
      e.gyro_stream = Given<std::string>{get_nonempty_string(*n, key), where(*n, key)};
    }

    if (e.cutoff_hz) {
      for (const auto* other : {&e.smoothing, &e.smoothing_r, &e.smoothing_t}) {
        if (*other) {
          fail(e.cutoff_hz->where, "cannot be given together with " + (*other)->where.key + " (line " +
                                       std::to_string((*other)->where.at.line) +
                                       ") in one table: cutoff_hz sets smoothing_r and smoothing_t");
        }
      }
    }
    return e;
  }

  // [engine] with the stream's [stream.engine] on top, applied to WindowConfig's defaults,
  // then validated as the engine would.
  WindowConfig build_engine(const EngineLayer& global, const EngineLayer* local,
                            const std::optional<Given<double>>& driver_rate, const toml::table& stream_table,
                            const std::string& stream_prefix, const std::string& stream_name) const {
    WindowConfig c;
    std::map<EngineSetting, Where> origin;  // WindowConfig field -> where it was set
    struct Smoothing {
      bool set = false;
      bool from_cutoff = false;
      double value = 0.0;  // μ, or the cutoff in Hz
      Where where;
    };
    Smoothing r, t;
    for (const EngineLayer* layer : {&global, local}) {
      if (layer == nullptr) continue;
      auto take = [&](const auto& given, auto& field, EngineSetting setting) {
        if (given) {
          field = given->value;
          origin[setting] = given->where;
        }
      };
      take(layer->window, c.window, EngineSetting::Window);
      take(layer->window_time, c.window_s, EngineSetting::Window);
      take(layer->max_window, c.max_window, EngineSetting::Window);
      take(layer->lag, c.lag, EngineSetting::Lag);
      take(layer->horizon, c.horizon_s, EngineSetting::Horizon);
      take(layer->order, c.order, EngineSetting::Order);
      take(layer->solver, c.solver, EngineSetting::Solver);
      take(layer->iterations, c.iterations, EngineSetting::Iterations);
      take(layer->continuity, c.continuity, EngineSetting::Continuity);
      take(layer->lambda_r, c.lambda_r, EngineSetting::LambdaR);
      take(layer->lambda_t, c.lambda_t, EngineSetting::LambdaT);
      take(layer->variant, c.variant, EngineSetting::Variant);
      take(layer->epsilon_t, c.epsilon_t, EngineSetting::EpsilonT);
      take(layer->bound, c.bound, EngineSetting::Bound);
      take(layer->gap, c.gate.gap_threshold, EngineSetting::GapThreshold);
      take(layer->gap_intervals, c.gate.gap_intervals, EngineSetting::GapThreshold);
      take(layer->unit_tolerance, c.gate.unit_tolerance, EngineSetting::UnitTolerance);
      take(layer->outlier_threshold, c.outlier_threshold, EngineSetting::OutlierThreshold);
      take(layer->noise_time, c.adaptation.noise_time_s, EngineSetting::Adaptation);
      take(layer->motion_time, c.adaptation.motion_time_s, EngineSetting::Adaptation);
      take(layer->motion_span, c.adaptation.motion_span_s, EngineSetting::Adaptation);
      take(layer->motion_margin, c.adaptation.motion_margin, EngineSetting::Adaptation);
      take(layer->rest_threshold, c.adaptation.rest_threshold, EngineSetting::Adaptation);
      take(layer->rest_memory, c.adaptation.rest_memory_s, EngineSetting::Adaptation);
      if (layer->prediction_check) c.adaptation.prediction_check = layer->prediction_check->value;
      if (layer->gyro_aided) c.gyro.enabled = layer->gyro_aided->value;
      if (layer->gyro_estimate_offset) c.gyro.estimate_time_offset = layer->gyro_estimate_offset->value;
      if (layer->gyro_time_offset) c.gyro.time_offset_s = layer->gyro_time_offset->value;
      if (layer->gyro_mounting) c.gyro.mounting = layer->gyro_mounting->value;
      if (layer->epsilon_r) {
        // Given as a rotation angle; the engine's bound is the distance on S³, half of it.
        c.epsilon_r = layer->epsilon_r->value / 2.0;
        origin[EngineSetting::EpsilonR] = layer->epsilon_r->where;
      }
      // A more specific table replaces what a less specific one said, key by key; cutoff_hz
      // counts as `smoothing` given as a frequency.
      if (layer->cutoff_hz) r = t = Smoothing{true, true, layer->cutoff_hz->value, layer->cutoff_hz->where};
      if (layer->smoothing) r = t = Smoothing{true, false, layer->smoothing->value, layer->smoothing->where};
      if (layer->smoothing_r) r = Smoothing{true, false, layer->smoothing_r->value, layer->smoothing_r->where};
      if (layer->smoothing_t) t = Smoothing{true, false, layer->smoothing_t->value, layer->smoothing_t->where};
    }

    // The stream's sample rate: its own [stream.engine], else a synthetic driver's rate, else [engine].
    std::optional<Given<double>> rate;
    if (local != nullptr && local->rate_hz)
      rate = local->rate_hz;
    else if (driver_rate)
      rate = driver_rate;
    else if (global.rate_hz)
      rate = global.rate_hz;

    if (rate) {
      c.rate_hz = rate->value;
      origin[EngineSetting::Rate] = rate->where;
    }
    // Unset, a half is adapted to the stream; a cutoff without a known rate is turned into μ by
    // the engine at the rate it measures.
    auto resolve_smoothing = [&](const Smoothing& s, std::optional<double>& field, EngineSetting setting) {
      if (!s.set) return;
      origin[setting] = s.where;
      if (!s.from_cutoff) {
        field = s.value;
        return;
      }
      if (!rate) {
        c.cutoff_hz = s.value;
        origin[EngineSetting::Cutoff] = s.where;
        return;
      }
      try {
        field = smoothing_for_cutoff(s.value, rate->value, c.order);
      } catch (const std::invalid_argument&) {
        fail(s.where, "must be below half the sample rate: cutoff_hz " + number(s.value) + " Hz, rate_hz " +
                          number(rate->value) + " Hz (" + rate->where.key + ")");
      }
    };
    resolve_smoothing(r, c.smoothing_r, EngineSetting::SmoothingR);
    resolve_smoothing(t, c.smoothing_t, EngineSetting::SmoothingT);

    try {
      validate(c);
      // The constructor also refuses an unstable continuity (and checks the gate). It
      // factorises the system for every fill level: milliseconds up to W = 512, which covers
      // every continuity > 0 (validate allows no more), but seconds and hundreds of MB at
      // W = 4096, which the daemon pays once at start, not again for --check or a reload.
      if (c.window <= 512 || c.continuity > 0.0) {
        const FairingWindow probe(c);
      } else {
        const SampleGate gate(c.gate);
      }
    } catch (const std::invalid_argument& e) {
      // An InvalidEngineSetting names the setting; it is reported at the key that set it.
      // Anything else (or a setting left at its default) at the innermost engine table.
      const auto* refused = dynamic_cast<const InvalidEngineSetting*>(&e);
      const std::string what = e.what();
      Where at;
      if (auto it = refused ? origin.find(refused->setting()) : origin.end(); it != origin.end()) {
        at = it->second;
      } else if (local != nullptr) {
        at = Where{local->table->source().begin, local->prefix};
      } else if (global.table != nullptr) {
        at = Where{global.table->source().begin, global.prefix};
      } else {
        at = Where{stream_table.source().begin, stream_prefix};
      }
      std::string message = what;
      const Smoothing* s = nullptr;
      if (refused && refused->setting() == EngineSetting::SmoothingR) s = &r;
      if (refused && refused->setting() == EngineSetting::SmoothingT) s = &t;
      if (s != nullptr && s->from_cutoff && rate)
        message = "cutoff_hz " + number(s->value) + " Hz at rate_hz " + number(rate->value) + " Hz gives " + what;
      if (!at.key.starts_with(stream_prefix)) message += " (for " + stream_prefix + " " + in_quotes(stream_name) + ")";
      fail(at, message);
    }
    return c;
  }

  // device (an absolute path) or usb ("VID:PID", hexadecimal) with an optional serial_number:
  // how serial and HID sources name their device. The examples go into the error messages.
  void parse_device_selection(const toml::table& t, const std::string& prefix, std::string_view path_example,
                              std::string_view usb_example, std::string& device_out,
                              std::optional<drivers::UsbId>& usb_out, std::string& serial_out) const {
    auto key = [&](std::string_view name) { return join_key(prefix, name); };
    const toml::node* device = t.get("device");
    const toml::node* usb = t.get("usb");
    if (device != nullptr && usb != nullptr)
      fail(*usb, key("usb"), "give either device or usb, not both (device is set at line " +
                                 std::to_string(device->source().begin.line) + ")");
    if (device == nullptr && usb == nullptr)
      fail(t.source().begin, key("device"), "missing required key: device (a path) or usb (\"VID:PID\")");
    if (device != nullptr) {
      const std::string path = get_nonempty_string(*device, key("device"));
      if (!std::filesystem::path(path).is_absolute())
        fail(*device, key("device"), "must be an absolute path, e.g. " + std::string(path_example) + ", got " + in_quotes(path));
      device_out = path;
    }
    if (usb != nullptr) {
      const std::string text = get_string(*usb, key("usb"));
      usb_out = drivers::parse_usb_id(text);
      if (!usb_out)
        fail(*usb, key("usb"), "not a USB id: " + in_quotes(text) + "; expected VID:PID in hexadecimal, e.g. " + std::string(usb_example));
    }
    if (const toml::node* n = t.get("serial_number")) {
      if (usb == nullptr) fail(*n, key("serial_number"), "only with usb (it selects among devices of one USB id)");
      serial_out = get_nonempty_string(*n, key("serial_number"));
    }
  }

  // A string that must be one of `choices` ("expected one of ..." otherwise, with a suggestion).
  std::string get_string_choice(const toml::node& n, const std::string& key, std::span<const std::string_view> choices) const {
    const std::string s = get_string(n, key);
    if (std::find(choices.begin(), choices.end(), s) != choices.end()) return s;
    std::string list;
    for (std::string_view c : choices) list += (list.empty() ? "" : ", ") + in_quotes(c);
    fail(n, key, "expected one of " + list + ", got " + in_quotes(s) + suggestion(s, choices));
  }

  // One option value, checked against the TOML type its protocol declares.
  posefair::OptionValue get_option(const toml::node& n, const std::string& key, const posefair::OptionSpec& spec) const {
    using posefair::OptionType;
    switch (spec.type) {
      case OptionType::String:
        if (!spec.choices.empty()) return get_string_choice(n, key, spec.choices);
        return get_nonempty_string(n, key);
      case OptionType::IntegerOrString:  // a number written either way: 0x4F or "0x4F"
        if (n.is_integer()) return std::to_string(n.as_integer()->get());
        return get_nonempty_string(n, key);
      case OptionType::Integer:
        if (!n.is_integer()) wrong_type(n, key, "an integer");
        return n.as_integer()->get();
      case OptionType::Float:
        if (n.is_integer()) return static_cast<double>(n.as_integer()->get());
        if (!n.is_floating_point()) wrong_type(n, key, "a number");
        return n.as_floating_point()->get();
      case OptionType::Boolean:
        return get_bool(n, key);
      case OptionType::IntegerArray: {
        if (!n.is_array()) wrong_type(n, key, "an array of integers");
        const toml::array& a = *n.as_array();
        std::vector<std::int64_t> values;
        for (std::size_t i = 0; i < a.size(); ++i) {
          if (!a[i].is_integer()) wrong_type(a[i], element_key(key, i), "an integer");
          values.push_back(a[i].as_integer()->get());
        }
        return values;
      }
      case OptionType::StringArray: {
        if (!n.is_array()) wrong_type(n, key, "an array of strings");
        const toml::array& a = *n.as_array();
        std::vector<std::string> values;
        for (std::size_t i = 0; i < a.size(); ++i)  // an integer element is taken as its digits: trackers = [1, 2, "head"]
          values.push_back(a[i].is_integer() ? std::to_string(a[i].as_integer()->get()) : get_nonempty_string(a[i], element_key(key, i)));
        return values;
      }
    }
    wrong_type(n, key, to_string(spec.type));
  }

  // The protocol key of a device source (required) and the options of its kind: a key another
  // protocol of the kind declares is refused; each key the protocol declares is type-checked
  // into `out`. The name itself is judged by check_protocol.
  ProtocolGiven parse_protocol_options(const toml::table& t, const std::string& prefix, const ProtocolKind& kind,
                                       posefair::OptionMap& out) const {
    ProtocolGiven g;
    g.node = &require(t, "protocol", prefix);
    g.name = get_nonempty_string(*g.node, join_key(prefix, "protocol"));
    static_cast<OptionsGiven&>(g) = parse_options(t, prefix, kind, g.name, out);
    return g;
  }

  // The options of the entry `name` of `kind` in table t, in file order: a key another entry
  // of the kind declares is refused ("only for protocol 'x'"); each key `name` declares is
  // type-checked into `out`. Other keys are left to check_keys.
  OptionsGiven parse_options(const toml::table& t, const std::string& prefix, const ProtocolKind& kind,
                             const std::string& name, posefair::OptionMap& out) const {
    auto key = [&](std::string_view k) { return join_key(prefix, k); };
    OptionsGiven g;
    const ProtocolInfo* own = kind.find(name);
    // In file order, so that the first problem is the one reported.
    std::vector<std::pair<const toml::key*, const toml::node*>> given;
    for (auto&& [k, v] : t) given.emplace_back(&k, &v);
    std::sort(given.begin(), given.end(), [](const auto& a, const auto& b) { return before(a.first->source().begin, b.first->source().begin); });
    for (const auto& [k, n] : given) {
      const std::string_view option = k->str();
      const posefair::OptionSpec* spec = own ? posefair::find_option(own->options, option) : nullptr;
      if (spec == nullptr) {
        if (const ProtocolInfo* other = kind.owner_of(option, name)) {
          const std::string q(1, kind.owner_quote);
          fail(*n, key(option), "only for " + std::string(kind.key) + " " + q + std::string(other->name) + q + " (this " +
                                    std::string(kind.holder) + "'s " + std::string(kind.key) + " is " + in_quotes(name) + ")");
        }
        continue;
      }
      out[std::string(option)] = get_option(*n, key(option), *spec);
      if (g.first_option == nullptr) {
        g.first_option = n;
        g.first_option_key = key(option);
      }
    }
    return g;
  }

  // A device source's protocol must be one of its kind's ("unknown <what> ..." otherwise, with
  // the list and a suggestion), and its decoder must accept the options: `make` builds it. A
  // refusal (posefair::OptionError) is blamed on the key it names, in the table when given;
  // any other on the first option given, else on the protocol.
  template <class Make>
  void check_protocol(const toml::table& t, const std::string& prefix, const ProtocolKind& kind, const ProtocolGiven& g,
                      Make make) const {
    const std::string protocol_key = join_key(prefix, "protocol");
    if (kind.find(g.name) == nullptr) {
      const std::vector<std::string_view> names = kind.names();
      std::string list;
      for (std::string_view p : names) list += (list.empty() ? "" : ", ") + std::string(kind.closed_set ? in_quotes(p) : p);
      if (kind.closed_set) fail(*g.node, protocol_key, "expected one of " + list + ", got " + in_quotes(g.name) + suggestion(g.name, names));
      fail(*g.node, protocol_key,
           "unknown " + std::string(kind.what) + " " + in_quotes(g.name) + " (known: " + (list.empty() ? "none" : list) + ")" +
               suggestion(g.name, names));
    }
    judge_options(t, prefix, g, g.node, protocol_key, make);
  }

  // `make` builds the decoder or encoder, which judges its own options. A refusal
  // (posefair::OptionError) is blamed on the key it names, in the table when given; any other on
  // the first option given, else on `name_node` (the protocol or encoding key; nullptr: the table).
  template <class Make>
  void judge_options(const toml::table& t, const std::string& prefix, const OptionsGiven& g, const toml::node* name_node,
                     const std::string& name_key, Make make) const {
    try {
      make();
    } catch (const posefair::OptionError& e) {
      blame_option(t, prefix, e);
    } catch (const std::invalid_argument& e) {
      if (g.first_option != nullptr) fail(*g.first_option, g.first_option_key, e.what());
      if (name_node != nullptr) fail(*name_node, name_key, e.what());
      fail(t.source().begin, name_key, e.what());
    }
  }

  // Reports a decoder's refusal at the key it names: "name" or "name[n]" (an array element,
  // 1-based); a key not in the table (a default judged against a given one) at the table.
  [[noreturn]] void blame_option(const toml::table& t, const std::string& prefix, const posefair::OptionError& e) const {
    std::string name = e.key();
    std::size_t index = 0;
    if (const std::size_t open = name.find('['); open != std::string::npos) {
      index = static_cast<std::size_t>(std::strtoul(name.c_str() + open + 1, nullptr, 10));
      name.resize(open);
    }
    std::string message = e.message();
    if (!e.related_key().empty())
      if (const toml::node* other = t.get(e.related_key()))
        message += " (" + e.related_key() + " is set at line " + std::to_string(other->source().begin.line) + ")";
    const toml::node* n = t.get(name);
    if (n != nullptr && index > 0 && n->is_array() && index <= n->as_array()->size()) n = n->as_array()->get(index - 1);
    if (n != nullptr) fail(*n, join_key(prefix, e.key()), message);
    fail(t.source().begin, join_key(prefix, e.key()), message);
  }

  // time_source of a device source (time_base.hpp).
  void parse_time_source(const toml::table& t, const std::string& prefix, drivers::TimeSource& out) const {
    if (const toml::node* n = t.get("time_source"))
      out = get_choice<drivers::TimeSource>(*n, join_key(prefix, "time_source"),
                                            {{"auto", drivers::TimeSource::Auto},
                                             {"receive", drivers::TimeSource::Receive},
                                             {"device", drivers::TimeSource::Device}});
  }

  // reconnect_min and reconnect_max of a device source or GPIO lines: the backoff between open
  // (or request) attempts.
  void parse_reconnect(const toml::table& t, const std::string& prefix, double& min, double& max) const {
    auto key = [&](std::string_view name) { return join_key(prefix, name); };
    const toml::node* min_node = t.get("reconnect_min");
    const toml::node* max_node = t.get("reconnect_max");
    if (min_node != nullptr) min = get_float(*min_node, key("reconnect_min"), FloatRange{0.0, true, 60.0, false});
    if (max_node != nullptr) max = get_float(*max_node, key("reconnect_max"), FloatRange{0.0, true, 3600.0, false});
    if (max < min) {
      if (max_node != nullptr)
        fail(*max_node, key("reconnect_max"), "must be >= reconnect_min (" + number(min) + " s), got " + number(max));
      fail(*min_node, key("reconnect_min"), "must be <= reconnect_max (" + number(max) + " s, the default), got " + number(min));
    }
  }

  // [stream.driver] with type = "serial". The device is not opened (nor required to exist):
  // the driver waits for it.
  void parse_serial(const toml::table& t, const std::string& prefix, SerialSourceConfig& c) const {
    auto key = [&](std::string_view name) { return join_key(prefix, name); };
    parse_device_selection(t, prefix, "'/dev/ttyUSB0' or '/dev/serial/by-id/...'", "'1a86:7523'", c.port.device,
                           c.port.usb, c.port.usb_serial);

    drivers::SerialSettings& st = c.settings;
    if (const toml::node* n = t.get("baud")) st.baud = static_cast<int>(get_int(*n, key("baud"), 50, 12000000));
    if (const toml::node* n = t.get("data_bits")) st.data_bits = static_cast<int>(get_int(*n, key("data_bits"), 5, 8));
    if (const toml::node* n = t.get("parity"))
      st.parity = get_choice<drivers::Parity>(*n, key("parity"),
                                              {{"none", drivers::Parity::None}, {"odd", drivers::Parity::Odd},
                                               {"even", drivers::Parity::Even}, {"mark", drivers::Parity::Mark},
                                               {"space", drivers::Parity::Space}});
    if (const toml::node* n = t.get("stop_bits")) {
      if (!n->is_integer()) wrong_type(*n, key("stop_bits"), "an integer");
      const std::int64_t v = n->as_integer()->get();
      if (v != 1 && v != 2) fail(*n, key("stop_bits"), "must be 1 or 2, got " + std::to_string(v));
      st.stop_bits = static_cast<int>(v);
    }
    if (const toml::node* n = t.get("flow_control"); n != nullptr && n->value<std::string>() == std::string("dtrdsr"))
      fail(*n, key("flow_control"), "Linux has no DTR/DSR flow control (use none, xonxoff or rtscts)");
    if (const toml::node* n = t.get("flow_control"))
      st.flow_control = get_choice<drivers::FlowControl>(
          *n, key("flow_control"),
          {{"none", drivers::FlowControl::None}, {"xonxoff", drivers::FlowControl::XonXoff},
           {"rtscts", drivers::FlowControl::RtsCts}, {"dtrdsr", drivers::FlowControl::DtrDsr}});

    const ProtocolGiven g = parse_protocol_options(t, prefix, serial_protocols(), c.decoder);
    c.protocol = g.name;
    parse_time_source(t, prefix, c.time_source);
    parse_reconnect(t, prefix, c.reconnect_min, c.reconnect_max);

    // Last, so that every other key is judged the same whichever decoders this build has.
    check_protocol(t, prefix, serial_protocols(), g, [&] { (void)drivers::make_decoder(c.protocol, c.decoder); });
  }

  // The CAN keys a live SocketCAN source and a candump replay share: protocol (required), its
  // decoder options, time_source. The protocol is checked last, as for serial.
  void parse_can_decoder(const toml::table& t, const std::string& prefix, SocketCanSourceConfig& c) const {
    const ProtocolGiven g = parse_protocol_options(t, prefix, can_protocols(), c.decoder);
    c.protocol = g.name;
    parse_time_source(t, prefix, c.time_source);
    check_protocol(t, prefix, can_protocols(), g, [&] { (void)drivers::make_can_decoder(c.protocol, c.decoder); });
  }

  // A network interface name as the kernel takes it: 1..15 characters, no '/', no blanks.
  std::string get_interface(const toml::node& n, const std::string& key) const {
    const std::string name = get_nonempty_string(n, key);
    if (name.size() > 15) fail(n, key, "an interface name has at most 15 characters, got " + in_quotes(name));
    if (name.find_first_of("/: \t") != std::string::npos || name == "." || name == "..")
      fail(n, key, "not an interface name: " + in_quotes(name));
    return name;
  }

  // [stream.driver] with type = "socketcan". The interface is not opened (nor required to
  // exist): the driver waits for it.
  void parse_socketcan(const toml::table& t, const std::string& prefix, SocketCanSourceConfig& c) const {
    auto key = [&](std::string_view name) { return join_key(prefix, name); };
    c.interface = get_interface(require(t, "interface", prefix), key("interface"));
    if (const toml::node* n = t.get("fd")) c.fd = get_bool(*n, key("fd"));
    parse_reconnect(t, prefix, c.reconnect_min, c.reconnect_max);
    parse_can_decoder(t, prefix, c);
  }

  // A path key naming a file that exists and is a regular file (resolved against the config's folder).
  std::filesystem::path existing_file(const toml::node& n, const std::string& key) const {
    std::filesystem::path path = resolve(get_nonempty_string(n, key));
    std::error_code ec;
    const auto status = std::filesystem::status(path, ec);
    if (!std::filesystem::exists(status)) fail(n, key, "no such file: " + path.string());
    if (!std::filesystem::is_regular_file(status)) fail(n, key, "not a regular file: " + path.string());
    return path;
  }

  // The timing keys of every replay (a pose file, a sample log, a candump log).
  void parse_replay_timing(const toml::table& t, const std::string& prefix, std::uint32_t stream_id,
                           drivers::ReplayOptions& o) const {
    auto key = [&](std::string_view name) { return join_key(prefix, name); };
    o.stream_id = stream_id;
    if (const toml::node* n = t.get("timing"))
      o.timing = get_choice<drivers::ReplayTiming>(*n, key("timing"), {{"original", drivers::ReplayTiming::Original},
                                                                       {"fast", drivers::ReplayTiming::AsFastAsPossible}});
    if (const toml::node* n = t.get("speed")) o.speed = get_float(*n, key("speed"), kPositive);
    if (const toml::node* n = t.get("schedule"))
      o.schedule = get_choice<drivers::ReplaySchedule>(*n, key("schedule"), {{"time", drivers::ReplaySchedule::Time},
                                                                             {"receive-time", drivers::ReplaySchedule::ReceiveTime}});
    if (const toml::node* n = t.get("loop")) o.loop = get_bool(*n, key("loop"));
    if (const toml::node* n = t.get("rounds")) o.max_rounds = static_cast<std::uint64_t>(get_int(*n, key("rounds"), 0, kMaxI64));
  }

  // [stream.driver] with type = "replay" and key candump: a candump log decoded by a CAN
  // protocol decoder (the driver factory decodes it). Timing keys as for any replay.
  void parse_candump_replay(const toml::table& t, const std::string& prefix, StreamConfig& s) const {
    auto key = [&](std::string_view name) { return join_key(prefix, name); };
    ReplaySourceConfig& r = s.driver.replay;
    const toml::node& log_node = *t.get("candump");
    for (std::string_view other : {"path", "format", "joint", "csv_prefix", "skip_missing", "source_stream"})
      if (const toml::node* n = t.get(other))
        fail(*n, key(other), "not for a candump log (candump is set at line " + std::to_string(log_node.source().begin.line) + ")");
    r.candump = existing_file(log_node, key("candump"));
    if (const toml::node* n = t.get("interface")) r.can.interface = get_interface(*n, key("interface"));
    parse_replay_timing(t, prefix, s.id, r.options);
    parse_can_decoder(t, prefix, r.can);
  }

  // [stream.driver] with type = "hid" (docs/hid-gpio.md). The device is not opened (nor
  // required to exist): the driver waits for it (a protocol may read the report layout from it).
  void parse_hid(const toml::table& t, const std::string& prefix, HidSourceConfig& c) const {
    parse_device_selection(t, prefix, "'/dev/hidraw0'", "'0483:5750'", c.device.device, c.device.usb, c.device.serial);

    const ProtocolGiven g = parse_protocol_options(t, prefix, hid_protocols(), c.decoder);
    c.protocol = g.name;
    parse_time_source(t, prefix, c.time_source);
    parse_reconnect(t, prefix, c.reconnect_min, c.reconnect_max);
    check_protocol(t, prefix, hid_protocols(), g, [&] { (void)drivers::configure_hid_decoder(c.protocol, c.decoder); });
  }

  // [stream.driver]; returns a synthetic driver's rate (the engine's default rate_hz).
  std::optional<Given<double>> parse_driver(const toml::table& t, const std::string& prefix, StreamConfig& s) const {
    const std::string type_key = join_key(prefix, "type");
    const toml::node& type_node = require(t, "type", prefix);
    s.driver.type = get_choice<DriverType>(
        type_node, type_key,
        {{"replay", DriverType::Replay}, {"synthetic", DriverType::Synthetic}, {"serial", DriverType::Serial},
         {"socketcan", DriverType::SocketCan}, {"hid", DriverType::Hid}});
    const std::vector<DriverKind>& kinds = driver_kinds();
    const DriverKind* own = &kinds[0];
    for (const DriverKind& k : kinds)
      if (k.type == s.driver.type) own = &k;
    const toml::key* first = nullptr;
    for (auto&& [k, v] : t) {
      if (std::find(own->keys.begin(), own->keys.end(), k.str()) != own->keys.end()) continue;
      if (first == nullptr || before(k.source().begin, first->source().begin)) first = &k;
    }
    if (first != nullptr) {
      const std::string key = join_key(prefix, first->str());
      const std::string unknown = "unknown key for driver type " + std::string(own->name);
      for (const DriverKind& other : kinds) {
        if (std::find(other.keys.begin(), other.keys.end(), first->str()) != other.keys.end())
          fail(first->source().begin, key, unknown + " (it belongs to type " + std::string(other.name) + ")");
      }
      // Suggestions among the type's own keys and those of the protocol named, when it is known.
      std::vector<std::string_view> candidates = own->keys;
      const toml::node* protocol = t.get("protocol");
      const ProtocolInfo* info = own->protocols && protocol && protocol->is_string()
                                     ? own->protocols->find(protocol->as_string()->get())
                                     : nullptr;
      if (info != nullptr) {
        candidates.assign(own->own_keys.begin(), own->own_keys.end());
        for (const posefair::OptionSpec& o : info->options) candidates.push_back(o.name);
      }
      fail(first->source().begin, key, unknown + suggestion(first->str(), candidates));
    }
    if (s.driver.type == DriverType::Serial) {
      parse_serial(t, prefix, s.driver.serial);
      return std::nullopt;
    }
    if (s.driver.type == DriverType::Hid) {
      parse_hid(t, prefix, s.driver.hid);
      return std::nullopt;
    }
    if (s.driver.type == DriverType::SocketCan) {
      parse_socketcan(t, prefix, s.driver.socketcan);
      return std::nullopt;
    }
    const bool replay = s.driver.type == DriverType::Replay;
    auto key = [&](std::string_view name) { return join_key(prefix, name); };

    if (replay && t.get("candump") != nullptr) {
      parse_candump_replay(t, prefix, s);
      return std::nullopt;
    }
    if (replay) {
      ReplaySourceConfig& r = s.driver.replay;
      for (std::string_view can_key : {"interface", "protocol", "time_source"})
        if (const toml::node* n = t.get(can_key)) fail(*n, key(can_key), "only for a candump log (key candump)");
      for (std::string_view can_key : can_protocols().all_keys())
        if (const toml::node* n = t.get(can_key)) fail(*n, key(can_key), "only for a candump log (key candump)");
      const toml::node& path_node = require(t, "path", prefix);
      r.path = existing_file(path_node, key("path"));
      drivers::ReplayOptions& o = r.options;
      parse_replay_timing(t, prefix, s.id, o);
      if (const toml::node* n = t.get("format")) {
        o.pose.format = get_choice<std::optional<formats::PoseFormat>>(
            *n, key("format"),
            {{"auto", std::nullopt}, {"tum", formats::PoseFormat::Tum}, {"csv", formats::PoseFormat::Csv}, {"bvh", formats::PoseFormat::Bvh}});
      }
      if (const toml::node* n = t.get("joint")) o.pose.bvh_joint = get_nonempty_string(*n, key("joint"));
      if (const toml::node* n = t.get("csv_prefix")) o.pose.csv_prefix = get_string(*n, key("csv_prefix"));
      if (const toml::node* n = t.get("skip_missing")) o.pose.skip_missing = get_bool(*n, key("skip_missing"));
      if (const toml::node* n = t.get("source_stream")) r.source_stream = get_u32(*n, key("source_stream"));
      const auto format = o.pose.format ? o.pose.format : formats::format_from_extension(r.path);
      if (format == formats::PoseFormat::Bvh && o.pose.bvh_joint.empty())
        fail(t.source().begin, key("joint"), "missing required key (a BVH source plays one joint)");
      return std::nullopt;
    }

    SyntheticSourceConfig& g = s.driver.synthetic;
    std::optional<Given<double>> rate;
    if (const toml::node* n = t.get("rate_hz")) {
      g.rate_hz = get_float(*n, key("rate_hz"), FloatRange{0.0, true, 100000.0, false});
      rate = Given<double>{g.rate_hz, where(*n, key("rate_hz"))};
    } else {
      rate = Given<double>{g.rate_hz, Where{t.source().begin, prefix}};
    }
    if (const toml::node* n = t.get("duration")) g.duration = get_float(*n, key("duration"), kNonNegative);
    if (const toml::node* n = t.get("rotation_noise")) g.rotation_noise = get_float(*n, key("rotation_noise"), kNonNegative);
    if (const toml::node* n = t.get("with_position")) g.with_position = get_bool(*n, key("with_position"));
    if (const toml::node* n = t.get("seed")) g.seed = static_cast<std::uint64_t>(get_int(*n, key("seed"), 0, kMaxI64));
    if (const toml::node* n = t.get("phase")) g.phase = get_float(*n, key("phase"), FloatRange{0.0, false, 1.0, true});
    return rate;
  }

  StreamConfig parse_stream(const toml::node& node, const std::string& prefix, const EngineLayer& global,
                            const std::vector<StreamConfig>& earlier, std::optional<Where>& gyro_stream) const {
    const toml::table& t = table_of(node, prefix, "[[stream]]");
    check_keys(t, prefix, kStreamKeys);
    auto key = [&](std::string_view name) { return join_key(prefix, name); };
    StreamConfig s;
    const toml::node& id_node = require(t, "id", prefix);
    s.id = get_u32(id_node, key("id"));
    const toml::node& name_node = require(t, "name", prefix);
    s.name = get_nonempty_string(name_node, key("name"));
    for (std::size_t i = 0; i < earlier.size(); ++i) {
      if (earlier[i].id == s.id)
        fail(id_node, key("id"), "duplicate stream id " + std::to_string(s.id) + " (also " + element_key("stream", i) + ")");
      if (earlier[i].name == s.name)
        fail(name_node, key("name"), "duplicate stream name " + in_quotes(s.name) + " (also " + element_key("stream", i) + ")");
    }
    if (const toml::node* n = t.get("ring_capacity")) s.ring_capacity = get_ring_capacity(*n, key("ring_capacity"));
    if (const toml::node* n = t.get("busy_poll")) s.busy_poll = get_bool(*n, key("busy_poll"));
    if (const toml::node* n = t.get("overflow"))
      s.overflow = get_choice<OverflowPolicy>(*n, key("overflow"), {{"drop-oldest", OverflowPolicy::DropOldest},
                                                                    {"drop-newest", OverflowPolicy::DropNewest}});
    const toml::node& driver_node = require(t, "driver", prefix);
    const std::optional<Given<double>> driver_rate =
        parse_driver(table_of(driver_node, key("driver"), "[stream.driver]"), key("driver"), s);
    std::optional<EngineLayer> local;
    if (const toml::node* n = t.get("engine")) local = parse_engine(table_of(*n, key("engine"), "[stream.engine]"), key("engine"));
    s.engine = build_engine(global, local ? &*local : nullptr, driver_rate, t, prefix, s.name);
    if (const toml::node* n = t.get("spline")) s.spline = parse_spline(table_of(*n, key("spline"), "[stream.spline]"), key("spline"));
    if (const toml::node* n = t.get("fusion")) s.fusion = parse_fusion(table_of(*n, key("fusion"), "[stream.fusion]"), key("fusion"));
    // A fusion stage's orientation is already the gyro's integral: its gyro aids the fairing
    // only when a table asks for it (gyro_aided, or a gyro_stream).
    if (s.fusion && !global.gyro_aided && !(local && (local->gyro_aided || local->gyro_stream))) s.engine.gyro.enabled = false;
    if (local && local->gyro_stream) {
      const Given<std::string>& g = *local->gyro_stream;
      if (!s.engine.gyro.enabled) fail(g.where, "needs gyro-aided fairing, which gyro_aided = false turns off for this stream");
      if (s.engine.solver != WindowSolver::Linear || s.engine.horizon_s > 0.0)
        fail(g.where, "gyro-aided fairing needs the linear solver and no horizon");
      s.gyro_stream = g.value;
      gyro_stream = g.where;
    }
    if (const toml::node* n = t.get("gpio")) {
      std::optional<Given<double>> rate = local && local->rate_hz ? local->rate_hz : driver_rate ? driver_rate : global.rate_hz;
      s.gpio = parse_gpio(table_of(*n, key("gpio"), "[stream.gpio]"), key("gpio"), rate);
    }
    if (const toml::node* n = t.get("mounting")) s.frame.mounting = get_rotation(*n, key("mounting"));
    if (const toml::node* n = t.get("world")) s.frame.world = get_rotation(*n, key("world"));
    return s;
  }

  // [stream.engine] gyro_stream, once every stream is known: the name of another stream that
  // can deliver a gyroscope, and no cycle (a → b → a), so the engine can take each source's
  // readings before the samples they pair with.
  void check_gyro_streams(const std::vector<StreamConfig>& streams, const std::vector<std::optional<Where>>& given) const {
    auto index_of = [&](const std::string& name) {
      for (std::size_t j = 0; j < streams.size(); ++j)
        if (streams[j].name == name) return j;
      return streams.size();
    };
    for (std::size_t i = 0; i < streams.size(); ++i) {
      if (!given[i]) continue;
      const std::string& name = streams[i].gyro_stream;
      const std::size_t j = index_of(name);
      if (j == streams.size()) {
        std::string names;
        for (const StreamConfig& s : streams) names += (names.empty() ? "" : ", ") + in_quotes(s.name);
        fail(*given[i], "no stream named " + in_quotes(name) + " (streams: " + names + ")");
      }
      if (j == i) fail(*given[i], "names this stream itself: the gyroscope must come from another stream on the same body");
      const DriverConfig& d = streams[j].driver;
      const std::string source = in_quotes(name) + " (" + element_key("stream", j) + ")";
      if (d.type == DriverType::Synthetic) fail(*given[i], "stream " + source + " has no gyroscope: a synthetic source makes orientations only");
      if (d.type == DriverType::Replay && d.replay.candump.empty() && !formats::is_sample_log_file(d.replay.path))
        fail(*given[i], "stream " + source + " has no gyroscope: it replays a pose file (" + d.replay.path.filename().string() +
                            "), which holds orientations only; a sample log holds readings");
      // Each stream names at most one source: follow the chain; coming back to i is a cycle.
      std::string chain = in_quotes(streams[i].name);
      for (std::size_t k = j, steps = 0; steps < streams.size(); ++steps) {
        chain += " -> " + in_quotes(streams[k].name);
        if (k == i) fail(*given[i], "forms a cycle of gyro_stream: " + chain);
        if (streams[k].gyro_stream.empty()) break;
        k = index_of(streams[k].gyro_stream);
        if (k == streams.size()) break;  // reported at that stream's own key
      }
    }
  }

  // A rotation ([[stream]] mounting, world): [yaw, pitch, roll] in degrees about posefair's
  // z, y, x (R = Rz Ry Rx), or a unit quaternion [w, x, y, z] (norm within 1e-3 of 1).
  Quat get_rotation(const toml::node& n, const std::string& key) const {
    if (!n.is_array()) wrong_type(n, key, "an array of 3 angles [yaw, pitch, roll] in degrees or a quaternion [w, x, y, z]");
    const toml::array& a = *n.as_array();
    if (a.size() != 3 && a.size() != 4)
      fail(n, key, "expected [yaw, pitch, roll] in degrees or a quaternion [w, x, y, z], got " + std::to_string(a.size()) + " numbers");
    double v[4] = {};
    for (std::size_t i = 0; i < a.size(); ++i) v[i] = get_float(a[i], element_key(key, i), FloatRange{});
    if (a.size() == 3) return rotation_from_zyx_degrees(v[0], v[1], v[2]);
    const Quat q(v[0], v[1], v[2], v[3]);
    if (std::abs(q.norm() - 1.0) > 1e-3) fail(n, key, "a quaternion must have norm 1 (within 1e-3), got " + number(q.norm()));
    return q.normalized();
  }

  // A GPIO line: an offset (integer) or a line name (string).
  drivers::GpioLineRef get_gpio_line(const toml::node& n, const std::string& key) const {
    drivers::GpioLineRef ref;
    if (n.is_integer())
      ref.offset = static_cast<unsigned>(get_int(n, key, 0, 65535));
    else if (n.is_string())
      ref.name = get_nonempty_string(n, key);
    else
      wrong_type(n, key, "a line offset (integer) or a line name (string)");
    return ref;
  }

  // [stream.gpio]; `rate` is the stream's sample rate where known, for the pairing window.
  GpioConfig parse_gpio(const toml::table& t, const std::string& prefix, const std::optional<Given<double>>& rate) const {
    check_keys(t, prefix, kGpioKeys);
    auto key = [&](std::string_view name) { return join_key(prefix, name); };
    GpioConfig g;
    g.chip = get_nonempty_string(require(t, "chip", prefix), key("chip"));
    const toml::node* input = t.get("data_ready_line");
    const toml::node* output = t.get("output_line");
    if (input == nullptr && output == nullptr)
      fail(t.source().begin, key("data_ready_line"), "missing required key: give data_ready_line, output_line or both");
    if (input) g.data_ready = get_gpio_line(*input, key("data_ready_line"));
    if (output) g.output = get_gpio_line(*output, key("output_line"));
    if (g.data_ready && g.output && g.data_ready->offset == g.output->offset && g.data_ready->name == g.output->name)
      fail(*output, key("output_line"), "is the data_ready_line too: a line is an input or an output");
    parse_reconnect(t, prefix, g.reconnect_min, g.reconnect_max);
    // The input line's keys mean nothing without it, the output's nothing without an output.
    for (std::string_view k : {"edge", "bias", "tolerance_min", "tolerance_max"})
      if (const toml::node* n = t.get(k); n && !input) fail(*n, key(k), "needs data_ready_line");
    for (std::string_view k : {"output_mode", "heartbeat_hz"})
      if (const toml::node* n = t.get(k); n && !output) fail(*n, key(k), "needs output_line");
    if (const toml::node* n = t.get("edge"))
      g.edge = get_choice<drivers::GpioEdge>(*n, key("edge"), {{"rising", drivers::GpioEdge::Rising}, {"falling", drivers::GpioEdge::Falling}});
    if (const toml::node* n = t.get("bias"))
      g.bias = get_choice<drivers::GpioBias>(*n, key("bias"), {{"as-is", drivers::GpioBias::AsIs},
                                                               {"pull-up", drivers::GpioBias::PullUp},
                                                               {"pull-down", drivers::GpioBias::PullDown},
                                                               {"disabled", drivers::GpioBias::Disabled}});
    const FloatRange seconds{0.0, false, 10.0, false};
    if (const toml::node* n = t.get("tolerance_min")) g.pairing.tolerance_min = get_float(*n, key("tolerance_min"), seconds);
    const toml::node* max_node = t.get("tolerance_max");
    if (max_node) g.pairing.tolerance_max = get_float(*max_node, key("tolerance_max"), seconds);
    const std::string max_key = key(max_node ? "tolerance_max" : "tolerance_min");
    const toml::source_position max_at = max_node ? max_node->source().begin : t.source().begin;
    try {
      (void)drivers::EdgePairer(g.pairing);  // the pairer judges its own window
    } catch (const std::invalid_argument& e) {
      fail(max_at, max_key, e.what());
    }
    if (input && rate) {
      const double width = g.pairing.tolerance_max - g.pairing.tolerance_min;
      if (width >= 1.0 / rate->value)
        fail(max_at, key("tolerance_max"),
             "the pairing window (tolerance_max - tolerance_min = " + number(width) + " s) must be narrower than the sample period 1/" +
                 number(rate->value) + " Hz (rate from " + rate->where.key + ")");
    }
    if (const toml::node* n = t.get("output_mode"))
      g.output_mode = get_choice<drivers::GpioOutputMode>(
          *n, key("output_mode"), {{"per-pose", drivers::GpioOutputMode::PerPose}, {"heartbeat", drivers::GpioOutputMode::Heartbeat}});
    if (const toml::node* n = t.get("heartbeat_hz")) {
      if (g.output_mode != drivers::GpioOutputMode::Heartbeat) fail(*n, key("heartbeat_hz"), "needs output_mode = 'heartbeat'");
      g.heartbeat_hz = get_float(*n, key("heartbeat_hz"), FloatRange{0.0, true, 10000.0, false});
    }
    return g;
  }

  // [stream.fusion]: an estimator (registry name, default the first: vqf) and its options,
  // type-checked here and judged by the estimator itself, as an output's encoding is.
  FusionConfig parse_fusion(const toml::table& t, const std::string& prefix) const {
    const toml::node* name_node = t.get("estimator");
    const posefair::OrientationEstimatorEntry* entry = posefair::orientation_estimator_entries().front();
    if (name_node != nullptr) {
      std::vector<Choice<const posefair::OrientationEstimatorEntry*>> choices;
      for (const posefair::OrientationEstimatorEntry* e : posefair::orientation_estimator_entries()) choices.push_back({e->name, e});
      entry = get_choice<const posefair::OrientationEstimatorEntry*>(*name_node, join_key(prefix, "estimator"), choices);
    }
    std::vector<std::string_view> known{"estimator"};
    for (std::string_view k : orientation_estimators().all_keys())
      if (std::find(known.begin(), known.end(), k) == known.end()) known.push_back(k);
    check_keys(t, prefix, known);
    FusionConfig f;
    f.estimator = std::string(entry->name);
    const OptionsGiven given = parse_options(t, prefix, orientation_estimators(), f.estimator, f.options);
    judge_options(t, prefix, given, name_node, join_key(prefix, "estimator"), [&] { entry->make(f.options); });
    return f;
  }

  SplineConfig parse_spline(const toml::table& t, const std::string& prefix) const {
    check_keys(t, prefix, kSplineKeys);
    auto key = [&](std::string_view name) { return join_key(prefix, name); };
    namespace gs = geometric_splines;
    SplineConfig c;
    if (const toml::node* n = t.get("publish_rate_hz")) c.publish_rate_hz = get_float(*n, key("publish_rate_hz"), FloatRange{0.0, true, 100000.0, false});
    if (const toml::node* n = t.get("bridge_gap")) c.bridge_gap = get_float(*n, key("bridge_gap"), FloatRange{0.0, true, 10.0, false});
    if (const toml::node* n = t.get("order")) c.spline.order = static_cast<int>(get_int(*n, key("order"), 1, gs::kMaxSplineOrder));
    if (const toml::node* n = t.get("manifold"))
      c.spline.manifold = get_choice<gs::OrientationManifold>(
          *n, key("manifold"), {{"sphere", gs::OrientationManifold::Sphere}, {"lie-group", gs::OrientationManifold::LieGroup}});
    if (const toml::node* n = t.get("velocity"))
      // The fit looks several knots ahead: more delay, and the gap bridge holds only one sample.
      c.spline.velocity.estimator = get_choice<gs::KnotVelocityEstimator>(
          *n, key("velocity"), {{"bessel", gs::KnotVelocityEstimator::Bessel}, {"central", gs::KnotVelocityEstimator::CentralDifference}});
    parse_pose_interpolation(t, prefix, c);
    return c;
  }

  // pose_interpolation: "matrix-lerp" lerps between the two neighbouring samples (C^0) and uses
  // no spline, so the spline's own keys would be silently ignored: they are refused with it.
  void parse_pose_interpolation(const toml::table& t, const std::string& prefix, SplineConfig& c) const {
    const toml::node* n = t.get("pose_interpolation");
    if (!n) return;
    c.pose_interpolation = get_choice<PoseInterpolation>(
        *n, join_key(prefix, "pose_interpolation"), {{"spline", PoseInterpolation::Spline}, {"matrix-lerp", PoseInterpolation::MatrixLerp}});
    if (c.pose_interpolation != PoseInterpolation::MatrixLerp) return;
    for (std::string_view k : {"order", "manifold", "velocity"})
      if (const toml::node* s = t.get(k))
        fail(*s, join_key(prefix, k),
             "has no meaning with pose_interpolation = 'matrix-lerp' (a lerp between the two neighbouring samples, "
             "no spline); remove it, or use pose_interpolation = 'spline'");
  }

  // [[output]] destinations: at least one; a destination without a port gets the encoding's
  // default port (its client's usual one).
  std::vector<Endpoint> parse_destinations(const toml::table& t, const std::string& prefix, const OutputEncoderEntry& encoding) const {
    auto key = [&](std::string_view name) { return join_key(prefix, name); };
    std::vector<Endpoint> out;
    const toml::node& dest_node = require(t, "destinations", prefix);
    if (!dest_node.is_array()) wrong_type(dest_node, key("destinations"), "an array of strings");
    const toml::array& dests = *dest_node.as_array();
    if (dests.empty()) fail(dest_node, key("destinations"), "must list at least one destination");
    for (std::size_t i = 0; i < dests.size(); ++i) {
      const std::string k = element_key(key("destinations"), i);
      const std::string text = get_string(dests[i], k);
      const std::optional<Endpoint> e = Endpoint::parse(text, encoding.default_port != 0 ? encoding.default_port : kDefaultPort);
      if (!e)
        fail(dests[i], k, "not a destination: " + in_quotes(text) +
                              "; expected a numeric IPv4 or IPv6 address with an optional port, e.g. '239.255.0.1:5700' or '[::1]:5700'");
      if (e->port() == 0) fail(dests[i], k, "port 0 is not a destination: " + in_quotes(text));
      if (e->is_unspecified()) fail(dests[i], k, "the unspecified address is not a destination: " + in_quotes(text));
      out.push_back(*e);
    }
    return out;
  }

  OutputConfig parse_output(const toml::node& node, const std::string& prefix, const std::vector<StreamConfig>& streams) const {
    const toml::table& t = table_of(node, prefix, "[[output]]");
    auto key = [&](std::string_view name) { return join_key(prefix, name); };
    OutputConfig o;
    // The encoding first: it may accept keys of its own, which it declares (output_encoder.hpp).
    const toml::node* encoding_node = t.get("encoding");
    const OutputEncoderEntry* encoding = output_encoder_entries().front();
    if (encoding_node != nullptr) {
      std::vector<Choice<const OutputEncoderEntry*>> encodings;
      for (const OutputEncoderEntry* e : output_encoder_entries()) encodings.push_back({e->name, e});
      encoding = get_choice<const OutputEncoderEntry*>(*encoding_node, key("encoding"), encodings);
    }
    // Every encoding's keys are known here, so that another encoding's is refused as such.
    std::vector<std::string_view> known(std::begin(kOutputKeys), std::end(kOutputKeys));
    for (std::string_view k : output_encodings().all_keys())
      if (std::find(known.begin(), known.end(), k) == known.end()) known.push_back(k);
    check_keys(t, prefix, known);
    posefair::OptionMap options;
    const OptionsGiven given = parse_options(t, prefix, output_encodings(), std::string(encoding->name), options);

    if (encoding->own_transport) {
      // It finds its readers by its own discovery (DDS): the UDP keys would mean nothing.
      for (std::string_view k : {"destinations", "ttl", "interface", "loopback", "sendmmsg"})
        if (const toml::node* n = t.get(k))
          fail(*n, key(k), "has no meaning with encoding " + in_quotes(encoding->name) + ", which finds its readers by its own discovery");
    } else {
      o.destinations = parse_destinations(t, prefix, *encoding);
    }

    if (const toml::node* n = t.get("ttl")) o.send.multicast_ttl = static_cast<int>(get_int(*n, key("ttl"), 0, 255));
    if (const toml::node* n = t.get("interface")) o.send.interface.name_or_address = get_nonempty_string(*n, key("interface"));
    if (const toml::node* n = t.get("loopback")) o.send.multicast_loopback = get_bool(*n, key("loopback"));
    if (const toml::node* n = t.get("sendmmsg")) o.send.sendmmsg = get_bool(*n, key("sendmmsg"));
    if (const toml::node* n = t.get("angular_velocity")) o.angular_velocity = get_bool(*n, key("angular_velocity"));
    if (const toml::node* n = t.get("max_rate_hz")) o.max_rate_hz = get_float(*n, key("max_rate_hz"), kPositive);
    if (const toml::node* n = t.get("streams")) {
      if (!n->is_array()) wrong_type(*n, key("streams"), "an array of stream ids");
      const toml::array& ids = *n->as_array();
      for (std::size_t i = 0; i < ids.size(); ++i) {
        const std::string k = element_key(key("streams"), i);
        const std::uint32_t id = get_u32(ids[i], k);
        if (std::none_of(streams.begin(), streams.end(), [&](const StreamConfig& s) { return s.id == id; }))
          fail(ids[i], k, "no [[stream]] has id " + std::to_string(id));
        if (std::find(o.streams.begin(), o.streams.end(), id) != o.streams.end())
          fail(ids[i], k, "stream " + std::to_string(id) + " is listed twice");
        o.streams.push_back(id);
      }
    }
    // Built once, here: the publisher only calls it. It learns the streams it carries in the
    // order the output lists them (all, in config order, when it lists none).
    std::vector<OutputStream> carried;
    for (const StreamConfig& s : streams)
      if (o.streams.empty()) carried.push_back({s.id, s.name});
    for (std::uint32_t id : o.streams)
      for (const StreamConfig& s : streams)
        if (s.id == id) carried.push_back({s.id, s.name});
    judge_options(t, prefix, given, encoding_node, key("encoding"), [&] { o.encoder = encoding->make(options, carried); });
    return o;
  }

  RecorderConfig parse_recorder(const toml::table& t) const {
    const std::string prefix = "recorder";
    check_keys(t, prefix, kRecorderKeys);
    auto key = [&](std::string_view name) { return join_key(prefix, name); };
    RecorderConfig r;
    r.enabled = true;
    if (const toml::node* n = t.get("enabled")) r.enabled = get_bool(*n, key("enabled"));
    const toml::node& path_node = require(t, "path", prefix);
    r.path = resolve(get_nonempty_string(path_node, key("path")));
    if (const toml::node* n = t.get("max_file_bytes")) r.max_file_bytes = static_cast<std::uint64_t>(get_int(*n, key("max_file_bytes"), 0, kMaxI64));
    if (const toml::node* n = t.get("flush_interval")) r.flush_interval = get_float(*n, key("flush_interval"), kPositive);
    if (const toml::node* n = t.get("overwrite")) r.overwrite = get_bool(*n, key("overwrite"));
    if (const toml::node* n = t.get("sync")) r.sync = get_bool(*n, key("sync"));
    if (const toml::node* n = t.get("ring_capacity")) r.ring_capacity = get_ring_capacity(*n, key("ring_capacity"));
    if (r.enabled) {
      std::error_code ec;
      if (std::filesystem::is_directory(r.path, ec)) fail(path_node, key("path"), "is a directory: " + r.path.string());
      const std::filesystem::path dir = r.path.parent_path();
      if (!std::filesystem::is_directory(dir, ec)) fail(path_node, key("path"), "no such directory: " + dir.string());
    }
    return r;
  }

  // [subscription] (subscription_handler.hpp): absent or enabled = false, no port is opened.
  std::optional<SubscriptionSettings> parse_subscription(const toml::table& t) const {
    const std::string prefix = "subscription";
    check_keys(t, prefix, kSubscriptionKeys);
    auto key = [&](std::string_view name) { return join_key(prefix, name); };
    if (const toml::node* n = t.get("enabled"); n && !get_bool(*n, key("enabled"))) return std::nullopt;
    SubscriptionSettings s;
    if (const toml::node* n = t.get("listen")) {
      const std::string text = get_string(*n, key("listen"));
      const auto e = Endpoint::parse(text, kDefaultControlPort);
      if (!e || e->is_multicast())
        fail(*n, key("listen"), "not a local address: " + in_quotes(text) + "; expected e.g. '127.0.0.1:5710' or '[::1]:5710'");
      s.listen = *e;
    }
    if (const toml::node* n = t.get("allow")) {
      if (!n->is_array()) wrong_type(*n, key("allow"), "an array of CIDR ranges");
      std::vector<CidrRange> ranges;
      const toml::array& a = *n->as_array();
      for (std::size_t i = 0; i < a.size(); ++i) {
        const std::string k = element_key(key("allow"), i);
        const std::string text = get_string(a[i], k);
        const auto r = CidrRange::parse(text);
        if (!r) fail(a[i], k, "not a CIDR range: " + in_quotes(text) + "; expected e.g. '192.168.1.0/24' or '::1/128'");
        ranges.push_back(*r);
      }
      s.allow = AddressAllowList(std::move(ranges));
    }
    auto count = [&](std::string_view name, std::uint32_t& out, std::int64_t hi) {
      if (const toml::node* n = t.get(name)) out = static_cast<std::uint32_t>(get_int(*n, key(name), 1, hi));
    };
    count("max_subscribers", s.max_subscribers, 4096);
    count("max_per_address", s.max_per_address, 4096);
    count("source_table", s.source_table, 1 << 20);
    const FloatRange rate{0.0, true, 1e9, false};
    if (const toml::node* n = t.get("rate_per_source")) s.rate_per_source = get_float(*n, key("rate_per_source"), rate);
    if (const toml::node* n = t.get("burst_per_source")) s.burst_per_source = get_float(*n, key("burst_per_source"), FloatRange{1.0, false, 1e9, false});
    if (const toml::node* n = t.get("max_lease")) s.max_lease = get_float(*n, key("max_lease"), FloatRange{1.0, false, 86400.0, false});
    if (const toml::node* n = t.get("psk_file")) {
      const std::filesystem::path path = resolve(get_nonempty_string(*n, key("psk_file")));
      std::FILE* f = std::fopen(path.c_str(), "rb");
      if (!f) fail(*n, key("psk_file"), "cannot read " + path.string() + ": " + std::strerror(errno));
      char buf[256];
      const std::size_t got = std::fread(buf, 1, sizeof buf, f);
      std::fclose(f);
      s.psk = parse_psk(std::string_view(buf, got));
      if (!s.psk) fail(*n, key("psk_file"), path.string() + " does not hold a key: expected 64 hex digits (32 bytes)");
    }
    return s;
  }

  // [control] (ControlSocketConfig): absent or enabled = false, no socket is made.
  std::optional<ControlSocketConfig> parse_control(const toml::table& t) const {
    const std::string prefix = "control";
    check_keys(t, prefix, kControlKeys);
    auto key = [&](std::string_view name) { return join_key(prefix, name); };
    if (const toml::node* n = t.get("enabled"); n && !get_bool(*n, key("enabled"))) return std::nullopt;
    ControlSocketConfig c;
    if (const toml::node* n = t.get("socket")) c.path = resolve(get_nonempty_string(*n, key("socket")));
    if (const toml::node* n = t.get("mode")) c.mode = static_cast<std::uint32_t>(get_int(*n, key("mode"), 0, 0777));
    if (const toml::node* n = t.get("group")) c.group = get_nonempty_string(*n, key("group"));
    if (c.mode & 0007) fail(*t.get("mode"), key("mode"), "must give others no access (the socket reconfigures the daemon)");
    return c;
  }

  std::string file_;
  std::filesystem::path base_;
};

}  // namespace

DaemonConfig parse_config(std::string_view text, const std::filesystem::path& file) {
  const std::string name = file.string();
  try {
    toml::table root;
    try {
      root = toml::parse(text, std::string_view(name));
    } catch (const toml::parse_error& e) {
      const toml::source_position at = e.source().begin;
      throw ConfigError(name, at.line, at.line > 0 ? at.column : 0, "", std::string(e.description()));
    }
    std::error_code ec;
    std::filesystem::path absolute = std::filesystem::absolute(file, ec);
    if (ec) absolute = file;
    Parser parser(name, absolute.parent_path());
    DaemonConfig config = parser.parse(root);
    config.source_file = file;
    return config;
  } catch (const ConfigError&) {
    throw;
  } catch (const std::exception& e) {
    throw ConfigError(name, 0, 0, "", e.what());  // e.g. out of memory: still a ConfigError
  }
}

DaemonConfig load_config(const std::filesystem::path& file) {
  const std::string name = file.string();
  std::unique_ptr<std::FILE, int (*)(std::FILE*)> f(std::fopen(name.c_str(), "rb"), &std::fclose);
  if (!f) throw ConfigError(name, 0, 0, "", std::string("cannot read: ") + std::strerror(errno));
  std::string text;
  char buf[65536];
  std::size_t got = 0;
  while ((got = std::fread(buf, 1, sizeof buf, f.get())) > 0) text.append(buf, got);
  if (std::ferror(f.get())) throw ConfigError(name, 0, 0, "", std::string("cannot read: ") + std::strerror(errno));
  return parse_config(text, file);
}

}  // namespace posefair::daemon
