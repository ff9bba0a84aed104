#include "posefair/core/fairing_sweep.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <type_traits>

#include "posefair/core/quaternion_lanes.hpp"

namespace posefair {
namespace {

using lanes::Lane;
using lanes::QuatOf;
using lanes::VecOf;

// Raw views of the arrays one sweep reads and writes.
struct SweepData {
  const double* q[4];   // current iterate (w, x, y, z)
  double* next[4];      // candidate
  const double* q0[4];  // measurements
  const double* u[3];   // W¹ of the current iterate (m = 3)
  const double* p[3];
  double* p_next[3];
  const double* p0[3];
  double factor;     // the rotation step: λ_r, or ⅔λ_r for the fused m = 3 corrected slerps
  double lambda_t;
  double epsilon_t;
  double k_inside, k_outside;
};

// Per lane: 1 where a sample surely breaks eq. 20; 1 where its rotation is too close to the
// bound to judge by chords; the largest squared movement from the current iterate.
template <class T> struct Checks {
  T violation = lanes::splat<T>(0.0), uncertain = lanes::splat<T>(0.0), moved = lanes::splat<T>(0.0);
};

// P is const double* or double*: the arrays read from either side.
template <class T, class P> POSEFAIR_LANE_INLINE QuatOf<T> quat_at(P const (&c)[4], std::size_t i) {
  return {lanes::load<T>(c[0] + i), lanes::load<T>(c[1] + i), lanes::load<T>(c[2] + i), lanes::load<T>(c[3] + i)};
}
template <class T, class P> POSEFAIR_LANE_INLINE VecOf<T> vec_at(P const (&c)[3], std::size_t i) {
  return {lanes::load<T>(c[0] + i), lanes::load<T>(c[1] + i), lanes::load<T>(c[2] + i)};
}
template <class T> POSEFAIR_LANE_INLINE void store_quat(double* const (&c)[4], std::size_t i, const QuatOf<T>& q) {
  lanes::store(c[0] + i, q.w);
  lanes::store(c[1] + i, q.x);
  lanes::store(c[2] + i, q.y);
  lanes::store(c[3] + i, q.z);
}
template <class T> POSEFAIR_LANE_INLINE void store_vec(double* const (&c)[3], std::size_t i, const VecOf<T>& v) {
  lanes::store(c[0] + i, v.x);
  lanes::store(c[1] + i, v.y);
  lanes::store(c[2] + i, v.z);
}

// Eq. 20 and the movement for samples i … i+width-1 of the candidate.
template <class T, bool WithP> POSEFAIR_LANE_INLINE void judge(const SweepData& d, std::size_t i, Checks<T>& c) {
  using lanes::if_less;
  using lanes::splat;
  const T one = splat<T>(1.0), zero = splat<T>(0.0);
  const QuatOf<T> o = quat_at<T>(d.q0, i), q = quat_at<T>(d.q, i), qn = quat_at<T>(d.next, i);
  // dist(o, qn) = 2 atan2(|o − s qn|, |o + s qn|) < ε_r  ⟺  |o − s qn|² < tan²(ε_r/2) |o + s qn|².
  const T s = if_less(lanes::dot(o, qn), zero, splat<T>(-1.0), one);
  const T dw = o.w - s * qn.w, dx = o.x - s * qn.x, dy = o.y - s * qn.y, dz = o.z - s * qn.z;
  // |o + s qn|² = 4 − |o − s qn|² for unit o and qn, well inside the margin.
  const T a2 = dw * dw + dx * dx + dy * dy + dz * dz, b2 = splat<T>(4.0) - a2;
  const T out = if_less(T(d.k_outside * b2), a2, one, zero);
  const T in = if_less(a2, T(d.k_inside * b2), one, zero);
  c.uncertain = lanes::lane_max(c.uncertain, T(one - in - out));
  const T mw = qn.w - q.w, mx = qn.x - q.x, my = qn.y - q.y, mz = qn.z - q.z;
  T moved = mw * mw + mx * mx + my * my + mz * mz;
  T violation = out;
  if constexpr (WithP) {
    const VecOf<T> p0 = vec_at<T>(d.p0, i), p = vec_at<T>(d.p, i), pn = vec_at<T>(d.p_next, i);
    const T fx = pn.x - p0.x, fy = pn.y - p0.y, fz = pn.z - p0.z;
    // ‖p_i' − p_i⁽⁰⁾‖ < ε_t, with the norm as Eigen forms it.
    const T dev = lanes::lane_sqrt(T(fx * fx + fy * fy + fz * fz));
    violation = lanes::lane_max(violation, T(one - if_less(dev, splat<T>(d.epsilon_t), one, zero)));
    const T gx = pn.x - p.x, gy = pn.y - p.y, gz = pn.z - p.z;
    moved = lanes::lane_max(moved, T(gx * gx + gy * gy + gz * gz));
  }
  c.violation = lanes::lane_max(c.violation, violation);
  c.moved = lanes::lane_max(c.moved, moved);
}

// The damped fairing update of interior sample(s) i (eqs. 16–18, damped by eq. 17), then eq. 20.
template <class T, int M, bool Corrected, bool WithP> POSEFAIR_LANE_INLINE void update_interior(const SweepData& d, std::size_t i,
                                                                           Checks<T>& c) {
  using lanes::splat;
  const QuatOf<T> qi = quat_at<T>(d.q, i);
  QuatOf<T> r;  // q_i⁻¹ q_i*: the rotation from q_i toward its target
  if constexpr (M == 3) {
    // The printed target q_{i+1} exp(−½(u_{i+1} + u_{i−1})); the corrected one is ⅔ of the way
    // there, folded into d.factor.
    const VecOf<T> um = vec_at<T>(d.u, i - 1), up = vec_at<T>(d.u, i + 1);
    const T h = splat<T>(-0.5);
    const QuatOf<T> target =
        lanes::multiply(quat_at<T>(d.q, i + 1), lanes::exp(VecOf<T>{T(h * (up.x + um.x)), T(h * (up.y + um.y)),
                                                                   T(h * (up.z + um.z))}));
    r = lanes::conjugate_times(qi, target);
  } else if constexpr (Corrected) {
    // The geodesic midpoint of the neighbours, b taken on a's side.
    const QuatOf<T> a = quat_at<T>(d.q, i - 1), b = quat_at<T>(d.q, i + 1);
    const T s = lanes::if_less(lanes::dot(a, b), splat<T>(0.0), splat<T>(-1.0), splat<T>(1.0));
    const QuatOf<T> mid = lanes::normalized(QuatOf<T>{T(a.w + s * b.w), T(a.x + s * b.x), T(a.y + s * b.y),
                                                      T(a.z + s * b.z)});
    r = lanes::conjugate_times(qi, mid);
  } else {
    // Eq. 16 as printed: q_{i+1} q_i⁻¹ q_{i−1}.
    const QuatOf<T> qc{qi.w, T(-qi.x), T(-qi.y), T(-qi.z)};
    const QuatOf<T> target = lanes::multiply(lanes::multiply(quat_at<T>(d.q, i + 1), qc), quat_at<T>(d.q, i - 1));
    r = lanes::conjugate_times(qi, target);
  }
  // slerp(factor; q_i, q_i*) along the shorter arc, renormalised.
  const VecOf<T> l = lanes::log(r);
  const QuatOf<T> step = lanes::exp(VecOf<T>{T(d.factor * l.x), T(d.factor * l.y), T(d.factor * l.z)});
  store_quat(d.next, i, lanes::normalized(lanes::multiply(qi, step)));

  if constexpr (WithP) {
    const VecOf<T> pi = vec_at<T>(d.p, i), pm = vec_at<T>(d.p, i - 1), pp = vec_at<T>(d.p, i + 1);
    VecOf<T> t;
    if constexpr (M == 2) {
      t = {T(0.5 * (pm.x + pp.x)), T(0.5 * (pm.y + pp.y)), T(0.5 * (pm.z + pp.z))};
    } else {
      const VecOf<T> p2 = vec_at<T>(d.p, i + 2);
      t = {T(pp.x + (pm.x - p2.x) / 3.0), T(pp.y + (pm.y - p2.y) / 3.0), T(pp.z + (pm.z - p2.z) / 3.0)};
    }
    const double keep = 1.0 - d.lambda_t;
    store_vec(d.p_next, i, VecOf<T>{T(d.lambda_t * t.x + keep * pi.x), T(d.lambda_t * t.y + keep * pi.y),
                                    T(d.lambda_t * t.z + keep * pi.z)});
  }
  judge<T, WithP>(d, i, c);
}

// W¹ of the current iterate: u_j = log(q_j⁻¹ q_{j+1}), j = 0 … n−2.
void w1_pass(const SweepData& d, std::size_t n, double* ux, double* uy, double* uz) {
  constexpr std::size_t W = lanes::kLaneWidth;
  double* u[3] = {ux, uy, uz};
  std::size_t j = 0;
  for (; j + W <= n - 1; j += W)
    store_vec(u, j, lanes::log(lanes::conjugate_times(quat_at<Lane>(d.q, j), quat_at<Lane>(d.q, j + 1))));
  for (; j < n - 1; ++j)
    store_vec(u, j, lanes::log(lanes::conjugate_times(quat_at<double>(d.q, j), quat_at<double>(d.q, j + 1))));
}

// Interior samples 1 … last, kLaneWidth at a time, the remainder one at a time.
template <int M, bool Corrected, bool WithP>
void interior_pass(const SweepData& d, std::size_t last, Checks<Lane>& wide, Checks<double>& narrow) {
  constexpr std::size_t W = lanes::kLaneWidth;
  std::size_t i = 1;
  for (; i + W <= last + 1; i += W) update_interior<Lane, M, Corrected, WithP>(d, i, wide);
  for (; i <= last; ++i) update_interior<double, M, Corrected, WithP>(d, i, narrow);
}

template <class T> double reduce_max(const T& v) {
  if constexpr (std::is_same_v<T, double>) {
    return v;
  } else {
    return lanes::max_of(v);
  }
}

}  // namespace

void QuaternionArrays::assign(std::span<const Quat> q) {
  w.resize(q.size());
  x.resize(q.size());
  y.resize(q.size());
  z.resize(q.size());
  for (std::size_t i = 0; i < q.size(); ++i) {
    w[i] = q[i].w();
    x[i] = q[i].x();
    y[i] = q[i].y();
    z[i] = q[i].z();
  }
}

void PositionArrays::assign(std::span<const Vec3> p) {
  x.resize(p.size());
  y.resize(p.size());
  z.resize(p.size());
  for (std::size_t i = 0; i < p.size(); ++i) {
    x[i] = p[i].x();
    y[i] = p[i].y();
    z[i] = p[i].z();
  }
}

FairingSweep::FairingSweep(const FairingParams& params, std::span<const Quat> q0, std::span<const Vec3> p0)
    : params_(params), n_(q0.size()), with_p_(!p0.empty()) {
  q0_.assign(q0);
  q_ = q0_;
  next_ = q0_;
  if (with_p_) {
    p0_.assign(p0);
    p_ = p0_;
    p_next_ = p0_;
  }
  ux_.assign(n_ - 1, 0.0);
  uy_.assign(n_ - 1, 0.0);
  uz_.assign(n_ - 1, 0.0);
  // dist < ε_r ⟺ chord ratio² < tan²(ε_r/2) (dist ≤ π/2 always, so ε_r > 2 bounds nothing);
  // the lanes decide outside a relative margin of 1e-9, far wider than the rounding of either side.
  const double k = params.epsilon_r > 2.0 ? std::numeric_limits<double>::infinity()
                                          : std::pow(std::tan(0.5 * params.epsilon_r), 2);
  k_inside_ = k * (1.0 - 1e-9);
  k_outside_ = k * (1.0 + 1e-9);
}

void FairingSweep::accept() {
  std::swap(q_, next_);
  if (with_p_) std::swap(p_, p_next_);
}

void FairingSweep::current(std::vector<Quat>& q, std::vector<Vec3>& p) const {
  q.resize(n_);
  for (std::size_t i = 0; i < n_; ++i) q[i] = q_.at(i);
  p.resize(with_p_ ? n_ : 0);
  for (std::size_t i = 0; i < p.size(); ++i) p[i] = p_.at(i);
}

double FairingSweep::step() const {
  double step = 0.0;
  for (std::size_t i = 0; i < n_; ++i) {
    step = std::max(step, so3::dist(q_.at(i), next_.at(i)));
    if (with_p_) step = std::max(step, (p_next_.at(i) - p_.at(i)).norm());
  }
  return step;
}

bool FairingSweep::exact_bound_check() const {
  for (std::size_t i = 0; i < n_; ++i) {
    if (!(so3::dist(q0_.at(i), next_.at(i)) < params_.epsilon_r)) return false;
    if (with_p_ && !((p_next_.at(i) - p0_.at(i)).norm() < params_.epsilon_t)) return false;
  }
  return true;
}

// The end samples, by the operators' own rules (fairing_operators.cpp), then the damped slerp.
template <int M, bool Corrected> void FairingSweep::rotation_ends() {
  const std::size_t n = n_;
  auto q = [&](std::size_t i) { return q_.at(i); };
  auto damp = [&](std::size_t i, const Quat& target) {
    const Quat r = so3::slerp(params_.lambda_r, q(i), target).normalized();
    next_.w[i] = r.w();
    next_.x[i] = r.x();
    next_.y[i] = r.y();
    next_.z[i] = r.z();
  };
  if constexpr (M == 2) {
    damp(0, q(1) * so3::exp(-so3::log(q(1).conjugate() * q(2))));
    damp(n - 1, q(n - 2) * so3::exp(so3::log(q(n - 3).conjugate() * q(n - 2))));
  } else {
    auto u = [&](std::size_t j) { return Vec3(ux_[j], uy_[j], uz_[j]); };
    damp(0, q(1) * so3::exp(u(2) - 2.0 * u(1)));
    const Quat printed = q(n - 3) * so3::exp(0.5 * (u(n - 2) + u(n - 4)));
    damp(n - 2, Corrected ? so3::slerp(2.0 / 3.0, q(n - 2), printed) : printed);
    damp(n - 1, q(n - 2) * so3::exp(2.0 * u(n - 3) - u(n - 4)));
  }
}

void FairingSweep::position_ends() {
  const std::size_t n = n_;
  auto p = [&](std::size_t i) { return p_.at(i); };
  auto damp = [&](std::size_t i, const Vec3& t) {
    const Vec3 r = params_.lambda_t * t + (1.0 - params_.lambda_t) * p(i);
    p_next_.x[i] = r.x();
    p_next_.y[i] = r.y();
    p_next_.z[i] = r.z();
  };
  if (params_.order == 2) {
    damp(0, 2.0 * p(1) - p(2));
    damp(n - 1, 2.0 * p(n - 2) - p(n - 3));
  } else {
    damp(0, p(3) - 3.0 * p(2) + 3.0 * p(1));
    damp(n - 2, p(n - 3) + (p(n - 1) - p(n - 4)) / 3.0);
    damp(n - 1, p(n - 4) - 3.0 * p(n - 3) + 3.0 * p(n - 2));
  }
}

template <int M, bool Corrected, bool WithP> SweepOutcome FairingSweep::sweep_as() {
  const std::size_t n = n_;
  SweepData d{};
  d.q[0] = q_.w.data(), d.q[1] = q_.x.data(), d.q[2] = q_.y.data(), d.q[3] = q_.z.data();
  d.next[0] = next_.w.data(), d.next[1] = next_.x.data(), d.next[2] = next_.y.data(), d.next[3] = next_.z.data();
  d.q0[0] = q0_.w.data(), d.q0[1] = q0_.x.data(), d.q0[2] = q0_.y.data(), d.q0[3] = q0_.z.data();
  d.u[0] = ux_.data(), d.u[1] = uy_.data(), d.u[2] = uz_.data();
  if constexpr (WithP) {
    d.p[0] = p_.x.data(), d.p[1] = p_.y.data(), d.p[2] = p_.z.data();
    d.p_next[0] = p_next_.x.data(), d.p_next[1] = p_next_.y.data(), d.p_next[2] = p_next_.z.data();
    d.p0[0] = p0_.x.data(), d.p0[1] = p0_.y.data(), d.p0[2] = p0_.z.data();
  }
  d.factor = (M == 3 && Corrected) ? params_.lambda_r * (2.0 / 3.0) : params_.lambda_r;
  d.lambda_t = params_.lambda_t;
  d.epsilon_t = params_.epsilon_t;
  d.k_inside = k_inside_;
  d.k_outside = k_outside_;

  // W¹: u_j = log(q_j⁻¹ q_{j+1}), j = 0 … n−2 (m = 2 needs it only at its two ends).
  if constexpr (M == 3) w1_pass(d, n, ux_.data(), uy_.data(), uz_.data());

  // The interior, fused: targets, damping, renormalisation, eq. 20 and movement.
  const std::size_t last = M == 3 ? n - 3 : n - 2;  // interior samples are 1 … last
  Checks<Lane> wide;
  Checks<double> narrow;
  // m = 3's interior is the same code for both variants (d.factor differs): one instantiation.
  interior_pass<M, M == 2 && Corrected, WithP>(d, last, wide, narrow);

  rotation_ends<M, Corrected>();
  if constexpr (WithP) position_ends();
  judge<double, WithP>(d, 0, narrow);
  for (std::size_t e = last + 1; e < n; ++e) judge<double, WithP>(d, e, narrow);

  SweepOutcome o;
  const double violation = std::max(reduce_max(wide.violation), narrow.violation);
  const double uncertain = std::max(reduce_max(wide.uncertain), narrow.uncertain);
  o.within = violation == 0.0 && (uncertain == 0.0 || exact_bound_check());
  o.moved = std::max(reduce_max(wide.moved), narrow.moved) != 0.0;
  return o;
}

SweepOutcome FairingSweep::sweep() {
  const bool corrected = params_.variant == OperatorVariant::Corrected;
  if (params_.order == 2) {
    if (corrected) return with_p_ ? sweep_as<2, true, true>() : sweep_as<2, true, false>();
    return with_p_ ? sweep_as<2, false, true>() : sweep_as<2, false, false>();
  }
  if (corrected) return with_p_ ? sweep_as<3, true, true>() : sweep_as<3, true, false>();
  return with_p_ ? sweep_as<3, false, true>() : sweep_as<3, false, false>();
}

}  // namespace posefair
