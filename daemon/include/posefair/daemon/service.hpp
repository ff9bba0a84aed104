#pragma once
// posefaird's main loop: load the config (exit 78 on a bad one), build and start a Pipeline,
// tell systemd READY=1, then wait for signals while keeping STATUS= and the watchdog fed:
//   SIGTERM, SIGINT  drain (every sample handed over is faired and sent, the recording synced)
//                    and exit 0;
//   SIGHUP           reload: parse and check the file again off the real-time path; a good one
//                    replaces the running pipeline whole (a new session, unless session_id is
//                    fixed: then the session stays and sequences continue), a bad one is logged
//                    and the running one kept;
//   SIGUSR1          log every stream's counters now.
// With [subscription] it also runs the subscription port (its own thread, kept across reloads),
// and with [control] it answers the control socket on the main thread, polled with the signals
// (a signalfd): status, streams, subscribers, counters, reload, record start|stop.
// docs/operations.md describes it for operators. The exit status is exit_code() of the failure's
// ErrorKind (core/error.hpp): Config (78) for a bad configuration or an unusable source, OsErr
// (71) for a socket that cannot be opened, CantCreate (73) for a recording that cannot be
// created, Software (70) for an internal error.
#include <filesystem>
#include <optional>
#include <string>

namespace posefair::daemon {

struct ServiceOptions {
  std::filesystem::path config;
  std::optional<std::string> log_level;   // overrides [logging] level
  std::optional<std::string> log_target;  // "stderr" or "journald": overrides [logging] target
  bool check_only = false;  // validate the config (and load its sources), print the result, exit
};

int run_service(const ServiceOptions& options);

}  // namespace posefair::daemon
