#pragma once
// Cholesky factorisation of a symmetric positive-definite band matrix, and solves with
// 3-vector right-hand sides. The window solver's matrix I + μ DᵀD (+ κ on the emitted
// samples) has bandwidth m, so a solve costs O(n·m) instead of the O(n²) of a dense one.
// Eigen stores band matrices but has no band solver; this is the textbook algorithm, written
// here for that reason. Storage is fixed at construction: no allocation in solve().
#include <span>
#include <vector>

#include "posefair/core/so3.hpp"

namespace posefair {

class BandedCholesky {
 public:
  BandedCholesky() = default;
  // n×n matrix with `bandwidth` sub-diagonals. Entries are set with at(i, j), |i-j| ≤ bandwidth.
  BandedCholesky(int n, int bandwidth);

  int size() const { return n_; }
  // Largest size this object's storage holds (reshape() below it never allocates).
  int capacity() const { return b_ + 1 > 0 ? static_cast<int>(band_.size()) / (b_ + 1) : 0; }
  // Makes the matrix n×n (n ≤ capacity()) and all zero, keeping the storage: for systems
  // built again at run time without allocating.
  void reshape(int n);
  int bandwidth() const { return b_; }
  // The lower triangle of A before factor(); of L after it. Requires 0 ≤ i-j ≤ bandwidth.
  double& at(int i, int j) { return band_[static_cast<std::size_t>(i * (b_ + 1) + (i - j))]; }
  double at(int i, int j) const { return band_[static_cast<std::size_t>(i * (b_ + 1) + (i - j))]; }

  // Factors in place. Returns false (and leaves the object unusable) if A is not positive definite.
  bool factor();
  // Solves A x = rhs in place, for each of the three components at once.
  void solve(std::span<Vec3> rhs) const;

 private:
  int n_ = 0, b_ = 0;
  std::vector<double> band_;
};

// The symmetric matrix diag(d) + μ·(D^m)ᵀ D^m of size n, as a band matrix (bandwidth m), with
// D^m the forward difference operator of eq. 8 (n-m rows). Factored and ready to solve.
// Throws std::invalid_argument if the result is not positive definite (some d_i ≤ 0 and μ = 0).
BandedCholesky make_smoothing_system(int n, int m, double mu, std::span<const double> diagonal);

// The same system assembled and factored in a's storage (a.bandwidth() == m, n ≤ a.capacity()),
// without allocating. Returns false if it is not positive definite.
bool assemble_smoothing_system(BandedCholesky& a, int n, int m, double mu, std::span<const double> diagonal);

}  // namespace posefair
