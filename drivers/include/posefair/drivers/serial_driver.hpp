#pragma once
// The serial driver (docs/devices.md, "Serial"): a tracker or IMU on a serial port (USB-serial
// adapter, CDC-ACM, a UART), its byte stream decoded by a protocol decoder (decoder.hpp), each
// sample timed (time_base.hpp) and handed to the sink. The link (opening with backoff, losses,
// reconnects, counters, health, the log lines) is DeviceLinkDriver's (device_link_driver.hpp).
//
// Here:
//   - opens the port (serial_port.hpp); a missing device (not found) is "absent", any other
//     refusal (permissions, busy, settings) is logged as an error.
//   - reads with poll() and a short timeout (read_timeout, 20 ms); feeds the decoder whatever
//     each read returned; receive_time is CLOCK_MONOTONIC taken right after that read, shared
//     by every sample decoded from it.
//   - the device is gone when a read says so (unplugged: EIO, ENXIO, ENODEV, hangup); it then
//     closes the port and resets the decoder, which starts afresh on the new connection.
#include <atomic>
#include <cstdint>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "posefair/drivers/decoder.hpp"
#include "posefair/drivers/device_link_driver.hpp"
#include "posefair/drivers/serial_port.hpp"

namespace posefair::drivers {

// stream_id, reconnect_min/max, time_source, time_base, read_timeout, log and name are the
// link's (DeviceLinkOptions); the default name is "serial:<device or usb id>".
struct SerialDriverOptions : DeviceLinkOptions {
  SerialPortSpec port;
  SerialSettings settings;
  std::string protocol;                // decoder registry name (decoder.hpp), used when `decoder` is null
  OptionMap decoder_options;           // its options (decoder.hpp, core/options.hpp)
  std::unique_ptr<Decoder> decoder;    // an injected decoder (tests); takes the place of `protocol`
  std::size_t read_buffer = 4096;      // bytes per read, > 0
};

class SerialDriver final : public DeviceLinkDriver {
 public:
  // Throws std::invalid_argument: no device and no USB id, an unknown protocol (the message
  // lists the known ones), an option the decoder refuses, bad settings or backoff.
  explicit SerialDriver(SerialDriverOptions options);

  std::uint64_t bytes() const { return bytes_.load(std::memory_order_relaxed); }  // bytes read
  std::string_view protocol() const { return decoder_->protocol(); }

 private:
  std::variant<LinkOpened, LinkOpenFailure> open_link() override;
  LinkRead read_link(int timeout_ms, SampleStamper& stamper) override;
  void close_link() override;
  DecoderCounters link_decoder_counters() const override { return decoder_->counters(); }

  SerialDriverOptions options_;
  std::unique_ptr<Decoder> decoder_;
  SerialPort port_;                   // run()'s thread only
  std::vector<std::uint8_t> buffer_;  // run()'s thread only
  std::atomic<std::uint64_t> bytes_{0};
};

}  // namespace posefair::drivers
