#pragma once
namespace CLI {
class App;
}  // namespace CLI

namespace posefair::tools {
// `posefair bench streams`: posefair's defaults on generated streams that nothing was tuned on
// (generated_streams.hpp), against raw, One Euro's defaults, and the best posefair and One Euro
// configurations for each stream picked on that stream itself (docs/benchmarks.md).
void add_bench_streams_command(CLI::App& bench, int& exit_code);
}
