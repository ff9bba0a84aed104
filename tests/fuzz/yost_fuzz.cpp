// Fuzz target: the Yost 3-Space decoder (the default header 0x4F; every header field, 0x7F,
// with 20 data bytes; and 0x4F with the corrected sensor data slot, yost_slots 0x00,0x25). Any bytes: no crash and no exception; the samples and counters do not
// depend on how the bytes are cut (whole, split in two at a point chosen from the data, and in
// three); every sample is a finite unit quaternion; every byte is counted. abort() on any
// difference.
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <tuple>
#include <utility>

#include "decoder_fuzz.hpp"
#include "posefair/drivers/yost_decoder.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  std::uint64_t h = 1469598103934665603ull;  // FNV-1a of the input: the cut points
  for (std::size_t i = 0; i < size; ++i) h = (h ^ data[i]) * 1099511628211ull;
  const std::size_t a = static_cast<std::size_t>(h % (size + 1));
  const std::size_t b = static_cast<std::size_t>((h >> 32) % (size + 1));
  for (const auto& [header, length, slots] :
       {std::tuple{"0x4F", "16", "0x00"}, std::tuple{"0x7F", "20", "0x00"}, std::tuple{"0x4F", "52", "0x00,0x25"}}) {
    const posefair::OptionMap options{{"yost_header", std::string(header)},
                                      {"yost_data_length", std::string(length)},
                                      {"yost_slots", std::string(slots)}};
    const auto whole = posefair::testing::fuzz_decoder(posefair::drivers::make_yost_decoder, options, {data, size},
                                                       {{a}, {std::min(a, b), std::max(a, b)}});
    for (const auto& s : whole.samples)
      if (!posefair::testing::finite_unit(s.orientation, 1e-9)) std::abort();
  }
  return 0;
}
