#include "bench_latency_command.hpp"

#include <CLI/CLI.hpp>

#include <sys/resource.h>
#include <stdlib.h>
#include <time.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cinttypes>
#include <cstdio>
#include <iterator>
#include <map>
#include <optional>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "posefair/core/error.hpp"
#include "posefair/daemon/config.hpp"
#include "posefair/daemon/pipeline.hpp"
#include "posefair/daemon/stage_latency.hpp"
#include "posefair/daemon/subscription_client.hpp"
#include "posefair/daemon/subscription_server.hpp"
#include "posefair/daemon/udp_socket.hpp"
#include "posefair/daemon/wire_protocol.hpp"

namespace posefair::tools {
namespace {

struct LatencyOptions {
  int streams = 16;
  double rate = 1000.0;
  double duration = 10.0;
  int window = 32;
  int lag = 0;
  std::string solver = "linear";
  int ring_capacity = 1024;
  int realtime_priority = 0;
  bool aligned = false;  // all streams sample at the same instant (one sync line)
  // Nobody reads the destination socket (the subscriber is on another machine): the bench then
  // measures the daemon alone, without a receiver thread competing for the same cores.
  bool no_receiver = false;
  // Also an output of every other registered encoding (opentrack, freed, vmc, vrchat, dds;
  // docs/outputs.md) to a socket nobody reads, to see what enabling them all costs.
  bool all_encodings = false;
  double client_rate = 0.0;  // > 0: max_rate_hz of those outputs
  // --control-flood RATE: a subscription port in process, flooded with RATE unverified SUBSCRIBE
  // datagrams a second (every one processed: no rate limit), while one client subscribes.
  double control_flood = -1.0;  // < 0: no subscription port
  int destinations = 1;  // of the output: the receiver, and sockets nobody reads
  // --candidate (repeatable) and --repeat: configurations measured side by side, interleaved.
  std::vector<std::string> candidates;
  int repeat = 1;
};

// The subscription port's side of the bench: the server, the flood and one real subscriber.
struct ControlFlood {
  std::unique_ptr<daemon::SubscriptionServer> server;
  std::thread flood, client;
  std::atomic<bool> stop{false};
  std::atomic<std::uint64_t> sent{0};
  std::atomic<double> first_pose_ms{-1.0};
  double seconds = 0.0, server_cpu = 0.0;

  explicit ControlFlood(double rate, double duration, const std::vector<std::uint32_t>& streams) {
    daemon::SubscriptionSettings s;
    s.listen = *daemon::Endpoint::parse("127.0.0.1:0");
    s.rate_per_source = 1e9;
    s.burst_per_source = 1e9;
    server = std::make_unique<daemon::SubscriptionServer>(s);
    server->handler().set_streams(streams);
    server->start();
    const daemon::Endpoint port = server->local_endpoint();
    if (rate > 0)
      flood = std::thread([this, rate, port] {
        daemon::UdpSocket socket = daemon::UdpSocket::bind(*daemon::Endpoint::parse("127.0.0.1:0"));
        daemon::SubscriptionRequest r;
        r.encoding = "binary";
        r.lease_ms = 30000;
        const auto t0 = std::chrono::steady_clock::now();
        for (std::uint64_t i = 0; !stop.load(std::memory_order_relaxed); ++i) {
          r.request_id = static_cast<std::uint32_t>(i);
          socket.send_to(daemon::encode_request(r), port);
          sent.fetch_add(1, std::memory_order_relaxed);
          if (i % 100 == 99) std::this_thread::sleep_until(t0 + std::chrono::duration<double>(static_cast<double>(i + 1) / rate));
        }
        seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
      });
    // One subscriber, a second in: from its first SUBSCRIBE to its first pose.
    client = std::thread([this, port, duration] {
      std::this_thread::sleep_for(std::chrono::milliseconds(std::min(1000, static_cast<int>(duration * 250))));
      daemon::UdpSocket socket = daemon::UdpSocket::bind(*daemon::Endpoint::parse("127.0.0.1:0"));
      daemon::SubscriptionRequest r;
      r.encoding = "binary";
      r.lease_ms = 30000;
      daemon::SubscriptionClient c(port, r, std::nullopt, 1);
      std::vector<std::uint8_t> buf(daemon::kMaxDatagramSize + 1);
      const auto t0 = std::chrono::steady_clock::now();
      while (!stop.load(std::memory_order_relaxed)) {
        if (auto request = c.due(std::chrono::steady_clock::now())) socket.send_to(*request, port);
        const auto d = socket.receive(buf, std::chrono::milliseconds(5));
        if (!d) continue;
        const std::span<const std::uint8_t> bytes(buf.data(), d->size);
        if (c.on_reply(bytes, d->source, std::chrono::steady_clock::now())) continue;
        if (daemon::decode_datagram(bytes)) {
          first_pose_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
          return;
        }
      }
    });
  }
  void finish() {
    stop = true;
    if (flood.joinable()) flood.join();
    if (client.joinable()) client.join();
    server->stop();
  }
  void print() const {
    const daemon::SubscriptionCounters& c = server->handler().counters();
    const auto get = [](const std::atomic<std::uint64_t>& a) { return a.load(std::memory_order_relaxed); };
    const double in = static_cast<double>(get(c.unverified_bytes_in)), out = static_cast<double>(get(c.unverified_bytes_out));
    std::printf("control     flood %" PRIu64 " datagrams in %.2f s (%.0f/s); port processed %" PRIu64 " (%.0f/s), %" PRIu64
                " cookies; amplification %.3f\n",
                sent.load(), seconds, seconds > 0 ? static_cast<double>(sent.load()) / seconds : 0.0, get(c.datagrams),
                seconds > 0 ? static_cast<double>(get(c.datagrams)) / seconds : 0.0, get(c.cookies_sent), in > 0 ? out / in : 0.0);
    if (first_pose_ms.load() >= 0)
      std::printf("subscribe   first pose %.2f ms after the first SUBSCRIBE\n", first_pose_ms.load());
    else
      std::printf("subscribe   no pose reached the subscriber\n");
  }
};

// The extra [[output]] tables of --all-encodings: every registered encoding but the first (the
// binary one the receiver reads), with the per-stream keys the client encodings need.
std::string client_outputs(int streams, std::uint16_t sink_port, double max_rate_hz) {
  static constexpr const char* kBones[] = {"Hips", "Spine", "Chest", "UpperChest", "Neck", "Head", "LeftShoulder",
                                           "RightShoulder", "LeftUpperArm", "RightUpperArm", "LeftLowerArm",
                                           "RightLowerArm", "LeftHand", "RightHand", "LeftUpperLeg", "RightUpperLeg"};
  std::string toml;
  const std::string to = "destinations = [\"127.0.0.1:" + std::to_string(sink_port) + "\"]\n";
  for (const daemon::OutputEncoderEntry* e : daemon::output_encoder_entries().subspan(1)) {
    const std::string name(e->name);
    toml += "[[output]]\nencoding = \"" + name + "\"\n" + (e->own_transport ? "" : to);
    if (max_rate_hz > 0) toml += "max_rate_hz = " + std::to_string(max_rate_hz) + "\n";
    if (name == "vmc") {  // one bone per stream, at most as many as named here
      std::string ids, bones;
      for (int i = 0; i < std::min<int>(streams, std::size(kBones)); ++i) {
        ids += (i ? ", " : "") + std::to_string(i + 1);
        bones += std::string(i ? ", " : "") + "\"" + kBones[i] + "\"";
      }
      toml += "streams = [" + ids + "]\nbones = [" + bones + "]\n";
    } else if (name == "vrchat") {  // trackers 1 to 8
      std::string ids;
      for (int i = 0; i < std::min(streams, 8); ++i) ids += (i ? ", " : "") + std::to_string(i + 1);
      toml += "streams = [" + ids + "]\n";
    }
  }
  return toml;
}

double seconds(const timeval& t) { return static_cast<double>(t.tv_sec) + 1e-6 * static_cast<double>(t.tv_usec); }

double process_cpu_seconds() {
  rusage ru{};
  ::getrusage(RUSAGE_SELF, &ru);
  return seconds(ru.ru_utime) + seconds(ru.ru_stime);
}

double thread_cpu_seconds() {
  timespec ts{};
  ::clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

void merge(daemon::HistogramSnapshot& into, const daemon::HistogramSnapshot& s) {
  if (s.count == 0) return;
  into.min = into.count == 0 ? s.min : std::min(into.min, s.min);
  into.max = std::max(into.max, s.max);
  into.count += s.count;
  into.sum += s.sum;
  into.mean = static_cast<double>(into.sum) / static_cast<double>(into.count);
  for (std::size_t i = 0; i < into.buckets.size(); ++i) into.buckets[i] += s.buckets[i];
}

// One configuration of the pipeline to measure (--candidate "publish_on=engine spin_us=50"):
// [daemon] keys (docs/config.md), how many streams busy-poll, and the outputs' sendmmsg.
struct Candidate {
  std::string name = "default";  // as given
  std::string daemon_keys;       // TOML lines for [daemon]
  int busy_poll = 0;             // the first N streams get busy_poll = true
  std::string sendmmsg;          // "true"/"false", empty: the default
};

// Space-separated key=value pairs; the values are checked by the config parser, as posefaird would.
std::optional<Candidate> parse_candidate(const std::string& text) {
  Candidate c;
  if (!text.empty()) c.name = text;
  std::istringstream in(text);
  for (std::string pair; in >> pair;) {
    const std::size_t eq = pair.find('=');
    if (pair == "default") continue;
    if (eq == std::string::npos) return std::nullopt;
    const std::string key = pair.substr(0, eq), value = pair.substr(eq + 1);
    if (key == "fair_on" || key == "publish_on" || key == "wake") {
      c.daemon_keys += key + " = \"" + value + "\"\n";
    } else if (key == "spin_us" || key == "realtime_priority") {
      c.daemon_keys += key + " = " + value + "\n";
    } else if (key == "cpu_affinity") {  // cpu_affinity=1 or cpu_affinity=0:1
      std::string list = value;
      std::replace(list.begin(), list.end(), ':', ',');
      c.daemon_keys += "cpu_affinity = [" + list + "]\n";
    } else if (key == "busy_poll") {
      try {
        c.busy_poll = std::stoi(value);
      } catch (const std::exception&) {
        return std::nullopt;
      }
    } else if (key == "sendmmsg") {
      c.sendmmsg = value;
    } else {
      return std::nullopt;
    }
  }
  return c;
}

struct RunResult {
  daemon::HistogramSnapshot all;
  daemon::StageLatencySnapshot stages;
  std::uint64_t received = 0, emitted = 0, ring_dropped = 0, publish_dropped = 0, rejected = 0, out_of_order = 0,
                raw_unfused = 0, published = 0, failures = 0, worst_p99 = 0, datagrams = 0, lost = 0;
  double cpu = 0.0, wall = 0.0;
  std::int64_t unaccounted() const {
    return static_cast<std::int64_t>(received) -
           static_cast<std::int64_t>(emitted + ring_dropped + rejected + out_of_order + raw_unfused);
  }
};

double load_average() {
  double load[1] = {0.0};
  return ::getloadavg(load, 1) == 1 ? load[0] : -1.0;
}

double us(std::uint64_t ns) { return static_cast<double>(ns) / 1000.0; }

void print_stages(const daemon::StageLatencySnapshot& st) {
  const std::pair<const char*, const daemon::HistogramSnapshot*> stages[] = {
      {"ring wait", &st.ring_wait}, {"engine", &st.engine}, {"hand-off", &st.hand_off}, {"encode", &st.encode}, {"send", &st.send}};
  for (const auto& [name, h] : stages) {
    if (h->count == 0) {
      std::printf("stage us    %-9s none (no such hop)\n", name);
      continue;
    }
    std::printf("stage us    %-9s p50 %.1f  p90 %.1f  p99 %.1f  p99.9 %.1f  max %.1f  (%" PRIu64 ")\n", name,
                us(h->percentile(50)), us(h->percentile(90)), us(h->percentile(99)), us(h->percentile(99.9)), us(h->max),
                h->count);
  }
}

// One run of the pipeline with candidate c; prints its lines when `verbose`.
std::optional<RunResult> run_once(const LatencyOptions& o, const Candidate& c, bool verbose) {
  // The receiver: a loopback socket drained by its own thread, counting what arrives and the
  // gaps in each stream's sequence numbers.
  daemon::ReceiveOptions ro;
  ro.receive_buffer_bytes = 8 << 20;
  daemon::UdpSocket socket = daemon::UdpSocket::bind(*daemon::Endpoint::parse("127.0.0.1:0"), ro);
  const std::uint16_t port = socket.local_endpoint().port();

  std::string toml = "[logging]\nlevel = \"warn\"\n[daemon]\nrealtime_priority = " + std::to_string(o.realtime_priority) + "\n";
  if (c.daemon_keys.find("realtime_priority") != std::string::npos) toml = "[logging]\nlevel = \"warn\"\n[daemon]\n";
  toml += c.daemon_keys;
  toml += "[engine]\nwindow = " + std::to_string(o.window) + "\nlag = " + std::to_string(o.lag) + "\nsolver = \"" +
          o.solver + "\"\ncutoff_hz = 20.0\nepsilon_r = 0.05\n";
  for (int i = 0; i < o.streams; ++i) {
    toml += "[[stream]]\nid = " + std::to_string(i + 1) + "\nname = \"s" + std::to_string(i + 1) +
            "\"\nring_capacity = " + std::to_string(o.ring_capacity) + (i < c.busy_poll ? "\nbusy_poll = true" : "") +
            "\n[stream.driver]\ntype = \"synthetic\"\nrate_hz = " + std::to_string(o.rate) +
            "\nduration = " + std::to_string(o.duration) + "\nseed = " + std::to_string(i + 1) +
            "\nphase = " + std::to_string(o.aligned ? 0.0 : static_cast<double>(i) / o.streams) + "\n";
  }
  // --destinations N: the receiver, then N - 1 sockets nobody reads (a full one drops silently).
  std::vector<daemon::UdpSocket> extra;
  std::string destinations = "\"127.0.0.1:" + std::to_string(port) + "\"";
  for (int i = 1; i < o.destinations; ++i) {
    extra.push_back(daemon::UdpSocket::bind(*daemon::Endpoint::parse("127.0.0.1:0")));
    destinations += ", \"127.0.0.1:" + std::to_string(extra.back().local_endpoint().port()) + "\"";
  }
  toml += "[[output]]\ndestinations = [" + destinations + "]\n";
  if (!c.sendmmsg.empty()) toml += "sendmmsg = " + c.sendmmsg + "\n";
  daemon::UdpSocket sink = daemon::UdpSocket::bind(*daemon::Endpoint::parse("127.0.0.1:0"));  // read by nobody
  if (o.all_encodings) toml += client_outputs(o.streams, sink.local_endpoint().port(), o.client_rate);
  daemon::DaemonConfig config;
  try {
    config = daemon::parse_config(toml, "bench-latency.toml");
  } catch (const daemon::ConfigError& e) {
    std::fprintf(stderr, "posefair bench latency: candidate '%s': %s\n", c.name.c_str(), e.what());
    return std::nullopt;
  }

  RunResult r;
  std::atomic<bool> stop{false};
  std::atomic<std::uint64_t> datagrams{0}, lost{0};
  double receiver_cpu = 0.0;
  std::thread receiver([&] {
    if (o.no_receiver) return;
    std::vector<std::uint8_t> buffer(daemon::kMaxDatagramSize + 1);
    std::map<std::uint32_t, std::uint64_t> next;
    while (!stop.load(std::memory_order_acquire)) {
      const auto d = socket.receive(buffer, std::chrono::milliseconds(50));
      if (!d) continue;
      const auto m = daemon::decode_datagram(std::span<const std::uint8_t>(buffer.data(), d->size));
      if (!m) continue;
      datagrams.fetch_add(1, std::memory_order_relaxed);
      auto [it, fresh] = next.try_emplace(m.message.stream, 0);
      if (m.message.sequence > it->second) lost.fetch_add(m.message.sequence - it->second, std::memory_order_relaxed);
      it->second = m.message.sequence + 1;
    }
    receiver_cpu = thread_cpu_seconds();
  });
  if (o.no_receiver) receiver.join();

  if (verbose)
    std::printf("bench latency: %d streams at %.0f Hz for %.1f s, window %d, lag %d, %s solver, ring %d, %s%s, %d destination%s, "
                "candidate '%s', load average %.2f\n",
                o.streams, o.rate, o.duration, o.window, o.lag, o.solver.c_str(), o.ring_capacity,
                o.aligned ? "phases aligned" : "phases spread", o.all_encodings ? ", every encoding" : "", o.destinations,
                o.destinations == 1 ? "" : "s", c.name.c_str(), load_average());
  std::unique_ptr<ControlFlood> control;
  if (o.control_flood >= 0) {
    std::vector<std::uint32_t> ids;
    for (const auto& s : config.streams) ids.push_back(s.id);
    control = std::make_unique<ControlFlood>(o.control_flood, o.duration, ids);
  }
  const double cpu0 = process_cpu_seconds();
  const auto t0 = std::chrono::steady_clock::now();
  {
    daemon::Pipeline pipeline(config, 0x62656e63, {}, false, {}, control ? control->server->table() : nullptr);
    for (const std::string& w : pipeline.start()) std::fprintf(stderr, "warning: %s\n", w.c_str());
    while (!pipeline.sources_ended()) std::this_thread::sleep_for(std::chrono::milliseconds(20));
    if (control) control->finish();
    pipeline.stop();
    r.wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    std::this_thread::sleep_for(std::chrono::milliseconds(300));  // the last datagrams
    stop.store(true, std::memory_order_release);
    if (receiver.joinable()) receiver.join();
    r.cpu = process_cpu_seconds() - cpu0 - receiver_cpu;
    r.datagrams = datagrams.load();
    r.lost = lost.load();
    r.stages = pipeline.stage_latency();
    for (const daemon::StreamStats& s : pipeline.stats()) {
      merge(r.all, s.latency);
      r.received += s.received;
      r.emitted += s.emitted;
      r.ring_dropped += s.ring_dropped;
      r.publish_dropped += s.publish_dropped;
      r.rejected += s.rejected;
      r.out_of_order += s.out_of_order;
      r.raw_unfused += s.raw_unfused;
      r.published += s.published;
      r.failures += s.send_failures;
      r.worst_p99 = std::max(r.worst_p99, s.latency.percentile(99));
    }
  }
  if (!verbose) return r;
  std::printf("samples     %" PRIu64 " handed over (%.0f/s), %" PRIu64 " emitted, %" PRIu64 " published\n", r.received,
              static_cast<double>(r.received) / r.wall, r.emitted, r.published);
  std::printf("latency us  p50 %.1f  p90 %.1f  p99 %.1f  p99.9 %.1f  max %.1f  (worst stream p99 %.1f)\n",
              us(r.all.percentile(50)), us(r.all.percentile(90)), us(r.all.percentile(99)), us(r.all.percentile(99.9)),
              us(r.all.max), us(r.worst_p99));
  print_stages(r.stages);
  std::printf("drops       ring %" PRIu64 ", publish %" PRIu64 ", rejected %" PRIu64 ", out-of-order %" PRIu64
              ", send failures %" PRIu64 "; unaccounted %" PRId64 "\n",
              r.ring_dropped, r.publish_dropped, r.rejected, r.out_of_order, r.failures, r.unaccounted());
  if (o.no_receiver)
    std::printf("receiver    none (datagrams sent to a socket nobody reads)\n");
  else
    std::printf("receiver    %" PRIu64 " datagrams, %" PRIu64 " lost (sequence gaps)\n", r.datagrams, r.lost);
  std::printf("cpu         %.3f s in %.2f s wall: %.1f%% of one core, %.2f%% per stream at %.0f Hz (receiver excluded%s)\n",
              r.cpu, r.wall, 100.0 * r.cpu / r.wall, 100.0 * r.cpu / r.wall / o.streams, o.rate,
              control ? ", flood included" : "");
  if (control) control->print();
  return r;
}

// --candidate ... --repeat N: every candidate N times, interleaved (A B A B ...), so that the
// machine's changing load spreads over all of them; then a side-by-side table of the pooled
// histograms (every run's poses together) with the range of the runs' p99.
int compare_candidates(const LatencyOptions& o, const std::vector<Candidate>& candidates) {
  struct Pooled {
    RunResult sum;
    std::vector<double> p99s;
    std::int64_t unaccounted = 0;
  };
  std::vector<Pooled> pooled(candidates.size());
  const double load_before = load_average();
  for (int run = 0; run < o.repeat; ++run) {
    for (std::size_t i = 0; i < candidates.size(); ++i) {
      const std::optional<RunResult> r = run_once(o, candidates[i], false);
      if (!r) return exit_code(ErrorKind::Usage);
      Pooled& p = pooled[i];
      merge(p.sum.all, r->all);
      merge(p.sum.stages.ring_wait, r->stages.ring_wait);
      merge(p.sum.stages.engine, r->stages.engine);
      merge(p.sum.stages.hand_off, r->stages.hand_off);
      merge(p.sum.stages.encode, r->stages.encode);
      merge(p.sum.stages.send, r->stages.send);
      p.sum.received += r->received;
      p.sum.lost += r->lost;
      p.sum.ring_dropped += r->ring_dropped;
      p.sum.publish_dropped += r->publish_dropped;
      p.sum.failures += r->failures;
      p.sum.cpu += r->cpu;
      p.sum.wall += r->wall;
      p.unaccounted += r->unaccounted();
      p.p99s.push_back(us(r->all.percentile(99)));
      std::printf("run %d/%d  %-40s p50 %7.1f  p99 %8.1f  p99.9 %8.1f us  cpu/stream %.2f%%  unaccounted %" PRId64 "  load %.2f\n",
                  run + 1, o.repeat, candidates[i].name.c_str(), us(r->all.percentile(50)), us(r->all.percentile(99)),
                  us(r->all.percentile(99.9)), 100.0 * r->cpu / r->wall / o.streams, r->unaccounted(), load_average());
      std::fflush(stdout);
    }
  }
  std::printf("\n%d streams at %.0f Hz, %.1f s a run, %d runs per candidate interleaved, %s, %d destination%s; "
              "load average %.2f before, %.2f after\n\n",
              o.streams, o.rate, o.duration, o.repeat, o.aligned ? "phases aligned" : "phases spread", o.destinations,
              o.destinations == 1 ? "" : "s", load_before, load_average());
  std::printf("| candidate | p50 µs | p99 µs | p99.9 µs | max µs | p99 of the runs µs | drops (ring, publish) | unaccounted | lost | CPU per stream |\n");
  std::printf("|---|---|---|---|---|---|---|---|---|---|\n");
  for (std::size_t i = 0; i < candidates.size(); ++i) {
    const Pooled& p = pooled[i];
    const auto [lo, hi] = std::minmax_element(p.p99s.begin(), p.p99s.end());
    std::printf("| `%s` | %.1f | %.1f | %.1f | %.0f | %.0f–%.0f | %" PRIu64 ", %" PRIu64 " | %" PRId64 " | %" PRIu64
                " | %.2f %% |\n",
                candidates[i].name.c_str(), us(p.sum.all.percentile(50)), us(p.sum.all.percentile(99)),
                us(p.sum.all.percentile(99.9)), us(p.sum.all.max), *lo, *hi, p.sum.ring_dropped, p.sum.publish_dropped,
                p.unaccounted, p.sum.lost, 100.0 * p.sum.cpu / p.sum.wall / o.streams);
  }
  std::printf("\nby stage, p99 µs (pooled):\n\n| candidate | ring wait | engine | hand-off | encode | send |\n|---|---|---|---|---|---|\n");
  for (std::size_t i = 0; i < candidates.size(); ++i) {
    const daemon::StageLatencySnapshot& st = pooled[i].sum.stages;
    const auto cell = [](const daemon::HistogramSnapshot& h) {
      return h.count == 0 ? std::string("–") : std::to_string(static_cast<int>(us(h.percentile(99)) + 0.5));
    };
    std::printf("| `%s` | %s | %s | %s | %s | %s |\n", candidates[i].name.c_str(), cell(st.ring_wait).c_str(),
                cell(st.engine).c_str(), cell(st.hand_off).c_str(), cell(st.encode).c_str(), cell(st.send).c_str());
  }
  return kExitOk;
}

int bench_latency(const LatencyOptions& o) {
  std::vector<Candidate> candidates;
  for (const std::string& text : o.candidates) {
    std::optional<Candidate> c = parse_candidate(text);
    if (!c) {
      std::fprintf(stderr, "posefair bench latency: --candidate '%s': expected space-separated key=value pairs of "
                   "fair_on, publish_on, spin_us, wake, realtime_priority, cpu_affinity, busy_poll, sendmmsg\n", text.c_str());
      return exit_code(ErrorKind::Usage);
    }
    candidates.push_back(std::move(*c));
  }
  if (candidates.size() > 1 || o.repeat > 1) {
    if (o.control_flood >= 0) {
      std::fprintf(stderr, "posefair bench latency: --control-flood runs one candidate once\n");
      return exit_code(ErrorKind::Usage);
    }
    if (candidates.empty()) candidates.emplace_back();
    return compare_candidates(o, candidates);
  }
  return run_once(o, candidates.empty() ? Candidate{} : candidates.front(), true) ? kExitOk : exit_code(ErrorKind::Usage);
}

}  // namespace

void add_bench_latency_command(CLI::App& bench, int& exit_code) {
  auto o = std::make_shared<LatencyOptions>();
  auto* cmd = bench.add_subcommand("latency", "posefaird's processing latency and CPU with N synthetic streams");
  cmd->add_option("--streams", o->streams, "number of streams")->capture_default_str()->check(CLI::Range(1, 256));
  cmd->add_option("--rate", o->rate, "samples per second per stream")->capture_default_str()->check(CLI::Range(1.0, 100000.0));
  cmd->add_option("--duration", o->duration, "seconds")->capture_default_str()->check(CLI::Range(0.1, 3600.0));
  cmd->add_option("--window", o->window, "window W")->capture_default_str();
  cmd->add_option("--lag", o->lag, "lag L")->capture_default_str();
  cmd->add_option("--solver", o->solver, "linear, gauss-newton or sweeps")
      ->capture_default_str()
      ->check(CLI::IsMember({"linear", "gauss-newton", "sweeps"}));
  cmd->add_option("--realtime-priority", o->realtime_priority, "SCHED_FIFO priority of engine and publisher (0: off)")
      ->capture_default_str()
      ->check(CLI::Range(0, 99));
  cmd->add_flag("--no-receiver", o->no_receiver, "send to a socket nobody reads (measure the daemon alone)");
  cmd->add_flag("--all-encodings", o->all_encodings,
                "also an output of every other encoding (opentrack, freed, vmc, vrchat, dds) to a socket nobody reads; "
                "with dds, run it in a network namespace of its own (docs/outputs.md)");
  cmd->add_option("--client-rate", o->client_rate, "with --all-encodings: their outputs' max_rate_hz (0: every pose)")
      ->capture_default_str()
      ->check(CLI::Range(0.0, 100000.0));
  cmd->add_flag("--aligned", o->aligned, "all streams sample at the same instant (default: phases spread over the period)");
  cmd->add_option("--control-flood", o->control_flood,
                  "also run a subscription port, flooded with this many unverified SUBSCRIBEs a second (0: none), while "
                  "one client subscribes")
      ->check(CLI::Range(0.0, 1e7));
  cmd->add_option("--ring", o->ring_capacity, "ring capacity per stream (power of two)")->capture_default_str();
  cmd->add_option("--destinations", o->destinations, "destinations of the output (the receiver, then sockets nobody reads)")
      ->capture_default_str()
      ->check(CLI::Range(1, 64));
  cmd->add_option("--candidate", o->candidates,
                  "a configuration to measure, as space-separated key=value pairs: fair_on=engine|driver, "
                  "publish_on=engine|publisher, "
                  "spin_us=N, wake=per-batch|per-sample, realtime_priority=N, cpu_affinity=1[:0...], busy_poll=STREAMS, "
                  "sendmmsg=true|false (\"default\": none); repeat it to compare several")
      ->take_all();
  cmd->add_option("--repeat", o->repeat, "runs of each candidate, interleaved (A B A B ...), then a side-by-side table")
      ->capture_default_str()
      ->check(CLI::Range(1, 100));
  cmd->callback([o, &exit_code] { exit_code = bench_latency(*o); });
}

}  // namespace posefair::tools
