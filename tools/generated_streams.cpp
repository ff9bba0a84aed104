#include "generated_streams.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <functional>
#include <memory>
#include <numbers>
#include <random>
#include <stdexcept>

#include "posefair/core/rests_and_turns.hpp"
#include "posefair/core/so3.hpp"
#include "posefair/core/synthetic_motion.hpp"

namespace posefair::tools {
namespace {

constexpr double kTwoPi = 2.0 * std::numbers::pi;
constexpr double kWarmUpSeconds = 1.0;
// Noise bursts: a second long, from kBurstFrom seconds into every kBurstEvery.
constexpr double kBurstEvery = 5.0, kBurstFrom = 3.0;

// FNV-1a of the name: the same seed on every platform (std::hash is not).
std::uint64_t seed_of(const std::string& name) {
  std::uint64_t h = 1469598103934665603ULL;
  for (unsigned char c : name) h = (h ^ c) * 1099511628211ULL;
  return h;
}

Vec3 random_axis(std::mt19937_64& rng) {
  std::normal_distribution<double> gauss(0.0, 1.0);
  Vec3 a(gauss(rng), gauss(rng), gauss(rng));
  return a.normalized();
}

// Three slow sines about the three axes.
std::function<Quat(double)> sway(std::mt19937_64& rng, double amplitude) {
  std::uniform_real_distribution<double> uni(0.0, 1.0);
  std::array<double, 3> f{}, phase{};
  for (int k = 0; k < 3; ++k) {
    f[static_cast<std::size_t>(k)] = 0.2 + 0.6 * uni(rng);
    phase[static_cast<std::size_t>(k)] = kTwoPi * uni(rng);
  }
  return [=](double t) {
    Vec3 v;
    for (int k = 0; k < 3; ++k) v(k) = amplitude * std::sin(kTwoPi * f[static_cast<std::size_t>(k)] * t + phase[static_cast<std::size_t>(k)]);
    return so3::from_rotation_vector(v);
  };
}

// Rests and quick turns (smoothstep in the angle).
std::function<Quat(double)> turns(std::mt19937_64& rng, double seconds) {
  const RestsAndTurnsSpec spec{.seconds = seconds,
                               .rest_min_s = 0.5,
                               .rest_max_s = 2.0,
                               .angle_min_deg = 30.0,
                               .angle_max_deg = 120.0,
                               .turn_min_s = 0.15,
                               .turn_max_s = 0.4};
  auto motion = std::make_shared<RestsAndTurns>(spec, rng);
  return [motion](double t) { return motion->at(t); };
}

// A handheld camera: body rate ω an Ornstein–Uhlenbeck process, integrated on a fine grid
// (dt) and looked up between its points.
std::function<Quat(double)> walk(std::mt19937_64& rng, double seconds, double dt) {
  constexpr double kRms = 0.5, kCorrelation = 0.3;
  std::normal_distribution<double> gauss(0.0, 1.0);
  const double a = std::exp(-dt / kCorrelation), b = kRms * std::sqrt(1.0 - a * a);
  const auto n = static_cast<std::size_t>(std::ceil(seconds / dt)) + 2;
  std::vector<double> time(n);
  std::vector<Quat> q(n);
  Vec3 w(gauss(rng), gauss(rng), gauss(rng));
  w *= kRms;
  Quat at = Quat::Identity();
  for (std::size_t i = 0; i < n; ++i) {
    time[i] = static_cast<double>(i) * dt;
    q[i] = at;
    at = (at * so3::from_rotation_vector(w * dt)).normalized();
    w = a * w + b * Vec3(gauss(rng), gauss(rng), gauss(rng));
  }
  auto track = std::make_shared<TruthTrack>(std::move(time), std::move(q), 1.5 * dt);
  return [track](double t) {
    std::size_t cursor = 0;
    Quat out = Quat::Identity();
    track->at(t, out, cursor);
    return out;
  };
}

// Removes runs of `shortest` to `longest` samples from the stream, starting at times a Poisson
// process of `per_s` a second puts them (from its first sample on), with a sample kept between two.
void drop_runs(QualitySequence& s, double per_s, int shortest, int longest, std::mt19937_64 rng) {
  std::exponential_distribution<double> until_next(per_s);
  std::uniform_int_distribution<int> run(shortest, longest);
  double next = s.input.time.front() + until_next(rng);
  int lost = 0;
  bool kept_one = true;  // a sample kept since the last run (two runs back to back are one)
  std::size_t kept = 0;  // the samples kept so far, compacted to the front (the truth is untouched)
  for (std::size_t i = 0; i < s.input.size(); ++i) {
    if (lost == 0 && kept_one && s.input.time[i] >= next) {
      lost = run(rng);
      next = s.input.time[i] + until_next(rng);
    }
    if (lost > 0) {
      --lost;
      kept_one = false;
      continue;
    }
    kept_one = true;
    s.input.time[kept] = s.input.time[i];
    s.input.orientation[kept] = s.input.orientation[i];
    s.use[kept] = s.use[i];
    ++kept;
  }
  s.input.time.resize(kept);
  s.input.orientation.resize(kept);
  s.use.resize(kept);
}

}  // namespace

std::string GeneratedStreamSpec::name() const {
  char b[128];
  if (source_hz > 0.0)
    std::snprintf(b, sizeof b, "%s-%gHz-noise%g-from%gHz-%s", motion.c_str(), rate_hz, noise, source_hz, resampling.c_str());
  else
    std::snprintf(b, sizeof b, "%s-%gHz-noise%g", motion.c_str(), rate_hz, noise);
  return std::string(b) + (dropouts_per_s > 0.0 ? "-dropouts" : "") + (lost_per_s > 0.0 ? "-lost" : "") +
         (burst_factor > 0.0 ? "-bursts" : "");
}

std::vector<GeneratedStreamSpec> generated_stream_specs(bool quick) {
  std::vector<GeneratedStreamSpec> out;
  if (quick) {
    for (const char* motion : {"sway", "turns"})
      for (double rate : {30.0, 100.0}) out.push_back({motion, rate, 0.01, 5.0, 0.0, {}});
    return out;
  }
  for (const char* motion : {"still", "sway", "turns", "shake", "walk"})
    for (double rate : {10.0, 30.0, 60.0, 120.0, 250.0, 1000.0})
      for (double noise : {0.0002, 0.002, 0.01, 0.04}) out.push_back({motion, rate, noise, rate > 500.0 ? 10.0 : 20.0, 0.0, {}});
  for (const char* motion : {"still", "sway", "turns", "walk"})
    for (const char* resampling : {"hold", "linear"}) out.push_back({motion, 250.0, 0.01, 20.0, 60.0, resampling});
  for (const char* motion : {"still", "sway", "turns", "walk"})
    for (double noise : {0.002, 0.01}) out.push_back({motion, 120.0, noise, 20.0, 0.0, {}, 1.0});
  for (const char* motion : {"still", "sway", "turns", "walk"})
    for (double noise : {0.002, 0.01}) out.push_back({motion, 60.0, noise, 20.0, 0.0, {}, 0.0, 5.0});
  for (const char* motion : {"still", "sway", "turns", "walk"})
    for (double rate : {60.0, 250.0}) out.push_back({motion, rate, 0.002, 20.0, 0.0, {}, 0.0, 0.0, 5.0});
  return out;
}

QualitySequence generated_stream(const GeneratedStreamSpec& spec) {
  // With dropouts or lost packets, the same stream as without them, less the samples it loses;
  // with noise bursts, the same stream with its noise scaled in them.
  GeneratedStreamSpec whole = spec;
  whole.dropouts_per_s = 0.0;
  whole.lost_per_s = 0.0;
  whole.burst_factor = 0.0;
  std::mt19937_64 rng(seed_of(whole.name()));
  const double dense_rate = std::max(8.0 * spec.rate_hz, 2000.0);
  std::function<Quat(double)> truth_at;
  if (spec.motion == "still") {
    truth_at = [](double) { return Quat::Identity(); };
  } else if (spec.motion == "sway") {
    truth_at = sway(rng, 0.4);
  } else if (spec.motion == "turns") {
    truth_at = turns(rng, spec.seconds);
  } else if (spec.motion == "shake") {
    const auto slow = sway(rng, 0.4);
    std::uniform_real_distribution<double> uni(0.0, 1.0);
    const double f = 5.0 + 4.0 * uni(rng);
    const Vec3 axis = random_axis(rng);
    truth_at = [slow, f, axis](double t) { return (slow(t) * so3::from_rotation_vector(0.02 * std::sin(kTwoPi * f * t) * axis)).normalized(); };
  } else if (spec.motion == "walk") {
    truth_at = walk(rng, spec.seconds, 1.0 / dense_rate);
  } else {
    throw std::invalid_argument("no generated motion '" + spec.motion + "' (still, sway, turns, shake, walk)");
  }
  QualitySequence s;
  s.name = spec.name();
  s.rate_hz = spec.rate_hz;
  const auto n = static_cast<std::size_t>(spec.seconds * spec.rate_hz);
  // The measurements, at the source rate where the stream is resampled.
  const double measured_hz = spec.source_hz > 0.0 ? spec.source_hz : spec.rate_hz;
  if (spec.source_hz > 0.0 && spec.resampling != "hold" && spec.resampling != "linear")
    throw std::invalid_argument("no resampling '" + spec.resampling + "' (hold, linear)");
  std::vector<Quat> measured;
  for (std::size_t i = 0; static_cast<double>(i) / measured_hz <= spec.seconds + 1.0 / measured_hz; ++i) {
    const double t = static_cast<double>(i) / measured_hz;
    const bool in_burst = std::fmod(t, kBurstEvery) >= kBurstFrom && std::fmod(t, kBurstEvery) < kBurstFrom + 1.0;
    const Vec3 offset = random_offset(rng, spec.noise);
    measured.push_back((truth_at(t) * so3::exp(spec.burst_factor > 0.0 && in_burst ? spec.burst_factor * offset : offset)).normalized());
  }
  for (std::size_t i = 0; i < n; ++i) {
    const double t = static_cast<double>(i) / spec.rate_hz;
    s.input.time.push_back(t);
    if (spec.source_hz <= 0.0) {
      s.input.orientation.push_back(measured[i]);
      continue;
    }
    // The source sample at or before t (a hair's tolerance: t on a source time is that sample).
    const double at = t * spec.source_hz;
    const auto j = static_cast<std::size_t>(std::floor(at + 1e-9));
    const double f = std::max(0.0, at - static_cast<double>(j));
    s.input.orientation.push_back(spec.resampling == "hold" || f == 0.0 ? measured[j] : measured[j].slerp(f, measured[j + 1]).normalized());
  }
  std::vector<double> time;
  std::vector<Quat> orientation;
  const double last = s.input.time.back();
  for (std::size_t i = 0; static_cast<double>(i) / dense_rate <= last + 1e-12; ++i) {
    time.push_back(static_cast<double>(i) / dense_rate);
    orientation.push_back(truth_at(time.back()));
  }
  s.truth = TruthTrack(std::move(time), std::move(orientation), 1.5 / dense_rate);
  s.use.assign(n, 1);
  for (std::size_t i = 0; i < n && static_cast<double>(i) < kWarmUpSeconds * spec.rate_hz; ++i) s.use[i] = 0;
  if (spec.dropouts_per_s > 0.0) drop_runs(s, spec.dropouts_per_s, 4, 12, std::mt19937_64(seed_of(spec.name()) + 1));
  if (spec.lost_per_s > 0.0) drop_runs(s, spec.lost_per_s, 1, 2, std::mt19937_64(seed_of(spec.name()) + 1));
  return s;
}

}  // namespace posefair::tools
