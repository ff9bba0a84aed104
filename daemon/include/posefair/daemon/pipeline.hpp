#pragma once
// One running configuration of posefaird: its drivers, rings, engine, publisher and recorder.
//
//   driver thread (one per stream) ─► ring (SPSC, per stream) ─► engine thread ─► ring (per
//   stream) ─► publisher thread ─► UDP;   driver thread ─► ring (per stream) ─► recorder thread
//
// The engine thread owns every FairingWindow and never blocks, allocates or logs; it sleeps on
// a futex (WakeSignal) only when every ring is empty (after a bounded adaptive spin with
// [daemon] spin_us, never while a busy_poll stream runs). With [daemon] publish_on = "engine"
// it sends the poses itself, right after fairing (no second hop, no publisher thread); with
// "publisher" a publisher thread is fed through rings, so a slow network cannot stall the
// engine. Each ring's overflow is counted. Every stage's latency is kept (stage_latency.hpp).
// With [daemon] fair_on = "driver" (the default) the driver thread that hands a sample over fairs
// it (and, with publish_on = "engine", sends it) itself: each stream has an engine role, a flag
// one thread holds at a time, which its driver takes unless the engine thread holds it. Drivers
// of different streams fair at once and never wait for each other. The engine thread keeps only
// what no driver does (a stream's end, the drain at stop, the watchdog's poke, what a driver
// left after its passes). No wake, no hop between threads.
// A SIGHUP reload builds a new Pipeline from the new config while the old one runs, then stops
// the old one (drained) and starts the new one: the swap is whole.
#include <atomic>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "posefair/daemon/adaptive_spin.hpp"
#include "posefair/daemon/config.hpp"
#include "posefair/daemon/ring_items.hpp"
#include "posefair/daemon/stage_latency.hpp"
#include "posefair/daemon/stream_counters.hpp"
#include "posefair/daemon/subscriber_table.hpp"
#include "posefair/daemon/wake_signal.hpp"
#include "posefair/formats/sample_log.hpp"

namespace posefair::daemon {

struct PipelineHooks {
  // Called on the engine thread before each sample is faired (tests: a deliberately slow consumer).
  std::function<void(std::uint32_t stream_id)> before_engine_sample;
  // Called first thing on the engine thread and on the publisher thread (tests: count what
  // those threads allocate).
  std::function<void()> on_realtime_thread_start;
  // Called on a driver thread before it tries its stream's engine role (true) and after it has let
  // it go (false), with fair_on = "driver" (tests: count what a driver thread allocates while it fairs).
  std::function<void(bool held)> on_engine_role;
};

class Pipeline {
 public:
  // Builds everything that can fail before anything runs: drivers (replay sources are loaded),
  // sockets, the recording file (unless adopt_recorder() will hand one over). A recorder path
  // containing '%' is expanded by strftime at the local time now ("run-%Y%m%d-%H%M%S.pflog"),
  // so a service restarted by systemd starts a new file instead of refusing an existing one. Throws
  // posefair::Error naming the stream or output: of kind Config (an unusable source, with the
  // stream's key) or CantCreate (the recording, key "recorder.path"); std::system_error for a
  // socket the OS refused. `session` and `first_sequence` continue the wire protocol across reloads.
  // `subscribers`: the subscription port's table (may be null), which the publisher sends to too.
  Pipeline(const DaemonConfig& config, std::uint32_t session, const std::map<std::uint32_t, std::uint64_t>& first_sequence,
           bool defer_recorder = false, PipelineHooks hooks = {}, std::shared_ptr<SubscriberTable> subscribers = nullptr);
  ~Pipeline();
  Pipeline(const Pipeline&) = delete;
  Pipeline& operator=(const Pipeline&) = delete;

  // Starts the threads (once). Returns problems worth a warning (real-time priority refused).
  std::vector<std::string> start();
  // Stops the drivers, then drains: every sample already handed over is faired, every window
  // flushed, every pose sent, every recorded sample written and the recording synced and closed
  // (unless keep_recorder). Idempotent.
  void stop(bool keep_recorder = false);
  // Every driver has returned on its own (a replay reached its end). stop() then drains the rest.
  bool sources_ended() const;

  std::vector<StreamStats> stats() const;
  // Latency by stage over every stream since start (docs/benchmarks.md, "Latency by stage").
  StageLatencySnapshot stage_latency() const { return stages_.snapshot(); }
  // Before start(): continue the wire sequence numbers from a stopped pipeline's (a reload).
  void continue_sequences(const std::map<std::uint32_t, std::uint64_t>& next_sequence);
  // The wire sequence number each stream continues from (after stop()).
  std::map<std::uint32_t, std::uint64_t> next_sequences() const;
  // Liveness of the engine thread for the systemd watchdog: poke, then see the heartbeat move.
  std::uint64_t engine_heartbeat() const { return heartbeat_.load(std::memory_order_relaxed); }
  void poke_engine();

  const DaemonConfig& config() const { return config_; }
  // `posefair ctl record stop|start`: the recorder thread discards samples (counted as recorder
  // drops) instead of writing them, or writes again. Only with a [recorder]; true at start.
  void set_recording(bool on) { recording_.store(on, std::memory_order_relaxed); }
  bool recording() const { return config_.recorder.enabled && recording_.load(std::memory_order_relaxed); }
  // 0 while the recording's writes succeed; the errno of the failure (ENOSPC, EIO, ...) while
  // they fail. The main thread logs the changes (the recorder thread does not log).
  int recorder_errno() const { return recorder_errno_.load(std::memory_order_relaxed); }
  // Accepted damage in replay sources etc., to be logged once by the caller.
  const std::vector<std::string>& warnings() const { return warnings_; }
  // The recording's header (stream table) this pipeline writes or would write.
  const formats::SampleLogHeader& recording_header() const { return header_; }
  // Recorder hand-over at a reload that leaves the recording unchanged: the old pipeline,
  // stopped with keep_recorder, releases its writer; the new one, built with defer_recorder,
  // adopts it before start().
  std::unique_ptr<formats::SampleLogWriter> release_recorder();
  void adopt_recorder(std::unique_ptr<formats::SampleLogWriter> writer);
  // The same recording (config and stream table): a reload may hand the writer over.
  bool same_recording(const Pipeline& other) const;

 private:
  struct Stream;
  void engine_loop();
  bool engine_pass();
  bool stream_pass(Stream& s);
  bool take_engine_role(Stream& s);
  void release_engine_role(Stream& s);
  bool engine_work_pending(const Stream& s) const;
  struct StreamFairing {
    bool worked = false;  // a pass did something
    bool left = false;    // work remains for the stream after the last round
  };
  StreamFairing fair_stream(Stream& s, int rounds);
  void handed_over(Stream& s);  // a driver thread has pushed a sample into its stream's ring
  static constexpr int kDriverPasses = 4;  // fair_on = "driver": passes a driver thread makes at most
  bool emit(Stream& s, const FairedPose& pose, std::uint64_t enqueued_ns);
  void deliver(Stream& s, const FairedPose& pose, std::uint64_t enqueued_ns);
  void publish_pose(Stream& s, const RingPose& pose, std::uint64_t popped_ns);
  bool engine_publishes() const { return config_.daemon.publish_on == PublishThread::Engine; }
  bool window_push(Stream& s, const Sample& sample, std::uint64_t enqueued_ns);
  bool fair(Stream& s, const Sample& sample, std::uint64_t enqueued_ns);
  void flush_stream(Stream& s);
  void pair_gyro_streams();
  bool busy_polling() const;  // a busy_poll stream's driver still runs
  void publisher_loop();
  void recorder_loop();
  void wake_engine();
  void wake_publisher();

  DaemonConfig config_;
  PipelineHooks hooks_;
  std::vector<std::unique_ptr<Stream>> streams_;
  std::vector<Stream*> engine_order_;  // streams_, each gyro_stream source before the streams it feeds
  std::vector<std::string> warnings_;
  formats::SampleLogHeader header_;
  std::unique_ptr<class Publisher> publisher_;
  std::unique_ptr<formats::SampleLogWriter> writer_;
  std::map<std::uint32_t, std::uint64_t> final_sequences_;

  WakeSignal engine_wake_;
  WakeSignal publisher_wake_;
  AdaptiveSpin engine_spin_, publisher_spin_;  // each used by its own thread only
  StageLatency stages_;
  std::atomic<std::uint64_t> heartbeat_{0};
  std::atomic<bool> engine_stop_{false};
  std::atomic<bool> publisher_stop_{false};
  std::atomic<bool> recorder_stop_{false};
  std::atomic<bool> recording_{true};
  std::atomic<int> recorder_errno_{0};
  std::atomic<int> drivers_running_{0};
  std::thread engine_thread_, publisher_thread_, recorder_thread_;
  std::vector<std::jthread> driver_threads_;
  bool started_ = false;
  bool stopped_ = false;
};

}  // namespace posefair::daemon
