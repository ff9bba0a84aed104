// Fuzz target: the vendor HID report layout decoder (drivers/src/hid_vendor_layout_decoder.cpp).
// The first eight bytes make a layout (type, byte order, component order, report ID, four
// offsets, scale); layouts that do not validate must throw HidVendorLayoutError and nothing
// else. The rest is cut into reports; every sample is a finite unit quaternion (abort()
// otherwise).
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>

#include "../support/decoder_feed.hpp"
#include "hid_fuzz_layouts.hpp"
#include "posefair/drivers/hid_vendor_layout_decoder.hpp"

using namespace posefair::drivers;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size < 8) return 0;
  HidVendorLayout l;
  l.type = static_cast<HidVendorType>(data[0] % 4);
  l.big_endian = data[1] & 1;
  l.w_first = data[1] & 2;
  l.report_id = data[1] & 4 ? data[2] : -1;  // data[2] = 0 is refused (report ID 0 is reserved)
  l.report_length = data[1] & 8 ? data[3] % 64 : 0;
  for (int k = 0; k < 4; ++k) l.offset_bits[k] = data[4 + k];
  l.scale = l.type == HidVendorType::Int16 ? 1.0 / 16384 : l.type == HidVendorType::Int32 ? 1.0 / (1 << 30) : 1.0;
  std::unique_ptr<HidReportDecoder> decoder;
  try {
    decoder = make_hid_vendor_layout_decoder(l);
  } catch (const HidVendorLayoutError&) {
    return 0;
  }
  posefair::testing::Collector sink;
  for (const auto report : posefair::testing::hid_fuzz_reports({data + 8, size - 8}, 72)) decoder->decode(report, sink);
  for (const auto& s : sink.samples)
    if (!posefair::testing::finite_unit(s.orientation, 1e-12)) std::abort();
  if (decoder->counters().samples != sink.samples.size()) std::abort();
  return 0;
}
