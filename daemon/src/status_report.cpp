#include "posefair/daemon/status_report.hpp"

#include <cinttypes>
#include <cstdio>

namespace posefair::daemon {
namespace {

const StreamStats* find(const std::vector<StreamStats>& v, std::uint32_t id) {
  for (const StreamStats& s : v)
    if (s.id == id) return &s;
  return nullptr;
}

double rate(std::uint64_t now, std::uint64_t before, double seconds) {
  return seconds > 0.0 && now >= before ? static_cast<double>(now - before) / seconds : 0.0;
}

double us(std::uint64_t ns) { return static_cast<double>(ns) / 1000.0; }

// "; device connected, outages 1, reconnects 1, open failures 3, read errors 0, frames 2000,
//  bad 2, resyncs 3 (skipped 41 bytes), device time trusted (fallbacks 0)"
std::string device_text(const drivers::DeviceHealth& d) {
  char buf[320];
  std::snprintf(buf, sizeof buf,
                "; device %s, outages %" PRIu64 ", reconnects %" PRIu64 ", open failures %" PRIu64
                ", read errors %" PRIu64 ", frames %" PRIu64 ", bad %" PRIu64 ", resyncs %" PRIu64
                " (skipped %" PRIu64 " bytes), %s time (fallbacks %" PRIu64 ")",
                d.connected ? "connected" : "DISCONNECTED", d.outages, d.reconnects, d.open_failures, d.read_errors,
                d.frames, d.bad_frames, d.resyncs, d.skipped_bytes, d.device_time_trusted ? "device" : "receive",
                d.time_fallbacks);
  return buf;
}

// "; gpio data-ready held, edges 300, paired 298, missing 2, extra 1, late 0, overflow 0,
//  request failures 0, losses 0; gpio output held, toggles 298, errors 0"
std::string gpio_text(const std::optional<drivers::GpioDataReadyCounters>& in,
                      const std::optional<drivers::GpioOutputCounters>& out) {
  std::string text;
  char buf[320];
  if (in) {
    const drivers::EdgePairingCounters& p = in->pairing;
    std::snprintf(buf, sizeof buf,
                  "; gpio data-ready %s, edges %" PRIu64 ", paired %" PRIu64 ", missing %" PRIu64 ", extra %" PRIu64
                  ", late %" PRIu64 ", overflow %" PRIu64 ", request failures %" PRIu64 ", losses %" PRIu64,
                  in->line_held ? "held" : "NOT HELD", p.edges, p.paired, p.missing, p.extra_edges, p.late_edges, p.overflow,
                  in->request_failures, in->losses);
    text += buf;
  }
  if (out) {
    std::snprintf(buf, sizeof buf, "; gpio output %s, toggles %" PRIu64 ", errors %" PRIu64,
                  out->line_held ? "held" : "NOT HELD", out->toggles, out->errors);
    text += buf;
  }
  return text;
}

// A channel at rest, and averaged over seconds (the rest line, docs/engine.md "At rest").
const char* rest_text(const ChannelAdaptation& a) {
  return a.rest_averaged ? ", at rest, averaged over seconds" : a.at_rest ? ", at rest" : "";
}

// The noise a rest is judged against, where the newest samples' has risen over the estimate (a
// burst of noise, docs/engine.md "A noise burst at rest"): " (risen to 0.006 lately)".
std::string risen_text(const ChannelAdaptation& a) {
  if (!(a.rest_noise > a.noise)) return {};
  char buf[48];
  std::snprintf(buf, sizeof buf, " (risen to %.3g lately)", a.rest_noise);
  return buf;
}

// The noise the level is chosen for, where the check by the next measurement took less than the
// estimate (docs/engine.md, "Checked by the next measurement"): " (chosen for noise/1024, predicted)".
std::string scale_text(const ChannelAdaptation& a) {
  if (!(a.noise_scale < 1.0)) return {};
  char buf[64];
  std::snprintf(buf, sizeof buf, " (chosen for noise^2/%.4g, predicted)", 1.0 / a.noise_scale);
  return buf;
}

// "; engine 285.7 Hz, window 128, rotation adapted: noise 0.0012 rad, motion 3.1 rad/s^2,
//  cutoff 8.2 Hz (mu 352)" — the adaptation's measurements and choice, or the fixed smoothing.
std::string engine_text(const EngineState& e, const std::optional<GyroPairingStats>& pairing, std::uint64_t gyro_bridged) {
  std::string text;
  char buf[400];
  if (e.rate_hz > 0.0)
    std::snprintf(buf, sizeof buf, "; engine %.4g Hz, window %d", e.rate_hz, e.window);
  else
    std::snprintf(buf, sizeof buf, "; engine rate not yet measured");
  text += buf;
  auto channel = [&](const char* name, const ChannelAdaptation& a, const char* unit) {
    if (a.adaptive)
      std::snprintf(buf, sizeof buf, ", %s adapted: noise %.3g %s%s, motion %.3g %s/s^m, cutoff %.3g Hz (mu %.4g)%s%s", name,
                    a.noise, unit, risen_text(a).c_str(), a.motion, unit, a.cutoff_hz, a.smoothing, scale_text(a).c_str(),
                    rest_text(a));
    else
      std::snprintf(buf, sizeof buf, ", %s fixed: cutoff %.3g Hz (mu %.4g)", name, a.cutoff_hz, a.smoothing);
    text += buf;
  };
  channel("rotation", e.rotation, "rad");
  // Positions once the adaptation has measured some (a stream without them shows none).
  if (e.position.adaptive ? e.position.noise > 0.0 : e.position.smoothing > 0.0) channel("position", e.position, "units");
  // Gyro-aided fairing, once it has seen a gyro, or as soon as it is paired with another stream's.
  if (e.gyro.intervals > 0 || pairing) {
    constexpr double kDegPerRad = 180.0 / 3.14159265358979323846;
    std::string from;
    if (pairing)
      from = " from '" + pairing->source + "' (matched " + std::to_string(pairing->matched) + ", unmatched " +
             std::to_string(pairing->unmatched) + ")";
    std::snprintf(buf, sizeof buf,
                  ", gyro-aided%s%s: bias (%.3f %.3f %.3f) deg/s, time offset %.2f ms (%s), intervals %" PRIu64
                  ", bridged %" PRIu64,
                  from.c_str(), e.gyro.active ? "" : " (not now)", e.gyro.bias.x() * kDegPerRad, e.gyro.bias.y() * kDegPerRad,
                  e.gyro.bias.z() * kDegPerRad, 1e3 * e.gyro.time_offset_s, e.gyro.offset_estimated ? "estimated" : "configured",
                  e.gyro.intervals, gyro_bridged);
    text += buf;
  }
  return text;
}

}  // namespace

std::vector<std::string> counter_lines(const std::vector<StreamStats>& now, const std::vector<StreamStats>& previous,
                                       double seconds) {
  std::vector<std::string> lines;
  for (const StreamStats& s : now) {
    const StreamStats* p = find(previous, s.id);
    char rate_text[48] = "";
    if (p) std::snprintf(rate_text, sizeof rate_text, " (%.1f/s)", rate(s.received, p->received, seconds));
    char buf[640];
    std::snprintf(buf, sizeof buf,
                  "stream %s (id %" PRIu32 ", %s%s): received %" PRIu64 "%s, dropped %" PRIu64 " (ring %" PRIu64
                  ", publish %" PRIu64 "), rejected %" PRIu64 ", out-of-order %" PRIu64 ", emitted %" PRIu64
                  ", clamped %" PRIu64 ", restarts %" PRIu64 ", published %" PRIu64 ", send failures %" PRIu64
                  ", recorded %" PRIu64 " (dropped %" PRIu64 "), latency us p50 %.1f p90 %.1f p99 %.1f max %.1f",
                  s.name.c_str(), s.id, s.driver.c_str(), s.driver_running ? "" : ", ended", s.received, rate_text,
                  s.dropped(), s.ring_dropped, s.publish_dropped, s.rejected, s.out_of_order, s.emitted, s.clamped,
                  s.restarts, s.published, s.send_failures, s.recorded, s.record_dropped,
                  us(s.latency.percentile(50)), us(s.latency.percentile(90)), us(s.latency.percentile(99)),
                  us(s.latency.max));
    lines.emplace_back(buf);
    if (s.outliers_held > 0) {
      std::snprintf(buf, sizeof buf, ", outliers held %" PRIu64 " (released %" PRIu64 ")", s.outliers_held, s.outliers_released);
      lines.back() += buf;
    }
    if (s.rate_changes > 0) {  // restarts the stream caused by changing its rate, not by a gap
      std::snprintf(buf, sizeof buf, ", rate changes %" PRIu64 " (of the restarts)", s.rate_changes);
      lines.back() += buf;
    }
    if (s.repeated > 0) {  // a source read faster than it updates (repeated_measurements.hpp)
      std::snprintf(buf, sizeof buf, ", repeated %" PRIu64 " (carried forward; %s)", s.repeated,
                    s.engine.repeating ? "the rate is the source's" : "not repeating now");
      lines.back() += buf;
    }
    if (s.interpolated > 0) {  // a stream slerped from a slower source (slerped_measurements.hpp)
      std::snprintf(buf, sizeof buf, ", interpolated %" PRIu64 " (between its measurements; %s)", s.interpolated,
                    s.engine.slerped ? "the rate is the source's" : "not slerped now");
      lines.back() += buf;
    }
    if (s.lost > 0) {  // lost packets: steps of a few intervals, not gaps (fairing_window.hpp, kLostStepTolerance)
      std::snprintf(buf, sizeof buf, ", lost %" PRIu64 " (stood in for)", s.lost);
      lines.back() += buf;
    }
    if (s.raw_unfused > 0) {  // a raw IMU source without a fusion stage: say why nothing is faired
      std::snprintf(buf, sizeof buf, ", raw-only %" PRIu64 " (not faired: no orientation, no fusion stage)", s.raw_unfused);
      lines.back() += buf;
    }
    if (s.bridging) {
      std::snprintf(buf, sizeof buf, ", bridged gaps %" PRIu64 " (samples %" PRIu64 ", passed through %" PRIu64 ")", s.bridged_gaps,
                    s.bridged_samples, s.unbridged_gaps);
      lines.back() += buf;
    }
    if (s.resampling) {
      std::snprintf(buf, sizeof buf, ", resampled %" PRIu64, s.resampled);
      lines.back() += buf;
    }
    if (s.matrix_lerp && (s.bridging || s.resampling)) {
      std::snprintf(buf, sizeof buf, ", lerp fallbacks %" PRIu64, s.lerp_fallbacks);
      lines.back() += buf;
    }
    if (s.fusion) {
      const EstimatorState& f = *s.fusion;
      constexpr double kDegPerRad = 180.0 / 3.14159265358979323846;
      std::snprintf(buf, sizeof buf,
                    ", fusion: gyro bias (%.3f %.3f %.3f) deg/s, %s, %s, waiting %" PRIu64 ", non-finite %" PRIu64
                    ", gyro saturated %" PRIu64 ", mag stuck %" PRIu64 ", mag absent %" PRIu64 ", bad steps %" PRIu64
                    ", gaps %" PRIu64,
                    f.gyro_bias.x() * kDegPerRad, f.gyro_bias.y() * kDegPerRad, f.gyro_bias.z() * kDegPerRad,
                    f.at_rest ? "at rest" : "moving", f.mag_disturbed ? "field disturbed" : "field undisturbed",
                    s.fusion_waiting, f.nonfinite, f.gyro_saturated, f.mag_stuck, f.mag_absent, f.bad_time_steps, f.gaps);
      lines.back() += buf;
    }
    lines.back() += engine_text(s.engine, s.gyro_pairing, s.gyro_bridged);
    if (s.device) lines.back() += device_text(*s.device);
    lines.back() += gpio_text(s.data_ready, s.gpio_output);
  }
  return lines;
}

std::string status_line(const std::vector<StreamStats>& now, const std::vector<StreamStats>& previous, double seconds) {
  std::string out;
  for (const StreamStats& s : now) {
    const StreamStats* p = find(previous, s.id);
    const HistogramSnapshot interval = p ? s.latency.since(p->latency) : s.latency;
    char buf[160];
    std::snprintf(buf, sizeof buf, "%s%s %.1f/s drop %" PRIu64 " p99 %.0fus", out.empty() ? "" : "; ", s.name.c_str(),
                  p ? rate(s.emitted, p->emitted, seconds) : 0.0, s.dropped(), us(interval.percentile(99)));
    out += buf;
    // What the smoothing is doing: its cutoff now (adapted or fixed), once the rate is known.
    if (s.engine.rate_hz > 0.0) {
      const ChannelAdaptation& r = s.engine.rotation;
      std::snprintf(buf, sizeof buf, " fc %.3gHz%s", r.cutoff_hz,
                    !r.adaptive              ? ""
                    : r.rest_averaged        ? " (adapted, at rest, averaged)"
                    : r.at_rest              ? " (adapted, at rest)"
                    : r.noise_scale < 1.0    ? " (adapted, predicted)"
                                             : " (adapted)");
      out += buf;
      if (s.engine.repeating || s.engine.slerped) {
        std::snprintf(buf, sizeof buf, " source %.3gHz (%s)", s.engine.rate_hz, s.engine.repeating ? "repeated" : "slerped");
        out += buf;
      }
    }
    if (s.raw_unfused > 0) {
      std::snprintf(buf, sizeof buf, " raw-only %" PRIu64 " unfused", s.raw_unfused);
      out += buf;
    }
    // Gyro-aided fairing: its time offset and the size of its bias estimate; with a gyro_stream,
    // the source and how many samples found no reading of it.
    if (s.gyro_pairing) {
      std::snprintf(buf, sizeof buf, " gyro from %s unmatched %" PRIu64 "%s", s.gyro_pairing->source.c_str(),
                    s.gyro_pairing->unmatched, s.engine.gyro.active ? "" : " (not aided now)");
      out += buf;
    }
    if (s.engine.gyro.active) {
      std::snprintf(buf, sizeof buf, " gyro dt %.1fms bias %.2fdeg/s", 1e3 * s.engine.gyro.time_offset_s,
                    s.engine.gyro.bias.norm() * 180.0 / 3.14159265358979323846);
      out += buf;
    }
    // A device stream says when its device is away and how often it went: what `systemctl
    // status` readers need first.
    if (s.device) {
      std::snprintf(buf, sizeof buf, "%s outages %" PRIu64 " bad %" PRIu64, s.device->connected ? "" : " DISCONNECTED",
                    s.device->outages, s.device->bad_frames);
      out += buf;
    }
    // A fusion stage: at rest or moving, and a magnetic disturbance being rejected.
    if (s.fusion) {
      std::snprintf(buf, sizeof buf, " imu %s%s", s.fusion->at_rest ? "rest" : "moving",
                    s.fusion->mag_disturbed ? " MAG-DISTURBED" : "");
      out += buf;
    }
    // A data-ready line that is not held means unpaired (receive-timed) samples.
    if (s.data_ready) {
      std::snprintf(buf, sizeof buf, "%s missing %" PRIu64, s.data_ready->line_held ? " gpio" : " GPIO-LINE-NOT-HELD",
                    s.data_ready->pairing.missing);
      out += buf;
    }
  }
  return out;
}

}  // namespace posefair::daemon
