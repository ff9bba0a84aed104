#pragma once
// posefaird's end of the operators' control socket (docs/operations.md, "Control socket"): a
// Unix stream socket at [control] socket, its file given [control] mode and group, so access is
// decided by the kernel on connect() from the file's permissions. The main thread polls fd()
// and calls serve_one() when it is readable: one client, one request line (read for at most
// 200 ms), one reply, closed. The peer's credentials (SO_PEERCRED) go to the handler, which logs
// them for every command that changes the daemon.
#include <sys/types.h>

#include <functional>
#include <string>

#include "posefair/daemon/config.hpp"
#include "posefair/daemon/control_command.hpp"

namespace posefair::daemon {

struct PeerCredentials {
  pid_t pid = 0;
  uid_t uid = 0;
  gid_t gid = 0;
};

class ControlServer {
 public:
  // Makes the socket (a stale socket file at the path is replaced; anything else there is
  // refused). Throws posefair::Error: Config (an unknown group, key control.group) or OsErr.
  explicit ControlServer(const ControlSocketConfig& config);
  ~ControlServer();  // closes and removes the socket file
  ControlServer(const ControlServer&) = delete;
  ControlServer& operator=(const ControlServer&) = delete;

  int fd() const { return fd_; }
  const ControlSocketConfig& config() const { return config_; }

  using Handler = std::function<std::string(const ControlCommand&, const PeerCredentials&)>;
  // Accepts one waiting client and answers it with handler's JSON (a malformed request with an
  // error object, without calling the handler). Never throws for what a client does.
  void serve_one(const Handler& handler);

 private:
  ControlSocketConfig config_;
  int fd_ = -1;
};

}  // namespace posefair::daemon
