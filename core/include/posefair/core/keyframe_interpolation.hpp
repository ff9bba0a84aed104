#pragma once
// Frames from keyframe matrices by eq. 8 with the change of origin of eq. 7 / 3.3.1:
// frame = e^{sum w_i log(M_i X_o^-1)} X_o, o = the frame's origin key. The origin transform of
// a key is the key itself for plain poses, and the view part (S R T) for cameras, whose
// perspective factor P_b stays in the logarithm (eq. 7). Logarithms are cached per
// (key, origin) pair, so a frame costs one exponential once its keys have been seen.
#include <map>
#include <optional>
#include <utility>
#include <vector>

#include "posefair/core/keyframe_weights.hpp"
#include "posefair/core/linear_combination.hpp"

namespace posefair {

class KeyframeInterpolator {
 public:
  // origins empty: every key is its own origin.
  KeyframeInterpolator(std::vector<Mat4> matrices, std::vector<Mat4> origins = {}, CombinationOptions o = {});
  // The frame, or an error naming the key (and the origin key) that failed.
  MatrixResult frame(const FrameWeights& w);
  // Section 3.2: every step from a key to the next, about the first, must rotate by less than
  // max_step_angle, whatever frames are asked for. The error names the later key.
  std::optional<MatrixError> check_steps() const;
  std::size_t size() const { return matrices_.size(); }

 private:
  const MatrixResult& log_of(int key, int origin);
  std::vector<Mat4> matrices_, origins_;
  CombinationOptions options_;
  std::map<std::pair<int, int>, MatrixResult> logs_;
};

// All frames of a key sequence: weights by `method`, then KeyframeInterpolator.
Result<std::vector<Mat4>> interpolate_keyframes(InterpolationMethod method, std::span<const double> key_times,
                                                std::span<const Mat4> matrices, std::span<const Mat4> origins,
                                                std::span<const double> frame_times, const CombinationOptions& o = {});

}  // namespace posefair
