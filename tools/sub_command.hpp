#pragma once
// `posefair sub`: subscribe to posefair poses over UDP (docs/protocol.md, "posefair sub").
namespace CLI {
class App;
}  // namespace CLI

#include <array>
#include <bitset>
#include <chrono>
#include <cstdint>
#include <map>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "posefair/daemon/wire_protocol.hpp"

namespace posefair::tools {

void add_sub_command(CLI::App& app, int& exit_code);

// Sequence accounting for one (session, stream), as docs/protocol.md "Receiver accounting"
// defines it. Numbers skipped over count as lost; one that arrives later than a higher one
// (and was not seen) is reordered and no longer lost; one seen before is a duplicate.
// Duplicates are recognised among the last kWindow sequence numbers below the highest.
class SequenceTracker {
 public:
  static constexpr std::uint64_t kWindow = 4096;
  enum class Verdict { kFirst, kNext, kAfterGap, kReordered, kDuplicate };

  Verdict observe(std::uint64_t sequence);

  std::uint64_t received() const { return received_; }  // every observed datagram, duplicates included
  std::uint64_t lost() const { return lost_; }
  std::uint64_t reordered() const { return reordered_; }
  std::uint64_t duplicates() const { return duplicates_; }
  std::uint64_t first() const { return first_; }
  std::uint64_t highest() const { return highest_; }

 private:
  bool seen(std::uint64_t s) const { return seen_[s % kWindow]; }
  void mark(std::uint64_t s) { seen_[s % kWindow] = true; }

  bool started_ = false;
  std::uint64_t first_ = 0, highest_ = 0;
  std::uint64_t received_ = 0, lost_ = 0, reordered_ = 0, duplicates_ = 0;
  std::bitset<kWindow> seen_;
};

// Latency (receive CLOCK_REALTIME − send time) summary: exact min and max, median and p99 from
// every sample up to kMaxSamples and a uniform reservoir sample beyond.
class LatencyStats {
 public:
  static constexpr std::size_t kMaxSamples = 200000;
  void add(double seconds);
  std::uint64_t count() const { return count_; }
  double min() const { return min_; }
  double max() const { return max_; }
  double quantile(double q) const;  // nearest rank; NaN without samples

 private:
  std::uint64_t count_ = 0;
  double min_ = 0, max_ = 0;
  std::vector<double> samples_;
  std::mt19937_64 rng_{0x5eed};
};

// Everything `posefair sub` counts.
struct SubscriberStats {
  std::map<std::pair<std::uint32_t, std::uint32_t>, SequenceTracker> streams;  // (session, stream)
  std::array<std::uint64_t, daemon::kDecodeErrorCount> malformed{};
  LatencyStats latency;

  SequenceTracker::Verdict observe(const daemon::PoseMessage& m, std::chrono::system_clock::time_point received_at);
  void reject(daemon::DecodeError e) { ++malformed[static_cast<std::size_t>(e)]; }

  std::uint64_t received() const;
  std::uint64_t lost() const;
  std::uint64_t reordered() const;
  std::uint64_t duplicates() const;
  std::uint64_t malformed_total() const;
  // "stats: received N, lost N, reordered N, duplicates N, malformed N (reason N, …),
  //  latency min A µs p50 B µs p99 C µs max D µs" (latency "n/a" without send times).
  std::string summary_line() const;
  // One line per (session, stream) for --stats.
  std::vector<std::string> stream_lines() const;
};

}  // namespace posefair::tools
