// Fuzz target: the VectorNav ASCII decoder (both settings of vectornav_unchecked). Any bytes:
// no crash and no exception; the samples and counters do not depend on how the bytes are cut
// (whole, split in two at a point chosen from the data, and in three); every sample is a finite
// unit quaternion; every byte is counted. abort() on any difference.
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstdlib>

#include "decoder_fuzz.hpp"
#include "posefair/drivers/vectornav_decoder.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  std::uint64_t h = 1469598103934665603ull;  // FNV-1a of the input: the cut points
  for (std::size_t i = 0; i < size; ++i) h = (h ^ data[i]) * 1099511628211ull;
  const std::size_t a = static_cast<std::size_t>(h % (size + 1));
  const std::size_t b = static_cast<std::size_t>((h >> 32) % (size + 1));
  for (const char* mode : {"reject", "accept"}) {
    const posefair::OptionMap options{{"vectornav_unchecked", std::string(mode)}};
    const auto whole = posefair::testing::fuzz_decoder(posefair::drivers::make_vectornav_decoder, options, {data, size},
                                                       {{a}, {std::min(a, b), std::max(a, b)}});
    for (const auto& s : whole.samples)
      if (!posefair::testing::finite_unit(s.orientation, 1e-9)) std::abort();
  }
  return 0;
}
