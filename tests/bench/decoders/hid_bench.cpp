// Throughput of the HID decoders, the report descriptor parser and the GPIO edge pairing rule.
// HID reports come one per read() from hidraw; each benchmark decodes a stream of whole
// reports along smooth random motion (core/synthetic_motion.hpp), with one report in 16 of
// another report ID (another sensor of the hub) and one in 64 cut short, and reports MB/s of
// report bytes. Goal: at least 50 MB/s on one core.
// Run: build/tests/bench/hid_bench
#include <benchmark/benchmark.h>

#include <cstdint>
#include <random>
#include <variant>
#include <vector>

#include "../../support/hid_descriptor_builder.hpp"
#include "../../support/hid_sensor_descriptor.hpp"
#include "decoder_bench.hpp"
#include "posefair/core/synthetic_motion.hpp"
#include "posefair/drivers/gpio_edge_pairing.hpp"
#include "posefair/drivers/hid_sensor_orientation_decoder.hpp"
#include "posefair/drivers/hid_vendor_layout_decoder.hpp"

namespace posefair::drivers {
namespace {

using Reports = std::vector<std::vector<std::uint8_t>>;

std::vector<Quat> motion() {
  SyntheticMotionSpec spec;
  spec.samples = 20000;
  spec.sample_rate_hz = 400.0;
  spec.cycles = 20.0;
  spec.rotation_noise = 0.01;
  spec.with_position = false;
  const SyntheticMotion m = make_synthetic_motion(spec);
  return {m.noisy.orientation.begin(), m.noisy.orientation.end()};
}

// Every 16th report gets another ID byte, every 64th loses its last byte.
Reports disturb(Reports reports) {
  for (std::size_t k = 0; k < reports.size(); ++k) {
    if (k % 16 == 5 && !reports[k].empty()) reports[k][0] ^= 0x40;
    if (k % 64 == 9) reports[k].pop_back();
  }
  return reports;
}

HidOrientationLayout layout_of(const std::vector<std::uint8_t>& descriptor) {
  return resolve_hid_orientation_layout(std::get<HidReportDescriptor>(parse_hid_report_descriptor(descriptor)));
}

void run_reports(benchmark::State& state, HidReportDecoder& decoder, const Reports& reports) {
  bench::CountingSink sink;
  std::size_t bytes = 0;
  for (const auto& r : reports) bytes += r.size();
  for (auto _ : state) {
    for (const auto& r : reports) decoder.decode(r, sink);
    benchmark::DoNotOptimize(sink.sum);
  }
  state.SetBytesProcessed(static_cast<std::int64_t>(state.iterations() * bytes));
  state.counters["report_bytes"] = static_cast<double>(bytes) / static_cast<double>(reports.size());
  state.counters["reports_per_s"] = benchmark::Counter(static_cast<double>(reports.size()), benchmark::Counter::kIsIterationInvariantRate);
  state.counters["samples_per_pass"] = static_cast<double>(decoder.counters().samples) / static_cast<double>(state.iterations());
}

// The genuine ST descriptor: 20-byte reports, 4 x int32, exponent -8.
void BM_HidSensorGenuine32(benchmark::State& state) {
  const std::vector<std::uint8_t> d(testing::kStImuOrientationDescriptor.begin(), testing::kStImuOrientationDescriptor.end());
  const HidOrientationLayout l = layout_of(d);
  Reports reports;
  for (const Quat& q : motion()) reports.push_back(encode_hid_orientation_report(l, q));
  reports = disturb(std::move(reports));
  auto decoder = make_hid_sensor_orientation_decoder(l);
  run_reports(state, *decoder, reports);
}
BENCHMARK(BM_HidSensorGenuine32);

// 16-bit values with exponent -2 and a 32-bit timestamp: 14-byte reports.
void BM_HidSensor16WithTimestamp(benchmark::State& state) {
  const HidOrientationLayout l = layout_of(testing::hid_sensor_orientation_descriptor(16, -2, 3, 32, 0x1001, -6));
  Reports reports;
  std::uint64_t t = 0;
  for (const Quat& q : motion()) reports.push_back(encode_hid_orientation_report(l, q, t += 2500));
  reports = disturb(std::move(reports));
  auto decoder = make_hid_sensor_orientation_decoder(l);
  run_reports(state, *decoder, reports);
}
BENCHMARK(BM_HidSensor16WithTimestamp);

// A vendor layout: report ID, int16 Q14 little-endian w x y z after a 2-byte counter.
void BM_HidVendorInt16(benchmark::State& state) {
  HidVendorLayout l;
  l.report_id = 1;
  l.report_length = 16;
  l.offset_bits = {16, 32, 48, 64};
  Reports reports;
  for (const Quat& q : motion()) reports.push_back(encode_hid_vendor_report(l, q));
  reports = disturb(std::move(reports));
  auto decoder = make_hid_vendor_layout_decoder(l);
  run_reports(state, *decoder, reports);
}
BENCHMARK(BM_HidVendorInt16);

// A vendor layout: float32 big-endian x y z w, no report ID.
void BM_HidVendorFloat32BigEndian(benchmark::State& state) {
  HidVendorLayout l;
  l.type = HidVendorType::Float32;
  l.big_endian = true;
  l.w_first = false;
  l.scale = 1.0;
  l.offset_bits = {0, 32, 64, 96};
  Reports reports;
  for (const Quat& q : motion()) reports.push_back(encode_hid_vendor_report(l, q));
  reports = disturb(std::move(reports));
  auto decoder = make_hid_vendor_layout_decoder(l);
  run_reports(state, *decoder, reports);
}
BENCHMARK(BM_HidVendorFloat32BigEndian);

// Parsing the genuine descriptor (done once per open; here for its bytes/s).
void BM_HidDescriptorParse(benchmark::State& state) {
  const std::vector<std::uint8_t> d(testing::kStImuOrientationDescriptor.begin(), testing::kStImuOrientationDescriptor.end());
  for (auto _ : state) {
    auto r = parse_hid_report_descriptor(d);
    benchmark::DoNotOptimize(r);
  }
  state.SetBytesProcessed(static_cast<std::int64_t>(state.iterations() * d.size()));
}
BENCHMARK(BM_HidDescriptorParse);

// The edge pairing rule: one edge and one sample per step, delays jittered inside the window.
void BM_GpioEdgePairing(benchmark::State& state) {
  std::mt19937_64 rng(1);
  std::uniform_real_distribution<double> delay(0.0002, 0.003);
  std::vector<double> delays(4096);
  for (double& d : delays) d = delay(rng);
  EdgePairingOptions o;
  o.tolerance_min = 0.0002;
  o.tolerance_max = 0.003;
  EdgePairer pairer(o);
  double t = 0.0, sum = 0.0;
  std::size_t k = 0;
  for (auto _ : state) {
    t += 0.005;
    pairer.add_edge(t);
    sum += pairer.pair(t + delays[k++ & 4095]).time;
  }
  benchmark::DoNotOptimize(sum);
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations()));
}
BENCHMARK(BM_GpioEdgePairing);

}  // namespace
}  // namespace posefair::drivers

BENCHMARK_MAIN();
