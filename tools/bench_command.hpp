#pragma once
namespace CLI {
class App;
}  // namespace CLI

namespace posefair::tools {
// `posefair bench quality`: posefair's engine against One Euro and the other reference
// filters on synthetic and recorded data (docs/benchmarks.md).
void add_bench_command(CLI::App& app, int& exit_code);
}
