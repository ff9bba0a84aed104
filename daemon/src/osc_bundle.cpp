#include "osc_bundle.hpp"

#include <stdexcept>

namespace posefair::daemon {

OscBundle::OscBundle() : bundle_(lo_bundle_new(LO_TT_IMMEDIATE)) { failed_ = bundle_ == nullptr; }

OscBundle::~OscBundle() {
  if (bundle_ != nullptr) lo_bundle_free_recursive(bundle_);  // and the messages it holds
}

lo_message OscBundle::message() {
  lo_message m = lo_message_new();
  if (m == nullptr) failed_ = true;
  return m;
}

void OscBundle::append(const char* path, lo_message m) {
  if (bundle_ == nullptr || lo_bundle_add_message(bundle_, path, m) != 0) {
    lo_message_free(m);
    failed_ = true;
  }
}

void OscBundle::add(const char* path, const char* text, std::initializer_list<float> floats) {
  lo_message m = message();
  if (m == nullptr) return;
  bool ok = text == nullptr || lo_message_add_string(m, text) == 0;
  for (float f : floats) ok = ok && lo_message_add_float(m, f) == 0;
  if (!ok) failed_ = true;
  append(path, m);
}

void OscBundle::add(const char* path, std::int32_t value) {
  lo_message m = message();
  if (m == nullptr) return;
  if (lo_message_add_int32(m, value) != 0) failed_ = true;
  append(path, m);
}

std::size_t OscBundle::serialise(std::span<std::uint8_t> out) const {
  if (failed_) throw std::runtime_error("OSC: liblo could not build a message");
  std::size_t size = lo_bundle_length(bundle_);
  if (size > out.size()) throw std::length_error("OSC: bundle larger than the datagram buffer");
  if (lo_bundle_serialise(bundle_, out.data(), &size) == nullptr) throw std::runtime_error("OSC: liblo could not serialise a bundle");
  return size;
}

}  // namespace posefair::daemon
