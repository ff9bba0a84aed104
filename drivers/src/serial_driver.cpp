// The serial driver: port and decoder behind the device link; see serial_driver.hpp.
#include "posefair/drivers/serial_driver.hpp"

#include <span>
#include <stdexcept>
#include <utility>

#include "monotonic_clock.hpp"
#include "sample_stamper.hpp"

namespace posefair::drivers {
namespace {

std::unique_ptr<Decoder> take_decoder(SerialDriverOptions& o) {
  if (o.decoder) return std::move(o.decoder);
  std::unique_ptr<Decoder> d = make_decoder(o.protocol, o.decoder_options);  // may throw for a bad option
  if (!d) {
    std::string known;
    for (const std::string& p : decoder_protocols()) known += (known.empty() ? "" : ", ") + p;
    throw std::invalid_argument("unknown protocol '" + o.protocol + "' (known: " + (known.empty() ? "none" : known) + ")");
  }
  return d;
}

const SerialDriverOptions& checked(const SerialDriverOptions& o) {
  if (!o.port.usb && o.port.device.empty()) throw std::invalid_argument("serial: give a device path or a USB id");
  validate(o.settings);
  if (o.read_buffer == 0) throw std::invalid_argument("serial: read_buffer must be > 0");
  return o;
}

}  // namespace

SerialDriver::SerialDriver(SerialDriverOptions options)
    : DeviceLinkDriver("serial", checked(options)), options_(std::move(options)) {
  decoder_ = take_decoder(options_);
  buffer_.resize(options_.read_buffer);
  set_name(options_.name.empty() ? "serial:" + options_.port.describe() : options_.name);
}

std::variant<DeviceLinkDriver::LinkOpened, DeviceLinkDriver::LinkOpenFailure> SerialDriver::open_link() {
  const SerialError e = port_.open(options_.port, options_.settings);
  if (e)
    return LinkOpenFailure{static_cast<unsigned>(e.kind), e.kind == SerialErrorKind::NotFound, std::string(to_string(e.kind)),
                           e.message};
  decoder_->reset();
  LinkOpened o;
  o.path = port_.path();
  o.where = port_.path() == options_.port.device ? port_.path() : options_.port.describe() + " -> " + port_.path();
  o.details = " at " + describe(options_.settings) + ", protocol " + std::string(decoder_->protocol()) + ", time source " +
              std::string(to_string(options_.time_source));
  o.note = port_.note();
  return o;
}

DeviceLinkDriver::LinkRead SerialDriver::read_link(int timeout_ms, SampleStamper& stamper) {
  const SerialPort::ReadResult r = port_.read(buffer_, timeout_ms);
  LinkRead result;
  if (r.bytes > 0) {
    const double received = monotonic_seconds();
    bytes_.fetch_add(r.bytes, std::memory_order_relaxed);
    stamper.set_receive_time(received);
    decoder_->feed(std::span<const std::uint8_t>(buffer_.data(), r.bytes), stamper);
    result.decoded = true;
    return result;
  }
  if (!r.error) return result;  // timeout
  result.error = r.error.kind == SerialErrorKind::DeviceGone ? LinkRead::Error::Gone : LinkRead::Error::Transient;
  result.message = r.error.message;
  return result;
}

void SerialDriver::close_link() {
  port_.close();
  decoder_->reset();  // a half-received frame must not merge with the first bytes after a replug
}

}  // namespace posefair::drivers
