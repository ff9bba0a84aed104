#pragma once
// Shared by the sample log and replay tests: a scratch folder per test, sample factories,
// bit-exact comparison.
#include <gtest/gtest.h>
#include <unistd.h>

#include <bit>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <random>
#include <string>
#include <vector>

#include "posefair/core/sample.hpp"

namespace posefair::formats::testing {

// A fresh folder under the system temp dir, named after the running test, removed afterwards.
class ScratchDir {
 public:
  ScratchDir() {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    std::string name = "posefair-replaylog-" + std::to_string(::getpid()) + "-" +
                       (info ? std::string(info->test_suite_name()) + "." + info->name() : "x");
    for (char& c : name) {
      if (c == '/') c = '_';
    }
    path_ = std::filesystem::temp_directory_path() / name;
    std::filesystem::remove_all(path_);
    std::filesystem::create_directories(path_);
  }
  ScratchDir(const ScratchDir&) = delete;
  ScratchDir& operator=(const ScratchDir&) = delete;
  ~ScratchDir() {
    std::error_code ec;
    std::filesystem::remove_all(path_, ec);
  }
  const std::filesystem::path& path() const { return path_; }
  std::filesystem::path operator/(const std::string& name) const { return path_ / name; }

 private:
  std::filesystem::path path_;
};

inline std::vector<unsigned char> slurp(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

inline void spit(const std::filesystem::path& p, const std::vector<unsigned char>& bytes) {
  std::ofstream out(p, std::ios::binary | std::ios::trunc);
  out.write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
}

inline std::uint64_t bits(double v) { return std::bit_cast<std::uint64_t>(v); }

// Every field equal bit for bit (NaN payloads and the sign of zero included).
inline ::testing::AssertionResult bit_identical(const Sample& a, const Sample& b) {
  const double av[] = {a.time, a.device_time, a.receive_time, a.orientation.w(), a.orientation.x(),
                       a.orientation.y(), a.orientation.z(), a.position.x(), a.position.y(), a.position.z(),
                       a.gyro.x(), a.gyro.y(), a.gyro.z(), a.accel.x(), a.accel.y(), a.accel.z(),
                       a.mag.x(), a.mag.y(), a.mag.z()};
  const double bv[] = {b.time, b.device_time, b.receive_time, b.orientation.w(), b.orientation.x(),
                       b.orientation.y(), b.orientation.z(), b.position.x(), b.position.y(), b.position.z(),
                       b.gyro.x(), b.gyro.y(), b.gyro.z(), b.accel.x(), b.accel.y(), b.accel.z(),
                       b.mag.x(), b.mag.y(), b.mag.z()};
  if (a.stream_id != b.stream_id) return ::testing::AssertionFailure() << "stream_id " << a.stream_id << " vs " << b.stream_id;
  if (a.sequence != b.sequence) return ::testing::AssertionFailure() << "sequence " << a.sequence << " vs " << b.sequence;
  if (a.flags != b.flags) return ::testing::AssertionFailure() << "flags " << a.flags << " vs " << b.flags;
  for (std::size_t i = 0; i < std::size(av); ++i) {
    if (bits(av[i]) != bits(bv[i])) {
      return ::testing::AssertionFailure() << "value " << i << ": " << av[i] << " vs " << bv[i];
    }
  }
  return ::testing::AssertionSuccess();
}

// `n` samples over `streams` streams (round robin), 100 Hz per stream, streams with odd ids
// have positions, some have device times.
inline std::vector<Sample> make_samples(std::size_t n, std::uint32_t streams = 3, std::uint64_t seed = 7) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> g(0.0, 1.0);
  std::vector<Sample> out(n);
  for (std::size_t i = 0; i < n; ++i) {
    Sample& s = out[i];
    s.stream_id = 10 + static_cast<std::uint32_t>(i % streams);
    s.sequence = 1000 * s.stream_id + i / streams;
    s.time = 100.0 + 0.01 * static_cast<double>(i / streams) + 0.001 * static_cast<double>(i % streams);
    s.receive_time = 5000.0 + s.time + 1e-4 * g(rng);
    Quat q(g(rng), g(rng), g(rng), g(rng));
    q.normalize();
    s.orientation = q;
    if (s.stream_id % 2 == 1) {
      s.flags |= kHasPosition;
      s.position = Vec3(g(rng), g(rng), g(rng));
    }
    if (i % 5 == 0) {
      s.flags |= kHasDeviceTime;
      s.device_time = 42.0 + s.time;
    }
  }
  return out;
}

}  // namespace posefair::formats::testing
