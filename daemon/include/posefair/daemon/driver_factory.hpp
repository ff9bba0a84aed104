#pragma once
// The daemon's driver table: one entry per [stream.driver] type (config.hpp), in the manner
// of gpsd's driver list. A new device kind is one driver in drivers/ plus one case here.
#include <memory>
#include <string>
#include <vector>

#include "posefair/daemon/config.hpp"
#include "posefair/drivers/driver.hpp"
#include "posefair/drivers/gpio_data_ready.hpp"
#include "posefair/drivers/gpio_output_line.hpp"

namespace posefair::daemon {

struct MadeDriver {
  std::unique_ptr<drivers::Driver> driver;
  std::string source;                 // for the recording's stream table, e.g. "replay:/data/x.csv"
  std::vector<std::string> warnings;  // accepted damage of a replay source, to be logged
};

// Builds the stream's driver; every sample it delivers carries stream.id. Throws
// std::runtime_error with a message naming the stream when the source cannot be used (an
// unreadable or damaged-header recording, a log without the requested stream).
MadeDriver make_driver(const StreamConfig& stream);

// A stream's [stream.gpio] lines, both absent without that table. Neither touches the hardware
// before it runs: the data-ready sink requests its line on the first push, the output line on
// start().
struct MadeGpioLines {
  std::unique_ptr<drivers::GpioDataReadySink> data_ready;  // wraps `next`: the driver pushes into it
  std::unique_ptr<drivers::GpioOutputLine> output;
};
MadeGpioLines make_gpio_lines(const StreamConfig& stream, drivers::SampleSink& next);

}  // namespace posefair::daemon
