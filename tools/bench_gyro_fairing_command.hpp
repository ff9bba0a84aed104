#pragma once
namespace CLI {
class App;
}  // namespace CLI

namespace posefair::tools {
// `posefair bench gyro-fairing`: gyro-aided fairing on BROAD's optical orientation with added
// jitter and the real gyroscope, against fairing alone, One Euro and the raw stream
// (docs/fusion.md).
void add_bench_gyro_fairing_command(CLI::App& bench, int& exit_code);
}  // namespace posefair::tools
