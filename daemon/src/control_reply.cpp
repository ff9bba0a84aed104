#include "posefair/daemon/control_reply.hpp"

#include <cinttypes>
#include <cmath>
#include <cstdio>

namespace posefair::daemon {
namespace {

// Members appended one by one into one string (no chains of temporaries).
class JsonObject {
 public:
  JsonObject& add(std::string_view name, std::string_view raw) {
    if (!first_) text_ += ',';
    first_ = false;
    text_ += json_string(name);
    text_ += ':';
    text_ += raw;
    return *this;
  }
  JsonObject& add(std::string_view name, std::uint64_t v) { return add(name, std::to_string(v)); }
  JsonObject& add(std::string_view name, bool v) { return add(name, std::string_view(v ? "true" : "false")); }
  JsonObject& number(std::string_view name, double v) { return add(name, json_number(v)); }
  JsonObject& text(std::string_view name, std::string_view v) { return add(name, json_string(v)); }
  std::string str() const { return text_ + "}"; }

 private:
  std::string text_ = "{";
  bool first_ = true;
};

std::string channel(const ChannelAdaptation& c) {
  return JsonObject()
      .add("adaptive", c.adaptive)
      .number("noise", c.noise)
      .number("rest_noise", c.rest_noise)
      .number("motion", c.motion)
      .number("smoothing", c.smoothing)
      .number("cutoff_hz", c.cutoff_hz)
      .add("at_rest", c.at_rest)
      .add("rest_averaged", c.rest_averaged)
      .number("noise_scale", c.noise_scale)
      .str();
}

std::string member(std::string_view name, const std::string& value) {
  std::string out = json_string(name);
  out += ':';
  out += value;
  return out;
}

// [stream.spline]'s counters: null when neither bridging nor resampling is configured, and a
// part that is not configured is null (as the counter line leaves it out).
std::string spline_object(const StreamStats& s) {
  if (!s.bridging && !s.resampling) return "null";
  const auto if_configured = [](bool configured, std::uint64_t v) { return configured ? std::to_string(v) : std::string("null"); };
  return JsonObject()
      .add("bridged_gaps", if_configured(s.bridging, s.bridged_gaps))
      .add("bridged_samples", if_configured(s.bridging, s.bridged_samples))
      .add("passed_through", if_configured(s.bridging, s.unbridged_gaps))
      .add("resampled", if_configured(s.resampling, s.resampled))
      .add("lerp_fallbacks", if_configured(s.matrix_lerp, s.lerp_fallbacks))
      .str();
}

// The device link's health, as the counter line's device part.
std::string device_object(const drivers::DeviceHealth& d) {
  return JsonObject()
      .add("connected", d.connected)
      .add("outages", d.outages)
      .add("reconnects", d.reconnects)
      .add("open_failures", d.open_failures)
      .add("read_errors", d.read_errors)
      .add("frames", d.frames)
      .add("bad_frames", d.bad_frames)
      .add("resyncs", d.resyncs)
      .add("skipped_bytes", d.skipped_bytes)
      .add("device_time_trusted", d.device_time_trusted)
      .add("time_fallbacks", d.time_fallbacks)
      .str();
}

// [stream.fusion]'s estimator, as the counter line's fusion part (the bias in rad/s).
std::string fusion_object(const EstimatorState& f, std::uint64_t waiting) {
  return JsonObject()
      .add("initialised", f.initialised)
      .number("gyro_bias_x_rad_s", f.gyro_bias.x())
      .number("gyro_bias_y_rad_s", f.gyro_bias.y())
      .number("gyro_bias_z_rad_s", f.gyro_bias.z())
      .add("at_rest", f.at_rest)
      .add("field_disturbed", f.mag_disturbed)
      .add("waiting", waiting)
      .add("updates", f.updates)
      .add("non_finite", f.nonfinite)
      .add("gyro_saturated", f.gyro_saturated)
      .add("mag_stuck", f.mag_stuck)
      .add("mag_absent", f.mag_absent)
      .add("bad_time_steps", f.bad_time_steps)
      .add("gaps", f.gaps)
      .add("state_resets", f.state_resets)
      .str();
}

// [stream.gpio]'s lines, as the counter line's gpio parts.
std::string data_ready_object(const drivers::GpioDataReadyCounters& d) {
  const drivers::EdgePairingCounters& p = d.pairing;
  return JsonObject()
      .add("held", d.line_held)
      .add("edges", p.edges)
      .add("paired", p.paired)
      .add("missing", p.missing)
      .add("extra", p.extra_edges)
      .add("late", p.late_edges)
      .add("overflow", p.overflow)
      .add("request_failures", d.request_failures)
      .add("losses", d.losses)
      .str();
}

std::string gpio_output_object(const drivers::GpioOutputCounters& o) {
  return JsonObject().add("held", o.line_held).add("toggles", o.toggles).add("errors", o.errors).str();
}

}  // namespace

std::string json_string(std::string_view s) {
  std::string out = "\"";
  for (const char ch : s) {
    const auto c = static_cast<unsigned char>(ch);
    if (c == '"' || c == '\\') {
      out += '\\';
      out += ch;
    } else if (c < 0x20) {
      char buf[8];
      std::snprintf(buf, sizeof buf, "\\u%04x", c);
      out += buf;
    } else {
      out += ch;
    }
  }
  out += '"';
  return out;
}

std::string json_number(double v) {
  if (!std::isfinite(v)) return "null";
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.17g", v);
  return buf;
}

std::string control_error_reply(const std::string& message, ErrorKind kind) {
  return JsonObject().add("ok", false).text("error", message).add("exit", static_cast<std::uint64_t>(exit_code(kind))).str();
}

std::string streams_member(const std::vector<StreamStats>& now, const std::vector<StreamStats>& previous, double seconds) {
  std::string list = "[";
  for (std::size_t i = 0; i < now.size(); ++i) {
    const StreamStats& s = now[i];
    std::string rate = "null";
    for (const StreamStats& p : previous)
      if (p.id == s.id && seconds > 0) rate = json_number(static_cast<double>(s.emitted - p.emitted) / seconds);
    const HistogramSnapshot& l = s.latency;
    const auto us = [&](double p) { return l.count ? json_number(static_cast<double>(l.percentile(p)) / 1000.0) : "null"; };
    const std::string latency = JsonObject()
                                    .add("p50", us(50))
                                    .add("p90", us(90))
                                    .add("p99", us(99))
                                    .add("max", l.count ? json_number(static_cast<double>(l.max) / 1000.0) : "null")
                                    .str();
    const std::string engine = JsonObject()
                                   .number("rate_hz", s.engine.rate_hz)
                                   .add("window", std::to_string(s.engine.window))
                                   .add("repeating", s.engine.repeating)
                                   .add("slerped", s.engine.slerped)
                                   .add("rotation", channel(s.engine.rotation))
                                   .add("position", channel(s.engine.position))
                                   .add("gyro", JsonObject()
                                                    .add("active", s.engine.gyro.active)
                                                    .number("bias_x_rad_s", s.engine.gyro.bias.x())
                                                    .number("bias_y_rad_s", s.engine.gyro.bias.y())
                                                    .number("bias_z_rad_s", s.engine.gyro.bias.z())
                                                    .number("time_offset_s", s.engine.gyro.time_offset_s)
                                                    .add("time_offset_estimated", s.engine.gyro.offset_estimated)
                                                    .add("intervals", s.engine.gyro.intervals)
                                                    .add("bridged", s.gyro_bridged)
                                                    .add("source", s.gyro_pairing ? json_string(s.gyro_pairing->source) : "null")
                                                    .add("matched", s.gyro_pairing ? s.gyro_pairing->matched : 0)
                                                    .add("unmatched", s.gyro_pairing ? s.gyro_pairing->unmatched : 0)
                                                    .str())
                                   .str();
    if (i) list += ',';
    list += JsonObject()
                .add("id", std::uint64_t{s.id})
                .text("name", s.name)
                .text("driver", s.driver)
                .add("running", s.driver_running)
                .add("rate_hz", rate)
                .add("received", s.received)
                .add("emitted", s.emitted)
                .add("dropped", s.dropped())
                .add("ring_dropped", s.ring_dropped)
                .add("publish_dropped", s.publish_dropped)
                .add("rejected", s.rejected)
                .add("out_of_order", s.out_of_order)
                .add("clamped", s.clamped)
                .add("outliers_held", s.outliers_held)
                .add("outliers_released", s.outliers_released)
                .add("restarts", s.restarts)
                .add("rate_changes", s.rate_changes)
                .add("repeated", s.repeated)
                .add("interpolated", s.interpolated)
                .add("lost", s.lost)
                .add("published", s.published)
                .add("send_failures", s.send_failures)
                .add("recorded", s.recorded)
                .add("record_dropped", s.record_dropped)
                .add("raw_unfused", s.raw_unfused)
                .add("latency_us", latency)
                .add("engine", engine)
                .add("spline", spline_object(s))
                .add("device", s.device ? device_object(*s.device) : "null")
                .add("fusion", s.fusion ? fusion_object(*s.fusion, s.fusion_waiting) : "null")
                .add("gpio_data_ready", s.data_ready ? data_ready_object(*s.data_ready) : "null")
                .add("gpio_output", s.gpio_output ? gpio_output_object(*s.gpio_output) : "null")
                .str();
  }
  list += ']';
  return member("streams", list);
}

std::string stages_member(const StageLatencySnapshot& stages) {
  const auto stage = [](const HistogramSnapshot& h) {
    const auto us = [&](std::uint64_t ns) { return h.count ? json_number(static_cast<double>(ns) / 1000.0) : "null"; };
    return JsonObject()
        .add("count", h.count)
        .add("p50", us(h.percentile(50)))
        .add("p99", us(h.percentile(99)))
        .add("p999", us(h.percentile(99.9)))
        .add("max", us(h.max))
        .str();
  };
  return member("stages", JsonObject()
                              .add("ring_wait", stage(stages.ring_wait))
                              .add("engine", stage(stages.engine))
                              .add("hand_off", stage(stages.hand_off))
                              .add("encode", stage(stages.encode))
                              .add("send", stage(stages.send))
                              .str());
}

std::string subscribers_member(const std::vector<SubscriberTable::Listed>& list, std::int64_t now_ns) {
  const auto entries = output_encoder_entries();
  std::string out = "[";
  for (std::size_t i = 0; i < list.size(); ++i) {
    const Subscriber& s = list[i].subscriber;
    std::string streams = "[";
    for (std::size_t k = 0; k < s.stream_count; ++k) {
      if (k) streams += ',';
      streams += std::to_string(s.streams[k]);
    }
    streams += ']';
    const std::string_view encoding = s.encoding < entries.size() ? entries[s.encoding]->name : "?";
    if (i) out += ',';
    out += JsonObject()
               .text("address", s.address.to_string())
               .text("encoding", encoding)
               .add("streams", streams)
               .add("angular_velocity", s.angular_velocity)
               .number("lease_left_s", static_cast<double>(s.expires_ns - now_ns) / 1e9)
               .number("subscribed_s", static_cast<double>(now_ns - s.since_ns) / 1e9)
               .add("sent", list[i].sent)
               .str();
  }
  out += ']';
  return member("subscribers", out);
}

std::string subscription_member(const SubscriptionHandler& handler, std::size_t subscribers) {
  const SubscriptionCounters& c = handler.counters();
  const auto get = [](const std::atomic<std::uint64_t>& a) { return a.load(std::memory_order_relaxed); };
  const double in = static_cast<double>(get(c.unverified_bytes_in));
  const double out = static_cast<double>(get(c.unverified_bytes_out));
  return member("subscription", JsonObject()
                                    .text("listen", handler.settings().listen.to_string())
                                    .add("subscribers", std::uint64_t{subscribers})
                                    .add("capacity", std::uint64_t{handler.settings().max_subscribers})
                                    .add("authenticated", handler.settings().psk.has_value())
                                    .add("datagrams", get(c.datagrams))
                                    .add("bytes_in", get(c.bytes_in))
                                    .add("bytes_out", get(c.bytes_out))
                                    .add("not_allowed", get(c.not_allowed))
                                    .add("rate_limited", get(c.rate_limited))
                                    .add("malformed", get(c.malformed))
                                    .add("unauthenticated", get(c.unauthenticated))
                                    .add("cookies_sent", get(c.cookies_sent))
                                    .add("bad_cookie", get(c.bad_cookie))
                                    .add("subscribed", get(c.subscribed))
                                    .add("renewed", get(c.renewed))
                                    .add("replayed", get(c.replayed))
                                    .add("unsubscribed", get(c.unsubscribed))
                                    .add("refused", get(c.refused))
                                    .add("expired", get(c.expired))
                                    .add("unverified_bytes_in", get(c.unverified_bytes_in))
                                    .add("unverified_bytes_out", get(c.unverified_bytes_out))
                                    .add("amplification", in > 0 ? json_number(out / in) : "null")
                                    .str());
}

}  // namespace posefair::daemon
