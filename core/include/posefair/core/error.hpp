#pragma once
// What kind of failure an error is, and the one place its exit status is defined. posefaird and
// the posefair tool exit with BSD sysexits.h values (as gpsd's and chrony's tools do); every
// layer throws Error (or a type derived from it) carrying its kind and, where one exists, the
// key or option that was wrong, so a caller picks the exit status from the kind, never from
// the message text. core does no I/O; the kinds about files and sockets are for the layers above.
#include <stdexcept>
#include <string>

namespace posefair {

inline constexpr int kExitOk = 0;

enum class ErrorKind {
  Usage,        // bad command line
  DataErr,      // an input file is malformed
  NoInput,      // an input file cannot be opened
  Unavailable,  // a service the command needs is unavailable (e.g. a socket cannot be bound)
  Software,     // an internal error
  OsErr,        // the operating system refused (e.g. a socket could not be opened)
  CantCreate,   // an output (file, recording) cannot be created or written
  Config,       // the configuration is bad, or names an unusable source
};

// The sysexits.h status of each kind.
constexpr int exit_code(ErrorKind kind) {
  switch (kind) {
    case ErrorKind::Usage: return 64;        // EX_USAGE
    case ErrorKind::DataErr: return 65;      // EX_DATAERR
    case ErrorKind::NoInput: return 66;      // EX_NOINPUT
    case ErrorKind::Unavailable: return 69;  // EX_UNAVAILABLE
    case ErrorKind::Software: return 70;     // EX_SOFTWARE
    case ErrorKind::OsErr: return 71;        // EX_OSERR
    case ErrorKind::CantCreate: return 73;   // EX_CANTCREAT
    case ErrorKind::Config: return 78;       // EX_CONFIG
  }
  return 70;
}

// An error of a known kind. what() is the whole message as printed; key() names the
// configuration key or option at fault ("" when none applies).
class Error : public std::runtime_error {
 public:
  Error(ErrorKind kind, const std::string& what, std::string key = {})
      : std::runtime_error(what), kind_(kind), key_(std::move(key)) {}
  ErrorKind kind() const noexcept { return kind_; }
  int exit_code() const noexcept { return posefair::exit_code(kind_); }
  const std::string& key() const noexcept { return key_; }

 private:
  ErrorKind kind_;
  std::string key_;
};

}  // namespace posefair
