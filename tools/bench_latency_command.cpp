#include "bench_latency_command.hpp"

#include <CLI/CLI.hpp>

#include <sys/resource.h>
#include <time.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cinttypes>
#include <cstdio>
#include <iterator>
#include <map>
#include <string>
#include <thread>
#include <vector>

#include "posefair/core/error.hpp"
#include "posefair/daemon/config.hpp"
#include "posefair/daemon/pipeline.hpp"
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

int bench_latency(const LatencyOptions& o) {
  // The receiver: a loopback socket drained by its own thread, counting what arrives and the
  // gaps in each stream's sequence numbers.
  daemon::ReceiveOptions ro;
  ro.receive_buffer_bytes = 8 << 20;
  daemon::UdpSocket socket = daemon::UdpSocket::bind(*daemon::Endpoint::parse("127.0.0.1:0"), ro);
  const std::uint16_t port = socket.local_endpoint().port();

  std::string toml = "[logging]\nlevel = \"warn\"\n[daemon]\nrealtime_priority = " + std::to_string(o.realtime_priority) + "\n";
  toml += "[engine]\nwindow = " + std::to_string(o.window) + "\nlag = " + std::to_string(o.lag) + "\nsolver = \"" +
          o.solver + "\"\ncutoff_hz = 20.0\nepsilon_r = 0.05\n";
  for (int i = 0; i < o.streams; ++i) {
    toml += "[[stream]]\nid = " + std::to_string(i + 1) + "\nname = \"s" + std::to_string(i + 1) +
            "\"\nring_capacity = " + std::to_string(o.ring_capacity) + "\n[stream.driver]\ntype = \"synthetic\"\nrate_hz = " +
            std::to_string(o.rate) + "\nduration = " + std::to_string(o.duration) + "\nseed = " + std::to_string(i + 1) +
            "\nphase = " + std::to_string(o.aligned ? 0.0 : static_cast<double>(i) / o.streams) + "\n";
  }
  toml += "[[output]]\ndestinations = [\"127.0.0.1:" + std::to_string(port) + "\"]\n";
  daemon::UdpSocket sink = daemon::UdpSocket::bind(*daemon::Endpoint::parse("127.0.0.1:0"));  // read by nobody
  if (o.all_encodings) toml += client_outputs(o.streams, sink.local_endpoint().port(), o.client_rate);
  daemon::DaemonConfig config;
  try {
    config = daemon::parse_config(toml, "bench-latency.toml");
  } catch (const daemon::ConfigError& e) {
    std::fprintf(stderr, "posefair bench latency: %s\n", e.what());
    return exit_code(ErrorKind::Usage);
  }

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
      const auto r = daemon::decode_datagram(std::span<const std::uint8_t>(buffer.data(), d->size));
      if (!r) continue;
      datagrams.fetch_add(1, std::memory_order_relaxed);
      auto [it, fresh] = next.try_emplace(r.message.stream, 0);
      if (r.message.sequence > it->second) lost.fetch_add(r.message.sequence - it->second, std::memory_order_relaxed);
      it->second = r.message.sequence + 1;
    }
    receiver_cpu = thread_cpu_seconds();
  });
  if (o.no_receiver) receiver.join();

  std::printf("bench latency: %d streams at %.0f Hz for %.1f s, window %d, lag %d, %s solver, ring %d, realtime priority %d, %s%s\n",
              o.streams, o.rate, o.duration, o.window, o.lag, o.solver.c_str(), o.ring_capacity, o.realtime_priority,
              o.aligned ? "phases aligned" : "phases spread", o.all_encodings ? ", every encoding" : "");
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
    const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    std::this_thread::sleep_for(std::chrono::milliseconds(300));  // the last datagrams
    stop.store(true, std::memory_order_release);
    if (receiver.joinable()) receiver.join();
    const double cpu = process_cpu_seconds() - cpu0 - receiver_cpu;

    daemon::HistogramSnapshot all;
    std::uint64_t received = 0, emitted = 0, ring_dropped = 0, publish_dropped = 0, rejected = 0, out_of_order = 0,
                  raw_unfused = 0, published = 0, failures = 0, worst_p99 = 0;
    for (const daemon::StreamStats& s : pipeline.stats()) {
      merge(all, s.latency);
      received += s.received;
      emitted += s.emitted;
      ring_dropped += s.ring_dropped;
      publish_dropped += s.publish_dropped;
      rejected += s.rejected;
      out_of_order += s.out_of_order;
      raw_unfused += s.raw_unfused;
      published += s.published;
      failures += s.send_failures;
      worst_p99 = std::max(worst_p99, s.latency.percentile(99));
    }
    const auto us = [](std::uint64_t ns) { return static_cast<double>(ns) / 1000.0; };
    std::printf("samples     %" PRIu64 " handed over (%.0f/s), %" PRIu64 " emitted, %" PRIu64 " published\n", received,
                static_cast<double>(received) / wall, emitted, published);
    std::printf("latency us  p50 %.1f  p90 %.1f  p99 %.1f  p99.9 %.1f  max %.1f  (worst stream p99 %.1f)\n",
                us(all.percentile(50)), us(all.percentile(90)), us(all.percentile(99)), us(all.percentile(99.9)),
                us(all.max), us(worst_p99));
    const std::uint64_t accounted = emitted + ring_dropped + rejected + out_of_order + raw_unfused;
    std::printf("drops       ring %" PRIu64 ", publish %" PRIu64 ", rejected %" PRIu64 ", out-of-order %" PRIu64
                ", send failures %" PRIu64 "; unaccounted %" PRId64 "\n",
                ring_dropped, publish_dropped, rejected, out_of_order, failures,
                static_cast<std::int64_t>(received) - static_cast<std::int64_t>(accounted));
    if (o.no_receiver)
      std::printf("receiver    none (datagrams sent to a socket nobody reads)\n");
    else
      std::printf("receiver    %" PRIu64 " datagrams, %" PRIu64 " lost (sequence gaps)\n", datagrams.load(), lost.load());
    std::printf("cpu         %.3f s in %.2f s wall: %.1f%% of one core, %.2f%% per stream at %.0f Hz (receiver excluded%s)\n",
                cpu, wall, 100.0 * cpu / wall, 100.0 * cpu / wall / o.streams, o.rate, control ? ", flood included" : "");
    if (control) control->print();
  }
  return kExitOk;
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
  cmd->callback([o, &exit_code] { exit_code = bench_latency(*o); });
}

}  // namespace posefair::tools
