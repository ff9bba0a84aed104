#pragma once
// What every decoder fuzz target checks: the input fed whole to one decoder, and cut at points
// the target picks from the input to others, gives the same samples and counters; every byte
// fed and every sample handed over is counted; raw readings are finite, and a raw-only sample
// carries at least one. abort() otherwise. Each target adds the checks
// of its own protocol on the samples returned.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <initializer_list>
#include <memory>
#include <span>
#include <vector>

#include "../support/decoder_feed.hpp"

namespace posefair::testing {

using MakeDecoder = std::unique_ptr<drivers::Decoder> (*)(const posefair::OptionMap&);

// Decodes `data` whole, then once cut at each list of offsets (increasing, each at most
// data.size()) with a fresh decoder each time; aborts unless every run gives what the whole
// one gave. Returns the whole run.
inline Decoded fuzz_decoder(MakeDecoder make, const posefair::OptionMap& options, std::span<const std::uint8_t> data,
                            std::initializer_list<std::initializer_list<std::size_t>> cuts) {
  Decoded whole = decode_chunks(make(options), data);
  if (whole.counters.bytes != data.size() || whole.counters.samples != whole.samples.size()) std::abort();
  for (const drivers::DecodedSample& s : whole.samples)  // raw readings finite; a raw-only sample has some
    if (!s.gyro.allFinite() || !s.accel.allFinite() || !s.mag.allFinite() ||
        ((s.flags & kNoOrientation) != 0 && (s.flags & (kHasGyro | kHasAccel | kHasMag)) == 0))
      std::abort();
  for (const std::initializer_list<std::size_t> at : cuts)
    if (!same(whole, decode_chunks(make(options), data, chunks_cut_at(std::vector<std::size_t>(at))))) std::abort();
  return whole;
}

}  // namespace posefair::testing
