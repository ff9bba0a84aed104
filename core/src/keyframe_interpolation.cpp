#include "posefair/core/keyframe_interpolation.hpp"

#include <Eigen/LU>

namespace posefair {

KeyframeInterpolator::KeyframeInterpolator(std::vector<Mat4> matrices, std::vector<Mat4> origins, CombinationOptions o)
    : matrices_(std::move(matrices)), origins_(std::move(origins)), options_(o) {
  if (origins_.empty()) origins_ = matrices_;
}

const MatrixResult& KeyframeInterpolator::log_of(int key, int origin) {
  const auto k = std::make_pair(key, origin);
  auto it = logs_.find(k);
  if (it == logs_.end()) it = logs_.emplace(k, log_about(matrices_[key], origins_[origin], options_)).first;
  return it->second;
}

std::optional<MatrixError> KeyframeInterpolator::check_steps() const {
  for (std::size_t i = 0; i + 1 < matrices_.size(); ++i) {
    const Mat4 rel = matrices_[i + 1] * origins_[i].inverse();
    if (rotational_component(rel) >= options_.max_step_angle) {
      MatrixResult r = log_about(matrices_[i + 1], origins_[i], options_);  // the message
      MatrixError e = r ? MatrixError{MatrixErrorCode::UnsafeStep, "unsafe step"} : r.error();
      e.key = static_cast<int>(i + 1);
      e.origin_key = static_cast<int>(i);
      return e;
    }
  }
  return std::nullopt;
}

MatrixResult KeyframeInterpolator::frame(const FrameWeights& w) {
  Mat4 sum = Mat4::Zero();
  for (const WeightTerm& t : w.terms) {
    const MatrixResult& l = log_of(t.key, w.origin);
    if (!l) {
      MatrixError e = l.error();
      e.key = t.key;
      e.origin_key = w.origin;
      return e;
    }
    sum += t.weight * l.value();
  }
  MatrixResult e = matrix_exp(sum, options_.exp);
  if (!e) {
    MatrixError err = e.error();
    err.origin_key = w.origin;
    return err;
  }
  return Mat4(e.value() * origins_[w.origin]);
}

Result<std::vector<Mat4>> interpolate_keyframes(InterpolationMethod method, std::span<const double> key_times,
                                                std::span<const Mat4> matrices, std::span<const Mat4> origins,
                                                std::span<const double> frame_times, const CombinationOptions& o) {
  KeyframeInterpolator ki(std::vector<Mat4>(matrices.begin(), matrices.end()),
                          std::vector<Mat4>(origins.begin(), origins.end()), o);
  if (auto e = ki.check_steps()) return *e;
  std::vector<Mat4> out;
  out.reserve(frame_times.size());
  for (const FrameWeights& w : frame_weights(method, key_times, frame_times)) {
    MatrixResult f = ki.frame(w);
    if (!f) return f.error();
    out.push_back(f.value());
  }
  return out;
}

}  // namespace posefair
