// What each output encoding costs the publisher thread (docs/outputs.md, docs/benchmarks.md):
//   BM_Encode/<encoding>:   the encoder alone, one pose into the datagram buffer;
//   BM_Publish/<encoding>:  Publisher::publish of one pose to an output of that encoding with
//                           one destination on 127.0.0.1 (a bound socket nobody reads: the
//                           kernel drops what overflows it), i.e. the cost per pose and
//                           destination, the UDP send included. dds publishes through Cyclone
//                           DDS instead (no destination); run the program inside a network
//                           namespace of its own so its discovery stays there:
//   tests/dds/in_loopback_netns.sh build/tests/bench/output_encoder_bench
#include <benchmark/benchmark.h>

#include <cmath>
#include <string>
#include <vector>

#include "posefair/daemon/config.hpp"
#include "posefair/daemon/output_encoder.hpp"
#include "posefair/daemon/publisher.hpp"
#include "posefair/daemon/udp_socket.hpp"

namespace {

using namespace posefair;
using namespace posefair::daemon;

const std::vector<OutputStream> kStreams = {{1, "head"}};

// Per-encoding options for one stream.
posefair::OptionMap options_for(std::string_view encoding) {
  if (encoding == "vmc") return {{"bones", std::vector<std::string>{"Head"}}};
  if (encoding == "vrchat") return {{"trackers", std::vector<std::string>{"head"}}};
  return {};
}

PoseMessage pose(double t) {
  PoseMessage m;
  m.stream = 1;
  m.sequence = static_cast<std::uint64_t>(t * 1000);
  m.sample_time = t;
  m.send_time = 1.7e9 + t;
  m.orientation = Quat(Eigen::AngleAxisd(0.3 + t, Vec3(0.2, 0.5, 0.8).normalized()));
  m.position = Vec3(0.1, -0.2, 1.6);
  return m;
}

void BM_Encode(benchmark::State& state, std::string_view encoding) {
  const auto encoder = find_output_encoder(encoding)->make(options_for(encoding), kStreams);
  std::vector<std::uint8_t> buffer(kMaxDatagramSize);
  double t = 0;
  for (auto _ : state) {
    const PoseMessage m = pose(t += 0.001);
    if (encoder->delivers())
      benchmark::DoNotOptimize(encoder->deliver(m));
    else
      benchmark::DoNotOptimize(encoder->encode(m, buffer));
  }
}

void BM_Publish(benchmark::State& state, std::string_view encoding) {
  UdpSocket sink = UdpSocket::bind(*Endpoint::parse("127.0.0.1:0"));
  OutputConfig out;
  out.encoder = find_output_encoder(encoding)->make(options_for(encoding), kStreams);
  if (!out.encoder->delivers()) out.destinations = {*Endpoint::parse("127.0.0.1:" + std::to_string(sink.local_endpoint().port()))};
  Publisher publisher(1, {1}, {out}, {});
  RingPose p{};
  p.flags = kHasPosition;
  p.p[2] = 1.6;
  double t = 0;
  std::size_t failures = 0;
  for (auto _ : state) {
    p.time = (t += 0.001);
    const Quat q(Eigen::AngleAxisd(0.3 + t, Vec3(0.2, 0.5, 0.8).normalized()));
    p.q[0] = q.w(), p.q[1] = q.x(), p.q[2] = q.y(), p.q[3] = q.z();
    failures += publisher.publish(p).failures;
  }
  state.counters["failures"] = static_cast<double>(failures);
}

const char* const kEncodings[] = {"binary", "json", "opentrack", "freed", "vmc", "vrchat", "dds"};

const int registered = [] {
  for (const char* e : kEncodings) {
    if (find_output_encoder(e) == nullptr) continue;  // dds only in a build with Cyclone DDS
    benchmark::RegisterBenchmark((std::string("BM_Encode/") + e).c_str(), BM_Encode, std::string_view(e));
    benchmark::RegisterBenchmark((std::string("BM_Publish/") + e).c_str(), BM_Publish, std::string_view(e));
  }
  return 0;
}();

}  // namespace

BENCHMARK_MAIN();
