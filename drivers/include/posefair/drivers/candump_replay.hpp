#pragma once
// A recorded CAN bus replayed through posefair's CAN decoders: a candump log (candump_log.hpp)
// decoded frame by frame by the decoder of a CAN protocol (can_decoder.hpp), each sample timed
// exactly as the live SocketCAN driver times it (its receive time = the frame's logged time,
// then the time base rule of time_base.hpp), so the result can be played by ReplayDriver's
// in-memory constructor: ReplayDriver(std::move(result.samples), replay_options, name).
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "posefair/core/sample.hpp"
#include "posefair/drivers/can_decoder.hpp"
#include "posefair/drivers/time_base.hpp"
#include "posefair/formats/candump_log.hpp"

namespace posefair::drivers {

struct CandumpReplayOptions {
  std::string protocol;       // a CAN protocol name (can_decoder_protocols())
  OptionMap decoder;          // its options
  std::string interface;      // only frames logged on this interface; empty: every interface
  std::uint32_t stream_id = 0;
  TimeSource time_source = TimeSource::Auto;
  TimeBaseOptions time_base;
};

struct CandumpReplay {
  std::vector<Sample> samples;  // sequence 0, 1, ... in bus order; receive_time = logged time
  DecoderCounters counters;
  CanFrameCounters frame_counters;
  std::vector<formats::CandumpProblem> problems;  // malformed log lines (skipped)
  std::size_t other_interfaces = 0;      // frames skipped for their interface
};

// Decodes a parsed log. Throws std::invalid_argument for an unknown protocol or a bad option.
CandumpReplay decode_candump(const formats::CandumpLog& log, const CandumpReplayOptions& options);
// Reads and decodes a file. Throws CandumpFileError when it cannot be read, std::invalid_argument as above.
CandumpReplay decode_candump_file(const std::filesystem::path& path, const CandumpReplayOptions& options);

}  // namespace posefair::drivers
