#pragma once
// A pseudo-terminal standing in for a serial device: the test holds the master and writes the
// device's bytes; the driver under test opens the slave by its path (or through a symlink, as
// through /dev/serial/by-id). Closing the master is an unplug: the slave's reader sees a hangup.
#include <fcntl.h>
#include <stdlib.h>
#include <termios.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <stdexcept>
#include <string>
#include <string_view>

namespace posefair::testing {

class PseudoTerminal {
 public:
  PseudoTerminal() {
    master_ = ::posix_openpt(O_RDWR | O_NOCTTY | O_CLOEXEC);
    if (master_ < 0) throw std::runtime_error(std::string("posix_openpt: ") + std::strerror(errno));
    if (::grantpt(master_) != 0 || ::unlockpt(master_) != 0) throw std::runtime_error("grantpt/unlockpt failed");
    char name[128];
    if (::ptsname_r(master_, name, sizeof name) != 0) throw std::runtime_error("ptsname_r failed");
    slave_ = name;
    // Raw from the start, so nothing is echoed or edited before the driver configures it.
    const int s = ::open(name, O_RDWR | O_NOCTTY | O_CLOEXEC);
    if (s < 0) throw std::runtime_error(std::string("open slave: ") + std::strerror(errno));
    termios t{};
    ::tcgetattr(s, &t);
    ::cfmakeraw(&t);
    ::tcsetattr(s, TCSANOW, &t);
    ::close(s);
  }
  PseudoTerminal(const PseudoTerminal&) = delete;
  PseudoTerminal& operator=(const PseudoTerminal&) = delete;
  ~PseudoTerminal() { close(); }

  const std::string& slave() const { return slave_; }

  // Unplug: the slave's reader sees a hangup (EIO).
  void close() {
    if (master_ >= 0) ::close(master_);
    master_ = -1;
  }

  // Writes every byte (blocking while the slave's input queue is full). Throws on failure.
  void write(std::string_view bytes) const {
    std::size_t done = 0;
    while (done < bytes.size()) {
      const ssize_t n = ::write(master_, bytes.data() + done, bytes.size() - done);
      if (n < 0 && errno == EINTR) continue;
      if (n <= 0) throw std::runtime_error(std::string("write to the pty master: ") + std::strerror(errno));
      done += static_cast<std::size_t>(n);
    }
  }

 private:
  int master_ = -1;
  std::string slave_;
};

}  // namespace posefair::testing
