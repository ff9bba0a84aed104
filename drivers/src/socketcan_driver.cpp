// The SocketCAN driver: socket, filters, timestamps, error frames and reconnection; see
// socketcan_driver.hpp. Kernel interface: linux/can.h, linux/can/raw.h, linux/can/error.h
// (Documentation/networking/can.rst).
#include "posefair/drivers/socketcan_driver.hpp"

#include <linux/can.h>
#include <linux/can/error.h>
#include <linux/can/raw.h>
#include <net/if.h>
#include <poll.h>
#include <sys/ioctl.h>
#include <sys/socket.h>
#include <time.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <cstdio>
#include <cstring>
#include <stdexcept>
#include <utility>
#include <vector>

#include "link_log_text.hpp"
#include "monotonic_clock.hpp"
#include "sample_stamper.hpp"

namespace posefair::drivers {
namespace {

static_assert(CanFrame::kEffFlag == CAN_EFF_FLAG && CanFrame::kRtrFlag == CAN_RTR_FLAG && CanFrame::kErrFlag == CAN_ERR_FLAG);
static_assert(CanFrame::kFdBrs == CANFD_BRS && CanFrame::kFdEsi == CANFD_ESI);
static_assert(CanFrame::kMaxFd == CANFD_MAX_DLEN && CanFrame::kMaxClassic == CAN_MAX_DLEN);

double clock_seconds(clockid_t clock) {
  timespec ts{};
  ::clock_gettime(clock, &ts);
  return seconds_of(ts);
}

std::string errno_text(int e) { return std::strerror(e); }

// CLOCK_REALTIME − CLOCK_MONOTONIC, read between two monotonic reads (the midpoint is the best
// guess of when the realtime read happened), and the later monotonic read.
struct ClockOffset {
  double realtime_minus_monotonic = 0.0;
  double monotonic_now = 0.0;
};
ClockOffset measure_clock_offset() {
  const double m1 = clock_seconds(CLOCK_MONOTONIC);
  const double r = clock_seconds(CLOCK_REALTIME);
  const double m2 = clock_seconds(CLOCK_MONOTONIC);
  return {r - 0.5 * (m1 + m2), m2};
}

std::unique_ptr<CanDecoder> take_decoder(SocketCanDriverOptions& o) {
  if (o.decoder) return std::move(o.decoder);
  std::unique_ptr<CanDecoder> d = make_can_decoder(o.protocol, o.decoder_options);  // may throw for a bad option
  if (!d) {
    std::string known;
    for (const std::string& p : can_decoder_protocols()) known += (known.empty() ? "" : ", ") + p;
    throw std::invalid_argument("unknown CAN protocol '" + o.protocol + "' (known: " + (known.empty() ? "none" : known) + ")");
  }
  return d;
}

// Why an open failed; each is logged once per wait.
enum class OpenFailure { NoInterface, Down, Other };
constexpr unsigned bit_of(OpenFailure f) { return 1u << static_cast<unsigned>(f); }

// An open raw CAN socket bound to one interface, or why there is none.
class CanSocket {
 public:
  CanSocket() = default;
  ~CanSocket() { close(); }
  CanSocket(const CanSocket&) = delete;
  CanSocket& operator=(const CanSocket&) = delete;

  bool is_open() const { return fd_ >= 0; }
  int fd() const { return fd_; }
  const std::string& note() const { return note_; }
  void close() {
    if (fd_ >= 0) ::close(fd_);
    fd_ = -1;
  }

  // On failure: the reason and a message; the socket stays closed.
  std::optional<std::pair<OpenFailure, std::string>> open(const std::string& interface,
                                                          const std::vector<CanFilter>& filters, bool want_fd) {
    close();
    note_.clear();
    const int s = ::socket(PF_CAN, SOCK_RAW | SOCK_NONBLOCK | SOCK_CLOEXEC, CAN_RAW);
    if (s < 0) {
      const int e = errno;
      return std::pair{OpenFailure::Other, "cannot create a CAN socket: " + errno_text(e) +
                                               (e == EAFNOSUPPORT || e == EPROTONOSUPPORT ? " (load the can and can-raw modules)" : "")};
    }
    auto fail = [&](OpenFailure kind, std::string message) {
      ::close(s);
      return std::optional{std::pair{kind, std::move(message)}};
    };
    ifreq ifr{};
    std::memcpy(ifr.ifr_name, interface.data(), std::min(interface.size(), sizeof ifr.ifr_name - 1));
    if (::ioctl(s, SIOCGIFINDEX, &ifr) < 0) {
      const int e = errno;
      return fail(e == ENODEV ? OpenFailure::NoInterface : OpenFailure::Other,
                  "interface " + interface + ": " + (e == ENODEV ? std::string("no such interface") : errno_text(e)));
    }
    const int ifindex = ifr.ifr_ifindex;
    if (::ioctl(s, SIOCGIFFLAGS, &ifr) < 0) {
      const int e = errno;
      return fail(e == ENODEV ? OpenFailure::NoInterface : OpenFailure::Other, "interface " + interface + ": " + errno_text(e));
    }
    if ((ifr.ifr_flags & IFF_UP) == 0) return fail(OpenFailure::Down, "interface " + interface + " is down");

    std::vector<can_filter> kernel_filters;
    for (const CanFilter& f : filters) kernel_filters.push_back(can_filter{f.id, f.mask});
    // No filters from a decoder would mean "nothing": leave the kernel's default (everything).
    if (!kernel_filters.empty() &&
        ::setsockopt(s, SOL_CAN_RAW, CAN_RAW_FILTER, kernel_filters.data(),
                     static_cast<socklen_t>(kernel_filters.size() * sizeof(can_filter))) < 0)
      return fail(OpenFailure::Other, "CAN_RAW_FILTER: " + errno_text(errno));
    const can_err_mask_t err_mask = CAN_ERR_MASK;
    if (::setsockopt(s, SOL_CAN_RAW, CAN_RAW_ERR_FILTER, &err_mask, sizeof err_mask) < 0)
      return fail(OpenFailure::Other, "CAN_RAW_ERR_FILTER: " + errno_text(errno));
    if (want_fd) {
      const int on = 1;
      if (::setsockopt(s, SOL_CAN_RAW, CAN_RAW_FD_FRAMES, &on, sizeof on) < 0)
        return fail(OpenFailure::Other, "CAN_RAW_FD_FRAMES: " + errno_text(errno));
      if (::ioctl(s, SIOCGIFMTU, &ifr) == 0 && ifr.ifr_mtu != static_cast<int>(CANFD_MTU))
        note_ = "fd = true, but interface " + interface + " is not in CAN FD mode (mtu " + std::to_string(ifr.ifr_mtu) +
                "): only classic frames will arrive";
    }
    const int on = 1;
    if (::setsockopt(s, SOL_SOCKET, SO_TIMESTAMPNS, &on, sizeof on) < 0)
      return fail(OpenFailure::Other, "SO_TIMESTAMPNS: " + errno_text(errno));
    sockaddr_can addr{};
    addr.can_family = AF_CAN;
    addr.can_ifindex = ifindex;
    if (::bind(s, reinterpret_cast<sockaddr*>(&addr), sizeof addr) < 0) {
      const int e = errno;
      return fail(e == ENODEV ? OpenFailure::NoInterface : OpenFailure::Other, "bind to " + interface + ": " + errno_text(e));
    }
    fd_ = s;
    return std::nullopt;
  }

 private:
  int fd_ = -1;
  std::string note_;
};

// One recvmsg: a frame with its kernel timestamp (CLOCK_REALTIME s, 0 when none), or errno.
struct Received {
  CanFrame frame;
  double realtime = 0.0;
};
int receive_frame(int fd, Received& out) {
  canfd_frame raw{};
  iovec iov{&raw, sizeof raw};
  alignas(cmsghdr) char control[CMSG_SPACE(sizeof(timespec)) + 64];
  msghdr msg{};
  msg.msg_iov = &iov;
  msg.msg_iovlen = 1;
  msg.msg_control = control;
  msg.msg_controllen = sizeof control;
  const ssize_t n = ::recvmsg(fd, &msg, MSG_DONTWAIT);
  if (n < 0) return errno;
  CanFrame& f = out.frame;
  f = CanFrame{};
  f.can_id = raw.can_id;
  if (n == static_cast<ssize_t>(CANFD_MTU)) {
    f.fd = true;
    f.fd_flags = raw.flags;
    f.len = std::min<std::uint8_t>(raw.len, CANFD_MAX_DLEN);
  } else if (n == static_cast<ssize_t>(CAN_MTU)) {
    f.len = std::min<std::uint8_t>(raw.len, CAN_MAX_DLEN);  // struct can_frame's len sits where canfd_frame's does
  } else {
    return EBADMSG;  // neither size: not a frame this socket can carry
  }
  std::memcpy(f.data.data(), raw.data, f.len);
  out.realtime = 0.0;
  for (cmsghdr* c = CMSG_FIRSTHDR(&msg); c != nullptr; c = CMSG_NXTHDR(&msg, c)) {
    if (c->cmsg_level == SOL_SOCKET && c->cmsg_type == SCM_TIMESTAMPNS) {
      timespec ts{};
      std::memcpy(&ts, CMSG_DATA(c), sizeof ts);
      out.realtime = seconds_of(ts);
    }
  }
  return 0;
}

bool interface_gone(int e) { return e == ENETDOWN || e == ENODEV || e == ENXIO; }

// The controller's error state as error frames tell it.
enum ControllerState { kActive = 0, kWarning = 1, kPassive = 2, kBusOff = 3 };
const char* state_name(int s) {
  switch (s) {
    case kWarning: return "error-warning";
    case kPassive: return "error-passive";
    case kBusOff: return "bus-off";
    default: return "error-active";
  }
}

constexpr std::size_t kBatch = 64;        // frames read before their timestamps are converted
constexpr int kTransientLimit = 10;       // consecutive read errors before the socket is reopened
constexpr double kStableConnection = 1.0; // s: a connection this long resets the backoff when lost

}  // namespace

std::string_view can_error_class_name(std::size_t bit) {
  static constexpr std::string_view names[kCanErrorClasses] = {
      "tx-timeout", "lost-arbitration", "controller", "protocol",  "transceiver",
      "no-ack",     "bus-off",          "bus-error",  "restarted", "error-counter"};
  return bit < kCanErrorClasses ? names[bit] : "unknown";
}

SocketCanDriver::SocketCanDriver(SocketCanDriverOptions options) : options_(std::move(options)) {
  if (options_.interface.empty()) throw std::invalid_argument("socketcan: give an interface, e.g. can0");
  if (options_.interface.size() >= IFNAMSIZ)
    throw std::invalid_argument("socketcan: interface name '" + options_.interface + "' is longer than " +
                                std::to_string(IFNAMSIZ - 1) + " characters");
  if (!(options_.reconnect_min > 0.0) || !std::isfinite(options_.reconnect_min))
    throw std::invalid_argument("socketcan: reconnect_min must be finite and > 0");
  if (!(options_.reconnect_max >= options_.reconnect_min) || !std::isfinite(options_.reconnect_max))
    throw std::invalid_argument("socketcan: reconnect_max must be finite and >= reconnect_min");
  if (!(options_.read_timeout > 0.0 && options_.read_timeout <= 0.05))
    throw std::invalid_argument("socketcan: read_timeout must be in (0, 0.05] s");
  const TimeBase check(options_.time_source, options_.time_base);  // throws for bad time base options
  decoder_ = take_decoder(options_);
  name_ = options_.name.empty() ? "socketcan:" + options_.interface + " (" + std::string(decoder_->protocol()) + ")"
                                : options_.name;
}

void SocketCanDriver::log(LogLevel level, const std::string& message) const {
  if (options_.log) options_.log(level, message);
}

DecoderCounters SocketCanDriver::decoder_counters() const {
  std::lock_guard lock(snapshot_mutex_);
  return decoder_snapshot_;
}

CanFrameCounters SocketCanDriver::frame_counters() const {
  std::lock_guard lock(snapshot_mutex_);
  return frame_snapshot_;
}

TimeBaseCounters SocketCanDriver::time_base_counters() const {
  std::lock_guard lock(snapshot_mutex_);
  return time_base_snapshot_;
}

std::optional<DeviceHealth> SocketCanDriver::health() const {
  DeviceHealth h;
  h.connected = connected();
  h.outages = outages();
  h.reconnects = reconnects();
  h.open_failures = open_failures();
  h.read_errors = read_errors();
  const DecoderCounters d = decoder_counters();
  h.frames = d.frames;
  h.bad_frames = d.bad_checksum + d.malformed;
  h.resyncs = d.resyncs;
  h.skipped_bytes = d.skipped_bytes;
  h.device_time_trusted = trusted_.load(std::memory_order_relaxed);
  h.time_fallbacks = fallbacks_.load(std::memory_order_relaxed);
  return h;
}

void SocketCanDriver::publish_snapshots(const TimeBase& time_base) {
  {
    std::lock_guard lock(snapshot_mutex_);
    decoder_snapshot_ = decoder_->counters();
    frame_snapshot_ = decoder_->frame_counters();
    time_base_snapshot_ = time_base.counters();
  }
  fallbacks_.store(time_base.counters().fallbacks, std::memory_order_relaxed);
  trusted_.store(time_base.trusted(), std::memory_order_relaxed);
}

void SocketCanDriver::count_error_frame(const CanFrame& frame) {
  error_frames_.fetch_add(1, std::memory_order_relaxed);
  const std::uint32_t classes = frame.can_id & CAN_ERR_MASK;
  for (std::size_t b = 0; b < kCanErrorClasses; ++b)
    if ((classes & (1u << b)) != 0) error_classes_[b].fetch_add(1, std::memory_order_relaxed);
  int state = controller_state_;
  if ((classes & CAN_ERR_BUSOFF) != 0) {
    bus_off_.fetch_add(1, std::memory_order_relaxed);
    state = kBusOff;
  } else if ((classes & CAN_ERR_RESTARTED) != 0) {
    state = kActive;
  } else if ((classes & CAN_ERR_CRTL) != 0 && frame.len > 1) {
    const std::uint8_t c = frame.data[1];
    if ((c & (CAN_ERR_CRTL_RX_PASSIVE | CAN_ERR_CRTL_TX_PASSIVE)) != 0)
      state = kPassive;
    else if ((c & (CAN_ERR_CRTL_RX_WARNING | CAN_ERR_CRTL_TX_WARNING)) != 0)
      state = kWarning;
    else if ((c & CAN_ERR_CRTL_ACTIVE) != 0)
      state = kActive;
  }
  // One line per change: a new controller state, or a class not seen since the socket opened.
  const std::uint32_t new_classes = classes & ~logged_classes_;
  if (state == controller_state_ && new_classes == 0) return;
  logged_classes_ |= classes;
  std::string what;
  for (std::size_t b = 0; b < kCanErrorClasses; ++b)
    if ((classes & (1u << b)) != 0) what += (what.empty() ? "" : ", ") + std::string(can_error_class_name(b));
  std::string line = "error frame (" + (what.empty() ? std::string("no class") : what) + ")";
  if (state != controller_state_) line += std::string("; controller ") + state_name(controller_state_) + " -> " + state_name(state);
  line += "; error frames so far " + std::to_string(error_frames()) + ", bus-off " + std::to_string(bus_off());
  controller_state_ = state;
  log(state >= kPassive ? LogLevel::Error : LogLevel::Warn, line);
}

void SocketCanDriver::run(std::stop_token stop, SampleSink& sink) {
  using Clock = std::chrono::steady_clock;
  std::mutex wait_mutex;
  std::condition_variable_any wake;  // nobody notifies it: it wakes at the deadline or on stop
  auto wait = [&](double seconds) {
    std::unique_lock lock(wait_mutex);
    wake.wait_for(lock, stop, std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(seconds)),
                  [] { return false; });
  };

  const int timeout_ms = std::max(1, static_cast<int>(std::lround(options_.read_timeout * 1000.0)));
  TimeBase time_base(options_.time_source, options_.time_base);
  std::uint64_t sequence = 0;  // from 0 per run(), across reconnects
  SampleStamper stamper(options_.stream_id, time_base, sink, sequence, samples_, dropped_);
  CanSocket socket;
  const std::vector<CanFilter> filters = decoder_->filters();
  std::vector<Received> batch(kBatch);

  const std::string backoff = backoff_text(options_.reconnect_min) + " .. " + backoff_text(options_.reconnect_max);
  bool lost = false;
  double waiting_since = clock_seconds(CLOCK_MONOTONIC);
  std::uint64_t attempts = 0;
  double delay = options_.reconnect_min;
  unsigned logged_kinds = 0;
  int transient_streak = 0;
  double opened_at = 0.0;

  auto lose = [&](const std::string& why) {
    socket.close();
    decoder_->reset();
    connected_.store(false, std::memory_order_release);
    outages_.fetch_add(1, std::memory_order_relaxed);
    publish_snapshots(time_base);
    log(LogLevel::Warn, "lost interface " + options_.interface + " (" + why + "); reopening with backoff " + backoff);
    lost = true;
    waiting_since = clock_seconds(CLOCK_MONOTONIC);
    attempts = 0;
    logged_kinds = bit_of(OpenFailure::NoInterface) | bit_of(OpenFailure::Down);  // expected now: said above
    transient_streak = 0;
    if (waiting_since - opened_at >= kStableConnection) {
      delay = options_.reconnect_min;
    } else {
      wait(delay);  // an interface that opens and fails at once: keep backing off
      delay = std::min(delay * 2.0, options_.reconnect_max);
    }
  };

  while (!stop.stop_requested()) {
    if (!socket.is_open()) {
      if (const auto failure = socket.open(options_.interface, filters, options_.fd)) {
        open_failures_.fetch_add(1, std::memory_order_relaxed);
        ++attempts;
        if ((logged_kinds & bit_of(failure->first)) == 0) {  // one line per reason per wait
          logged_kinds |= bit_of(failure->first);
          log(failure->first == OpenFailure::Other ? LogLevel::Error : LogLevel::Warn,
              "cannot open: " + failure->second + "; retrying with backoff " + backoff);
        }
        wait(delay);
        delay = std::min(delay * 2.0, options_.reconnect_max);
        continue;
      }
      const double waited = clock_seconds(CLOCK_MONOTONIC) - waiting_since;
      if (lost) {
        reconnects_.fetch_add(1, std::memory_order_relaxed);
        log(LogLevel::Info, "reopened " + options_.interface + " after " + seconds_text(waited) + " and " +
                                attempts_text(attempts + 1));
      } else {
        std::string line = "opened " + options_.interface + ", protocol " + std::string(decoder_->protocol()) +
                           (options_.fd ? ", CAN FD" : "") + ", " + std::to_string(filters.size()) +
                           " kernel filters, time source " + std::string(to_string(options_.time_source));
        if (attempts > 0) line += " after " + seconds_text(waited) + " and " + attempts_text(attempts + 1);
        log(LogLevel::Info, line);
      }
      if (!socket.note().empty()) log(LogLevel::Warn, socket.note());
      lost = false;
      attempts = 0;
      opened_at = clock_seconds(CLOCK_MONOTONIC);
      logged_kinds = 0;
      logged_classes_ = 0;
      transient_streak = 0;
      decoder_->reset();
      time_base.restart();
      connected_.store(true, std::memory_order_release);
      continue;
    }

    pollfd p{socket.fd(), POLLIN, 0};
    const int ready = ::poll(&p, 1, timeout_ms);
    if (ready == 0 || (ready < 0 && errno == EINTR)) continue;  // look at the stop token again

    std::size_t n = 0;
    int error = 0;
    while (n < kBatch) {
      error = receive_frame(socket.fd(), batch[n]);
      if (error == EINTR) continue;
      if (error != 0) break;
      ++n;
    }
    if (n > 0) {
      const ClockOffset offset = measure_clock_offset();  // after the reads: see the header
      transient_streak = 0;
      for (std::size_t i = 0; i < n; ++i) {
        CanFrame& f = batch[i].frame;
        f.timestamp = batch[i].realtime > 0.0
                          ? std::min(batch[i].realtime - offset.realtime_minus_monotonic, offset.monotonic_now)
                          : offset.monotonic_now;
        frames_.fetch_add(1, std::memory_order_relaxed);
        if (f.fd) fd_frames_.fetch_add(1, std::memory_order_relaxed);
        if (f.error()) count_error_frame(f);
        stamper.set_receive_time(f.timestamp);
        decoder_->feed(f, stamper);
      }
      publish_snapshots(time_base);
    }
    if (error == 0 || error == EAGAIN || error == EWOULDBLOCK) continue;
    if (interface_gone(error)) {
      lose(error == ENETDOWN ? "interface down" : errno_text(error));
      continue;
    }
    read_errors_.fetch_add(1, std::memory_order_relaxed);
    if (transient_streak++ == 0) log(LogLevel::Warn, "read error: " + errno_text(error));
    if (transient_streak < kTransientLimit) {
      wait(options_.read_timeout);
      continue;
    }
    lose("repeated read errors: " + errno_text(error));
  }
  socket.close();
  connected_.store(false, std::memory_order_release);
}

}  // namespace posefair::drivers
