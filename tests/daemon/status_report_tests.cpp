// The operator's text (status_report.hpp): counter lines and systemd's STATUS=, with and
// without a device link.
#include "posefair/daemon/status_report.hpp"

#include "posefair/daemon/control_reply.hpp"

#include <gtest/gtest.h>

namespace posefair::daemon {
namespace {

StreamStats stream(std::uint32_t id, const std::string& name, std::uint64_t emitted) {
  StreamStats s;
  s.id = id;
  s.name = name;
  s.driver = "serial:/dev/ttyUSB0 (xsens)";
  s.driver_running = true;
  s.received = emitted;
  s.emitted = emitted;
  s.published = emitted;
  return s;
}

drivers::DeviceHealth link(bool connected) {
  drivers::DeviceHealth d;
  d.connected = connected;
  d.outages = 2;
  d.reconnects = 1;
  d.open_failures = 7;
  d.read_errors = 3;
  d.frames = 1990;
  d.bad_frames = 4;
  d.resyncs = 5;
  d.skipped_bytes = 41;
  d.device_time_trusted = true;
  d.time_fallbacks = 6;
  return d;
}

TEST(StatusReport, CounterLineWithoutDeviceHasNoDevicePart) {
  const auto lines = counter_lines({stream(1, "head", 2000)}, {}, 0.0);
  ASSERT_EQ(lines.size(), 1u);
  EXPECT_NE(lines[0].find("stream head (id 1, serial:/dev/ttyUSB0 (xsens)): received 2000,"), std::string::npos) << lines[0];
  EXPECT_EQ(lines[0].find("device"), std::string::npos) << lines[0];
}

// Raw-only samples that no fusion stage turned into orientations show in both texts with their
// reason, and only when there are some.
TEST(StatusReport, RawOnlySamplesShowWithTheirReason) {
  StreamStats s = stream(1, "imu", 0);
  EXPECT_EQ(counter_lines({s}, {}, 0.0)[0].find("raw-only"), std::string::npos);
  EXPECT_EQ(status_line({s}, {}, 1.0).find("raw-only"), std::string::npos);
  s.received = 500;
  s.raw_unfused = 500;
  const auto lines = counter_lines({s}, {}, 0.0);
  EXPECT_NE(lines[0].find(", raw-only 500 (not faired: no orientation, no fusion stage)"), std::string::npos) << lines[0];
  EXPECT_NE(status_line({s}, {}, 1.0).find("imu 0.0/s drop 0 p99 0us raw-only 500 unfused"), std::string::npos)
      << status_line({s}, {}, 1.0);
}

// A window restarted for a change of the stream's rate is counted among the restarts and on
// its own, in the counter line (only when there was one) and in the control reply.
TEST(StatusReport, AChangeOfRateShowsAmongTheRestarts) {
  StreamStats s = stream(1, "head", 2000);
  s.restarts = 3;
  EXPECT_EQ(counter_lines({s}, {}, 0.0)[0].find("rate changes"), std::string::npos);
  s.rate_changes = 1;
  const auto lines = counter_lines({s}, {}, 0.0);
  EXPECT_NE(lines[0].find(", restarts 3,"), std::string::npos) << lines[0];
  EXPECT_NE(lines[0].find(", rate changes 1 (of the restarts)"), std::string::npos) << lines[0];
  const std::string json = streams_member({s}, {}, 1.0);
  EXPECT_NE(json.find("\"restarts\":3,\"rate_changes\":1,"), std::string::npos) << json;
}

// Samples lost within a step (a lost packet, no gap) show once there are some.
TEST(StatusReport, LostSamplesShowOnceThereAreSome) {
  StreamStats s = stream(1, "head", 2000);
  EXPECT_EQ(counter_lines({s}, {}, 0.0)[0].find("lost"), std::string::npos);
  EXPECT_NE(streams_member({s}, {}, 1.0).find("\"lost\":0,"), std::string::npos);
  s.lost = 37;
  EXPECT_NE(counter_lines({s}, {}, 0.0)[0].find(", lost 37 (stood in for)"), std::string::npos) << counter_lines({s}, {}, 0.0)[0];
  EXPECT_NE(streams_member({s}, {}, 1.0).find("\"lost\":37,"), std::string::npos) << streams_member({s}, {}, 1.0);
}

// A source read faster than it updates (repeated_measurements.hpp): its repeats carried forward
// show in the counter line and the control reply once there are some, and while the stream
// repeats, STATUS= gives the source's rate the window runs at.
TEST(StatusReport, RepeatsCarriedForwardShowWithTheSourcesRate) {
  StreamStats s = stream(1, "head", 2000);
  s.engine.rate_hz = 250.0;
  EXPECT_EQ(counter_lines({s}, {}, 0.0)[0].find("repeated"), std::string::npos);
  EXPECT_EQ(status_line({s}, {}, 1.0).find("source"), std::string::npos);
  s.repeated = 1500;
  s.engine.repeating = true;
  s.engine.rate_hz = 62.5;
  const auto lines = counter_lines({s}, {}, 0.0);
  EXPECT_NE(lines[0].find(", repeated 1500 (carried forward; the rate is the source's)"), std::string::npos) << lines[0];
  EXPECT_NE(status_line({s}, {}, 1.0).find(" source 62.5Hz (repeated)"), std::string::npos) << status_line({s}, {}, 1.0);
  const std::string json = streams_member({s}, {}, 1.0);
  EXPECT_NE(json.find("\"repeated\":1500,"), std::string::npos) << json;
  EXPECT_NE(json.find("\"repeating\":true"), std::string::npos) << json;
  s.engine.repeating = false;  // it stopped: the count stays, the source's rate goes
  EXPECT_NE(counter_lines({s}, {}, 0.0)[0].find(", repeated 1500 (carried forward; not repeating now)"), std::string::npos);
  EXPECT_EQ(status_line({s}, {}, 1.0).find("source"), std::string::npos);
}

// A stream slerped from a slower source (slerped_measurements.hpp): its interpolated samples show
// as the repeats do, and STATUS= gives the source's rate while it is slerped.
TEST(StatusReport, InterpolatedSamplesShowWithTheSourcesRate) {
  StreamStats s = stream(1, "head", 2000);
  s.engine.rate_hz = 250.0;
  EXPECT_EQ(counter_lines({s}, {}, 0.0)[0].find("interpolated"), std::string::npos);
  s.interpolated = 1400;
  s.engine.slerped = true;
  s.engine.rate_hz = 60.0;
  const auto lines = counter_lines({s}, {}, 0.0);
  EXPECT_NE(lines[0].find(", interpolated 1400 (between its measurements; the rate is the source's)"), std::string::npos) << lines[0];
  EXPECT_NE(status_line({s}, {}, 1.0).find(" source 60Hz (slerped)"), std::string::npos) << status_line({s}, {}, 1.0);
  const std::string json = streams_member({s}, {}, 1.0);
  EXPECT_NE(json.find("\"interpolated\":1400,"), std::string::npos) << json;
  EXPECT_NE(json.find("\"slerped\":true"), std::string::npos) << json;
  s.engine.slerped = false;
  EXPECT_NE(counter_lines({s}, {}, 0.0)[0].find(", interpolated 1400 (between its measurements; not slerped now)"), std::string::npos);
  EXPECT_EQ(status_line({s}, {}, 1.0).find("source"), std::string::npos);
}

// [stream.engine] gyro_stream: the gyro part names the source and its matches from the start,
// before any interval was aided, and STATUS= says how many samples found no reading.
TEST(StatusReport, GapsBridgedAndPassedThroughShowWhenBridging) {
  StreamStats s = stream(1, "head", 2000);
  s.bridged_gaps = 2;
  s.bridged_samples = 30;
  s.unbridged_gaps = 1;
  EXPECT_EQ(counter_lines({s}, {}, 0.0)[0].find("bridged gaps"), std::string::npos) << "not configured, not shown";
  s.bridging = true;
  const auto lines = counter_lines({s}, {}, 0.0);
  EXPECT_NE(lines[0].find(", bridged gaps 2 (samples 30, passed through 1)"), std::string::npos) << lines[0];
}

// `posefair ctl streams --json` carries what the counter line does: the raw-only samples (so
// that received = dropped + rejected + out of order + raw-only + emitted + held back can be
// checked from it), the spline's counters where configured, and the device's health.
TEST(StatusReport, TheControlReplyCarriesTheSplineAndDeviceCounters) {
  StreamStats s = stream(1, "head", 2000);
  s.raw_unfused = 4;
  s.bridged_gaps = 2;
  s.bridged_samples = 30;
  s.unbridged_gaps = 1;
  s.resampled = 500;
  EXPECT_NE(streams_member({s}, {}, 1.0).find(R"("raw_unfused":4,)"), std::string::npos) << streams_member({s}, {}, 1.0);
  EXPECT_NE(streams_member({s}, {}, 1.0).find(R"("spline":null,"device":null,")"), std::string::npos) << "neither configured";
  s.bridging = true;
  EXPECT_NE(streams_member({s}, {}, 1.0).find(R"("spline":{"bridged_gaps":2,"bridged_samples":30,"passed_through":1,)"
                                              R"("resampled":null,"lerp_fallbacks":null})"),
            std::string::npos)
      << streams_member({s}, {}, 1.0);
  s.resampling = true;
  s.matrix_lerp = true;
  s.lerp_fallbacks = 3;
  s.device = drivers::DeviceHealth{false, 1, 1, 3, 0, 2000, 2, 3, 41, true, 0};
  const std::string json = streams_member({s}, {}, 1.0);
  EXPECT_NE(json.find(R"("resampled":500,"lerp_fallbacks":3})"), std::string::npos) << json;
  EXPECT_NE(json.find(R"("device":{"connected":false,"outages":1,"reconnects":1,"open_failures":3,"read_errors":0,"frames":2000,)"
                      R"("bad_frames":2,"resyncs":3,"skipped_bytes":41,"device_time_trusted":true,"time_fallbacks":0})"),
            std::string::npos)
      << json;
}

// And the fusion stage's and the GPIO lines' counters, null where not configured.
TEST(StatusReport, TheControlReplyCarriesTheFusionAndGpioCounters) {
  StreamStats s = stream(1, "imu", 2000);
  EXPECT_NE(streams_member({s}, {}, 1.0).find(R"("fusion":null,"gpio_data_ready":null,"gpio_output":null})"), std::string::npos)
      << streams_member({s}, {}, 1.0);
  EstimatorState f;
  f.initialised = true;
  f.at_rest = true;
  f.updates = 1990;
  f.mag_stuck = 2;
  f.gaps = 1;
  s.fusion = f;
  s.fusion_waiting = 10;
  drivers::GpioDataReadyCounters in;
  in.line_held = true;
  in.pairing.edges = 300;
  in.pairing.paired = 298;
  in.pairing.missing = 2;
  in.losses = 1;
  s.data_ready = in;
  s.gpio_output = drivers::GpioOutputCounters{true, 298, 0};
  const std::string json = streams_member({s}, {}, 1.0);
  EXPECT_NE(json.find(R"("at_rest":true,"field_disturbed":false,"waiting":10,"updates":1990,"non_finite":0,"gyro_saturated":0,)"
                      R"("mag_stuck":2,"mag_absent":0,"bad_time_steps":0,"gaps":1,"state_resets":0})"),
            std::string::npos)
      << json;
  EXPECT_NE(json.find(R"("gpio_data_ready":{"held":true,"edges":300,"paired":298,"missing":2,"extra":0,"late":0,"overflow":0,)"
                      R"("request_failures":0,"losses":1},"gpio_output":{"held":true,"toggles":298,"errors":0}})"),
            std::string::npos)
      << json;
}

TEST(StatusReport, AGyroFromAnotherStreamShowsItsSourceAndMatches) {
  StreamStats s = stream(1, "optical", 100);
  s.gyro_pairing = GyroPairingStats{"imu", 0, 100};
  EXPECT_NE(counter_lines({s}, {}, 0.0)[0].find(", gyro-aided from 'imu' (matched 0, unmatched 100) (not now): bias (0.000 0.000 "
                                                "0.000) deg/s, time offset 0.00 ms (configured), intervals 0"),
            std::string::npos)
      << counter_lines({s}, {}, 0.0)[0];
  EXPECT_NE(status_line({s}, {}, 1.0).find(" gyro from imu unmatched 100 (not aided now)"), std::string::npos)
      << status_line({s}, {}, 1.0);
  s.gyro_pairing = GyroPairingStats{"imu", 1400, 100};
  s.engine.gyro.active = true;
  s.engine.gyro.intervals = 1390;
  s.engine.gyro.time_offset_s = 0.004;
  s.engine.gyro.offset_estimated = true;
  s.gyro_bridged = 7;
  EXPECT_NE(counter_lines({s}, {}, 0.0)[0].find(", gyro-aided from 'imu' (matched 1400, unmatched 100): bias (0.000 0.000 0.000) "
                                                "deg/s, time offset 4.00 ms (estimated), intervals 1390, bridged 7"),
            std::string::npos)
      << counter_lines({s}, {}, 0.0)[0];
  EXPECT_NE(status_line({s}, {}, 1.0).find(" gyro from imu unmatched 100 gyro dt 4.0ms bias 0.00deg/s"), std::string::npos)
      << status_line({s}, {}, 1.0);
  // The outlier guard's counts, once it has held a sample (and in `posefair ctl status` always).
  EXPECT_EQ(counter_lines({s}, {}, 0.0)[0].find("outliers held"), std::string::npos);
  s.outliers_held = 12;
  s.outliers_released = 3;
  EXPECT_NE(counter_lines({s}, {}, 0.0)[0].find(", outliers held 12 (released 3)"), std::string::npos) << counter_lines({s}, {}, 0.0)[0];
  EXPECT_NE(streams_member({s}, {}, 1.0).find(R"("outliers_held":12,"outliers_released":3)"), std::string::npos);
  // `posefair ctl status`: the same counts in the stream's gyro object.
  const std::string json = streams_member({s}, {}, 1.0);
  EXPECT_NE(json.find(R"("intervals":1390,"bridged":7,"source":"imu","matched":1400,"unmatched":100)"), std::string::npos) << json;
}

TEST(StatusReport, CounterLineAndStatusCarryTheEngineAdaptation) {
  StreamStats s = stream(1, "head", 2000);
  const auto unknown = counter_lines({s}, {}, 0.0);
  EXPECT_NE(unknown[0].find("; engine rate not yet measured"), std::string::npos) << unknown[0];
  EXPECT_EQ(status_line({s}, {}, 1.0).find(" fc "), std::string::npos);
  s.engine.rate_hz = 285.7;
  s.engine.window = 128;
  s.engine.rotation = ChannelAdaptation{true, 0.0012, 3.1, 352.0, 8.2};
  s.engine.position = ChannelAdaptation{true, 0.0, 0.0, 0.0, 142.85};  // no positions measured
  const auto lines = counter_lines({s}, {}, 0.0);
  EXPECT_NE(lines[0].find("; engine 285.7 Hz, window 128, rotation adapted: noise 0.0012 rad, motion 3.1 rad/s^m, cutoff 8.2 Hz "
                          "(mu 352)"),
            std::string::npos)
      << lines[0];
  EXPECT_EQ(lines[0].find("position"), std::string::npos) << lines[0];
  EXPECT_NE(status_line({s}, {}, 1.0).find(" fc 8.2Hz (adapted)"), std::string::npos) << status_line({s}, {}, 1.0);
  s.engine.rotation = ChannelAdaptation{false, 0.0, 0.0, 100.0, 5.0};
  s.engine.position = ChannelAdaptation{true, 2.5, 40.0, 12.0, 9.0};
  const auto fixed = counter_lines({s}, {}, 0.0);
  EXPECT_NE(fixed[0].find(", rotation fixed: cutoff 5 Hz (mu 100), position adapted: noise 2.5 units"), std::string::npos) << fixed[0];
  // A still stream: the adaptation says it is at rest, in both texts and in the control reply.
  s.engine.rotation = ChannelAdaptation{true, 0.0012, 0.0, 1e9, 0.11, true};
  const auto still = counter_lines({s}, {}, 0.0);
  EXPECT_NE(still[0].find("rotation adapted: noise 0.0012 rad, motion 0 rad/s^m, cutoff 0.11 Hz (mu 1e+09), at rest"),
            std::string::npos)
      << still[0];
  EXPECT_NE(status_line({s}, {}, 1.0).find(" fc 0.11Hz (adapted, at rest)"), std::string::npos) << status_line({s}, {}, 1.0);
  EXPECT_NE(streams_member({s}, {}, 1.0).find(R"("cutoff_hz":0.11,"at_rest":true,"rest_averaged":false,"noise_scale":1})"), std::string::npos)
      << streams_member({s}, {}, 1.0);
  // A burst of noise at rest: the noise the rest is judged against, where it has risen over the
  // estimate (docs/engine.md, "A noise burst at rest"), in the counter line and the control reply.
  s.engine.rotation.rest_noise = 0.006;
  const auto risen = counter_lines({s}, {}, 0.0);
  EXPECT_NE(risen[0].find("rotation adapted: noise 0.0012 rad (risen to 0.006 lately), motion 0 rad/s^m"), std::string::npos) << risen[0];
  EXPECT_NE(streams_member({s}, {}, 1.0).find(R"("rest_noise":0.0060000000000000001,"motion":0)"), std::string::npos) << streams_member({s}, {}, 1.0);
  s.engine.rotation.rest_noise = 0.0012;
  EXPECT_EQ(counter_lines({s}, {}, 0.0)[0].find("risen"), std::string::npos);
  // Averaged over seconds by the rest line (docs/engine.md, "At rest"): said in all three.
  s.engine.rotation.rest_averaged = true;
  const auto averaged = counter_lines({s}, {}, 0.0);
  EXPECT_NE(averaged[0].find("cutoff 0.11 Hz (mu 1e+09), at rest, averaged over seconds"), std::string::npos) << averaged[0];
  EXPECT_NE(status_line({s}, {}, 1.0).find(" fc 0.11Hz (adapted, at rest, averaged)"), std::string::npos) << status_line({s}, {}, 1.0);
  EXPECT_NE(streams_member({s}, {}, 1.0).find(R"("at_rest":true,"rest_averaged":true,"noise_scale":1})"), std::string::npos) << streams_member({s}, {}, 1.0);
  // Moving, with the level chosen for less noise than the estimate: a lighter smoothing predicted
  // the next measurement better (docs/engine.md, "Checked by the next measurement").
  s.engine.rotation = ChannelAdaptation{true, 0.0012, 3.1, 0.5, 40.0};
  s.engine.rotation.noise_scale = 1.0 / 64.0;
  const auto predicted = counter_lines({s}, {}, 0.0);
  EXPECT_NE(predicted[0].find("cutoff 40 Hz (mu 0.5) (chosen for noise^2/64, predicted)"), std::string::npos) << predicted[0];
  EXPECT_NE(status_line({s}, {}, 1.0).find(" fc 40Hz (adapted, predicted)"), std::string::npos) << status_line({s}, {}, 1.0);
  EXPECT_NE(streams_member({s}, {}, 1.0).find(R"("noise_scale":0.015625})"), std::string::npos) << streams_member({s}, {}, 1.0);
}

TEST(StatusReport, AFusionStageAddsItsBiasRestDisturbanceAndCounters) {
  StreamStats s = stream(1, "imu", 2000);
  EXPECT_EQ(counter_lines({s}, {}, 0.0)[0].find("fusion"), std::string::npos);
  EstimatorState f;
  f.gyro_bias = Vec3(0.01, -0.02, 0.005);  // rad/s
  f.at_rest = true;
  f.mag_disturbed = true;
  f.nonfinite = 3;
  f.gyro_saturated = 4;
  f.mag_stuck = 5;
  f.mag_absent = 6;
  f.bad_time_steps = 7;
  f.gaps = 8;
  s.fusion = f;
  s.fusion_waiting = 2;
  const std::string line = counter_lines({s}, {}, 0.0)[0];
  EXPECT_NE(line.find(", fusion: gyro bias (0.573 -1.146 0.286) deg/s, at rest, field disturbed, waiting 2, non-finite 3, "
                      "gyro saturated 4, mag stuck 5, mag absent 6, bad steps 7, gaps 8"),
            std::string::npos)
      << line;
  EXPECT_NE(status_line({s}, {}, 1.0).find(" imu rest MAG-DISTURBED"), std::string::npos) << status_line({s}, {}, 1.0);
}

TEST(StatusReport, CounterLineCarriesEveryDeviceCounter) {
  StreamStats s = stream(1, "head", 2000);
  s.device = link(true);
  const auto lines = counter_lines({s}, {}, 0.0);
  ASSERT_EQ(lines.size(), 1u);
  EXPECT_NE(lines[0].find("; device connected, outages 2, reconnects 1, open failures 7, read errors 3, frames 1990, "
                          "bad 4, resyncs 5 (skipped 41 bytes), device time (fallbacks 6)"),
            std::string::npos)
      << lines[0];
  s.device->connected = false;
  s.device->device_time_trusted = false;
  const auto away = counter_lines({s}, {}, 0.0);
  EXPECT_NE(away[0].find("; device DISCONNECTED,"), std::string::npos) << away[0];
  EXPECT_NE(away[0].find(", receive time (fallbacks 6)"), std::string::npos) << away[0];
}

TEST(StatusReport, StatusLineMarksADisconnectedDevice) {
  StreamStats head = stream(1, "head", 2000);
  head.device = link(false);
  StreamStats prev_head = stream(1, "head", 1000);
  StreamStats hand = stream(2, "hand", 500);
  StreamStats prev_hand = stream(2, "hand", 0);
  const std::string line = status_line({head, hand}, {prev_head, prev_hand}, 2.0);
  EXPECT_EQ(line, "head 500.0/s drop 0 p99 0us DISCONNECTED outages 2 bad 4; hand 250.0/s drop 0 p99 0us");
  head.device->connected = true;
  EXPECT_EQ(status_line({head}, {prev_head}, 2.0), "head 500.0/s drop 0 p99 0us outages 2 bad 4");
}

TEST(StatusReport, GpioLinesAddTheirCountersAndALineNotHeldShows) {
  StreamStats s = stream(1, "head", 2000);
  drivers::GpioDataReadyCounters in;
  in.line_held = true;
  in.pairing.edges = 300;
  in.pairing.paired = 298;
  in.pairing.missing = 2;
  in.pairing.extra_edges = 1;
  in.pairing.late_edges = 3;
  in.pairing.overflow = 4;
  in.request_failures = 5;
  in.losses = 6;
  s.data_ready = in;
  s.gpio_output = drivers::GpioOutputCounters{true, 298, 0};
  const auto lines = counter_lines({s}, {}, 0.0);
  EXPECT_NE(lines[0].find("; gpio data-ready held, edges 300, paired 298, missing 2, extra 1, late 3, overflow 4, "
                          "request failures 5, losses 6; gpio output held, toggles 298, errors 0"),
            std::string::npos)
      << lines[0];
  EXPECT_EQ(status_line({s}, {stream(1, "head", 1000)}, 2.0), "head 500.0/s drop 0 p99 0us gpio missing 2");
  s.data_ready->line_held = false;
  s.gpio_output->line_held = false;
  EXPECT_NE(counter_lines({s}, {}, 0.0)[0].find("; gpio data-ready NOT HELD, edges 300"), std::string::npos);
  EXPECT_NE(counter_lines({s}, {}, 0.0)[0].find("; gpio output NOT HELD, toggles 298"), std::string::npos);
  EXPECT_EQ(status_line({s}, {stream(1, "head", 1000)}, 2.0), "head 500.0/s drop 0 p99 0us GPIO-LINE-NOT-HELD missing 2");
}

}  // namespace
}  // namespace posefair::daemon
