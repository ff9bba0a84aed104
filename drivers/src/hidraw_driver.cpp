// The hidraw driver: finding the node through sysfs, the report descriptor and the decoder
// behind the device link; see hidraw_driver.hpp.
#include "posefair/drivers/hidraw_driver.hpp"

#include <fcntl.h>
#include <linux/hidraw.h>
#include <poll.h>
#include <sys/ioctl.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <charconv>
#include <cstring>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <system_error>
#include <utility>
#include <variant>

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

// Why a node could not be opened; each kind is logged once per wait. NotFound is "absent".
enum class OpenFailure : unsigned { NotFound, PermissionDenied, Descriptor, Other };

// hidraw's largest report (HID_MAX_BUFFER_SIZE in the kernel).
constexpr std::size_t kMaxReport = 16384;

bool is_gone(int error) { return error == EIO || error == ENODEV || error == ENXIO || error == EPIPE; }

const HidrawDriverOptions& checked(const HidrawDriverOptions& o) {
  if (!o.device.usb && o.device.device.empty()) throw std::invalid_argument("hid: give a device path or a USB id");
  return o;
}

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

HidrawDriver::HidrawDriver(HidrawDriverOptions options)
    : DeviceLinkDriver("hid", checked(options)), options_(std::move(options)), node_(std::make_unique<Node>()),
      buffer_(kMaxReport) {
  decoder_factory_ = configure_hid_decoder(options_.protocol, options_.decoder_options);  // throws OptionError
  if (!decoder_factory_) {
    std::string known;
    for (const std::string& p : hid_decoder_protocols()) known += (known.empty() ? "" : ", ") + p;
    throw std::invalid_argument("hid: unknown protocol '" + options_.protocol + "' (known: " + known + ")");
  }
  set_name(options_.name.empty() ? "hid:" + options_.device.describe() : options_.name);
}

HidrawDriver::~HidrawDriver() = default;

// An open node with its decoder.
struct HidrawDriver::Node {
  int fd = -1;
  std::string path;
  std::string note;                             // worth one log line (several nodes matched)
  std::string what;                             // the report read, for the "opened" line
  std::unique_ptr<HidReportDecoder> decoder;    // built for this node's descriptor
};

DecoderCounters HidrawDriver::link_decoder_counters() const {
  DecoderCounters sum = past_;
  if (node_->decoder) sum += node_->decoder->counters();
  return sum;
}

// Opens the node and has the protocol's factory build its decoder.
std::variant<DeviceLinkDriver::LinkOpened, DeviceLinkDriver::LinkOpenFailure> HidrawDriver::open_link() {
  auto failure = [](OpenFailure kind, std::string message) {
    return LinkOpenFailure{static_cast<unsigned>(kind), kind == OpenFailure::NotFound, "", std::move(message)};
  };
  Node& o = *node_;
  std::string path = options_.device.device;
  o.note.clear();
  if (options_.device.usb) {
    const std::vector<std::string> nodes = find_hidraw_nodes(options_.device, options_.sysfs_root, options_.dev_root);
    if (nodes.empty()) return failure(OpenFailure::NotFound, "no hidraw node with HID id " + options_.device.describe());
    path = nodes.front();
    if (nodes.size() > 1)
      o.note = std::to_string(nodes.size()) + " hidraw nodes match " + options_.device.describe() + "; using " + path +
               " (set serial_number or device to choose)";
  }
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC | O_NONBLOCK);
  if (fd < 0) {
    const int e = errno;
    const std::string message = path + ": " + std::strerror(e);
    if (e == ENOENT || e == ENODEV || e == ENXIO) return failure(OpenFailure::NotFound, message);
    if (e == EACCES || e == EPERM) return failure(OpenFailure::PermissionDenied, message);
    return failure(OpenFailure::Other, message);
  }
  auto refuse = [&](OpenFailure kind, const std::string& message) {
    ::close(fd);
    return failure(kind, path + ": " + message);
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
  LinkOpened opened;
  opened.path = path;
  opened.where = path == options_.device.device ? path : options_.device.describe() + " -> " + path;
  opened.details = ", protocol " + options_.protocol + " (" + o.what + "), time source " +
                   std::string(to_string(options_.time_source));
  opened.note = o.note;
  return opened;
}

DeviceLinkDriver::LinkRead HidrawDriver::read_link(int timeout_ms, SampleStamper& stamper) {
  LinkRead result;
  auto gone = [&](std::string why) {
    result.error = LinkRead::Error::Gone;
    result.message = std::move(why);
    return result;
  };
  pollfd p{node_->fd, POLLIN, 0};
  const int ready = ::poll(&p, 1, timeout_ms);
  if (ready < 0 && errno != EINTR) return gone(std::string("poll: ") + std::strerror(errno));
  if (ready > 0 && (p.revents & POLLIN) != 0) {
    const ssize_t n = ::read(node_->fd, buffer_.data(), buffer_.size());
    if (n > 0) {
      const double received = monotonic_seconds();
      reports_.fetch_add(1, std::memory_order_relaxed);
      stamper.set_receive_time(received);
      node_->decoder->decode(std::span<const std::uint8_t>(buffer_.data(), static_cast<std::size_t>(n)), stamper);
      result.decoded = true;
      return result;
    }
    const int e = n == 0 ? 0 : errno;
    if (n < 0 && (e == EAGAIN || e == EINTR)) return result;
    if (n == 0 || is_gone(e)) return gone(n == 0 ? "end of file" : std::strerror(e));
    result.error = LinkRead::Error::Transient;
    result.message = std::strerror(e);
    return result;
  }
  if (ready > 0 && (p.revents & (POLLHUP | POLLERR | POLLNVAL)) != 0) return gone("hangup");
  return result;  // timeout: look at the stop token again
}

void HidrawDriver::close_link() {
  Node& node = *node_;
  if (node.fd >= 0) ::close(node.fd);
  node.fd = -1;
  if (node.decoder) {
    past_ += node.decoder->counters();
    node.decoder.reset();
  }
}

}  // namespace posefair::drivers
