#pragma once
// Hawkins & Grimm Section 4.2 (termination constants of the iterations) and Section 5.1 (excess
// screen path of mesh vertices, camera-parameter vs matrix interpolation), as data for
// docs/matrix-interpolation.md. Errors are measured against Eigen's MatrixFunctions log.
#include <cstdint>
#include <random>
#include <vector>

#include "posefair/core/camera_matrix.hpp"

namespace posefair {

// How Section 4.2's scales in [1e-2, 1e2] are drawn (the paper gives only the range).
enum class ScaleDraw { LogUniform, Uniform };

// Section 4.2's random transform T R S: R = Rz Ry Rx with each angle uniform in
// [min_angle, max_angle], scales in [1e-2, 1e2] per axis (log-uniform unless asked otherwise),
// translations uniform in [0.1, 100] per axis.
Mat4 random_test_transform(std::mt19937_64& rng, double min_angle = 0.0, double max_angle = 3.141592653589793,
                           ScaleDraw scales = ScaleDraw::LogUniform);

// 4.2.1: |XX - A| before each Denman-Beavers update (no stopping; up to `iterations` updates).
struct SqrtStudyRow {
  int matrix;
  int iteration;
  double residual;
  bool principal;  // false: the matrix has a negative real eigenvalue
};
std::vector<SqrtStudyRow> sqrt_iteration_study(int matrices, int iterations, std::uint64_t seed);

// 4.2.3 / 4.2.2: the logarithm with exactly n = 0 .. max_roots square roots (eps3 as given),
// the series to eps2 (up to 60 terms); change from n - 1 and error against Eigen's log.
struct LogStudyRow {
  int matrix;
  int square_roots;
  double distance_to_identity;  // eps1 reached: |A^(1/2^n) - I|
  int series_terms;             // -1: the series did not converge in 60 terms
  double change;                // |log_n - log_(n-1)| (nan when either failed)
  double error;                 // |log_n - Eigen log| / |Eigen log|
};
std::vector<LogStudyRow> log_square_root_study(int matrices, int max_roots, double eps3, bool relative_eps3,
                                               std::uint64_t seed);

// 3.2 / ERRATA item 4: Section 4.2 transforms whose rotation (polar factor) is pi/2 or more.
struct LargeRotationStudy {
  int matrices = 0;
  int negative_eigenvalue = 0;           // no principal logarithm exists
  int sqrt_failed = 0;                   // the bare iteration did not reach eps3 in 10 updates
  int sqrt_failed_without_negative = 0;  // ... although a principal square root exists
  int log_ok = 0;                        // matrix_log succeeded
  int log_root_cap = 0;                  // matrix_log: 20 roots did not reach eps1 (or a root failed)
  double worst_log_error = 0.0;          // relative, against Eigen, over the successes
};
LargeRotationStudy large_rotation_study(int matrices, std::uint64_t seed, ScaleDraw scales = ScaleDraw::LogUniform);

// 5.1: random keyframe pairs of cameras around a sphere mesh; per pair the mean excess length
// 100 (l - l0) / l0 (ERRATA item 3) of the vertices' paths at t = 0, 0.1, .., 1, measured twice:
//   in camera space (the paper's Fig. 8): the vertex under the affine camera map P_b S R T
//     (matrix interpolation's M(t); for parameter interpolation the interpolated parameters'),
//     before P_a and the divide;
//   on the screen: x, y after the divide (a second view).
// Vertices whose displacement l0 is under 1e-3 of the mesh's radius (camera space) or under
// 0.01 (screen), or which pass behind the camera (screen), are left out and counted.
enum class KeyPairDraw {
  UniformAngle,  // key b is key a's view turned by an angle uniform in [0°, 90°) about a random
                 // axis, at its own distance (3-6) and with its own lens
  Independent,   // both keys drawn independently (views 60-90° apart, most of them)
};
struct PathPairRow {
  int pair;
  double drawn_angle_deg;  // the turn drawn (UniformAngle), else nan
  double rotation_deg;     // rotation between the two keys' S R T (polar factor)
  double camera_parameter, camera_matrix;  // mean excess in camera space, percent
  double screen_parameter, screen_matrix;  // mean excess on the screen, percent
  int camera_vertices, screen_vertices;    // vertex paths used
};
struct PathMeans {
  double mean_parameter = 0, mean_matrix = 0, median_parameter = 0, median_matrix = 0;
  int matrix_lower = 0;  // pairs where matrix interpolation's excess is the lower one
};
struct PathStudy {
  std::vector<PathPairRow> pairs;
  int rejected_unsafe = 0;  // generated pairs rotating pi/2 or more (matrix lerp refuses them)
  int camera_skipped = 0, screen_skipped = 0;
  PathMeans camera, screen;
};
PathStudy path_length_study(int pairs, std::uint64_t seed, KeyPairDraw draw = KeyPairDraw::UniformAngle);

}  // namespace posefair
