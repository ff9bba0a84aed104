#include "posefair/daemon/control_server.hpp"

#include <fcntl.h>
#include <grp.h>
#include <poll.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/un.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <string>
#include <vector>

#include "posefair/core/error.hpp"
#include "posefair/daemon/control_reply.hpp"

namespace posefair::daemon {
namespace {

[[noreturn]] void os_error(const std::string& what) {
  throw Error(ErrorKind::OsErr, "control socket: " + what + ": " + std::strerror(errno), "control.socket");
}

gid_t group_id(const std::string& name) {
  std::vector<char> buf(16384);
  group g{};
  group* found = nullptr;
  if (::getgrnam_r(name.c_str(), &g, buf.data(), buf.size(), &found) != 0 || found == nullptr)
    throw Error(ErrorKind::Config, "control socket: no such group: " + name, "control.group");
  return found->gr_gid;
}

}  // namespace

ControlServer::ControlServer(const ControlSocketConfig& config) : config_(config) {
  const std::string path = config_.path.string();
  sockaddr_un addr{};
  addr.sun_family = AF_UNIX;
  if (path.size() >= sizeof addr.sun_path)
    throw Error(ErrorKind::Config, "control socket: path too long for a Unix socket: " + path, "control.socket");
  std::memcpy(addr.sun_path, path.c_str(), path.size() + 1);
  const gid_t gid = config_.group.empty() ? ::getegid() : group_id(config_.group);

  struct stat st{};
  if (::lstat(path.c_str(), &st) == 0) {
    if (!S_ISSOCK(st.st_mode))
      throw Error(ErrorKind::Config, "control socket: " + path + " exists and is not a socket", "control.socket");
    ::unlink(path.c_str());  // left by a daemon that did not stop cleanly
  }
  fd_ = ::socket(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC | SOCK_NONBLOCK, 0);
  if (fd_ < 0) os_error("socket");
  // Made with no access for anyone, then given its mode and group: never open wider in between.
  const mode_t old_mask = ::umask(0777);
  const int rc = ::bind(fd_, reinterpret_cast<const sockaddr*>(&addr), sizeof addr);
  ::umask(old_mask);
  if (rc != 0) {
    const int e = errno;
    ::close(fd_);
    errno = e;
    os_error("bind " + path);
  }
  if (::chown(path.c_str(), static_cast<uid_t>(-1), gid) != 0 || ::chmod(path.c_str(), config_.mode) != 0 ||
      ::listen(fd_, 8) != 0) {
    const int e = errno;
    ::close(fd_);
    ::unlink(path.c_str());
    errno = e;
    os_error("set up " + path);
  }
}

ControlServer::~ControlServer() {
  if (fd_ >= 0) {
    ::close(fd_);
    ::unlink(config_.path.c_str());
  }
}

void ControlServer::serve_one(const Handler& handler) {
  const int client = ::accept4(fd_, nullptr, nullptr, SOCK_CLOEXEC | SOCK_NONBLOCK);
  if (client < 0) return;
  PeerCredentials peer;
  ucred cred{};
  socklen_t len = sizeof cred;
  if (::getsockopt(client, SOL_SOCKET, SO_PEERCRED, &cred, &len) == 0) peer = {cred.pid, cred.uid, cred.gid};

  // One line, read for at most 200 ms in all: a slow client cannot hold the main thread.
  std::vector<std::uint8_t> request;
  std::uint8_t buf[kMaxControlRequest + 1];
  for (int waited = 0; waited < 200 && (request.empty() || request.back() != '\n') && request.size() <= kMaxControlRequest;) {
    pollfd p{client, POLLIN, 0};
    if (::poll(&p, 1, 20) <= 0) {
      waited += 20;
      continue;
    }
    const ssize_t n = ::recv(client, buf, sizeof buf, 0);
    if (n <= 0) break;
    request.insert(request.end(), buf, buf + n);
  }
  const ControlCommand command = parse_control_command(request);
  std::string reply = command ? handler(command, peer) : control_error_reply(std::string("bad request: ") + std::string(to_string(command.error)), ErrorKind::Usage);
  reply += '\n';
  const char* p = reply.data();
  std::size_t left = reply.size();
  for (int tries = 0; left > 0 && tries < 50; ++tries) {
    const ssize_t n = ::send(client, p, left, MSG_NOSIGNAL);
    if (n > 0) {
      p += n;
      left -= static_cast<std::size_t>(n);
      continue;
    }
    if (n < 0 && errno != EAGAIN && errno != EINTR) break;
    pollfd w{client, POLLOUT, 0};
    ::poll(&w, 1, 20);
  }
  ::close(client);
}

}  // namespace posefair::daemon
