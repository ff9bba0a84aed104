#pragma once
namespace CLI {
class App;
}  // namespace CLI

namespace posefair::tools {
// `posefair bench fusion`: the orientation estimators on BROAD, scored exactly as BROAD scores
// them, against Madgwick and Mahony at BROAD's TAGP and BROAD's published figures
// (docs/fusion.md).
void add_bench_fusion_command(CLI::App& bench, int& exit_code);
}  // namespace posefair::tools
