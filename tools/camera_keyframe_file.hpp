#pragma once
// The camera keyframe file of `posefair camera` (format in docs/matrix-interpolation.md):
// one keyframe per line, whitespace-separated, '#' starts a comment.
//   key <time> from X Y Z at X Y Z [up X Y Z] [fov DEG] [aspect A] [skew G] [cop U V] [near N] [far F]
//   key <time> matrix M00 M01 .. M33 [near N] [far F]     (row-major P_b S R T, bottom row 0 0 0 1)
#include <filesystem>
#include <stdexcept>
#include <string>
#include <vector>

#include "posefair/core/camera_matrix.hpp"

namespace posefair::tools {

struct CameraKeyframe {
  double time;
  CameraKey key;
  int line;  // 1-based line in the file
};

// "file:line: message" for malformed or unusable keyframes.
struct KeyframeFileError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// Throws KeyframeFileError; std::ios_base::failure when the file cannot be opened.
std::vector<CameraKeyframe> read_camera_keyframes(const std::filesystem::path& path);

}  // namespace posefair::tools
