// Fuzz target: the HID Sensor orientation decoder (drivers/src/hid_sensor_orientation_decoder.cpp).
// The first byte picks one of four layouts (hid_fuzz_layouts.hpp), the rest is cut into
// reports. Every report is counted once (a frame, another report ID, or too short); every
// sample is a finite unit quaternion with a finite device time, and encoding it again and
// decoding gives it back within the layout's resolution (abort() otherwise).
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>

#include "../support/decoder_feed.hpp"
#include "hid_fuzz_layouts.hpp"

using namespace posefair::drivers;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const std::vector<HidOrientationLayout> layouts = posefair::testing::hid_fuzz_layouts();
  if (size == 0) return 0;
  const HidOrientationLayout& layout = layouts[data[0] % layouts.size()];
  auto decoder = make_hid_sensor_orientation_decoder(layout);
  auto again = make_hid_sensor_orientation_decoder(layout);
  posefair::testing::Collector sink, back;
  const auto reports = posefair::testing::hid_fuzz_reports({data + 1, size - 1}, 2 * layout.report_bytes);
  for (const auto report : reports) decoder->decode(report, sink);
  const DecoderCounters& c = decoder->counters();
  const std::uint64_t short_reports = c.malformed - (c.frames - c.samples);
  if (c.frames + c.ignored_frames + short_reports != reports.size() || c.samples != sink.samples.size()) std::abort();
  const double step = std::pow(10.0, layout.values[0].unit_exponent);
  for (const auto& s : sink.samples) {
    if (!posefair::testing::finite_unit(s.orientation, 1e-12) || !std::isfinite(s.device_time)) std::abort();
    again->decode(encode_hid_orientation_report(layout, s.orientation), back);
    if (back.samples.empty()) std::abort();
    if ((back.samples.back().orientation.coeffs() - s.orientation.coeffs()).norm() > 8 * step) std::abort();
  }
  return 0;
}
