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
// docs/operations.md describes it for operators.
#include <filesystem>
#include <optional>
#include <string>

namespace posefair::daemon {

// sysexits.h values posefaird exits with.
inline constexpr int kExitOk = 0;
inline constexpr int kExitSoftware = 70;  // an internal error
inline constexpr int kExitOsError = 71;   // a socket could not be opened
inline constexpr int kExitCantCreate = 73;  // the recording could not be created
inline constexpr int kExitConfig = 78;    // EX_CONFIG: the configuration is bad (or names an unusable source)

struct ServiceOptions {
  std::filesystem::path config;
  std::optional<std::string> log_level;   // overrides [logging] level
  std::optional<std::string> log_target;  // "stderr" or "journald": overrides [logging] target
  bool check_only = false;  // validate the config (and load its sources), print the result, exit
};

int run_service(const ServiceOptions& options);

}  // namespace posefair::daemon
