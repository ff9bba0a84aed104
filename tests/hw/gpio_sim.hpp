#pragma once
// A simulated GPIO chip for a test (Linux gpio-sim, made through configfs; needs root, the
// gpio-sim module and configfs mounted at /sys/kernel/config). Made by the constructor, removed
// by the destructor. Input lines are driven with pull(): pull-up makes a rising edge, pull-down
// a falling one; value() reads a line as the chip sees it, including what a consumer drives on
// an output line. See the kernel's Documentation/admin-guide/gpio/gpio-sim.rst.
#include <gpiod.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

namespace posefair::testing {

class GpioSim {
 public:
  static constexpr const char* kConfigfs = "/sys/kernel/config/gpio-sim";

  // A chip of `lines` lines with the given label; `names` name the first lines.
  GpioSim(unsigned lines, const std::string& label, const std::vector<std::string>& names = {}) {
    static std::atomic<int> counter{0};
    if (!std::filesystem::is_directory(kConfigfs))
      throw std::runtime_error(std::string(kConfigfs) + " is missing: load gpio-sim and mount configfs");
    dir_ = std::filesystem::path(kConfigfs) / ("pf-" + std::to_string(::getpid()) + "-" + std::to_string(counter++));
    std::filesystem::create_directory(dir_);
    std::filesystem::create_directory(dir_ / "bank0");
    write(dir_ / "bank0" / "num_lines", std::to_string(lines));
    write(dir_ / "bank0" / "label", label);
    for (std::size_t i = 0; i < names.size(); ++i) {
      const auto line = dir_ / "bank0" / ("line" + std::to_string(i));
      std::filesystem::create_directory(line);
      write(line / "name", names[i]);
      named_.push_back(line);
    }
    write(dir_ / "live", "1");
    dev_name_ = read(dir_ / "dev_name");
    chip_name_ = read(dir_ / "bank0" / "chip_name");
    // The device node appears asynchronously (devtmpfs): wait until libgpiod can open it.
    const auto until = std::chrono::steady_clock::now() + std::chrono::seconds(10);
    for (;;) {
      if (gpiod_chip* c = ::gpiod_chip_open_lookup(chip_name_.c_str())) {
        ::gpiod_chip_close(c);
        break;
      }
      if (std::chrono::steady_clock::now() > until) throw std::runtime_error("/dev/" + chip_name_ + " did not appear");
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
  }
  ~GpioSim() {
    std::error_code ec;
    try {
      write(dir_ / "live", "0");
    } catch (...) {
    }
    for (const auto& l : named_) std::filesystem::remove(l, ec);
    std::filesystem::remove(dir_ / "bank0", ec);
    std::filesystem::remove(dir_, ec);
  }
  GpioSim(const GpioSim&) = delete;
  GpioSim& operator=(const GpioSim&) = delete;

  const std::string& chip_name() const { return chip_name_; }  // "gpiochip1"
  void pull(unsigned line, bool up) const { write(line_dir(line) / "pull", up ? "pull-up" : "pull-down"); }
  int value(unsigned line) const { return std::stoi(read(line_dir(line) / "value")); }

  // The line's consumer as the kernel reports it ("" when free): a gpioinfo-like check.
  std::string consumer(unsigned line) const {
    std::string who;
    if (gpiod_chip* c = ::gpiod_chip_open_lookup(chip_name_.c_str())) {
      if (gpiod_line* l = ::gpiod_chip_get_line(c, line)) {
        ::gpiod_line_update(l);
        if (::gpiod_line_is_used(l) && ::gpiod_line_consumer(l) != nullptr) who = ::gpiod_line_consumer(l);
      }
      ::gpiod_chip_close(c);
    }
    return who;
  }

 private:
  std::filesystem::path line_dir(unsigned line) const {
    return std::filesystem::path("/sys/devices/platform") / dev_name_ / chip_name_ / ("sim_gpio" + std::to_string(line));
  }
  static void write(const std::filesystem::path& p, const std::string& text) {
    std::ofstream out(p);
    out << text;
    out.flush();
    if (!out) throw std::runtime_error("cannot write '" + text + "' to " + p.string());
  }
  static std::string read(const std::filesystem::path& p) {
    std::ifstream in(p);
    std::string s;
    std::getline(in, s);
    if (!in && s.empty()) throw std::runtime_error("cannot read " + p.string());
    return s;
  }

  std::filesystem::path dir_;
  std::vector<std::filesystem::path> named_;
  std::string dev_name_, chip_name_;
};

}  // namespace posefair::testing
