#pragma once
namespace CLI {
class App;
}  // namespace CLI

namespace posefair::tools {
// `posefair camera`: camera keyframes -> interpolated camera matrices per frame by Alexa's
// linear combination of transformations (docs/matrix-interpolation.md).
void add_camera_command(CLI::App& app, int& exit_code);
}
