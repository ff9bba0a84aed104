// The data-ready line on libgpiod 1.6; see gpio_data_ready.hpp.
#include "posefair/drivers/gpio_data_ready.hpp"

#include <fcntl.h>
#include <gpiod.h>
#include <sys/utsname.h>
#include <time.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <stdexcept>
#include <utility>

#include "link_log_text.hpp"
#include "monotonic_clock.hpp"

namespace posefair::drivers {
namespace {

int bias_flags(GpioBias b) {
  switch (b) {
    case GpioBias::AsIs: return 0;
    case GpioBias::PullUp: return GPIOD_LINE_REQUEST_FLAG_BIAS_PULL_UP;
    case GpioBias::PullDown: return GPIOD_LINE_REQUEST_FLAG_BIAS_PULL_DOWN;
    case GpioBias::Disabled: return GPIOD_LINE_REQUEST_FLAG_BIAS_DISABLE;
  }
  return 0;
}

std::string kernel_release() {
  utsname u{};
  return ::uname(&u) == 0 ? std::string(u.release) : std::string();
}

// Edge events drained per read() (the kernel's v1 event queue holds 16).
constexpr unsigned kEventBatch = 16;

}  // namespace

std::string GpioLineRef::describe() const {
  return offset ? "line " + std::to_string(*offset) : "line '" + name + "'";
}

bool gpio_event_clock_is_monotonic(const std::string& release) {
  int major = 0, minor = 0;
  if (std::sscanf(release.c_str(), "%d.%d", &major, &minor) != 2) return true;  // unknown: assume a current kernel
  return major > 5 || (major == 5 && minor >= 7);
}

std::string GpioLineHandle::open(const std::string& chip, const GpioLineRef& ref) {
  release();
  errno = 0;
  chip_ = ::gpiod_chip_open_lookup(chip.c_str());
  if (chip_ == nullptr)
    return "cannot open GPIO chip '" + chip + "': " + (errno != 0 ? std::strerror(errno) : "not found");
  errno = 0;
  line_ = ref.offset ? ::gpiod_chip_get_line(chip_, *ref.offset) : ::gpiod_chip_find_line(chip_, ref.name.c_str());
  if (line_ == nullptr) {
    const std::string why = errno != 0 ? std::strerror(errno) : "not found";
    release();
    return "GPIO chip '" + chip + "' has no " + ref.describe() + " (" + why + ")";
  }
  return {};
}

std::string GpioLineHandle::held_by() const {
  ::gpiod_line_update(line_);
  const char* holder = ::gpiod_line_consumer(line_);
  return std::string(" (held by '") + (holder != nullptr ? holder : "?") + "')";
}

void GpioLineHandle::release() {
  if (line_ != nullptr && ::gpiod_line_is_requested(line_)) ::gpiod_line_release(line_);
  line_ = nullptr;
  if (chip_ != nullptr) ::gpiod_chip_close(chip_);  // closes the line's request fd too
  chip_ = nullptr;
}

GpioDataReadySink::GpioDataReadySink(GpioDataReadyOptions options, SampleSink& next)
    : options_(std::move(options)), next_(next), pairer_(options_.pairing), backoff_(options_) {
  validate(static_cast<const ReconnectSettings&>(options_), "GPIO data-ready");
  if (options_.chip.empty()) throw std::invalid_argument("GPIO data-ready: no chip");
  const std::string release = kernel_release();
  clock_ok_ = gpio_event_clock_is_monotonic(release);
  if (!clock_ok_ && options_.log)
    options_.log(LogLevel::Error, "GPIO edge timestamps are CLOCK_REALTIME on Linux " + release +
                                      " (CLOCK_MONOTONIC from 5.7): " + describe() +
                                      " is not used, samples keep their receive times");
}

GpioDataReadySink::~GpioDataReadySink() { release(); }

std::string GpioDataReadySink::describe() const {
  return options_.chip + " " + options_.line.describe() + " (" + (options_.edge == GpioEdge::Rising ? "rising" : "falling") + ")";
}

void GpioDataReadySink::release() {
  handle_.release();
  fd_ = -1;
  held_.store(false, std::memory_order_release);
}

void GpioDataReadySink::try_request(double now) {
  std::string why = handle_.open(options_.chip, options_.line);
  if (why.empty()) {
    const int flags = bias_flags(options_.bias);
    const int rc = options_.edge == GpioEdge::Rising
                       ? ::gpiod_line_request_rising_edge_events_flags(handle_.line(), options_.consumer.c_str(), flags)
                       : ::gpiod_line_request_falling_edge_events_flags(handle_.line(), options_.consumer.c_str(), flags);
    if (rc != 0) {
      const int e = errno;
      why = "cannot request " + describe() + ": " + std::strerror(e);
      if (e == EBUSY) why += handle_.held_by();
    } else {
      fd_ = ::gpiod_line_event_get_fd(handle_.line());
      const int fl = ::fcntl(fd_, F_GETFL);
      if (fd_ < 0 || fl < 0 || ::fcntl(fd_, F_SETFL, fl | O_NONBLOCK) != 0) why = "cannot set the event fd non-blocking";
    }
  }
  if (why.empty()) {
    pairer_.reset();  // edges from before the request are not ours
    held_.store(true, std::memory_order_release);
    if (options_.log)
      options_.log(LogLevel::Info, "took GPIO " + describe() + (attempts_ > 0 ? " after " + attempts_text(attempts_ + 1) : std::string()));
    attempts_ = 0;
    backoff_.reset();
    logged_reason_.clear();
    return;
  }
  handle_.release();
  fd_ = -1;
  ++attempts_;
  request_failures_.fetch_add(1, std::memory_order_relaxed);
  // One line per reason while waiting, not one per retry (the holder's name is part of it).
  if (why != logged_reason_ && options_.log) {
    options_.log(LogLevel::Warn, why + "; samples pass unpaired, retrying with backoff " + backoff_.describe());
    logged_reason_ = why;
  }
  next_attempt_ = now + backoff_.next();
}

bool GpioDataReadySink::drain() {
  gpiod_line_event events[kEventBatch];
  for (;;) {
    const int n = ::gpiod_line_event_read_fd_multiple(fd_, events, kEventBatch);
    if (n < 0) return errno == EAGAIN || errno == EINTR;
    for (int i = 0; i < n; ++i)
      pairer_.add_edge(static_cast<double>(events[i].ts.tv_sec) + 1e-9 * static_cast<double>(events[i].ts.tv_nsec));
    if (n < static_cast<int>(kEventBatch)) return true;
  }
}

bool GpioDataReadySink::push(const Sample& sample) {
  Sample out = sample;
  if (clock_ok_) {
    if (!held_.load(std::memory_order_relaxed)) {
      const double now = monotonic_seconds();
      if (now >= next_attempt_) try_request(now);
    }
    if (held_.load(std::memory_order_relaxed)) {
      if (!drain()) {
        const std::string why = std::strerror(errno);
        release();
        losses_.fetch_add(1, std::memory_order_relaxed);
        next_attempt_ = monotonic_seconds() + options_.reconnect_min;
        if (options_.log)
          options_.log(LogLevel::Warn, "lost GPIO " + describe() + " (" + why + "); samples pass unpaired, retrying");
      } else {
        const PairedTime p = pairer_.pair(sample.receive_time);
        if (p.paired) out.time = p.time;
      }
      std::lock_guard lock(snapshot_mutex_);
      snapshot_ = pairer_.counters();
    }
  }
  return next_.push(out);
}

std::size_t GpioDataReadySink::take_edges() {
  if (held_.load(std::memory_order_relaxed)) {
    (void)drain();  // a lost line shows at the next push
    std::lock_guard lock(snapshot_mutex_);
    snapshot_ = pairer_.counters();
  }
  return pairer_.pending();
}

GpioDataReadyCounters GpioDataReadySink::counters() const {
  GpioDataReadyCounters c;
  {
    std::lock_guard lock(snapshot_mutex_);
    c.pairing = snapshot_;
  }
  c.line_held = held_.load(std::memory_order_acquire);
  c.request_failures = request_failures_.load(std::memory_order_relaxed);
  c.losses = losses_.load(std::memory_order_relaxed);
  return c;
}

}  // namespace posefair::drivers
