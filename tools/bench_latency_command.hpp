#pragma once
namespace CLI {
class App;
}  // namespace CLI

namespace posefair::tools {
// `posefair bench latency`: posefaird's pipeline in process, N synthetic streams at R Hz, poses
// sent over loopback UDP to a receiver; prints processing-latency percentiles (sample handed
// over → datagram sent), drops and CPU per stream (docs/benchmarks.md).
void add_bench_latency_command(CLI::App& bench, int& exit_code);
}
