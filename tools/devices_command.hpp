#pragma once
// `posefair devices`: the serial ports this machine has, with their USB ids and serial numbers
// (what a [stream.driver] with type = "serial" names as device or usb), and the protocol
// decoders this build knows (docs/config.md).
namespace CLI {
class App;
}  // namespace CLI

#include <string>
#include <vector>

#include "posefair/drivers/serial_port.hpp"

namespace posefair::tools {

void add_devices_command(CLI::App& app, int& exit_code);

// The listing as printed: a table of ports (or "no serial ports found"), then the protocols.
std::string format_devices(const std::vector<drivers::PortInfo>& ports, const std::vector<std::string>& protocols);
// Every device protocol of the serial, CAN and HID registries, then every output encoding, with
// its description and options (name, type, default, doc), as `posefair devices` prints it after
// the ports.
std::string format_protocols();

}  // namespace posefair::tools
