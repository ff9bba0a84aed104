#include "posefair/daemon/service.hpp"

#include <signal.h>
#include <sys/random.h>
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
#include <memory>
#include <string>
#include <system_error>

#include "posefair/core/error.hpp"
#include "posefair/daemon/config.hpp"
#include "posefair/daemon/pipeline.hpp"
#include "posefair/daemon/status_report.hpp"

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
          bool defer_recorder, std::unique_ptr<Pipeline>& out) {
  try {
    out = std::make_unique<Pipeline>(config, session, sequences, defer_recorder);
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
    // Every thread started from here inherits the mask; only sigtimedwait below sees them.
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
    if (int rc = build(config, session_, {}, options_.check_only, pipeline_); rc != kExitOk) return rc;
    for (const std::string& w : pipeline_->warnings()) spdlog::warn("{}", w);
    if (options_.check_only) {
      std::printf("%s: ok (%zu streams, %zu outputs%s)\n", options_.config.c_str(), config.streams.size(),
                  config.outputs.size(), config.recorder.enabled ? ", recorder" : "");
      pipeline_.reset();
      return kExitOk;
    }
    for (const std::string& w : pipeline_->start()) spdlog::warn("{}", w);
    spdlog::info("started: {} streams, {} outputs, session {:08x}, config {}", config.streams.size(),
                 config.outputs.size(), session_, options_.config.string());
    mark_interval();
    last_log_ = Clock::now();
    last_log_stats_ = pipeline_->stats();
    notify("READY=1\nSTATUS=running");

    std::uint64_t watchdog_usec = 0;
    const bool watchdog = ::sd_watchdog_enabled(0, &watchdog_usec) > 0 && watchdog_usec > 0;
    auto tick = std::chrono::milliseconds(1000);
    if (watchdog) tick = std::min(tick, std::chrono::milliseconds(std::max<std::uint64_t>(10, watchdog_usec / 4000)));
    std::uint64_t heartbeat_at_poke = pipeline_->engine_heartbeat();
    pipeline_->poke_engine();

    for (;;) {
      timespec ts{static_cast<time_t>(tick.count() / 1000), static_cast<long>((tick.count() % 1000) * 1'000'000)};
      siginfo_t info{};
      const int sig = ::sigtimedwait(&signals, &info, &ts);
      if (sig == SIGTERM || sig == SIGINT) {
        spdlog::info("{}: draining and stopping", sig == SIGTERM ? "SIGTERM" : "SIGINT");
        return finish("stopped");
      }
      if (sig == SIGHUP) reload();
      if (sig == SIGUSR1) log_counters(*pipeline_, last_log_stats_, seconds_since(last_log_));

      // The engine thread is alive when it went round its loop since the last poke.
      const std::uint64_t hb = pipeline_->engine_heartbeat();
      if (watchdog && hb != heartbeat_at_poke) notify("WATCHDOG=1");
      heartbeat_at_poke = hb;
      pipeline_->poke_engine();

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
        spdlog::info("every source has ended: draining and stopping");
        return finish("sources ended");
      }
    }
  }

 private:
  static double seconds_since(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

  void mark_interval() {
    last_status_ = Clock::now();
    last_status_stats_ = pipeline_->stats();
  }

  int finish(const char* why) {
    notify(std::string("STOPPING=1\nSTATUS=") + why);
    pipeline_->stop();
    log_counters(*pipeline_, {}, 0.0);
    spdlog::info("{}: exiting", why);
    pipeline_.reset();
    spdlog::shutdown();
    return kExitOk;
  }

  void reload() {
    notify("RELOADING=1");
    spdlog::info("SIGHUP: reloading {}", options_.config.string());
    DaemonConfig next_config;
    try {
      next_config = load_config(options_.config);
    } catch (const ConfigError& e) {
      spdlog::error("reload refused, keeping the running configuration: {}", e.what());
      notify("READY=1");
      return;
    }
    const RecorderConfig& old_rec = pipeline_->config().recorder;
    const bool carry = next_config.recorder.enabled && old_rec.enabled && next_config.recorder.path == old_rec.path;
    // A reload restarts every window and every source's time base (a replay starts again), so
    // by default it starts a new session: subscribers see the sequence restart (docs/protocol.md).
    // A fixed session_id keeps the session and continues each stream's sequence instead.
    const bool keep_session = next_config.daemon.session_id.has_value();
    const std::uint32_t session = keep_session ? *next_config.daemon.session_id : random_session();
    std::unique_ptr<Pipeline> next;
    if (build(next_config, session, {}, carry, next) != kExitOk) {
      spdlog::error("reload refused, keeping the running configuration");
      notify("READY=1");
      return;
    }
    if (carry && !next->same_recording(*pipeline_)) {
      spdlog::error("reload refused, keeping the running configuration: the recording {} is running with another "
                    "stream table or rotation; give the recorder a new path to change them",
                    old_rec.path.string());
      notify("READY=1");
      return;
    }
    for (const std::string& w : next->warnings()) spdlog::warn("{}", w);
    pipeline_->stop(carry);
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
    notify("READY=1");
  }

  ServiceOptions options_;
  std::uint32_t session_ = 0;
  std::unique_ptr<Pipeline> pipeline_;
  Clock::time_point last_status_, last_log_;
  std::vector<StreamStats> last_status_stats_, last_log_stats_;
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
