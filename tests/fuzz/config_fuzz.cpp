// Fuzz target: posefaird's config parser. Any bytes either parse into a DaemonConfig or are
// refused with a ConfigError; nothing else may escape (no other exception, no crash, no hang).
#include <cstdint>
#include <cstdlib>
#include <string_view>

#include "posefair/daemon/config.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  try {
    (void)posefair::daemon::parse_config(text, "/nonexistent/fuzz.toml");
  } catch (const posefair::daemon::ConfigError&) {
    // refused with file:line:key: fine
  }
  return 0;
}
