#include "devices_command.hpp"

#include <CLI/CLI.hpp>

#include <algorithm>
#include <array>
#include <cstdio>
#include <iostream>
#include <span>
#include <string_view>
#include <stdexcept>

#include "posefair/core/error.hpp"
#include "posefair/daemon/output_encoder.hpp"
#include "posefair/drivers/can_decoder.hpp"
#include "posefair/drivers/decoder.hpp"
#include "posefair/drivers/hid_report_decoder.hpp"

namespace posefair::tools {
namespace {

std::string or_dash(const std::string& s) { return s.empty() ? "-" : s; }

// Manufacturer and product as the device reports them, else libserialport's description.
std::string description(const drivers::PortInfo& p) {
  std::string d = p.usb_manufacturer;
  if (!p.usb_product.empty()) d += (d.empty() ? "" : " ") + p.usb_product;
  if (d.empty()) d = p.description;
  return or_dash(d);
}

// One registry's protocols: name, description, and each option with its type and default.
template <class Entry>
std::string format_registry(std::string_view title, std::span<const Entry* const> entries) {
  std::string out = "\n" + std::string(title) + ":\n";
  for (const Entry* e : entries) {
    out += "  " + std::string(e->name) + ": " + std::string(e->description) + "\n";
    for (const posefair::OptionSpec& o : e->options) {
      out += "    " + std::string(o.name) + " (" + std::string(posefair::to_string(o.type));
      if (!o.default_value.empty()) out += ", default " + std::string(o.default_value);
      for (std::size_t c = 0; c < o.choices.size(); ++c) out += (c == 0 ? ", one of " : "|") + std::string(o.choices[c]);
      out += "): " + std::string(o.doc) + "\n";
    }
  }
  return out;
}

}  // namespace

std::string format_protocols() {
  return format_registry("serial protocols (type = \"serial\")", drivers::decoder_entries()) +
         format_registry("CAN protocols (type = \"socketcan\", or a candump replay)", drivers::can_decoder_entries()) +
         format_registry("HID protocols (type = \"hid\")", drivers::hid_decoder_entries()) +
         format_registry("output encodings ([[output]] encoding)", daemon::output_encoder_entries());
}

std::string format_devices(const std::vector<drivers::PortInfo>& ports, const std::vector<std::string>& protocols) {
  std::string out;
  if (ports.empty()) {
    out += "no serial ports found\n";
  } else {
    using Row = std::array<std::string, 5>;
    std::vector<Row> rows{{"PATH", "TRANSPORT", "USB ID", "SERIAL NUMBER", "DESCRIPTION"}};
    for (const drivers::PortInfo& p : ports)
      rows.push_back({p.path, or_dash(p.transport), p.has_usb_id ? drivers::to_string(p.usb) : "-", or_dash(p.usb_serial),
                      description(p)});
    std::array<std::size_t, 5> width{};
    for (const Row& r : rows)
      for (std::size_t c = 0; c < r.size(); ++c) width[c] = std::max(width[c], r[c].size());
    for (const Row& r : rows) {
      std::string line;
      for (std::size_t c = 0; c < r.size(); ++c) {
        line += r[c];
        if (c + 1 < r.size()) line += std::string(width[c] - r[c].size() + 2, ' ');
      }
      out += line + "\n";
    }
  }
  std::string list;
  for (const std::string& p : protocols) list += (list.empty() ? "" : ", ") + p;
  out += "protocols: " + (list.empty() ? std::string("none registered") : list) + "\n";
  return out;
}

void add_devices_command(CLI::App& app, int& exit_code) {
  auto* cmd = app.add_subcommand("devices",
                                 "List serial ports (path, USB VID:PID, serial number) and the known device protocols with their options");
  cmd->footer(
      "A [stream.driver] with type = \"serial\" names a port by device = \"/dev/...\" (a /dev/serial/by-id/ link "
      "survives replugging) or by usb = \"VID:PID\" with serial_number to choose among equal devices; protocol is one "
      "of the protocols listed (docs/config.md). Pseudo-terminals are not listed.");
  cmd->callback([&exit_code] {
    try {
      std::cout << format_devices(drivers::list_serial_ports(), drivers::decoder_protocols()) << format_protocols();
      exit_code = kExitOk;
    } catch (const std::runtime_error& e) {
      std::cerr << "posefair devices: " << e.what() << "\n";
      exit_code = posefair::exit_code(ErrorKind::Software);
    }
  });
}

}  // namespace posefair::tools
