#include "posefair/daemon/pipeline.hpp"

#include <pthread.h>
#include <sched.h>

#include <algorithm>
#include <bit>
#include <chrono>
#include <cstring>
#include <ctime>
#include <filesystem>
#include <stdexcept>
#include <system_error>
#include <utility>

#include "posefair/core/error.hpp"
#include "posefair/core/fairing_window.hpp"
#include "posefair/core/fixed_rate_resampler.hpp"
#include "posefair/core/gap_bridge.hpp"
#include "posefair/daemon/driver_factory.hpp"
#include "posefair/daemon/fusion_stage.hpp"
#include "posefair/daemon/gyro_pairing.hpp"
#include "posefair/daemon/publisher.hpp"
#include "posefair/daemon/ring_items.hpp"
#include "posefair/daemon/spsc_ring.hpp"

namespace posefair::daemon {

namespace {

std::filesystem::path expand_time_pattern(const std::filesystem::path& path) {
  const std::string name = path.filename().string();
  if (name.find('%') == std::string::npos) return path;
  const std::time_t now = std::time(nullptr);
  std::tm local{};
  ::localtime_r(&now, &local);
  char buf[512];
  const std::size_t n = std::strftime(buf, sizeof buf, name.c_str(), &local);
  if (n == 0) throw Error(ErrorKind::CantCreate, "recorder: cannot expand the time pattern in " + path.string(), "recorder.path");
  return path.parent_path() / std::string(buf, n);
}

// The engine's state through relaxed atomics: written by the engine thread, read for reports.
void store_fusion_state(StreamCounters::Fusion& f, const EstimatorState& e, std::uint64_t waiting) {
  constexpr auto relaxed = std::memory_order_relaxed;
  f.waiting.store(waiting, relaxed);
  f.updates.store(e.updates, relaxed);
  f.initialised.store(e.initialised, relaxed);
  f.nonfinite.store(e.nonfinite, relaxed);
  f.gyro_saturated.store(e.gyro_saturated, relaxed);
  f.mag_stuck.store(e.mag_stuck, relaxed);
  f.mag_absent.store(e.mag_absent, relaxed);
  f.bad_time_steps.store(e.bad_time_steps, relaxed);
  f.gaps.store(e.gaps, relaxed);
  f.state_resets.store(e.state_resets, relaxed);
  f.at_rest.store(e.at_rest, relaxed);
  f.mag_disturbed.store(e.mag_disturbed, relaxed);
  f.bias_x.store(e.gyro_bias.x(), relaxed);
  f.bias_y.store(e.gyro_bias.y(), relaxed);
  f.bias_z.store(e.gyro_bias.z(), relaxed);
}

EstimatorState load_fusion_state(const StreamCounters::Fusion& f) {
  constexpr auto relaxed = std::memory_order_relaxed;
  EstimatorState e;
  e.initialised = f.initialised.load(relaxed);
  e.updates = f.updates.load(relaxed);
  e.nonfinite = f.nonfinite.load(relaxed);
  e.gyro_saturated = f.gyro_saturated.load(relaxed);
  e.mag_stuck = f.mag_stuck.load(relaxed);
  e.mag_absent = f.mag_absent.load(relaxed);
  e.bad_time_steps = f.bad_time_steps.load(relaxed);
  e.gaps = f.gaps.load(relaxed);
  e.state_resets = f.state_resets.load(relaxed);
  e.at_rest = f.at_rest.load(relaxed);
  e.mag_disturbed = f.mag_disturbed.load(relaxed);
  e.gyro_bias = Vec3(f.bias_x.load(relaxed), f.bias_y.load(relaxed), f.bias_z.load(relaxed));
  return e;
}

void store_engine_state(StreamCounters& c, const EngineState& e) {
  constexpr auto relaxed = std::memory_order_relaxed;
  c.engine_rate_hz.store(e.rate_hz, relaxed);
  c.engine_window.store(e.window, relaxed);
  c.engine_repeating.store(e.repeating, relaxed);
  c.engine_slerped.store(e.slerped, relaxed);
  for (const bool rotation : {true, false}) {
    const ChannelAdaptation& from = rotation ? e.rotation : e.position;
    StreamCounters::Channel& to = rotation ? c.rotation : c.position;
    to.adaptive.store(from.adaptive, relaxed);
    to.noise.store(from.noise, relaxed);
    to.motion.store(from.motion, relaxed);
    to.smoothing.store(from.smoothing, relaxed);
    to.cutoff_hz.store(from.cutoff_hz, relaxed);
    to.at_rest.store(from.at_rest, relaxed);
    to.rest_averaged.store(from.rest_averaged, relaxed);
    to.noise_scale.store(from.noise_scale, relaxed);
    to.rest_noise.store(from.rest_noise, relaxed);
  }
  c.gyro.active.store(e.gyro.active, relaxed);
  c.gyro.offset_estimated.store(e.gyro.offset_estimated, relaxed);
  c.gyro.bias_x.store(e.gyro.bias.x(), relaxed);
  c.gyro.bias_y.store(e.gyro.bias.y(), relaxed);
  c.gyro.bias_z.store(e.gyro.bias.z(), relaxed);
  c.gyro.time_offset_s.store(e.gyro.time_offset_s, relaxed);
  c.gyro.intervals.store(e.gyro.intervals, relaxed);
}

EngineState load_engine_state(const StreamCounters& c) {
  constexpr auto relaxed = std::memory_order_relaxed;
  EngineState e;
  e.rate_hz = c.engine_rate_hz.load(relaxed);
  e.window = c.engine_window.load(relaxed);
  e.repeating = c.engine_repeating.load(relaxed);
  e.slerped = c.engine_slerped.load(relaxed);
  for (const bool rotation : {true, false}) {
    const StreamCounters::Channel& from = rotation ? c.rotation : c.position;
    ChannelAdaptation& to = rotation ? e.rotation : e.position;
    to.adaptive = from.adaptive.load(relaxed);
    to.noise = from.noise.load(relaxed);
    to.motion = from.motion.load(relaxed);
    to.smoothing = from.smoothing.load(relaxed);
    to.cutoff_hz = from.cutoff_hz.load(relaxed);
    to.at_rest = from.at_rest.load(relaxed);
    to.rest_averaged = from.rest_averaged.load(relaxed);
    to.noise_scale = from.noise_scale.load(relaxed);
    to.rest_noise = from.rest_noise.load(relaxed);
  }
  e.gyro.active = c.gyro.active.load(relaxed);
  e.gyro.offset_estimated = c.gyro.offset_estimated.load(relaxed);
  e.gyro.bias = Vec3(c.gyro.bias_x.load(relaxed), c.gyro.bias_y.load(relaxed), c.gyro.bias_z.load(relaxed));
  e.gyro.time_offset_s = c.gyro.time_offset_s.load(relaxed);
  e.gyro.intervals = c.gyro.intervals.load(relaxed);
  return e;
}

}  // namespace

// Drained per ring per pass, so one busy stream cannot starve the others.
constexpr int kPopBudget = 64;

struct Pipeline::Stream final : drivers::SampleSink {
  Stream(Pipeline& owner, const StreamConfig& c, MadeDriver made, std::uint32_t index, bool record)
      : pipeline(owner),
        config(c),
        index(index),
        driver(std::move(made.driver)),
        source(std::move(made.source)),
        window(c.engine),
        ring(c.ring_capacity, c.overflow),
        // The publisher ring drops the oldest pose (a subscriber wants the newest). It holds at
        // least two engine batches, so a publisher that is merely waiting to be scheduled never
        // loses a pose however small the input ring is.
        pose_ring(std::max<std::size_t>(c.ring_capacity, std::bit_ceil(static_cast<std::size_t>(2 * kPopBudget + c.engine.lag + 1))),
                  OverflowPolicy::DropOldest),
        outputs(static_cast<std::size_t>(window.max_outputs_per_push())) {
    if (c.spline.bridging()) {
      GapBridgeOptions o;
      o.max_gap = c.spline.bridge_gap;
      o.spline = c.spline.spline;
      o.interpolation = c.spline.pose_interpolation;
      bridge.emplace(o);
      bridged.resize(bridge->max_outputs());
    }
    if (c.spline.resampling()) {
      FixedRateResamplerOptions o;
      o.rate_hz = c.spline.publish_rate_hz;
      o.max_step = c.engine.gate.gap_threshold;  // the window restarts after a longer step
      o.spline = c.spline.spline;
      o.interpolation = c.spline.pose_interpolation;
      resampler.emplace(o);
      grid.resize(resampler->max_outputs());
    }
    if (record) record_ring = std::make_unique<SpscRing<RingSample>>(owner.config_.recorder.ring_capacity, OverflowPolicy::DropNewest);
    if (c.fusion) fusion.emplace(*c.fusion);  // its options were accepted at load
  }

  // Driver thread: hand the sample over (stamped), to the recorder too.
  bool push(const Sample& s) override {
    RingSample r = pack(s, monotonic_ns());
    r.stream_id = config.id;
    counters.received.fetch_add(1, std::memory_order_relaxed);
    if (record_ring) record_ring->push(r);
    const bool stored = ring.push(r);
    pipeline.handed_over(*this);
    return stored;
  }

  Pipeline& pipeline;
  StreamConfig config;
  std::uint32_t index;
  std::unique_ptr<drivers::Driver> driver;
  std::string source;
  FairingWindow window;                         // engine role only
  SpscRing<RingSample> ring;                    // driver → engine
  SpscRing<RingPose> pose_ring;                 // engine → publisher
  std::unique_ptr<SpscRing<RingSample>> record_ring;  // driver → recorder
  std::vector<FairedPose> outputs;              // engine scratch
  std::optional<GapBridge> bridge;              // engine role only; [stream.spline] bridge_gap
  std::vector<Sample> bridged;                  // engine scratch
  std::optional<FixedRateResampler> resampler;  // engine role only; [stream.spline] publish_rate_hz
  std::vector<FairedPose> grid;                 // engine scratch
  std::optional<FusionStage> fusion;            // engine role only; [stream.fusion]
  std::optional<GyroPairing> gyro_pairing;      // engine role only; [stream.engine] gyro_stream
  std::vector<GyroPairing*> gyro_consumers;     // the pairings this stream's gyroscope readings go to
  Stream* gyro_source = nullptr;                // [stream.engine] gyro_stream: the stream it reads
  // The stream's engine role (see take_engine_role): held by the one thread fairing it.
  std::atomic<bool> role{false};
  std::uint64_t pop_ns = 0;                     // engine role: when the sample being faired was popped
  bool stage_recorded = false;                  // engine role: that sample's engine stage is recorded
  StreamCounters counters;
  MadeGpioLines gpio;                           // [stream.gpio]: data-ready sink (driver thread), output line
  std::atomic<bool> driver_running{false};
  std::atomic<bool> driver_done{false};
  std::atomic<bool> flushed{false};             // written by the engine role's holder only
};

Pipeline::Pipeline(const DaemonConfig& config, std::uint32_t session,
                   const std::map<std::uint32_t, std::uint64_t>& first_sequence, bool defer_recorder, PipelineHooks hooks,
                   std::shared_ptr<SubscriberTable> subscribers)
    : config_(config),
      hooks_(std::move(hooks)),
      engine_wake_(config.daemon.wake_per_batch),
      publisher_wake_(config.daemon.wake_per_batch),
      engine_spin_(std::chrono::microseconds(config.daemon.spin_us)),
      publisher_spin_(std::chrono::microseconds(config.daemon.spin_us)) {
  const bool record = config_.recorder.enabled;
  std::vector<std::uint32_t> ids;
  std::vector<StreamFrame> frames;
  for (std::size_t i = 0; i < config_.streams.size(); ++i) {
    const StreamConfig& sc = config_.streams[i];
    // A source that cannot be used is a configuration error at the stream's key.
    const std::string stream_key = "stream[" + std::to_string(i + 1) + "]";
    MadeDriver made;
    try {
      made = make_driver(sc);
    } catch (const std::system_error&) {
      throw;
    } catch (const std::runtime_error& e) {
      throw Error(ErrorKind::Config, e.what(), stream_key + ".driver");
    }
    for (std::string& w : made.warnings) warnings_.push_back("stream '" + sc.name + "': " + w);
    header_.streams.push_back(formats::StreamInfo{sc.id, sc.name, made.source});
    streams_.push_back(std::make_unique<Stream>(*this, sc, std::move(made), static_cast<std::uint32_t>(i), record));
    try {
      streams_.back()->gpio = make_gpio_lines(sc, *streams_.back());
    } catch (const std::system_error&) {
      throw;
    } catch (const std::runtime_error& e) {
      throw Error(ErrorKind::Config, e.what(), stream_key + ".gpio");
    }
    ids.push_back(sc.id);
    frames.push_back(sc.frame);
  }
  pair_gyro_streams();
  publisher_ = std::make_unique<Publisher>(session, ids, config_.outputs, first_sequence, frames, std::move(subscribers));
  if (record && !defer_recorder) {
    formats::SampleLogWriterOptions wo;
    wo.max_file_bytes = config_.recorder.max_file_bytes;
    wo.flush_interval = config_.recorder.flush_interval;
    wo.overwrite = config_.recorder.overwrite;
    wo.sync = config_.recorder.sync;
    try {
      writer_ = std::make_unique<formats::SampleLogWriter>(expand_time_pattern(config_.recorder.path), header_, wo);
    } catch (const formats::SampleLogError& e) {
      throw Error(ErrorKind::CantCreate, std::string("recorder: ") + e.what(), "recorder.path");
    }
  }
}

Pipeline::~Pipeline() { stop(); }

// [stream.engine] gyro_stream: each paired stream's source feeds its pairing, and the engine
// visits a source before the streams it feeds, so a pass takes the readings before the samples
// they match (the config refused cycles and unknown names).
void Pipeline::pair_gyro_streams() {
  auto find = [&](const std::string& name) -> Stream* {
    for (auto& sp : streams_)
      if (sp->config.name == name) return sp.get();
    return nullptr;
  };
  for (auto& sp : streams_)
    if (Stream* source = sp->config.gyro_stream.empty() ? nullptr : find(sp->config.gyro_stream)) {
      sp->gyro_pairing.emplace();
      source->gyro_consumers.push_back(&*sp->gyro_pairing);
      sp->gyro_source = source;
    }
  std::vector<bool> placed(streams_.size(), false);
  auto place = [&](auto&& self, Stream* s, std::size_t depth) -> void {
    if (placed[s->index] || depth > streams_.size()) return;
    if (Stream* source = s->config.gyro_stream.empty() ? nullptr : find(s->config.gyro_stream)) self(self, source, depth + 1);
    placed[s->index] = true;
    engine_order_.push_back(s);
  };
  for (auto& sp : streams_) place(place, sp.get(), 0);
}

void Pipeline::wake_engine() {
  engine_wake_.notify();
}

void Pipeline::wake_publisher() {
  publisher_wake_.notify();
}

void Pipeline::poke_engine() { wake_engine(); }

std::vector<std::string> Pipeline::start() {
  std::vector<std::string> problems;
  if (started_) return problems;
  started_ = true;
  engine_thread_ = std::thread([this] { engine_loop(); });
  if (!engine_publishes()) publisher_thread_ = std::thread([this] { publisher_loop(); });
  std::vector<std::thread*> realtime{&engine_thread_};
  if (publisher_thread_.joinable()) realtime.push_back(&publisher_thread_);
  if (const int prio = config_.daemon.realtime_priority; prio > 0) {
    sched_param sp{};
    sp.sched_priority = prio;
    for (std::thread* t : realtime) {
      if (const int rc = ::pthread_setschedparam(t->native_handle(), SCHED_FIFO, &sp); rc != 0) {
        problems.push_back("realtime_priority " + std::to_string(prio) + " refused (" + std::strerror(rc) +
                           "): the engine runs with normal scheduling");
        break;
      }
    }
  }
  if (!config_.daemon.cpu_affinity.empty()) {
    cpu_set_t cpus;
    CPU_ZERO(&cpus);
    for (const int cpu : config_.daemon.cpu_affinity) CPU_SET(cpu, &cpus);
    for (std::thread* t : realtime) {
      if (const int rc = ::pthread_setaffinity_np(t->native_handle(), sizeof cpus, &cpus); rc != 0) {
        problems.push_back(std::string("cpu_affinity refused (") + std::strerror(rc) + "): the engine runs on any CPU");
        break;
      }
    }
  }
  if (config_.recorder.enabled) recorder_thread_ = std::thread([this] { recorder_loop(); });
  for (auto& sp : streams_)
    if (sp->gpio.output) sp->gpio.output->start();
  drivers_running_.store(static_cast<int>(streams_.size()), std::memory_order_release);
  for (auto& sp : streams_) {
    Stream* s = sp.get();
    s->driver_running.store(true, std::memory_order_release);
    driver_threads_.emplace_back([this, s](std::stop_token stop) {
      // "pf-d-<stream>", cut to the 15 characters Linux keeps.
      ::pthread_setname_np(::pthread_self(), ("pf-d-" + s->config.name).substr(0, 15).c_str());
      // With a data-ready line the driver pushes into it, and it into the stream.
      s->driver->run(stop, s->gpio.data_ready ? static_cast<drivers::SampleSink&>(*s->gpio.data_ready) : *s);
      if (s->gpio.data_ready) s->gpio.data_ready->release();
      s->driver_running.store(false, std::memory_order_release);
      s->driver_done.store(true, std::memory_order_release);
      drivers_running_.fetch_sub(1, std::memory_order_acq_rel);
      wake_engine();
    });
  }
  // With fair_on = "driver" the driver threads do the engine's work: they get its priority.
  if (const int prio = config_.daemon.realtime_priority; prio > 0 && config_.daemon.fair_on == FairThread::Driver) {
    sched_param sp{};
    sp.sched_priority = prio;
    for (std::jthread& t : driver_threads_) {
      if (const int rc = ::pthread_setschedparam(t.native_handle(), SCHED_FIFO, &sp); rc != 0) {
        problems.push_back("realtime_priority " + std::to_string(prio) + " refused for the driver threads (" +
                           std::strerror(rc) + "): they fair with normal scheduling");
        break;
      }
    }
  }
  return problems;
}

bool Pipeline::busy_polling() const {
  return std::any_of(streams_.begin(), streams_.end(),
                     [](const auto& s) { return s->config.busy_poll && !s->driver_done.load(std::memory_order_relaxed); });
}

bool Pipeline::sources_ended() const { return started_ && drivers_running_.load(std::memory_order_acquire) == 0; }

void Pipeline::stop(bool keep_recorder) {
  if (!started_ || stopped_) {
    if (!started_ && !stopped_ && !keep_recorder && writer_) writer_->close();
    stopped_ = true;
    if (publisher_) final_sequences_ = publisher_->next_sequences();
    return;
  }
  stopped_ = true;
  for (auto& t : driver_threads_) t.request_stop();
  for (auto& t : driver_threads_) t.join();
  // Drivers are done: the engine drains their rings and flushes the windows, then ends.
  engine_stop_.store(true, std::memory_order_release);
  wake_engine();
  engine_thread_.join();
  publisher_stop_.store(true, std::memory_order_release);
  wake_publisher();
  if (publisher_thread_.joinable()) publisher_thread_.join();
  for (auto& sp : streams_)
    if (sp->gpio.output) sp->gpio.output->stop();  // the line is free for the next pipeline
  if (recorder_thread_.joinable()) {
    recorder_stop_.store(true, std::memory_order_release);
    recorder_thread_.join();
  }
  if (writer_ && !keep_recorder) writer_->close();
  final_sequences_ = publisher_->next_sequences();
}

// Engine role: a faired pose to the publisher as it is, or as the grid poses it completes
// when the stream is resampled. True when anything was handed on.
bool Pipeline::emit(Stream& s, const FairedPose& pose, std::uint64_t enqueued_ns) {
  if (!s.resampler) {
    deliver(s, pose, enqueued_ns);
    return true;
  }
  const std::size_t n = s.resampler->push(pose, s.grid);
  for (std::size_t i = 0; i < n; ++i) deliver(s, s.grid[i], enqueued_ns);
  s.counters.resampled.fetch_add(n, std::memory_order_relaxed);
  return n > 0;
}

// Engine role: a pose made, to the publisher's ring, or sent at once when the engine publishes.
// The first pose of a sample ends the sample's engine stage.
void Pipeline::deliver(Stream& s, const FairedPose& pose, std::uint64_t enqueued_ns) {
  const std::uint64_t now = monotonic_ns();
  if (!s.stage_recorded) {
    stages_.engine.record(now - s.pop_ns);
    s.stage_recorded = true;
  }
  const RingPose p = pack(pose, s.index, enqueued_ns, now);
  if (engine_publishes())
    publish_pose(s, p, now);
  else
    s.pose_ring.push(p);
}

// The publishing thread (the publisher's, or the engine's): one pose sent and counted.
void Pipeline::publish_pose(Stream& s, const RingPose& p, std::uint64_t popped_ns) {
  const Publisher::Result res = publisher_->publish(p);
  const std::uint64_t done = monotonic_ns();
  s.counters.published.fetch_add(1, std::memory_order_relaxed);
  if (s.gpio.output) s.gpio.output->on_pose();  // the scope's edge: this pose has been sent
  if (res.failures) s.counters.send_failures.fetch_add(res.failures, std::memory_order_relaxed);
  s.counters.latency.record(done - p.enqueued_ns);
  if (!engine_publishes()) stages_.hand_off.record(popped_ns - p.faired_ns);
  stages_.encode.record(res.encode_ns);
  stages_.send.record(res.send_ns);
}

// Engine role: one sample into the window, its faired poses handed on.
bool Pipeline::window_push(Stream& s, const Sample& sample, std::uint64_t enqueued_ns) {
  bool any = false;
  const int k = s.window.push(sample, s.outputs);
  for (int j = 0; j < k; ++j) any = emit(s, s.outputs[static_cast<std::size_t>(j)], enqueued_ns) || any;
  return any;
}

// Engine role: one sample from the driver, through the fusion stage and the gap bridge when
// the stream has them.
bool Pipeline::fair(Stream& s, const Sample& raw, std::uint64_t enqueued_ns) {
  Sample sample = raw;
  if (s.fusion && !s.fusion->apply(sample)) return false;
  if (s.gyro_pairing) s.gyro_pairing->apply(sample);
  if (!s.bridge) return window_push(s, sample, enqueued_ns);
  bool any = false;
  const std::size_t n = s.bridge->push(sample, s.bridged);
  for (std::size_t i = 0; i < n; ++i) any = window_push(s, s.bridged[i], enqueued_ns) || any;
  return any;
}

// Engine role, after the stream's driver ended and its ring is empty: the sample the bridge
// holds, then the window's lagged tail.
void Pipeline::flush_stream(Stream& s) {
  const std::uint64_t now = monotonic_ns();
  s.pop_ns = now;
  s.stage_recorded = false;
  if (s.bridge) {
    const std::size_t n = s.bridge->flush(s.bridged);
    for (std::size_t i = 0; i < n; ++i) window_push(s, s.bridged[i], now);
  }
  const int k = s.window.flush(s.outputs);
  for (int j = 0; j < k; ++j) emit(s, s.outputs[static_cast<std::size_t>(j)], now);
}

// The holder of s's engine role (the engine thread, or with [daemon] fair_on = "driver" a driver
// thread): s's ring drained (a bounded batch), s flushed when its driver has ended, its counters
// stored. True when anything was done.
bool Pipeline::stream_pass(Stream& s) {
  // A gyro_stream source first, when its role is free, so this pass has the readings up to the
  // samples it fairs (as the engine thread's order has them).
  if (s.gyro_source && config_.daemon.fair_on == FairThread::Driver) {
    if (fair_stream(*s.gyro_source, 1).left) wake_engine();  // what is left: the engine thread's
  }
  bool any = false;
  bool emitted = false;
  RingSample r;
  for (int budget = kPopBudget; budget > 0 && s.ring.pop(r); --budget) {
    any = true;
    s.pop_ns = monotonic_ns();
    s.stage_recorded = false;
    stages_.ring_wait.record(s.pop_ns - r.enqueued_ns);
    if (hooks_.before_engine_sample) hooks_.before_engine_sample(s.config.id);
    const Sample sample = unpack(r);
    if (sample.has_gyro())
      for (GyroPairing* p : s.gyro_consumers) p->add(sample.time, sample.gyro);
    // A raw-only sample's quaternion is a placeholder, not a measurement: without a fusion
    // stage ([stream.fusion]) to make an orientation from its readings it must not reach
    // the window (the recorder has it already). Counted, and the stream goes on.
    if (!sample.has_orientation() && !s.fusion) {
      s.counters.raw_unfused.fetch_add(1, std::memory_order_relaxed);
      continue;
    }
    emitted = fair(s, sample, r.enqueued_ns) || emitted;
  }
  // The driver has ended and everything it delivered is in: hand over the lagged tail.
  if (!s.flushed.load(std::memory_order_relaxed) && s.driver_done.load(std::memory_order_acquire) &&
      s.ring.size_approx() == 0) {
    flush_stream(s);
    s.flushed.store(true, std::memory_order_relaxed);
    any = emitted = true;
  }
  // Wake the publisher after each stream's batch (not after a pass over every stream), so it
  // works alongside the engine instead of after it.
  if (emitted && !engine_publishes()) wake_publisher();
  const GateCounters& g = s.window.gate_counters();
  const WindowCounters& w = s.window.counters();
  s.counters.rejected.store(g.rejected(), std::memory_order_relaxed);
  s.counters.out_of_order.store(g.dropped(), std::memory_order_relaxed);
  s.counters.emitted.store(w.emitted, std::memory_order_relaxed);
  s.counters.clamped.store(w.clamped, std::memory_order_relaxed);
  s.counters.outliers_held.store(w.held, std::memory_order_relaxed);
  s.counters.outliers_released.store(w.released, std::memory_order_relaxed);
  s.counters.restarts.store(w.restarts, std::memory_order_relaxed);
  s.counters.rate_changes.store(w.rate_changes, std::memory_order_relaxed);
  s.counters.repeated.store(w.repeated, std::memory_order_relaxed);
  s.counters.interpolated.store(w.interpolated, std::memory_order_relaxed);
  s.counters.lost.store(w.lost, std::memory_order_relaxed);
  s.counters.gyro.bridged.store(w.gyro_bridged, std::memory_order_relaxed);
  store_engine_state(s.counters, s.window.state());
  if (s.gyro_pairing) {
    s.counters.gyro.matched.store(s.gyro_pairing->matched(), std::memory_order_relaxed);
    s.counters.gyro.unmatched.store(s.gyro_pairing->unmatched(), std::memory_order_relaxed);
  }
  if (s.bridge) {
    s.counters.bridged_gaps.store(s.bridge->counters().gaps, std::memory_order_relaxed);
    s.counters.bridged_samples.store(s.bridge->counters().samples, std::memory_order_relaxed);
    s.counters.unbridged_gaps.store(s.bridge->counters().too_long + s.bridge->counters().clumped, std::memory_order_relaxed);
  }
  if (s.fusion) store_fusion_state(s.counters.fusion, s.fusion->state(), s.fusion->waiting());
  if (s.bridge || s.resampler)
    s.counters.lerp_fallbacks.store((s.bridge ? s.bridge->counters().lerp_fallbacks : 0) +
                                        (s.resampler ? s.resampler->lerp_fallbacks() : 0),
                                    std::memory_order_relaxed);
  return any;
}

// The engine thread's pass: every stream whose role is free (a gyro_stream source before the
// streams it feeds). True when anything was done or is left to do.
bool Pipeline::engine_pass() {
  heartbeat_.fetch_add(1, std::memory_order_relaxed);
  bool any = false;
  for (Stream* sp : engine_order_) {
    const StreamFairing f = fair_stream(*sp, 1);
    any = any || f.worked || f.left;
  }
  return any;
}

// Each stream has its own engine role: a flag that one thread at a time holds (its driver thread
// that has just pushed a sample, the engine thread, or the driver thread of a stream it is the
// gyro_stream source of). Taking and releasing it orders everything the holders touch (the window,
// the stream's publisher state) as one thread alone would be ordered; what streams share (the
// stage histograms, the sockets, a gyro pairing's inbox) is safe across threads on its own. So a
// driver thread never waits for another stream's pass, and a stalled thread holds up only its
// own stream. Both are exchanges (read-modify-write, acquire and release): a hand-over that finds
// the role taken still writes the flag after its push into the ring, so the holder's releasing
// exchange reads that write and sees the push, and its look for work afterwards finds the
// sample. Either the hand-over takes the role, or the holder sees its sample: none is left
// behind (and ThreadSanitizer can follow it, which it cannot with fences).
bool Pipeline::take_engine_role(Stream& s) { return !s.role.exchange(true, std::memory_order_acq_rel); }

void Pipeline::release_engine_role(Stream& s) { s.role.exchange(false, std::memory_order_acq_rel); }

// Work a holder must not leave behind when it lets go of the role: a sample in the ring, or a
// driver that ended and a window not flushed yet.
bool Pipeline::engine_work_pending(const Stream& s) const {
  return s.ring.size_approx() > 0 ||
         (s.driver_done.load(std::memory_order_acquire) && !s.flushed.load(std::memory_order_relaxed));
}

// Passes s under its engine role until nothing is left for it, at most `rounds` times. Nothing
// is left to the caller when it is done or when another thread holds the role (which then sees
// the work: see take_engine_role); `left` when work remains after the last round.
Pipeline::StreamFairing Pipeline::fair_stream(Stream& s, int rounds) {
  StreamFairing f;
  for (int round = 1; round <= rounds; ++round) {
    if (!take_engine_role(s)) return f;
    f.worked = stream_pass(s) || f.worked;
    release_engine_role(s);
    if (!engine_work_pending(s)) return f;
  }
  f.left = true;
  return f;
}

// A driver thread has just pushed a sample into s's ring. With fair_on = "driver" it fairs and
// publishes it here, with no wake and no second thread; a driver thread must get back to its
// device, so after a few passes it leaves the rest to the engine thread.
void Pipeline::handed_over(Stream& s) {
  if (config_.daemon.fair_on != FairThread::Driver) {
    wake_engine();
    return;
  }
  if (hooks_.on_engine_role) hooks_.on_engine_role(true);
  const bool left = fair_stream(s, kDriverPasses).left;
  if (hooks_.on_engine_role) hooks_.on_engine_role(false);
  if (left) wake_engine();
}

void Pipeline::engine_loop() {
  ::pthread_setname_np(::pthread_self(), "pf-engine");  // for top -H, perf and gdb
  if (hooks_.on_realtime_thread_start) hooks_.on_realtime_thread_start();
  const bool shared = config_.daemon.fair_on == FairThread::Driver;
  for (;;) {
    const std::uint32_t seen = engine_wake_.prepare();
    // With fair_on = "driver" this fairs what no driver thread did: a stream's end, the drain at
    // stop, the samples a driver left after its passes; the drivers do the rest.
    if (engine_pass()) continue;
    if (engine_stop_.load(std::memory_order_acquire)) return;
    if (busy_polling()) {  // a busy_poll stream runs: look again at once, never park
      cpu_relax();
      continue;
    }
    // Nothing hands samples to this thread with fair_on = "driver": no spin for them.
    if (shared)
      engine_wake_.wait(seen);
    else
      engine_wake_.wait(seen, engine_spin_);
  }
}

void Pipeline::publisher_loop() {
  ::pthread_setname_np(::pthread_self(), "pf-publish");
  if (hooks_.on_realtime_thread_start) hooks_.on_realtime_thread_start();
  for (;;) {
    const std::uint32_t seen = publisher_wake_.prepare();
    bool any = false;
    for (auto& sp : streams_) {
      Stream& s = *sp;
      RingPose p;
      for (int budget = kPopBudget; budget > 0 && s.pose_ring.pop(p); --budget) {
        any = true;
        publish_pose(s, p, monotonic_ns());
      }
    }
    if (any) continue;
    if (publisher_stop_.load(std::memory_order_acquire)) return;
    publisher_wake_.wait(seen, publisher_spin_);
  }
}

void Pipeline::recorder_loop() {
  ::pthread_setname_np(::pthread_self(), "pf-record");
  using clock = std::chrono::steady_clock;
  const auto t0 = clock::now();
  for (;;) {
    // Read the flag first: once it is set every driver has returned, so one more full pass
    // after seeing it takes everything.
    const bool stopping = recorder_stop_.load(std::memory_order_acquire);
    for (auto& sp : streams_) {
      Stream& s = *sp;
      RingSample r;
      while (s.record_ring->pop(r)) {
        if (!recording_.load(std::memory_order_relaxed)) {
          s.counters.record_paused.fetch_add(1, std::memory_order_relaxed);
          continue;
        }
        // A sample the writer refuses (its buffer full while the disk refuses writes) is lost:
        // counted as a recorder drop, never as recorded.
        if (writer_ && !writer_->append(unpack(r))) {
          s.counters.record_refused.fetch_add(1, std::memory_order_relaxed);
          continue;
        }
        s.counters.recorded.fetch_add(1, std::memory_order_relaxed);
      }
    }
    if (writer_) {
      writer_->maybe_flush(std::chrono::duration<double>(clock::now() - t0).count());
      recorder_errno_.store(writer_->failing() ? writer_->stats().last_errno : 0, std::memory_order_relaxed);
    }
    if (stopping) {
      if (writer_) writer_->flush();
      return;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
}

std::vector<StreamStats> Pipeline::stats() const {
  std::vector<StreamStats> out;
  for (const auto& sp : streams_) {
    const Stream& s = *sp;
    StreamStats st;
    st.id = s.config.id;
    st.name = s.config.name;
    st.driver = s.source;
    st.driver_running = s.driver_running.load(std::memory_order_relaxed);
    const auto get = [](const std::atomic<std::uint64_t>& a) { return a.load(std::memory_order_relaxed); };
    st.received = get(s.counters.received);
    st.ring_dropped = s.ring.dropped();
    st.rejected = get(s.counters.rejected);
    st.out_of_order = get(s.counters.out_of_order);
    st.raw_unfused = get(s.counters.raw_unfused);
    st.emitted = get(s.counters.emitted);
    st.clamped = get(s.counters.clamped);
    st.outliers_held = get(s.counters.outliers_held);
    st.outliers_released = get(s.counters.outliers_released);
    st.restarts = get(s.counters.restarts);
    st.rate_changes = get(s.counters.rate_changes);
    st.repeated = get(s.counters.repeated);
    st.interpolated = get(s.counters.interpolated);
    st.lost = get(s.counters.lost);
    st.gyro_bridged = get(s.counters.gyro.bridged);
    st.engine = load_engine_state(s.counters);
    st.publish_dropped = s.pose_ring.dropped();
    st.published = get(s.counters.published);
    st.send_failures = get(s.counters.send_failures);
    st.recorded = get(s.counters.recorded);
    st.record_dropped =
        (s.record_ring ? s.record_ring->dropped() : 0) + get(s.counters.record_paused) + get(s.counters.record_refused);
    st.latency = s.counters.latency.snapshot();
    st.device = s.driver->health();
    if (s.gpio.data_ready) st.data_ready = s.gpio.data_ready->counters();
    if (s.gpio.output) st.gpio_output = s.gpio.output->counters();
    st.bridging = s.config.spline.bridging();
    st.resampling = s.config.spline.resampling();
    st.bridged_gaps = get(s.counters.bridged_gaps);
    st.bridged_samples = get(s.counters.bridged_samples);
    st.unbridged_gaps = get(s.counters.unbridged_gaps);
    st.resampled = get(s.counters.resampled);
    st.matrix_lerp = s.config.spline.pose_interpolation == PoseInterpolation::MatrixLerp;
    st.lerp_fallbacks = get(s.counters.lerp_fallbacks);
    if (s.gyro_pairing)
      st.gyro_pairing = GyroPairingStats{s.config.gyro_stream, get(s.counters.gyro.matched), get(s.counters.gyro.unmatched)};
    if (s.fusion) {
      st.fusion = load_fusion_state(s.counters.fusion);
      st.fusion_waiting = get(s.counters.fusion.waiting);
    }
    out.push_back(std::move(st));
  }
  return out;
}

void Pipeline::continue_sequences(const std::map<std::uint32_t, std::uint64_t>& next_sequence) {
  if (started_) throw std::logic_error("Pipeline::continue_sequences after start");
  publisher_->continue_from(next_sequence);
}

std::map<std::uint32_t, std::uint64_t> Pipeline::next_sequences() const { return final_sequences_; }

std::unique_ptr<formats::SampleLogWriter> Pipeline::release_recorder() { return std::move(writer_); }

void Pipeline::adopt_recorder(std::unique_ptr<formats::SampleLogWriter> writer) {
  if (started_) throw std::logic_error("Pipeline::adopt_recorder after start");
  writer_ = std::move(writer);
}

bool Pipeline::same_recording(const Pipeline& other) const {
  const RecorderConfig& a = config_.recorder;
  const RecorderConfig& b = other.config_.recorder;
  return a.enabled && b.enabled && a.path == b.path && a.max_file_bytes == b.max_file_bytes &&
         a.flush_interval == b.flush_interval && a.sync == b.sync && header_ == other.header_;
}

}  // namespace posefair::daemon
