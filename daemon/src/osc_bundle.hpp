#pragma once
// One OSC bundle, built and serialised by liblo (Debian liblo-dev 0.31) for the OSC encodings
// (vmc_encoder.cpp, vrchat_encoder.cpp): OSC's padding, type tags and bundle framing are
// liblo's, not posefair's. Internal to the daemon's sources.
#include <cstddef>
#include <cstdint>
#include <initializer_list>
#include <span>

#include <lo/lo_lowlevel.h>

namespace posefair::daemon {

class OscBundle {
 public:
  OscBundle();  // timetag "immediately", as VMC and VRChat senders use
  ~OscBundle();
  OscBundle(const OscBundle&) = delete;
  OscBundle& operator=(const OscBundle&) = delete;

  // A message to `path` with a string (when not null) and then float arguments.
  void add(const char* path, const char* text, std::initializer_list<float> floats);
  // A message to `path` with one int32 argument.
  void add(const char* path, std::int32_t value);
  // The bundle's bytes into out; returns their number. Throws std::length_error when out is
  // too small, std::runtime_error when liblo failed to build a message (out of memory).
  std::size_t serialise(std::span<std::uint8_t> out) const;

 private:
  lo_message message();  // a new message, counted so a failure is reported at serialise()
  void append(const char* path, lo_message m);
  lo_bundle bundle_;
  bool failed_ = false;
};

}  // namespace posefair::daemon
