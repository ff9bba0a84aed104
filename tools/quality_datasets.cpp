#include "quality_datasets.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <fstream>
#include <functional>
#include <limits>
#include <numbers>
#include <cstdint>
#include <cstdio>
#include <initializer_list>
#include <ostream>
#include <random>
#include <sstream>
#include <stdexcept>

#include "benchmark_data.hpp"
#include "posefair/core/quality_metrics.hpp"
#include "posefair/core/stream_rate.hpp"
#include "posefair/core/rests_and_turns.hpp"
#include "posefair/core/synthetic_motion.hpp"
#include "posefair/formats/pose_file.hpp"

namespace posefair::tools {
namespace {

// Smooth truth plus bounded noise (Section 6 style), 10 s (quick: 3 s, 1 s at 1 kHz). The truth is the same
// analytic curve sampled 8 times as densely (make_synthetic_motion draws the curve before the
// noise and evaluates it at i/(n−1) of the span), so it can be looked up between samples.
QualitySequence synthetic(double rate, double noise, std::uint64_t seed, bool quick) {
  constexpr int kDense = 8;
  SyntheticMotionSpec spec;
  spec.sample_rate_hz = rate;
  const double seconds = quick ? (rate > 500.0 ? 1.0 : 3.0) : 10.0;
  spec.samples = static_cast<std::size_t>(seconds * rate);
  spec.cycles = 0.5 * seconds;  // about 0.5 Hz motion
  spec.rotation_noise = noise;
  spec.with_position = false;
  spec.seed = seed;
  const auto m = make_synthetic_motion(spec);
  SyntheticMotionSpec dense = spec;
  dense.samples = kDense * (spec.samples - 1) + 1;
  dense.sample_rate_hz = kDense * rate;
  auto d = make_synthetic_motion(dense).truth;
  QualitySequence q;
  q.name = "seed" + std::to_string(seed);
  q.input = m.noisy;
  q.truth = TruthTrack(std::move(d.time), std::move(d.orientation), 1.5 / dense.sample_rate_hz);
  q.rate_hz = rate;
  q.use.assign(q.input.size(), 1);
  for (std::size_t i = 0; i < q.use.size() && static_cast<double>(i) < 0.5 * rate; ++i) q.use[i] = 0;  // warm-up
  return q;
}

// A tracker that rests and turns (a head in VR, a tool put down and picked up), 20 s: still for
// 1–3 s, then turned by 20–90° about a random axis in 0.3–0.8 s (smoothstep in the angle), and
// so on, with synthetic()'s noise. The truth is analytic, evaluated 8 times as densely.
QualitySequence rests_and_turns(double rate, double noise, std::uint64_t seed) {
  constexpr int kDense = 8;
  constexpr double kSeconds = 20.0;
  std::mt19937_64 rng(seed);
  RestsAndTurnsSpec spec;  // still 1–3 s, turned 20–90° in 0.3–0.8 s
  spec.seconds = kSeconds;
  const RestsAndTurns motion(spec, rng);
  const auto truth_at = [&](double t) { return motion.at(t); };
  QualitySequence s;
  s.name = "seed" + std::to_string(seed);
  s.rate_hz = rate;
  const auto n = static_cast<std::size_t>(kSeconds * rate);
  for (std::size_t i = 0; i < n; ++i) {
    const double t = static_cast<double>(i) / rate;
    s.input.time.push_back(t);
    s.input.orientation.push_back((truth_at(t) * so3::exp(random_offset(rng, noise))).normalized());
  }
  std::vector<double> time;
  std::vector<Quat> orientation;
  for (std::size_t i = 0; i < kDense * (n - 1) + 1; ++i) {
    time.push_back(static_cast<double>(i) / (kDense * rate));
    orientation.push_back(truth_at(time.back()));
  }
  s.truth = TruthTrack(std::move(time), std::move(orientation), 1.5 / (kDense * rate));
  s.use.assign(s.input.size(), 1);
  for (std::size_t i = 0; i < s.use.size() && static_cast<double>(i) < 0.5 * rate; ++i) s.use[i] = 0;  // warm-up
  return s;
}

// A synthetic data set: tuned on the training seeds' sequences, reported on the others'.
QualityDataset seeded_set(const std::string& name, const std::vector<std::uint64_t>& train_seeds,
                          const std::vector<std::uint64_t>& report_seeds, const std::function<QualitySequence(std::uint64_t)>& make) {
  QualityDataset d;
  d.name = name;
  d.kind = "synthetic";
  d.prediction = true;
  QualityFold fold;
  for (auto seeds : {&train_seeds, &report_seeds})
    for (std::uint64_t seed : *seeds) {
      (seeds == &train_seeds ? fold.train : fold.report).push_back(d.sequences.size());
      d.sequences.push_back(make(seed));
    }
  d.split = "tuned on seeds " + std::to_string(train_seeds.front()) + "–" + std::to_string(train_seeds.back()) +
            ", reported on seeds " + std::to_string(report_seeds.front()) + "–" + std::to_string(report_seeds.back());
  d.folds.push_back(fold);
  return d;
}

// The shift τ (s) by which a raw estimate trails its truth (estimate(t) ≈ truth(t − τ)), found on
// a 1 ms grid over ±100 ms and refined by a parabola: the two clocks' offset.
double clock_offset(const PoseSequence& est, const TruthTrack& truth) {
  const auto error = [&](double tau) {
    double sum = 0.0;
    std::size_t count = 0, cursor = 0;
    for (std::size_t i = 0; i < est.size(); ++i) {
      Quat g;
      if (!truth.at(est.time[i] - tau, g, cursor)) continue;
      const double e = so3::rotation_angle(est.orientation[i], g);
      sum += e * e;
      ++count;
    }
    return count ? sum / static_cast<double>(count) : std::numeric_limits<double>::infinity();
  };
  constexpr double kStep = 0.001;
  int best = -100;
  std::vector<double> e;
  for (int k = -100; k <= 100; ++k) {
    e.push_back(error(k * kStep));
    if (e.back() < e[static_cast<std::size_t>(best + 100)]) best = k;
  }
  const auto b = static_cast<std::size_t>(best + 100);
  double frac = 0.0;
  if (b > 0 && b + 1 < e.size()) {
    const double den = e[b - 1] - 2.0 * e[b] + e[b + 1];
    if (den > 0.0) frac = std::clamp(0.5 * (e[b - 1] - e[b + 1]) / den, -1.0, 1.0);
  }
  return (best + frac) * kStep;
}

// A SLAM estimate scored against motion capture. The world and body frames are fitted on the
// raw estimate against the truth at the estimate's times; the whole motion-capture track is
// brought into the estimate's frames, so it can be looked up at any time (not across its gaps),
// and shifted by the offset between the two clocks, measured on the raw estimate as BROAD's
// gyroscope shift is: the raw estimate has no lag by definition, a smoother's lag is its own.
// decimate = k keeps every k-th estimate (a 10 Hz stream from a 30 Hz one).
QualitySequence tum(const std::filesystem::path& est_path, const std::filesystem::path& gt_path, const std::string& name,
                    int decimate) {
  formats::ReadOptions ro;
  ro.format = formats::PoseFormat::Tum;
  const PoseSequence est = formats::read_pose_file(est_path, ro).poses();
  const PoseSequence gt = formats::read_pose_file(gt_path, ro).poses();
  // Motion capture with a repeated time stamp keeps the first.
  PoseSequence g;
  for (std::size_t i = 0; i < gt.size(); ++i)
    if (g.time.empty() || gt.time[i] > g.time.back()) {
      g.time.push_back(gt.time[i]);
      g.orientation.push_back(gt.orientation[i]);
    }
  constexpr double kMaxTruthGap = 0.05;  // s: no truth across a longer motion-capture dropout
  // The motion-capture track in the estimate's frames, its clock moved by `offset`.
  const auto track = [&](const FrameAlignment& a, double offset) {
    std::vector<double> t = g.time;
    for (double& x : t) x += offset;
    std::vector<Quat> o = g.orientation;
    for (Quat& x : o) x = (a.world.conjugate() * x * a.body.conjugate()).normalized();
    return TruthTrack(std::move(t), std::move(o), kMaxTruthGap);
  };
  QualitySequence q;
  q.name = name;
  const TruthTrack plain = track(FrameAlignment{}, 0.0);
  std::size_t cursor = 0;
  for (std::size_t i = 0; i < est.size(); ++i) {
    const double t = est.time[i];
    Quat tq;
    if (!plain.at(t, tq, cursor)) continue;
    if (!q.input.time.empty() && t <= q.input.time.back()) continue;
    q.input.time.push_back(t);
    q.input.orientation.push_back(est.orientation[i]);
  }
  // Frames at no offset, the offset at those frames, then both once more.
  double offset = 0.0;
  FrameAlignment a;
  for (int round = 0; round < 2; ++round) {
    const TruthTrack shifted = track(FrameAlignment{}, offset);
    std::vector<Quat> est_kept, truth_at;
    std::size_t c = 0;
    for (std::size_t i = 0; i < q.input.size(); ++i) {
      Quat tq;
      if (!shifted.at(q.input.time[i], tq, c)) continue;
      est_kept.push_back(q.input.orientation[i]);
      truth_at.push_back(tq);
    }
    a = align_frames(est_kept, truth_at, true);
    offset += clock_offset(q.input, track(a, offset));
  }
  q.truth_shift = offset;
  q.truth = track(a, offset);
  if (decimate > 1) {
    PoseSequence d;
    for (std::size_t i = 0; i < q.input.size(); i += static_cast<std::size_t>(decimate)) {
      d.time.push_back(q.input.time[i]);
      d.orientation.push_back(q.input.orientation[i]);
    }
    q.input = std::move(d);
  }
  q.rate_hz = sample_rate(q.input.time);
  q.use.assign(q.input.size(), 1);
  return q;
}

}  // namespace

QualitySequence broad_sequence(const std::filesystem::path& path, const std::string& name) {
  std::ifstream f(path);
  if (!f) throw std::runtime_error(path.string() + ": cannot open");
  std::string line;
  std::getline(f, line);
  if (line.rfind("t_s,gt_qw,gt_qx,gt_qy,gt_qz,gt_px_m,gt_py_m,gt_pz_m,gyr_x_rads,gyr_y_rads,gyr_z_rads", 0) != 0)
    throw std::runtime_error(path.string() + ":1: not a BROAD CSV header");
  const auto header_fields = static_cast<std::size_t>(std::count(line.begin(), line.end(), ',') + 1);
  const std::size_t movement_col = header_fields - 1;
  QualitySequence q;
  q.name = name;
  std::vector<double> v;
  std::size_t lineno = 1;
  while (std::getline(f, line)) {
    ++lineno;
    v.clear();
    std::size_t start = 0;
    while (start <= line.size()) {
      const std::size_t end = std::min(line.find(',', start), line.size());
      double x = std::nan("");
      const std::string_view field(line.data() + start, end - start);
      if (field != "nan") {
        const auto [p, ec] = std::from_chars(field.data(), field.data() + field.size(), x);
        if (ec != std::errc() || p != field.data() + field.size())
          throw std::runtime_error(path.string() + ":" + std::to_string(lineno) + ": bad number '" + std::string(field) + "'");
      }
      v.push_back(x);
      start = end + 1;
    }
    if (v.size() != header_fields) throw std::runtime_error(path.string() + ":" + std::to_string(lineno) + ": wrong field count");
    if (std::isnan(v[1])) continue;  // optical dropout
    q.input.time.push_back(v[0]);
    q.input.orientation.push_back(Quat(v[1], v[2], v[3], v[4]).normalized());
    q.gyro.emplace_back(v[8], v[9], v[10]);
    q.use.push_back(v[movement_col] > 0.5 ? 1 : 0);
  }
  q.rate_hz = sample_rate(q.input.time);
  // A rate interval is scored only if both ends are consecutive samples (no dropout between).
  for (std::size_t i = 0; i + 1 < q.input.size(); ++i)
    if (q.input.time[i + 1] - q.input.time[i] > 1.5 / q.rate_hz) q.use[i] = 0;
  // The shift between the raw optical rates and the gyroscope, a property of the recording
  // (clock offset and sensor latency), measured once; every output is scored against it.
  const auto rates = body_rates(q.input.orientation, q.input.time);
  q.gyro_shift = best_rate_shift(rates, q.input.time, q.gyro, q.use, -0.05, 0.05, 0.25 / q.rate_hz).shift;
  return q;
}

namespace {

// A BVH joint (frame 0, the T-pose, left out) with bounded random rotations added.
QualitySequence bvh(const std::filesystem::path& path, const std::string& joint, double noise, std::uint64_t seed,
                    const std::string& name) {
  formats::ReadOptions ro;
  ro.bvh_joint = joint;
  PoseSequence clean = formats::read_pose_file(path, ro).poses();
  QualitySequence q;
  q.name = name;
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> g(0.0, 1.0);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::vector<double> tt;
  std::vector<Quat> tq;
  for (std::size_t i = 1; i < clean.size(); ++i) {
    const Vec3 dir = Vec3(g(rng), g(rng), g(rng)).normalized();
    q.input.time.push_back(clean.time[i]);
    q.input.orientation.push_back((clean.orientation[i] * so3::exp(dir * noise * u(rng))).normalized());
    tt.push_back(clean.time[i]);
    tq.push_back(clean.orientation[i]);
  }
  q.rate_hz = sample_rate(q.input.time);
  q.truth = TruthTrack(std::move(tt), std::move(tq), 1.5 / q.rate_hz);
  q.use.assign(q.input.size(), 1);
  return q;
}

// Drops a data set whose folds lost their train or report side to missing files.
bool complete(const QualityDataset& d) {
  if (d.folds.empty()) return false;
  for (const QualityFold& f : d.folds)
    if (f.train.empty() || f.report.empty()) return false;
  return true;
}

}  // namespace

TruthTrack::TruthTrack(std::vector<double> time, std::vector<Quat> orientation, double max_gap)
    : time_(std::move(time)), q_(std::move(orientation)), max_gap_(max_gap) {
  so3::make_continuous(q_);
}

bool TruthTrack::at(double t, Quat& out, std::size_t& cursor) const {
  if (time_.empty() || !(t >= time_.front()) || !(t <= time_.back())) return false;
  if (cursor >= time_.size() || time_[cursor] > t) cursor = static_cast<std::size_t>(std::upper_bound(time_.begin(), time_.end(), t) - time_.begin()) - 1;
  while (cursor + 1 < time_.size() && time_[cursor + 1] <= t) ++cursor;
  if (cursor + 1 == time_.size()) {  // t is the last sample
    out = q_[cursor];
    return true;
  }
  const double span = time_[cursor + 1] - time_[cursor];
  if (span > max_gap_) return false;
  // Normalised linear interpolation (the track is hemisphere-continuous): it departs from
  // slerp by under θ³/200 for a step of θ rad (5e-6 rad at 0.1 rad per sample), far below the
  // error of joining the samples by any geodesic, and costs no trigonometry.
  const double f = (t - time_[cursor]) / span;
  out.coeffs() = ((1.0 - f) * q_[cursor].coeffs() + f * q_[cursor + 1].coeffs()).normalized();
  return true;
}

std::vector<QualityDataset> load_quality_datasets(const std::filesystem::path& dir, bool quick, std::ostream& notes) {
  std::vector<QualityDataset> sets;
  // Synthetic: train seeds distinct from report seeds.
  const std::vector<std::uint64_t> train_seeds = quick ? std::vector<std::uint64_t>{1} : std::vector<std::uint64_t>{1, 2, 3};
  const std::vector<std::uint64_t> report_seeds =
      quick ? std::vector<std::uint64_t>{2, 3} : std::vector<std::uint64_t>{4, 5, 6, 7, 8};
  // Quick (a test of the command, not of the numbers): one noise level.
  const std::vector<double> noises = quick ? std::vector<double>{0.01} : std::vector<double>{0.01, 0.05};
  for (double rate : {100.0, 1000.0})
    for (double noise : noises) {
      char name[64];
      std::snprintf(name, sizeof name, "synthetic-%gHz-noise%g", rate, noise);
      sets.push_back(seeded_set(name, train_seeds, report_seeds,
                                [&](std::uint64_t seed) { return synthetic(rate, noise, seed, quick); }));
    }
  if (quick) return sets;
  // Rests between turns: what a still tracker's noise becomes, and how the turns out of rest go.
  sets.push_back(seeded_set("synthetic-100Hz-rests-noise0.01", train_seeds, report_seeds,
                            [](std::uint64_t seed) { return rests_and_turns(100.0, 0.01, seed); }));
  // The recorded sets are read in full from dir. A sequence whose files are missing is skipped
  // with a line saying where it comes from; none of them there at all is an error.
  struct Broad {
    const char* file;
    bool train;
  };
  // Split by trial, each side with slow and fast, rotation and translation, undisturbed and
  // disturbed trials (trials.json's groups); the three trials added last (05, 29, 33) are all
  // reported, none tuned on.
  const Broad broad_trials[] = {
      {"02_undisturbed_slow_rotation_B", true},         {"07_undisturbed_fast_rotation_B", true},
      {"16_undisturbed_fast_translation_B", true},      {"27_disturbed_phone_vibration_B", true},
      {"05_undisturbed_slow_rotation_with_breaks_B", false}, {"21_undisturbed_fast_combined", false},
      {"25_disturbed_tapping_B", false},                {"29_disturbed_stationary_magnet_B", false},
      {"33_disturbed_attached_magnet_2cm", false}};
  struct Joint {
    const char* file;
    const char* joint;
    bool train;
  };
  // Split by joint and by file: tuned on CMU 01_01 (120 Hz), reported on other joints of
  // Boxing_Toes (100 Hz), no joint name on both sides.
  const Joint bvh_joints[] = {{"bvh/01_01.bvh", "LeftArm", true},          {"bvh/01_01.bvh", "RightUpLeg", true},
                              {"bvh/01_01.bvh", "LeftForeArm", true},      {"bvh/01_01.bvh", "Spine1", true},
                              {"bvh/Boxing_Toes.bvh", "RightShoulder", false}, {"bvh/Boxing_Toes.bvh", "LeftShoulder", false},
                              {"bvh/Boxing_Toes.bvh", "RightElbow", false},    {"bvh/Boxing_Toes.bvh", "LeftHip", false},
                              {"bvh/Boxing_Toes.bvh", "Neck", false}};
  const std::pair<const char*, const char*> tum_sets[] = {
      {"tum/freiburg1_xyz-rgbdslam.txt", "tum/freiburg1_xyz-groundtruth.txt"}, {"tum/fr2_desk_ORB.txt", "tum/fr2_desk_groundtruth.txt"}};
  const char* tum_names[] = {"fr1xyz-rgbdslam", "fr2desk-orb"};
  std::vector<std::string> all_files;
  for (const auto& [e, g] : tum_sets) all_files.insert(all_files.end(), {e, g});
  for (const Broad& b : broad_trials) all_files.push_back(std::string("broad/") + b.file + ".csv");
  all_files.insert(all_files.end(), {"bvh/01_01.bvh", "bvh/Boxing_Toes.bvh"});
  if (std::none_of(all_files.begin(), all_files.end(), [&](const std::string& f) { return std::filesystem::exists(dir / f); })) {
    std::string m = "no recorded data set found in " + dir.string() + ":";
    for (const std::string& f : all_files) m += "\n  " + missing_file_line(dir, f);
    throw std::runtime_error(m + "\n" + where_benchmark_data_is_looked_for());
  }
  const auto present = [&](const std::string& name, std::initializer_list<std::string> files) {
    for (const std::string& f : files)
      if (!std::filesystem::exists(dir / f)) {
        notes << "posefair bench quality: skipping " << name << ": " << missing_file_line(dir, f) << "\n";
        return false;
      }
    return true;
  };
  const auto add = [&](QualityDataset&& d) {
    if (complete(d))
      sets.push_back(std::move(d));
    else if (!d.sequences.empty())
      notes << "posefair bench quality: skipping " << d.name << ": a side of its tuning split has no sequence left\n";
  };
  // TUM, as recorded (~30 Hz) and decimated to 10 Hz: two folds, each set tuning the other.
  for (int decimate : {1, 3}) {
    QualityDataset d;
    d.name = decimate == 1 ? "tum-30Hz" : "tum-10Hz";
    d.kind = "tum";
    d.split = "two folds: tuned on one set, reported on the other";
    for (int k = 0; k < 2; ++k)
      if (present(std::string(d.name) + "-" + tum_names[k], {tum_sets[k].first, tum_sets[k].second}))
        d.sequences.push_back(tum(dir / tum_sets[k].first, dir / tum_sets[k].second, tum_names[k], decimate));
    if (d.sequences.size() == 2) d.folds = {QualityFold{{0}, {1}}, QualityFold{{1}, {0}}};
    add(std::move(d));
  }
  {
    QualityDataset d;
    d.name = "broad";
    d.kind = "broad";
    d.prediction = true;
    d.split = "tuned on trials 02, 07, 16, 27; reported on 05, 21, 25, 29, 33";
    QualityFold fold;
    for (const Broad& b : broad_trials) {
      const std::string f = std::string("broad/") + b.file + ".csv";
      if (!present(std::string("broad-") + b.file, {f})) continue;
      (b.train ? fold.train : fold.report).push_back(d.sequences.size());
      d.sequences.push_back(broad_sequence(dir / f, b.file));
    }
    d.folds.push_back(fold);
    add(std::move(d));
  }
  {
    QualityDataset d;
    d.name = "bvh-noise0.02";
    d.kind = "bvh";
    d.prediction = true;
    d.split = "tuned on 01_01 LeftArm, RightUpLeg, LeftForeArm, Spine1; reported on Boxing_Toes RightShoulder, "
              "LeftShoulder, RightElbow, LeftHip, Neck";
    QualityFold fold;
    std::uint64_t seed = 7;
    for (const Joint& j : bvh_joints) {
      const std::string file_name = std::filesystem::path(j.file).stem().string();
      if (!present("bvh-" + file_name + "-" + j.joint, {j.file})) continue;
      (j.train ? fold.train : fold.report).push_back(d.sequences.size());
      d.sequences.push_back(bvh(dir / j.file, j.joint, 0.02, seed++, file_name + "-" + j.joint));
    }
    d.folds.push_back(fold);
    add(std::move(d));
  }
  return sets;
}

}  // namespace posefair::tools
