// A candump log decoded into samples (candump_replay.hpp): the bridge between can-utils'
// recordings and the replay driver. The decoder and the time base are the live ones, so a
// replay gives the samples the SocketCAN driver would have produced from the same frames.
#include "posefair/drivers/candump_replay.hpp"

#include <optional>
#include <stdexcept>

namespace posefair::drivers {
namespace {

// Stamps each decoded sample as the live driver does and keeps it.
class Stamper final : public DecodedSink {
 public:
  Stamper(const CandumpReplayOptions& o, std::vector<Sample>& out) : options_(o), base_(o.time_source, o.time_base), out_(out) {}
  void at(double receive_time) { receive_time_ = receive_time; }
  void on_sample(const DecodedSample& d) override {
    Sample s;
    s.stream_id = options_.stream_id;
    s.sequence = out_.size();
    s.receive_time = receive_time_;
    fill_sample(d, s);
    const std::optional<double> device = (d.flags & kHasDeviceTime) ? std::optional<double>(d.device_time) : std::nullopt;
    s.time = base_.update(receive_time_, device).time;
    out_.push_back(s);
  }

 private:
  const CandumpReplayOptions& options_;
  TimeBase base_;
  std::vector<Sample>& out_;
  double receive_time_ = 0.0;
};

}  // namespace

CandumpReplay decode_candump(const formats::CandumpLog& log, const CandumpReplayOptions& options) {
  std::unique_ptr<CanDecoder> decoder = make_can_decoder(options.protocol, options.decoder);
  if (!decoder) throw std::invalid_argument("unknown CAN protocol \"" + options.protocol + "\"");
  CandumpReplay r;
  r.problems = log.problems;
  Stamper stamper(options, r.samples);
  for (const formats::CandumpRecord& rec : log.records) {
    if (!options.interface.empty() && rec.interface != options.interface) {
      ++r.other_interfaces;
      continue;
    }
    stamper.at(rec.frame.timestamp);
    decoder->feed(rec.frame, stamper);
  }
  r.counters = decoder->counters();
  r.frame_counters = decoder->frame_counters();
  return r;
}

CandumpReplay decode_candump_file(const std::filesystem::path& path, const CandumpReplayOptions& options) {
  return decode_candump(formats::read_candump_log(path), options);
}

}  // namespace posefair::drivers
