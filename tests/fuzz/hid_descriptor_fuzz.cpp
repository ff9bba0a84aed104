// Fuzz target: the HID report descriptor parser (drivers/src/hid_report_descriptor.cpp). Any
// bytes either parse or are refused with an error at an offset inside them (abort() otherwise);
// a parsed descriptor's fields tile each report and its collections nest (parents before
// children); if it holds an orientation quaternion, the same bytes fed as reports to the
// decoder give only finite unit quaternions.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <stdexcept>
#include <variant>

#include "../support/decoder_feed.hpp"
#include "hid_fuzz_layouts.hpp"
#include "posefair/drivers/hid_report_descriptor.hpp"
#include "posefair/drivers/hid_sensor_orientation_decoder.hpp"

using namespace posefair::drivers;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::span<const std::uint8_t> bytes(data, size);
  auto parsed = parse_hid_report_descriptor(bytes);
  if (const auto* e = std::get_if<HidDescriptorError>(&parsed)) {
    if (e->offset > size || e->message.empty()) std::abort();
    return 0;
  }
  const HidReportDescriptor& d = std::get<HidReportDescriptor>(parsed);
  for (std::size_t c = 0; c < d.collections.size(); ++c)
    if (d.collections[c].parent >= static_cast<int>(c)) std::abort();
  for (const HidReport& r : d.reports) {
    std::uint64_t end = 0;
    for (const HidField& f : r.fields) {
      if (f.bit_offset != end || f.collection >= static_cast<int>(d.collections.size())) std::abort();
      end += static_cast<std::uint64_t>(f.bit_size) * f.count;
      for (std::uint32_t k = 0; k < f.count && k < 4; ++k) (void)hid_field_value(bytes, f, k);
    }
    if (end != r.bit_size || r.byte_size(true) > 16385) std::abort();
  }
  try {
    const HidOrientationLayout layout = resolve_hid_orientation_layout(d);
    auto decoder = make_hid_sensor_orientation_decoder(layout);
    posefair::testing::Collector sink;
    for (const auto report : posefair::testing::hid_fuzz_reports(bytes, 2 * layout.report_bytes)) decoder->decode(report, sink);
    for (const auto& s : sink.samples)
      if (!posefair::testing::finite_unit(s.orientation, 1e-12) || !std::isfinite(s.device_time)) std::abort();
  } catch (const std::invalid_argument&) {
    // no orientation quaternion: fine
  }
  return 0;
}
