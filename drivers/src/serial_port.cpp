// A serial port over libserialport, with a termios fallback for terminals libserialport does not
// know (pseudo-terminals); see serial_port.hpp.
#include "posefair/drivers/serial_port.hpp"

#include <fcntl.h>
#include <libserialport.h>
#include <poll.h>
#include <sys/ioctl.h>
#include <sys/stat.h>
#include <termios.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <memory>
#include <stdexcept>
#include <utility>

namespace posefair::drivers {
namespace {

std::string os_message(int error) { return std::strerror(error); }

// The kind of an errno from open(): absent, refused, or something else.
SerialErrorKind open_error_kind(int error) {
  switch (error) {
    case ENOENT:
    case ENODEV:
    case ENXIO:
    case ENOTDIR:
      return SerialErrorKind::NotFound;
    case EACCES:
    case EPERM:
      return SerialErrorKind::PermissionDenied;
    case EBUSY:
      return SerialErrorKind::Busy;
    case ENOTTY:
      return SerialErrorKind::NotATerminal;
    default:
      return SerialErrorKind::Transient;
  }
}

// The kind of an errno from read(), write() or poll() on an open port.
SerialErrorKind io_error_kind(int error) {
  switch (error) {
    case EIO:
    case ENXIO:
    case ENODEV:
    case EBADF:
    case EPIPE:
      return SerialErrorKind::DeviceGone;
    default:
      return SerialErrorKind::Transient;
  }
}

SerialError make_error(SerialErrorKind kind, int os_error, std::string message) {
  return SerialError{kind, os_error, std::move(message)};
}

SerialError os_error(SerialErrorKind kind, int error, const std::string& what) {
  return make_error(kind, error, what + ": " + os_message(error));
}

std::string c_string(const char* s) { return s == nullptr ? std::string() : std::string(s); }

// A libserialport port handle freed on scope exit.
struct PortDeleter {
  void operator()(sp_port* p) const {
    if (p != nullptr) sp_free_port(p);
  }
};
using PortHandle = std::unique_ptr<sp_port, PortDeleter>;

struct ConfigDeleter {
  void operator()(sp_port_config* c) const {
    if (c != nullptr) sp_free_config(c);
  }
};

sp_parity to_sp(Parity p) {
  switch (p) {
    case Parity::None: return SP_PARITY_NONE;
    case Parity::Odd: return SP_PARITY_ODD;
    case Parity::Even: return SP_PARITY_EVEN;
    case Parity::Mark: return SP_PARITY_MARK;
    case Parity::Space: return SP_PARITY_SPACE;
  }
  return SP_PARITY_NONE;
}

sp_flowcontrol to_sp(FlowControl f) {
  switch (f) {
    case FlowControl::None: return SP_FLOWCONTROL_NONE;
    case FlowControl::XonXoff: return SP_FLOWCONTROL_XONXOFF;
    case FlowControl::RtsCts: return SP_FLOWCONTROL_RTSCTS;
    case FlowControl::DtrDsr: return SP_FLOWCONTROL_DTRDSR;
  }
  return SP_FLOWCONTROL_NONE;
}

// The termios speed constant for a standard rate; false for any other rate.
bool termios_speed(int baud, speed_t& out) {
  struct Rate {
    int baud;
    speed_t speed;
  };
  static constexpr Rate kRates[] = {
      {50, B50},           {75, B75},           {110, B110},         {134, B134},         {150, B150},
      {200, B200},         {300, B300},         {600, B600},         {1200, B1200},       {1800, B1800},
      {2400, B2400},       {4800, B4800},       {9600, B9600},       {19200, B19200},     {38400, B38400},
      {57600, B57600},     {115200, B115200},   {230400, B230400},   {460800, B460800},   {500000, B500000},
      {576000, B576000},   {921600, B921600},   {1000000, B1000000}, {1152000, B1152000}, {1500000, B1500000},
      {2000000, B2000000}, {2500000, B2500000}, {3000000, B3000000}, {3500000, B3500000}, {4000000, B4000000},
  };
  for (const Rate& r : kRates) {
    if (r.baud == baud) {
      out = r.speed;
      return true;
    }
  }
  return false;
}

// Sets O_NONBLOCK, takes the port exclusively (TIOCEXCL: a second open fails with EBUSY) and
// drops bytes that arrived before the open (their receive time is unknown).
void prepare_descriptor(int fd) {
  const int flags = ::fcntl(fd, F_GETFL);
  if (flags >= 0) ::fcntl(fd, F_SETFL, flags | O_NONBLOCK);
  ::ioctl(fd, TIOCEXCL);
  ::tcflush(fd, TCIFLUSH);
}

}  // namespace

void validate(const SerialSettings& s) {
  if (s.baud <= 0) throw std::invalid_argument("serial: baud must be > 0, got " + std::to_string(s.baud));
  if (s.data_bits < 5 || s.data_bits > 8)
    throw std::invalid_argument("serial: data bits must be in [5, 8], got " + std::to_string(s.data_bits));
  if (s.stop_bits != 1 && s.stop_bits != 2)
    throw std::invalid_argument("serial: stop bits must be 1 or 2, got " + std::to_string(s.stop_bits));
}

std::string describe(const SerialSettings& s) {
  static constexpr char kParity[] = {'N', 'O', 'E', 'M', 'S'};
  std::string text = std::to_string(s.baud) + " " + std::to_string(s.data_bits) + kParity[static_cast<int>(s.parity)] +
                     std::to_string(s.stop_bits);
  switch (s.flow_control) {
    case FlowControl::None: break;
    case FlowControl::XonXoff: text += " xonxoff"; break;
    case FlowControl::RtsCts: text += " rtscts"; break;
    case FlowControl::DtrDsr: text += " dtrdsr"; break;
  }
  return text;
}

std::string SerialPortSpec::describe() const {
  if (!usb) return device;
  std::string s = "usb " + to_string(*usb);
  if (!usb_serial.empty()) s += " serial " + usb_serial;
  return s;
}

std::string_view to_string(SerialErrorKind kind) {
  switch (kind) {
    case SerialErrorKind::None: return "no error";
    case SerialErrorKind::NotFound: return "not found";
    case SerialErrorKind::PermissionDenied: return "permission denied";
    case SerialErrorKind::Busy: return "busy";
    case SerialErrorKind::BadSettings: return "settings refused";
    case SerialErrorKind::NotATerminal: return "not a terminal";
    case SerialErrorKind::DeviceGone: return "device gone";
    case SerialErrorKind::Transient: return "I/O error";
  }
  return "unknown";
}

std::vector<PortInfo> list_serial_ports() {
  sp_port** list = nullptr;
  if (sp_list_ports(&list) != SP_OK) {
    const std::string why = c_string(sp_last_error_message());
    throw std::runtime_error("cannot list serial ports" + (why.empty() ? std::string() : ": " + why));
  }
  std::vector<PortInfo> ports;
  for (sp_port** p = list; p != nullptr && *p != nullptr; ++p) {
    PortInfo info;
    info.path = c_string(sp_get_port_name(*p));
    info.description = c_string(sp_get_port_description(*p));
    switch (sp_get_port_transport(*p)) {
      case SP_TRANSPORT_NATIVE: info.transport = "native"; break;
      case SP_TRANSPORT_USB: info.transport = "usb"; break;
      case SP_TRANSPORT_BLUETOOTH: info.transport = "bluetooth"; break;
    }
    if (sp_get_port_transport(*p) == SP_TRANSPORT_USB) {
      int vid = 0, pid = 0;
      if (sp_get_port_usb_vid_pid(*p, &vid, &pid) == SP_OK) {
        info.has_usb_id = true;
        info.usb = UsbId{static_cast<std::uint16_t>(vid), static_cast<std::uint16_t>(pid)};
      }
      info.usb_serial = c_string(sp_get_port_usb_serial(*p));
      info.usb_manufacturer = c_string(sp_get_port_usb_manufacturer(*p));
      info.usb_product = c_string(sp_get_port_usb_product(*p));
    }
    ports.push_back(std::move(info));
  }
  sp_free_port_list(list);
  std::sort(ports.begin(), ports.end(), [](const PortInfo& a, const PortInfo& b) { return a.path < b.path; });
  return ports;
}

SerialPort::~SerialPort() { close(); }

SerialPort::SerialPort(SerialPort&& other) noexcept
    : port_(std::exchange(other.port_, nullptr)),
      fd_(std::exchange(other.fd_, -1)),
      path_(std::move(other.path_)),
      note_(std::move(other.note_)) {}

SerialPort& SerialPort::operator=(SerialPort&& other) noexcept {
  if (this != &other) {
    close();
    port_ = std::exchange(other.port_, nullptr);
    fd_ = std::exchange(other.fd_, -1);
    path_ = std::move(other.path_);
    note_ = std::move(other.note_);
  }
  return *this;
}

void SerialPort::close() {
  // Give up the exclusive hold first: a pseudo-terminal's slave keeps the flag after its last
  // close while the master lives, and a later open (a reopen, a reload) would be refused.
  if (fd_ >= 0) ::ioctl(fd_, TIOCNXCL);
  if (port_ != nullptr) {
    sp_close(port_);  // closes fd_
    sp_free_port(port_);
    port_ = nullptr;
  } else if (fd_ >= 0) {
    ::close(fd_);
  }
  fd_ = -1;
}

SerialError SerialPort::open(const SerialPortSpec& spec, const SerialSettings& settings) {
  close();
  path_.clear();
  note_.clear();
  try {
    validate(settings);
  } catch (const std::invalid_argument& e) {
    return make_error(SerialErrorKind::BadSettings, 0, e.what());
  }
  if (!spec.usb) {
    if (spec.device.empty()) return make_error(SerialErrorKind::NotFound, 0, "no device given");
    return open_path(spec.device, settings);
  }

  // By USB id: the matching ports in path order.
  std::vector<PortInfo> ports;
  try {
    ports = list_serial_ports();
  } catch (const std::runtime_error& e) {
    return make_error(SerialErrorKind::Transient, 0, e.what());
  }
  std::vector<std::string> matches;
  for (const PortInfo& p : ports) {
    if (!p.has_usb_id || !(p.usb == *spec.usb)) continue;
    if (!spec.usb_serial.empty() && p.usb_serial != spec.usb_serial) continue;
    matches.push_back(p.path);
  }
  if (matches.empty()) return make_error(SerialErrorKind::NotFound, 0, "no serial port with " + spec.describe());
  if (matches.size() > 1) {
    std::string list;
    for (const std::string& m : matches) list += (list.empty() ? "" : ", ") + m;
    note_ = std::to_string(matches.size()) + " ports match " + spec.describe() + " (" + list + "); using " +
            matches.front() + " (give serial_number to choose)";
  }
  return open_path(matches.front(), settings);
}

SerialError SerialPort::open_path(const std::string& device, const SerialSettings& settings) {
  // Resolve symlinks now: a by-id link or alias re-pointed by a replug is followed, and
  // libserialport looks the node up in sysfs by its real name.
  std::error_code ec;
  const std::filesystem::path node = std::filesystem::canonical(device, ec);
  if (ec) return os_error(open_error_kind(ec.value()), ec.value(), device);

  sp_port* raw = nullptr;
  if (sp_get_port_by_name(node.c_str(), &raw) != SP_OK) {
    // Not a port libserialport knows (a pseudo-terminal): plain termios.
    if (raw != nullptr) sp_free_port(raw);
    SerialError e = open_with_termios(node.string(), settings);
    if (!e) path_ = node.string();
    return e;
  }
  PortHandle port(raw);
  if (sp_open(port.get(), SP_MODE_READ_WRITE) != SP_OK) {
    const int error = sp_last_error_code();
    return os_error(open_error_kind(error), error, node.string());
  }
  // From here on sp_close() must run on failure.
  auto fail = [&](SerialErrorKind kind, int error, const std::string& what) {
    sp_close(port.get());
    return error != 0 ? os_error(kind, error, what) : make_error(kind, 0, what);
  };
  sp_port_config* raw_config = nullptr;
  if (sp_new_config(&raw_config) != SP_OK) return fail(SerialErrorKind::Transient, 0, node.string() + ": out of memory");
  const std::unique_ptr<sp_port_config, ConfigDeleter> config(raw_config);
  sp_set_config_baudrate(config.get(), settings.baud);
  sp_set_config_bits(config.get(), settings.data_bits);
  sp_set_config_parity(config.get(), to_sp(settings.parity));
  sp_set_config_stopbits(config.get(), settings.stop_bits);
  sp_set_config_flowcontrol(config.get(), to_sp(settings.flow_control));
  if (const sp_return r = sp_set_config(port.get(), config.get()); r != SP_OK) {
    const int error = r == SP_ERR_FAIL ? sp_last_error_code() : 0;
    const SerialErrorKind kind = r == SP_ERR_ARG || r == SP_ERR_SUPP || error == EINVAL ? SerialErrorKind::BadSettings
                                 : r == SP_ERR_FAIL                                    ? io_error_kind(error)
                                                                                       : SerialErrorKind::Transient;
    std::string what = node.string() + ": cannot set " + describe(settings);
    if (r == SP_ERR_SUPP) what += ": not supported by this port or operating system";
    return fail(kind, error, what);
  }
  int fd = -1;
  if (sp_get_port_handle(port.get(), &fd) != SP_OK || fd < 0)
    return fail(SerialErrorKind::Transient, 0, node.string() + ": no descriptor");
  prepare_descriptor(fd);
  port_ = port.release();
  fd_ = fd;
  path_ = node.string();
  return {};
}

SerialError SerialPort::open_with_termios(const std::string& node, const SerialSettings& settings) {
  const int fd = ::open(node.c_str(), O_RDWR | O_NOCTTY | O_NONBLOCK | O_CLOEXEC);
  if (fd < 0) {
    const int error = errno;
    return os_error(open_error_kind(error), error, node);
  }
  auto fail = [&](SerialError e) {
    ::close(fd);
    return e;
  };
  if (::isatty(fd) != 1) return fail(make_error(SerialErrorKind::NotATerminal, ENOTTY, node + ": not a terminal device"));
  termios t{};
  if (::tcgetattr(fd, &t) != 0) return fail(os_error(SerialErrorKind::Transient, errno, node));
  ::cfmakeraw(&t);
  t.c_cflag |= CLOCAL | CREAD;
  t.c_cflag &= ~static_cast<tcflag_t>(CSIZE);
  switch (settings.data_bits) {
    case 5: t.c_cflag |= CS5; break;
    case 6: t.c_cflag |= CS6; break;
    case 7: t.c_cflag |= CS7; break;
    default: t.c_cflag |= CS8; break;
  }
  t.c_cflag &= ~static_cast<tcflag_t>(PARENB | PARODD | CMSPAR);
  switch (settings.parity) {
    case Parity::None: break;
    case Parity::Odd: t.c_cflag |= PARENB | PARODD; break;
    case Parity::Even: t.c_cflag |= PARENB; break;
    case Parity::Mark: t.c_cflag |= PARENB | CMSPAR | PARODD; break;
    case Parity::Space: t.c_cflag |= PARENB | CMSPAR; break;
  }
  if (settings.parity != Parity::None) t.c_iflag |= INPCK;
  if (settings.stop_bits == 2)
    t.c_cflag |= CSTOPB;
  else
    t.c_cflag &= ~static_cast<tcflag_t>(CSTOPB);
  t.c_cflag &= ~static_cast<tcflag_t>(CRTSCTS);
  t.c_iflag &= ~static_cast<tcflag_t>(IXON | IXOFF | IXANY);
  switch (settings.flow_control) {
    case FlowControl::None: break;
    case FlowControl::XonXoff: t.c_iflag |= IXON | IXOFF; break;
    case FlowControl::RtsCts: t.c_cflag |= CRTSCTS; break;
    case FlowControl::DtrDsr:
      return fail(make_error(SerialErrorKind::BadSettings, 0,
                             node + ": DTR/DSR flow control needs a port libserialport knows (not a pseudo-terminal)"));
  }
  // VMIN 1: a read without data fails with EAGAIN (O_NONBLOCK), so 0 bytes means end of file.
  t.c_cc[VMIN] = 1;
  t.c_cc[VTIME] = 0;
  speed_t speed{};
  if (!termios_speed(settings.baud, speed))
    return fail(make_error(SerialErrorKind::BadSettings, 0,
                           node + ": " + std::to_string(settings.baud) + " baud is not a standard rate"));
  ::cfsetispeed(&t, speed);
  ::cfsetospeed(&t, speed);
  if (::tcsetattr(fd, TCSANOW, &t) != 0) {
    const int error = errno;
    return fail(os_error(error == EINVAL ? SerialErrorKind::BadSettings : io_error_kind(error), error,
                         node + ": cannot set " + describe(settings)));
  }
  prepare_descriptor(fd);
  fd_ = fd;
  return {};
}

SerialPort::ReadResult SerialPort::read(std::span<std::uint8_t> buffer, int timeout_ms) {
  ReadResult result;
  if (fd_ < 0) {
    result.error = make_error(SerialErrorKind::DeviceGone, EBADF, "port not open");
    return result;
  }
  pollfd p{fd_, POLLIN, 0};
  const int ready = ::poll(&p, 1, std::max(timeout_ms, 0));
  if (ready < 0) {
    const int error = errno;
    if (error != EINTR) result.error = os_error(SerialErrorKind::Transient, error, path_ + ": poll");
    return result;
  }
  if (ready == 0) return result;
  if ((p.revents & POLLNVAL) != 0) {
    result.error = make_error(SerialErrorKind::DeviceGone, EBADF, path_ + ": descriptor no longer valid");
    return result;
  }
  if (buffer.empty()) return result;
  const ssize_t n = ::read(fd_, buffer.data(), buffer.size());
  if (n > 0) {
    result.bytes = static_cast<std::size_t>(n);
    return result;
  }
  if (n == 0) {
    // poll() said readable, read() found nothing: end of file, i.e. the terminal hung up.
    result.error = make_error(SerialErrorKind::DeviceGone, 0, path_ + ": hung up");
    return result;
  }
  const int error = errno;
  if (error == EAGAIN || error == EWOULDBLOCK || error == EINTR) {
    if ((p.revents & (POLLHUP | POLLERR)) != 0)
      result.error = make_error(SerialErrorKind::DeviceGone, 0, path_ + ": hung up");
    return result;
  }
  result.error = os_error(io_error_kind(error), error, path_);
  return result;
}

SerialError SerialPort::write(std::span<const std::uint8_t> bytes, int timeout_ms) {
  if (fd_ < 0) return make_error(SerialErrorKind::DeviceGone, EBADF, "port not open");
  using Clock = std::chrono::steady_clock;
  const Clock::time_point deadline = Clock::now() + std::chrono::milliseconds(std::max(timeout_ms, 0));
  std::size_t done = 0;
  while (done < bytes.size()) {
    const ssize_t n = ::write(fd_, bytes.data() + done, bytes.size() - done);
    if (n > 0) {
      done += static_cast<std::size_t>(n);
      continue;
    }
    const int error = n < 0 ? errno : EAGAIN;
    if (error != EAGAIN && error != EWOULDBLOCK && error != EINTR) return os_error(io_error_kind(error), error, path_);
    const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(deadline - Clock::now()).count();
    if (left <= 0) return make_error(SerialErrorKind::Transient, ETIMEDOUT, path_ + ": write timed out");
    pollfd p{fd_, POLLOUT, 0};
    if (::poll(&p, 1, static_cast<int>(left)) < 0 && errno != EINTR)
      return os_error(SerialErrorKind::Transient, errno, path_ + ": poll");
    if ((p.revents & (POLLHUP | POLLERR | POLLNVAL)) != 0)
      return make_error(SerialErrorKind::DeviceGone, 0, path_ + ": hung up");
  }
  return {};
}

}  // namespace posefair::drivers
