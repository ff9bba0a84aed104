// Fuzz target: the control socket's request parser (daemon/control_command.hpp). Any bytes are a
// command or an error, never both; a command is exactly its text and a newline.
#include <cstdint>
#include <cstdlib>
#include <span>
#include <string>

#include "posefair/daemon/control_command.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace posefair::daemon;
  const ControlCommand c = parse_control_command(std::span<const std::uint8_t>(data, size));
  if (c) {
    const std::string expected = std::string(to_string(c.verb)) + "\n";
    if (expected != std::string(reinterpret_cast<const char*>(data), size)) std::abort();
  }
  return 0;
}
