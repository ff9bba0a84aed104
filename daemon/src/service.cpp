#include "posefair/daemon/service.hpp"

#include <poll.h>
#include <signal.h>
#include <sys/random.h>
#include <sys/signalfd.h>
#include <sys/stat.h>
#include <systemd/sd-daemon.h>
#include <unistd.h>

#include <spdlog/sinks/stdout_sinks.h>
#include <spdlog/sinks/systemd_sink.h>
#include <spdlog/spdlog.h>

#include <chrono>
#include <cinttypes>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <string>
#include <system_error>

#include "posefair/core/error.hpp"
#include "posefair/daemon/config.hpp"
#include "posefair/daemon/control_reply.hpp"
#include "posefair/daemon/control_server.hpp"
#include "posefair/daemon/pipeline.hpp"
#include "posefair/daemon/status_report.hpp"
#include "posefair/daemon/subscription_server.hpp"

namespace posefair::daemon {
namespace {

using Clock = std::chrono::steady_clock;

// stderr is the journal when systemd says so (JOURNAL_STREAM holds its device and inode).
bool stderr_is_journal() {
  const char* js = std::getenv("JOURNAL_STREAM");
  if (!js) return false;
  unsigned long long dev = 0, ino = 0;
  if (std::sscanf(js, "%llu:%llu", &dev, &ino) != 2) return false;
  struct stat st{};
  return ::fstat(STDERR_FILENO, &st) == 0 && st.st_dev == dev && st.st_ino == ino;
}

void setup_logging(const LoggingConfig& lc, const ServiceOptions& o) {
  LogTarget target = lc.target;
  if (o.log_target) target = *o.log_target == "journald" ? LogTarget::Journald : LogTarget::Stderr;
  const bool journald = target == LogTarget::Journald || (target == LogTarget::Auto && stderr_is_journal());
  std::shared_ptr<spdlog::logger> logger;
  if (journald) {
    logger = std::make_shared<spdlog::logger>("posefaird", std::make_shared<spdlog::sinks::systemd_sink_mt>("posefaird"));
    logger->set_pattern("%v");  // the journal stamps time, priority and unit itself
  } else {
    logger = std::make_shared<spdlog::logger>("posefaird", std::make_shared<spdlog::sinks::stderr_sink_mt>());
    logger->set_pattern("%Y-%m-%d %H:%M:%S.%e posefaird %l: %v");
  }
  logger->set_level(spdlog::level::from_str(o.log_level.value_or(lc.level)));
  logger->flush_on(spdlog::level::info);
  spdlog::set_default_logger(logger);
}

std::uint32_t random_session() {
  std::uint32_t v = 0;
  if (::getrandom(&v, sizeof v, 0) != static_cast<ssize_t>(sizeof v))
    v = static_cast<std::uint32_t>(Clock::now().time_since_epoch().count() ^ ::getpid());
  return v;
}

void notify(const std::string& message) { ::sd_notify(0, message.c_str()); }

// Builds a pipeline, mapping its failures onto exit codes by their kind (0 = built): an Error
// says its kind; a socket the OS refused (std::system_error) is OsErr; any other runtime_error
// from a source is an unusable source named in the configuration, Config.
int build(const DaemonConfig& config, std::uint32_t session, const std::map<std::uint32_t, std::uint64_t>& sequences,
          bool defer_recorder, std::unique_ptr<Pipeline>& out, std::shared_ptr<SubscriberTable> subscribers = nullptr) {
  try {
    out = std::make_unique<Pipeline>(config, session, sequences, defer_recorder, PipelineHooks{}, std::move(subscribers));
    return kExitOk;
  } catch (const Error& e) {
    spdlog::error("{}: {}", config.source_file.string(), e.what());
    return e.exit_code();
  } catch (const std::system_error& e) {
    spdlog::error("{}: {}", config.source_file.string(), e.what());
    return exit_code(ErrorKind::OsErr);
  } catch (const std::runtime_error& e) {
    spdlog::error("{}: {}", config.source_file.string(), e.what());
    return exit_code(ErrorKind::Config);
  }
}

void log_counters(const Pipeline& p, const std::vector<StreamStats>& previous, double seconds) {
  for (const std::string& line : counter_lines(p.stats(), previous, seconds)) spdlog::info("{}", line);
}

class Service {
 public:
  explicit Service(ServiceOptions o) : options_(std::move(o)) {}

  int run() {
    // Every thread started from here inherits the mask; only the signalfd below sees them.
    sigset_t signals;
    sigemptyset(&signals);
    for (int s : {SIGTERM, SIGINT, SIGHUP, SIGUSR1}) sigaddset(&signals, s);
    ::pthread_sigmask(SIG_BLOCK, &signals, nullptr);

    DaemonConfig config;
    try {
      config = load_config(options_.config);
    } catch (const ConfigError& e) {
      std::fprintf(stderr, "posefaird: %s\n", e.what());
      return e.exit_code();
    }
    setup_logging(config.logging, options_);
    session_ = config.daemon.session_id ? *config.daemon.session_id : random_session();
    if (int rc = open_control(config); rc != kExitOk) return rc;
    if (int rc = build(config, session_, {}, options_.check_only, pipeline_, subscribers()); rc != kExitOk) return rc;
    for (const std::string& w : pipeline_->warnings()) spdlog::warn("{}", w);
    if (options_.check_only) {
      std::printf("%s: ok (%zu streams, %zu outputs%s)\n", options_.config.c_str(), config.streams.size(),
                  config.outputs.size(), config.recorder.enabled ? ", recorder" : "");
      pipeline_.reset();
      return kExitOk;
    }
    for (const std::string& w : pipeline_->start()) spdlog::warn("{}", w);
    started_ = Clock::now();
    if (subscription_) {
      subscription_->handler().set_streams(stream_ids(config));
      subscription_->start();
      spdlog::info("subscription port on {} ({} allowed ranges{})", subscription_->local_endpoint().to_string(),
                   config.subscription->allow.ranges().size(), config.subscription->psk ? ", pre-shared key" : "");
    }
    if (control_) spdlog::info("control socket {}", control_->config().path.string());
    spdlog::info("started: {} streams, {} outputs, session {:08x}, config {}", config.streams.size(),
                 config.outputs.size(), session_, options_.config.string());
    mark_interval();
    last_log_ = Clock::now();
    last_log_stats_ = pipeline_->stats();
    notify("READY=1\nSTATUS=running");

    std::uint64_t watchdog_usec = 0;
    const bool watchdog = ::sd_watchdog_enabled(0, &watchdog_usec) > 0 && watchdog_usec > 0;
    watchdog_ = watchdog;
    auto tick = std::chrono::milliseconds(1000);
    if (watchdog) tick = std::min(tick, std::chrono::milliseconds(std::max<std::uint64_t>(10, watchdog_usec / 4000)));
    std::uint64_t heartbeat_at_poke = pipeline_->engine_heartbeat();
    pipeline_->poke_engine();

    // Signals arrive through a signalfd, so one poll() waits for them and for the control socket.
    const int signal_fd = ::signalfd(-1, &signals, SFD_CLOEXEC | SFD_NONBLOCK);
    if (signal_fd < 0) throw std::system_error(errno, std::generic_category(), "signalfd");
    const auto tick_end = [&] { return Clock::now() + tick; };
    auto next_tick = tick_end();
    for (;;) {
      pollfd fds[2] = {{signal_fd, POLLIN, 0}, {control_ ? control_->fd() : -1, POLLIN, 0}};
      const auto wait = std::chrono::ceil<std::chrono::milliseconds>(next_tick - Clock::now()).count();
      ::poll(fds, 2, static_cast<int>(std::max<long long>(0, wait)));
      int sig = 0;
      if (fds[0].revents & POLLIN) {
        signalfd_siginfo info{};
        if (::read(signal_fd, &info, sizeof info) == static_cast<ssize_t>(sizeof info)) sig = static_cast<int>(info.ssi_signo);
      }
      if (control_ && (fds[1].revents & POLLIN)) {
        control_->serve_one([this](const ControlCommand& c, const PeerCredentials& peer) { return control(c, peer); });
      }
      if (sig == 0 && Clock::now() < next_tick) continue;
      if (sig == 0) next_tick = tick_end();
      if (sig == SIGTERM || sig == SIGINT) {
        ::close(signal_fd);
        spdlog::info("{}: draining and stopping", sig == SIGTERM ? "SIGTERM" : "SIGINT");
        return finish("stopped");
      }
      if (sig == SIGHUP) {
        spdlog::info("SIGHUP");
        reload();
      }
      if (sig == SIGUSR1) log_counters(*pipeline_, last_log_stats_, seconds_since(last_log_));

      // The engine thread is alive when it went round its loop since the last poke.
      const std::uint64_t hb = pipeline_->engine_heartbeat();
      if (watchdog && hb != heartbeat_at_poke) notify("WATCHDOG=1");
      heartbeat_at_poke = hb;
      pipeline_->poke_engine();
      log_recorder_change();

      const auto now = Clock::now();
      if (now - last_status_ >= std::chrono::seconds(1)) {
        std::vector<StreamStats> stats = pipeline_->stats();
        notify("STATUS=" + status_line(stats, last_status_stats_, seconds_since(last_status_)));
        last_status_stats_ = std::move(stats);
        last_status_ = now;
      }
      const double interval = pipeline_->config().logging.status_interval;
      if (interval > 0 && seconds_since(last_log_) >= interval) {
        log_counters(*pipeline_, last_log_stats_, seconds_since(last_log_));
        last_log_stats_ = pipeline_->stats();
        last_log_ = now;
      }
      if (pipeline_->config().daemon.exit_when_sources_end && pipeline_->sources_ended()) {
        ::close(signal_fd);
        spdlog::info("every source has ended: draining and stopping");
        return finish("sources ended");
      }
    }
  }

 private:
  static double seconds_since(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

  // One line when the recording stops being written (disk full, I/O error), one when it writes
  // again: the recorder thread only sets the state, the main thread logs it.
  void log_recorder_change() {
    const int error = pipeline_->recorder_errno();
    if (error == recorder_errno_) return;
    const std::string path = pipeline_->config().recorder.path.string();
    if (error != 0)
      spdlog::error("recording {}: cannot write: {}; publishing continues, samples that no longer fit the "
                    "recorder's buffer are counted as recorder drops until a write succeeds",
                    path, std::strerror(error));
    else
      spdlog::info("recording {}: writing again", path);
    recorder_errno_ = error;
  }

  void mark_interval() {
    last_status_ = Clock::now();
    last_status_stats_ = pipeline_->stats();
  }

  int finish(const char* why) {
    notify(std::string("STOPPING=1\nSTATUS=") + why);
    if (subscription_) subscription_->stop();
    control_.reset();
    pipeline_->stop();
    log_counters(*pipeline_, {}, 0.0);
    spdlog::info("{}: exiting", why);
    pipeline_.reset();
    spdlog::shutdown();
    return kExitOk;
  }

  // The subscription port and the control socket: made once, at start (a reload keeps them).
  int open_control(const DaemonConfig& config) {
    try {
      if (config.subscription) subscription_ = std::make_unique<SubscriptionServer>(*config.subscription);
      if (config.control && !options_.check_only) control_ = std::make_unique<ControlServer>(*config.control);
    } catch (const Error& e) {
      spdlog::error("{}: {}", config.source_file.string(), e.what());
      return e.exit_code();
    } catch (const std::system_error& e) {
      spdlog::error("{}: subscription port {}: {}", config.source_file.string(), config.subscription->listen.to_string(), e.what());
      return exit_code(ErrorKind::OsErr);
    }
    return kExitOk;
  }

  std::shared_ptr<SubscriberTable> subscribers() const { return subscription_ ? subscription_->table() : nullptr; }

  static std::vector<std::uint32_t> stream_ids(const DaemonConfig& config) {
    std::vector<std::uint32_t> ids;
    for (const StreamConfig& s : config.streams) ids.push_back(s.id);
    return ids;
  }

  // One control socket command (control_command.hpp), on the main thread; the reply's JSON.
  std::string control(const ControlCommand& c, const PeerCredentials& peer) {
    const std::string who = fmt::format("pid {} uid {} gid {}", peer.pid, peer.uid, peer.gid);
    if (changes_daemon(c.verb)) spdlog::info("control socket: '{}' from {}", to_string(c.verb), who);
    const auto ok = [](const std::string& members) {
      std::string reply = "{\"ok\":true";
      if (!members.empty()) {
        reply += ',';
        reply += members;
      }
      reply += '}';
      return reply;
    };
    const auto now_ns = std::chrono::duration_cast<std::chrono::nanoseconds>(Clock::now().time_since_epoch()).count();
    switch (c.verb) {
      case ControlVerb::Status: {
        const DaemonConfig& config = pipeline_->config();
        std::string m = fmt::format("\"pid\":{},\"config\":{},\"session\":\"{:08x}\",\"uptime_s\":{},\"streams\":{},"
                                    "\"outputs\":{},\"recording\":{}",
                                    ::getpid(), json_string(options_.config.string()), session_, json_number(seconds_since(started_)),
                                    config.streams.size(), config.outputs.size(),
                                    config.recorder.enabled ? (pipeline_->recording() ? "true" : "false") : "null");
        m += ",\"subscribers\":";
        m += subscription_ ? std::to_string(subscription_->table()->size()) : std::string("null");
        return ok(m);
      }
      case ControlVerb::Streams:
        return ok(streams_member(pipeline_->stats(), last_status_stats_, seconds_since(last_status_)));
      case ControlVerb::Subscribers:
        if (!subscription_) return control_error_reply("no [subscription] in the configuration", ErrorKind::Unavailable);
        return ok(subscribers_member(subscription_->table()->list(), now_ns));
      case ControlVerb::Counters: {
        std::string m = streams_member(pipeline_->stats(), last_status_stats_, seconds_since(last_status_));
        m += ',';
        m += stages_member(pipeline_->stage_latency());
        if (subscription_) {
          m += ',';
          m += subscription_member(subscription_->handler(), subscription_->table()->size());
          m += ',';
          m += subscribers_member(subscription_->table()->list(), now_ns);
        }
        return ok(m);
      }
      case ControlVerb::Reload: {
        const std::uint32_t before = session_;
        const bool done = reload();
        if (!done) return control_error_reply("reload refused, the running configuration kept (see the log)", ErrorKind::Config);
        return ok(fmt::format("\"session\":\"{:08x}\",\"previous_session\":\"{:08x}\"", session_, before));
      }
      case ControlVerb::RecordStart:
      case ControlVerb::RecordStop: {
        if (!pipeline_->config().recorder.enabled)
          return control_error_reply("no [recorder] in the configuration", ErrorKind::Unavailable);
        pipeline_->set_recording(c.verb == ControlVerb::RecordStart);
        spdlog::info("recording {}", pipeline_->recording() ? "resumed" : "paused");
        return ok(fmt::format("\"recording\":{}", pipeline_->recording() ? "true" : "false"));
      }
    }
    return control_error_reply("unknown command", ErrorKind::Usage);
  }

  // True when the new configuration runs now.
  bool reload() {
    notify("RELOADING=1");
    spdlog::info("reloading {}", options_.config.string());
    DaemonConfig next_config;
    try {
      next_config = load_config(options_.config);
    } catch (const ConfigError& e) {
      spdlog::error("reload refused, keeping the running configuration: {}", e.what());
      notify("READY=1");
      return false;
    }
    const RecorderConfig& old_rec = pipeline_->config().recorder;
    const bool carry = next_config.recorder.enabled && old_rec.enabled && next_config.recorder.path == old_rec.path;
    // A reload restarts every window and every source's time base (a replay starts again), so
    // by default it starts a new session: subscribers see the sequence restart (docs/protocol.md).
    // A fixed session_id keeps the session and continues each stream's sequence instead.
    const bool keep_session = next_config.daemon.session_id.has_value();
    const std::uint32_t session = keep_session ? *next_config.daemon.session_id : random_session();
    std::unique_ptr<Pipeline> next;
    if (build(next_config, session, {}, carry, next, subscribers()) != kExitOk) {
      spdlog::error("reload refused, keeping the running configuration");
      notify("READY=1");
      return false;
    }
    if (carry && !next->same_recording(*pipeline_)) {
      spdlog::error("reload refused, keeping the running configuration: the recording {} is running with another "
                    "stream table or rotation; give the recorder a new path to change them",
                    old_rec.path.string());
      notify("READY=1");
      return false;
    }
    for (const std::string& w : next->warnings()) spdlog::warn("{}", w);
    pipeline_->stop(carry);
    // The old engine drained everything it held, so it was alive: say so, for a reload that takes
    // seconds on a loaded machine (the main thread does not tick meanwhile) must not look like a
    // hang to systemd's watchdog.
    if (watchdog_) notify("WATCHDOG=1");
    log_counters(*pipeline_, {}, 0.0);
    if (carry) next->adopt_recorder(pipeline_->release_recorder());
    if (keep_session && session == session_) next->continue_sequences(pipeline_->next_sequences());
    session_ = session;
    pipeline_ = std::move(next);
    for (const std::string& w : pipeline_->start()) spdlog::warn("{}", w);
    mark_interval();
    last_log_ = Clock::now();
    last_log_stats_ = pipeline_->stats();
    spdlog::info("reloaded: {} streams, {} outputs, session {:08x}", pipeline_->config().streams.size(),
                 pipeline_->config().outputs.size(), session_);
    if (subscription_) subscription_->handler().set_streams(stream_ids(pipeline_->config()));
    notify("READY=1");
    return true;
  }

  ServiceOptions options_;
  std::uint32_t session_ = 0;
  std::unique_ptr<SubscriptionServer> subscription_;
  std::unique_ptr<ControlServer> control_;
  Clock::time_point started_ = Clock::now();
  std::unique_ptr<Pipeline> pipeline_;
  Clock::time_point last_status_, last_log_;
  std::vector<StreamStats> last_status_stats_, last_log_stats_;
  int recorder_errno_ = 0;  // as last logged
  bool watchdog_ = false;   // systemd's watchdog is on (WATCHDOG_USEC)
};

}  // namespace

int run_service(const ServiceOptions& options) {
  try {
    return Service(options).run();
  } catch (const std::exception& e) {
    std::fprintf(stderr, "posefaird: internal error: %s\n", e.what());
    return exit_code(ErrorKind::Software);
  }
}

}  // namespace posefair::daemon
