// The SocketCAN driver: socket, filters, timestamps and error frames behind the device link;
// see socketcan_driver.hpp. Kernel interface: linux/can.h, linux/can/raw.h, linux/can/error.h
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
#include <cstring>
#include <optional>
#include <stdexcept>
#include <utility>
#include <vector>

#include "monotonic_clock.hpp"
#include "sample_stamper.hpp"

namespace posefair::drivers {
namespace {

static_assert(CanFrame::kEffFlag == CAN_EFF_FLAG && CanFrame::kRtrFlag == CAN_RTR_FLAG && CanFrame::kErrFlag == CAN_ERR_FLAG);
static_assert(CanFrame::kFdBrs == CANFD_BRS && CanFrame::kFdEsi == CANFD_ESI);
static_assert(CanFrame::kMaxFd == CANFD_MAX_DLEN && CanFrame::kMaxClassic == CAN_MAX_DLEN);

std::string errno_text(int e) { return std::strerror(e); }

// CLOCK_REALTIME − CLOCK_MONOTONIC, read between two monotonic reads (the midpoint is the best
// guess of when the realtime read happened), and the later monotonic read.
struct ClockOffset {
  double realtime_minus_monotonic = 0.0;
  double monotonic_now = 0.0;
};
ClockOffset measure_clock_offset() {
  const double m1 = monotonic_seconds();
  timespec ts{};
  ::clock_gettime(CLOCK_REALTIME, &ts);
  const double m2 = monotonic_seconds();
  return {seconds_of(ts) - 0.5 * (m1 + m2), m2};
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

const SocketCanDriverOptions& checked(const SocketCanDriverOptions& o) {
  if (o.interface.empty()) throw std::invalid_argument("socketcan: give an interface, e.g. can0");
  if (o.interface.size() >= IFNAMSIZ)
    throw std::invalid_argument("socketcan: interface name '" + o.interface + "' is longer than " +
                                std::to_string(IFNAMSIZ - 1) + " characters");
  return o;
}

// Why an open failed; each is logged once per wait. NoInterface and Down are "absent".
enum class OpenFailure { NoInterface, Down, Other };

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

constexpr std::size_t kBatch = 64;  // frames read before their timestamps are converted

}  // namespace

std::string_view can_error_class_name(std::size_t bit) {
  static constexpr std::string_view names[kCanErrorClasses] = {
      "tx-timeout", "lost-arbitration", "controller", "protocol",  "transceiver",
      "no-ack",     "bus-off",          "bus-error",  "restarted", "error-counter"};
  return bit < kCanErrorClasses ? names[bit] : "unknown";
}

struct SocketCanDriver::Bus {
  CanSocket socket;
  std::vector<Received> batch = std::vector<Received>(kBatch);
};

SocketCanDriver::SocketCanDriver(SocketCanDriverOptions options)
    : DeviceLinkDriver("socketcan", checked(options)), options_(std::move(options)), bus_(std::make_unique<Bus>()) {
  decoder_ = take_decoder(options_);
  filters_ = decoder_->filters();
  set_name(options_.name.empty() ? "socketcan:" + options_.interface + " (" + std::string(decoder_->protocol()) + ")"
                                 : options_.name);
}

SocketCanDriver::~SocketCanDriver() = default;

CanFrameCounters SocketCanDriver::frame_counters() const {
  std::lock_guard lock(frame_mutex_);
  return frame_snapshot_;
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

std::variant<DeviceLinkDriver::LinkOpened, DeviceLinkDriver::LinkOpenFailure> SocketCanDriver::open_link() {
  if (const auto failure = bus_->socket.open(options_.interface, filters_, options_.fd))
    return LinkOpenFailure{static_cast<unsigned>(failure->first), failure->first != OpenFailure::Other, "", failure->second};
  decoder_->reset();
  logged_classes_ = 0;
  LinkOpened o;
  o.path = options_.interface;
  o.where = options_.interface;
  o.details = ", protocol " + std::string(decoder_->protocol()) + (options_.fd ? ", CAN FD" : "") + ", " +
              std::to_string(filters_.size()) + " kernel filters, time source " + std::string(to_string(options_.time_source));
  o.note = bus_->socket.note();
  return o;
}

DeviceLinkDriver::LinkRead SocketCanDriver::read_link(int timeout_ms, SampleStamper& stamper) {
  LinkRead result;
  pollfd p{bus_->socket.fd(), POLLIN, 0};
  const int ready = ::poll(&p, 1, timeout_ms);
  if (ready == 0 || (ready < 0 && errno == EINTR)) return result;  // look at the stop token again

  std::vector<Received>& batch = bus_->batch;
  std::size_t n = 0;
  int error = 0;
  while (n < kBatch) {
    error = receive_frame(bus_->socket.fd(), batch[n]);
    if (error == EINTR) continue;
    if (error != 0) break;
    ++n;
  }
  if (n > 0) {
    const ClockOffset offset = measure_clock_offset();  // after the reads: see the header
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
    std::lock_guard lock(frame_mutex_);
    frame_snapshot_ = decoder_->frame_counters();
    result.decoded = true;
  }
  if (error == 0 || error == EAGAIN || error == EWOULDBLOCK) return result;
  result.error = interface_gone(error) ? LinkRead::Error::Gone : LinkRead::Error::Transient;
  result.message = error == ENETDOWN ? "interface down" : errno_text(error);
  return result;
}

void SocketCanDriver::close_link() {
  bus_->socket.close();
  decoder_->reset();  // partial transfers must not merge with frames from the new socket
}

}  // namespace posefair::drivers
