#pragma once
// Hawkins & Grimm Section 4.2 (termination constants of the iterations) and Section 5.1 (excess
// screen path of mesh vertices, camera-parameter vs matrix interpolation), as data for
// docs/matrix-interpolation.md. Errors are measured against Eigen's MatrixFunctions log.
#include <cstdint>
#include <random>
#include <vector>

#include "posefair/core/camera_matrix.hpp"

namespace posefair {

// Section 4.2's random transform T R S: R = Rz Ry Rx with each angle uniform in
// [min_angle, max_angle], scales log-uniform in [1e-2, 1e2] per axis, translations uniform in
// [0.1, 100] per axis.
Mat4 random_test_transform(std::mt19937_64& rng, double min_angle = 0.0, double max_angle = 3.141592653589793);

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
LargeRotationStudy large_rotation_study(int matrices, std::uint64_t seed);

// 5.1: random keyframe pairs of cameras around a sphere mesh; per pair the mean excess length
// 100 (l - l0) / l0 (ERRATA item 3) of the vertices' screen paths (x, y after the divide) at
// t = 0, 0.1, .., 1. Vertices whose screen displacement l0 is under 0.01 or which pass behind
// the camera are left out (and counted).
struct PathPairRow {
  int pair;
  double rotation_deg;      // rotation between the two keys
  double excess_parameter;  // camera-parameter interpolation, percent
  double excess_matrix;     // matrix interpolation (eq. 7), percent
  int vertices_used;
};
struct PathStudy {
  std::vector<PathPairRow> pairs;
  int rejected_unsafe = 0;     // generated pairs rotating pi/2 or more (matrix lerp refuses them)
  int vertices_skipped = 0;
  double mean_parameter = 0, mean_matrix = 0, median_parameter = 0, median_matrix = 0;
};
PathStudy path_length_study(int pairs, std::uint64_t seed);

}  // namespace posefair
