// The hidraw driver: finding the node through sysfs, the report descriptor, the decoder, the
// time base and reconnection; see hidraw_driver.hpp.
#include "posefair/drivers/hidraw_driver.hpp"

#include <fcntl.h>
#include <linux/hidraw.h>
#include <poll.h>
#include <sys/ioctl.h>
#include <time.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <charconv>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <system_error>
#include <utility>

#include "link_log_text.hpp"
#include "monotonic_clock.hpp"
#include "sample_stamper.hpp"

namespace posefair::drivers {
namespace {

// A hexadecimal number of 1..max_digits digits that fits 16 bits.
std::optional<std::uint16_t> hex16(std::string_view s, std::size_t max_digits) {
  if (s.empty() || s.size() > max_digits) return std::nullopt;
  std::uint32_t v = 0;
  const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), v, 16);
  if (ec != std::errc{} || end != s.data() + s.size() || v > 0xFFFF) return std::nullopt;
  return static_cast<std::uint16_t>(v);
}

std::string slurp_small(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream out;
  out << in.rdbuf();
  return out.str();
}

DecoderCounters& operator+=(DecoderCounters& a, const DecoderCounters& b) {
  a.bytes += b.bytes;
  a.frames += b.frames;
  a.samples += b.samples;
  a.bad_checksum += b.bad_checksum;
  a.malformed += b.malformed;
  a.ignored_frames += b.ignored_frames;
  a.resyncs += b.resyncs;
  a.skipped_bytes += b.skipped_bytes;
  return a;
}

// Why a node could not be opened; each kind is logged once per wait.
enum class OpenFailure : unsigned { NotFound, PermissionDenied, Descriptor, Other };

struct OpenError {
  OpenFailure kind = OpenFailure::Other;
  std::string message;
};

// Consecutive transient read errors after which the node is treated as gone and reopened.
constexpr int kTransientLimit = 10;
// A connection that lasted this long (s) resets the backoff when it is lost.
constexpr double kStableConnection = 1.0;
// hidraw's largest report (HID_MAX_BUFFER_SIZE in the kernel).
constexpr std::size_t kMaxReport = 16384;

bool is_gone(int error) { return error == EIO || error == ENODEV || error == ENXIO || error == EPIPE; }

}  // namespace

std::optional<HidUevent> parse_hid_uevent(std::string_view text) {
  HidUevent u;
  bool have_id = false;
  while (!text.empty()) {
    const std::size_t nl = text.find('\n');
    std::string_view line = text.substr(0, nl);
    text = nl == std::string_view::npos ? std::string_view{} : text.substr(nl + 1);
    if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
    const std::size_t eq = line.find('=');
    if (eq == std::string_view::npos) continue;
    const std::string_view key = line.substr(0, eq), value = line.substr(eq + 1);
    if (key == "HID_ID") {
      const std::size_t a = value.find(':');
      const std::size_t b = a == std::string_view::npos ? a : value.find(':', a + 1);
      if (b == std::string_view::npos) return std::nullopt;
      const auto bus = hex16(value.substr(0, a), 4);
      const auto vendor = hex16(value.substr(a + 1, b - a - 1), 8);
      const auto product = hex16(value.substr(b + 1), 8);
      if (!bus || !vendor || !product) return std::nullopt;
      u.bus = *bus;
      u.vendor = *vendor;
      u.product = *product;
      have_id = true;
    } else if (key == "HID_NAME") {
      u.name = std::string(value);
    } else if (key == "HID_UNIQ") {
      u.uniq = std::string(value);
    }
  }
  if (!have_id) return std::nullopt;
  return u;
}

std::string HidDeviceSpec::describe() const {
  if (!usb) return device;
  std::string s = "usb " + to_string(*usb);
  if (!serial.empty()) s += " serial " + serial;
  return s;
}

std::vector<std::string> find_hidraw_nodes(const HidDeviceSpec& spec, const std::filesystem::path& sysfs_root,
                                           const std::filesystem::path& dev_root) {
  std::vector<std::pair<unsigned long, std::string>> found;
  if (!spec.usb) return {};
  std::error_code ec;
  for (std::filesystem::directory_iterator it(sysfs_root / "class" / "hidraw", ec), end; !ec && it != end; it.increment(ec)) {
    const std::string name = it->path().filename().string();
    if (!name.starts_with("hidraw") || name.size() == 6) continue;
    unsigned long number = 0;
    const auto [p, err] = std::from_chars(name.data() + 6, name.data() + name.size(), number);
    if (err != std::errc{} || p != name.data() + name.size()) continue;
    const std::optional<HidUevent> u = parse_hid_uevent(slurp_small(it->path() / "device" / "uevent"));
    if (!u || u->vendor != spec.usb->vid || u->product != spec.usb->pid) continue;
    if (!spec.serial.empty() && u->uniq != spec.serial) continue;
    found.emplace_back(number, (dev_root / name).string());
  }
  std::sort(found.begin(), found.end());
  std::vector<std::string> nodes;
  for (auto& f : found) nodes.push_back(std::move(f.second));
  return nodes;
}

HidrawDriver::HidrawDriver(HidrawDriverOptions options) : options_(std::move(options)) {
  if (!options_.device.usb && options_.device.device.empty())
    throw std::invalid_argument("hid: give a device path or a USB id");
  if (!(options_.reconnect_min > 0.0) || !std::isfinite(options_.reconnect_min))
    throw std::invalid_argument("hid: reconnect_min must be finite and > 0");
  if (!(options_.reconnect_max >= options_.reconnect_min) || !std::isfinite(options_.reconnect_max))
    throw std::invalid_argument("hid: reconnect_max must be finite and >= reconnect_min");
  if (!(options_.read_timeout > 0.0 && options_.read_timeout <= 0.05))
    throw std::invalid_argument("hid: read_timeout must be in (0, 0.05] s");
  const TimeBase check(options_.time_source, options_.time_base);  // throws for bad time base options
  decoder_factory_ = configure_hid_decoder(options_.protocol, options_.decoder_options);  // throws OptionError
  if (!decoder_factory_) {
    std::string known;
    for (const std::string& p : hid_decoder_protocols()) known += (known.empty() ? "" : ", ") + p;
    throw std::invalid_argument("hid: unknown protocol '" + options_.protocol + "' (known: " + known + ")");
  }
  name_ = options_.name.empty() ? "hid:" + options_.device.describe() : options_.name;
}

void HidrawDriver::log(LogLevel level, const std::string& message) const {
  if (options_.log) options_.log(level, message);
}

DecoderCounters HidrawDriver::decoder_counters() const {
  std::lock_guard lock(snapshot_mutex_);
  return decoder_snapshot_;
}

std::string HidrawDriver::device_path() const {
  std::lock_guard lock(snapshot_mutex_);
  return device_path_;
}

std::optional<DeviceHealth> HidrawDriver::health() const {
  DeviceHealth h;
  h.connected = connected();
  h.outages = outages();
  h.reconnects = reconnects();
  h.open_failures = open_failures();
  h.read_errors = read_errors();
  const DecoderCounters d = decoder_counters();
  h.frames = d.frames;
  h.bad_frames = d.bad_checksum + d.malformed;
  h.device_time_trusted = trusted_.load(std::memory_order_relaxed);
  h.time_fallbacks = fallbacks_.load(std::memory_order_relaxed);
  return h;
}

// An open node with its decoder.
struct HidrawDriver::Opened {
  int fd = -1;
  std::string path;
  std::string note;                             // worth one log line (several nodes matched)
  std::string what;                             // the report read, for the "opened" line
  std::unique_ptr<HidReportDecoder> decoder;    // built for this node's descriptor
};

void HidrawDriver::run(std::stop_token stop, SampleSink& sink) {
  using Clock = std::chrono::steady_clock;
  std::mutex wait_mutex;
  std::condition_variable_any wake;  // nobody notifies it: it wakes at the deadline or on stop
  auto wait = [&](double seconds) {
    std::unique_lock lock(wait_mutex);
    wake.wait_for(lock, stop, std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(seconds)),
                  [] { return false; });
  };

  // Opens the node and builds its decoder.
  auto open = [&](Opened& o) -> std::optional<OpenError> {
    std::string path = options_.device.device;
    o.note.clear();
    if (options_.device.usb) {
      const std::vector<std::string> nodes = find_hidraw_nodes(options_.device, options_.sysfs_root, options_.dev_root);
      if (nodes.empty()) return OpenError{OpenFailure::NotFound, "no hidraw node with HID id " + options_.device.describe()};
      path = nodes.front();
      if (nodes.size() > 1)
        o.note = std::to_string(nodes.size()) + " hidraw nodes match " + options_.device.describe() + "; using " + path +
                 " (set serial_number or device to choose)";
    }
    const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC | O_NONBLOCK);
    if (fd < 0) {
      const int e = errno;
      const std::string message = path + ": " + std::strerror(e);
      if (e == ENOENT || e == ENODEV || e == ENXIO) return OpenError{OpenFailure::NotFound, message};
      if (e == EACCES || e == EPERM) return OpenError{OpenFailure::PermissionDenied, message};
      return OpenError{OpenFailure::Other, message};
    }
    auto refuse = [&](OpenFailure kind, const std::string& message) {
      ::close(fd);
      return OpenError{kind, path + ": " + message};
    };
    int size = 0;
    if (::ioctl(fd, HIDIOCGRDESCSIZE, &size) < 0) return refuse(OpenFailure::Other, std::string("HIDIOCGRDESCSIZE: ") + std::strerror(errno));
    hidraw_report_descriptor rd{};
    rd.size = static_cast<std::uint32_t>(std::clamp(size, 0, HID_MAX_DESCRIPTOR_SIZE));
    if (::ioctl(fd, HIDIOCGRDESC, &rd) < 0) return refuse(OpenFailure::Other, std::string("HIDIOCGRDESC: ") + std::strerror(errno));
    try {
      o.decoder = decoder_factory_->make(std::span<const std::uint8_t>(rd.value, rd.size), o.what);
    } catch (const std::invalid_argument& e) {
      return refuse(OpenFailure::Descriptor, e.what());
    }
    o.fd = fd;
    o.path = path;
    return std::nullopt;
  };

  const int timeout_ms = std::max(1, static_cast<int>(std::lround(options_.read_timeout * 1000.0)));
  std::vector<std::uint8_t> buffer(kMaxReport);
  TimeBase time_base(options_.time_source, options_.time_base);
  std::uint64_t sequence = 0;
  SampleStamper stamper(options_.stream_id, time_base, sink, sequence, samples_, dropped_);
  Opened node;
  DecoderCounters past;  // of the decoders of earlier connections (one is built per open)
  auto publish = [&] {
    DecoderCounters sum = past;
    if (node.decoder) sum += node.decoder->counters();
    {
      std::lock_guard lock(snapshot_mutex_);
      decoder_snapshot_ = sum;
    }
    fallbacks_.store(time_base.counters().fallbacks, std::memory_order_relaxed);
    trusted_.store(time_base.trusted(), std::memory_order_relaxed);
  };
  auto close_node = [&] {
    if (node.fd >= 0) ::close(node.fd);
    node.fd = -1;
    if (node.decoder) {
      past += node.decoder->counters();
      node.decoder.reset();
    }
  };

  const std::string backoff = backoff_text(options_.reconnect_min) + " .. " + backoff_text(options_.reconnect_max);
  bool lost = false;
  double waiting_since = monotonic_seconds();
  std::uint64_t attempts = 0;
  double delay = options_.reconnect_min;
  unsigned logged_kinds = 0;  // bit per OpenFailure already logged in this wait
  auto bit = [](OpenFailure k) { return 1u << static_cast<unsigned>(k); };
  std::string logged_note;
  int transient_streak = 0;
  double opened_at = 0.0;

  while (!stop.stop_requested()) {
    if (node.fd < 0) {
      if (const std::optional<OpenError> e = open(node)) {
        open_failures_.fetch_add(1, std::memory_order_relaxed);
        ++attempts;
        if ((logged_kinds & bit(e->kind)) == 0) {  // one line per reason per wait, not per retry
          logged_kinds |= bit(e->kind);
          log(e->kind == OpenFailure::NotFound ? LogLevel::Warn : LogLevel::Error,
              "cannot open: " + e->message + "; retrying with backoff " + backoff);
        }
        wait(delay);
        delay = std::min(delay * 2.0, options_.reconnect_max);
        continue;
      }
      const double waited = monotonic_seconds() - waiting_since;
      {
        std::lock_guard lock(snapshot_mutex_);
        device_path_ = node.path;
      }
      const std::string where = node.path == options_.device.device ? node.path : options_.device.describe() + " -> " + node.path;
      if (lost) {
        reconnects_.fetch_add(1, std::memory_order_relaxed);
        log(LogLevel::Info, "reopened " + where + " after " + seconds_text(waited) + " and " + attempts_text(attempts + 1));
      } else {
        std::string line = "opened " + where + ", protocol " + options_.protocol + " (" + node.what +
                           "), time source " + std::string(to_string(options_.time_source));
        if (attempts > 0) line += " after " + seconds_text(waited) + " and " + attempts_text(attempts + 1);
        log(LogLevel::Info, line);
      }
      if (!node.note.empty() && node.note != logged_note) {
        log(LogLevel::Warn, node.note);
        logged_note = node.note;
      }
      lost = false;
      attempts = 0;
      opened_at = monotonic_seconds();
      logged_kinds = 0;
      transient_streak = 0;
      time_base.restart();
      connected_.store(true, std::memory_order_release);
      continue;
    }

    pollfd p{node.fd, POLLIN, 0};
    const int ready = ::poll(&p, 1, timeout_ms);
    std::string gone;  // non-empty: the device went away
    if (ready < 0 && errno != EINTR) {
      gone = std::string("poll: ") + std::strerror(errno);
    } else if (ready > 0 && (p.revents & POLLIN) != 0) {
      const ssize_t n = ::read(node.fd, buffer.data(), buffer.size());
      if (n > 0) {
        const double received = monotonic_seconds();
        transient_streak = 0;
        reports_.fetch_add(1, std::memory_order_relaxed);
        stamper.set_receive_time(received);
        node.decoder->decode(std::span<const std::uint8_t>(buffer.data(), static_cast<std::size_t>(n)), stamper);
        publish();
        continue;
      }
      const int e = n == 0 ? 0 : errno;
      if (n < 0 && (e == EAGAIN || e == EINTR)) continue;
      if (n == 0 || is_gone(e)) {
        gone = n == 0 ? "end of file" : std::strerror(e);
      } else {
        read_errors_.fetch_add(1, std::memory_order_relaxed);
        if (transient_streak++ == 0) log(LogLevel::Warn, "read error: " + std::string(std::strerror(e)));
        if (transient_streak < kTransientLimit) {
          wait(options_.read_timeout);
          continue;
        }
        gone = std::string("repeated read errors: ") + std::strerror(e);
      }
    } else if (ready > 0 && (p.revents & (POLLHUP | POLLERR | POLLNVAL)) != 0) {
      gone = "hangup";
    } else {
      continue;  // timeout: look at the stop token again
    }

    // The device is gone: close, count, reconnect with backoff.
    close_node();
    connected_.store(false, std::memory_order_release);
    outages_.fetch_add(1, std::memory_order_relaxed);
    publish();
    log(LogLevel::Warn, "lost the device (" + gone + "); reconnecting with backoff " + backoff);
    lost = true;
    waiting_since = monotonic_seconds();
    attempts = 0;
    logged_kinds = bit(OpenFailure::NotFound);  // expected after a loss: the line above said so
    transient_streak = 0;
    if (waiting_since - opened_at >= kStableConnection) {
      delay = options_.reconnect_min;
    } else {
      wait(delay);  // a device that opens and fails at once: keep backing off instead of spinning
      delay = std::min(delay * 2.0, options_.reconnect_max);
    }
  }
  close_node();
  connected_.store(false, std::memory_order_release);
}

}  // namespace posefair::drivers
