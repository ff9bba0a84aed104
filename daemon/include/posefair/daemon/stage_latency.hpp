#pragma once
// Where a sample's latency goes, stage by stage, so that every claim about the pipeline's hops
// is measured rather than inferred (issue 20). One histogram per stage for the whole pipeline:
//
//   ring wait   driver's hand-over (RingSample::enqueued_ns) → the engine pops the sample
//   engine      pop → the sample's poses are faired (fusion, bridge, window, resampler)
//   hand-off    faired → the publisher thread pops the pose (0 when the engine publishes itself)
//   encode      the pose's datagrams encoded (every output's encoder, summed)
//   send        the datagrams sent (every sendto/sendmmsg of the pose, summed)
//
// Each stream's engine role (the engine thread, or its driver thread) records ring wait and engine,
// the thread that publishes the three others; streams fair on several threads at once, so each
// histogram has many writers (LatencyHistogram takes any number). Recording is a few relaxed
// atomic read-modify-writes, no allocation: safe on the real-time threads.
#include "posefair/daemon/latency_histogram.hpp"

namespace posefair::daemon {

struct StageLatencySnapshot {
  HistogramSnapshot ring_wait, engine, hand_off, encode, send;
};

struct StageLatency {
  LatencyHistogram ring_wait, engine, hand_off, encode, send;

  StageLatencySnapshot snapshot() const {
    return {ring_wait.snapshot(), engine.snapshot(), hand_off.snapshot(), encode.snapshot(), send.snapshot()};
  }
};

}  // namespace posefair::daemon
