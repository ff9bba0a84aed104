// Makes the golden replay logs (tests/replay/README.md): real motion, the bundled BROAD excerpt
// (data/demo/broad-07-excerpt.csv), encoded as each supported device sends it, with the faults
// a serial line shows in practice. Deterministic: the same source and seeds give the same bytes.
//
//   make_replay_logs <source.csv> <output directory>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstdio>
#include <fstream>
#include <functional>
#include <iostream>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "posefair/core/euler_angles.hpp"
#include "posefair/drivers/bno08x_rvc_decoder.hpp"
#include "posefair/drivers/posefair_serial_decoder.hpp"
#include "posefair/drivers/vectornav_decoder.hpp"
#include "posefair/drivers/witmotion_decoder.hpp"
#include "posefair/drivers/xsens_decoder.hpp"
#include "posefair/drivers/yost_decoder.hpp"
#include "posefair/formats/pose_file.hpp"

namespace {

using posefair::Quat;
using posefair::Vec3;
namespace drv = posefair::drivers;

constexpr std::size_t kStride = 3;    // 285.7 Hz optical samples -> 95.2 Hz device output
constexpr std::size_t kFrames = 300;  // 3.15 s of motion per log
constexpr double kRateHz = 285.714 / kStride;

struct Motion {
  double t;  // s since the first frame
  Quat q;
  Vec3 p;
  Vec3 gyro;   // rad/s, sensor axes: the excerpt's gyroscope columns
  Vec3 accel;  // m/s², sensor axes: gravity's specific force seen at orientation q (no linear acceleration)
};

// The gyr_x_rads, gyr_y_rads, gyr_z_rads columns of the excerpt, row by row (the pose reader
// takes the quaternion and position columns only).
std::vector<Vec3> read_gyro_columns(const std::string& path) {
  std::ifstream in(path);
  std::string line;
  std::getline(in, line);
  std::vector<std::string> names;
  for (std::size_t at = 0; at <= line.size();) {
    const std::size_t comma = std::min(line.find(',', at), line.size());
    names.push_back(line.substr(at, comma - at));
    at = comma + 1;
  }
  std::array<std::size_t, 3> column{};
  for (int k = 0; k < 3; ++k) {
    const std::string want = std::string("gyr_") + "xyz"[k] + "_rads";
    const auto it = std::find(names.begin(), names.end(), want);
    if (it == names.end()) throw std::runtime_error(path + ": no column " + want);
    column[static_cast<std::size_t>(k)] = static_cast<std::size_t>(it - names.begin());
  }
  std::vector<Vec3> out;
  while (std::getline(in, line)) {
    std::vector<double> v;
    for (std::size_t at = 0; at <= line.size();) {
      const std::size_t comma = std::min(line.find(',', at), line.size());
      v.push_back(std::strtod(line.c_str() + at, nullptr));
      at = comma + 1;
    }
    out.emplace_back(v.at(column[0]), v.at(column[1]), v.at(column[2]));
  }
  return out;
}

template <typename Bytes>
std::string text(const Bytes& b) {
  return std::string(b.begin(), b.end());
}

// Yaw, pitch, roll (Z-Y-X, degrees) of q, as the Euler-angle devices report them.
std::array<double, 3> ypr(const Quat& q) {
  return posefair::quat_to_euler_nearest(q, {posefair::Axis::Z, posefair::Axis::Y, posefair::Axis::X}, {0.0, 0.0, 0.0});
}

// What a UART at rx_baud reads from bytes sent at tx_baud (8N1, LSB first): a receiver finds
// a start bit's falling edge (oversampling 16x), samples each bit in the middle of its own bit
// time, and delivers 0x00 for a frame whose stop bit is low (a framing error in raw mode).
std::string uart_misread(const std::string& bytes, double tx_baud, double rx_baud) {
  std::vector<bool> bits(10, true);  // idle
  for (unsigned char c : bytes) {
    bits.push_back(false);
    for (int k = 0; k < 8; ++k) bits.push_back(((c >> k) & 1) != 0);
    bits.push_back(true);
  }
  bits.insert(bits.end(), 20, true);
  const auto level = [&](double t) {
    const auto i = static_cast<std::size_t>(t * tx_baud);
    return i >= bits.size() || bits[i];
  };
  const double end = static_cast<double>(bits.size()) / tx_baud;
  const double bit = 1.0 / rx_baud;
  std::string out;
  double t = 0.0;
  while (t < end) {
    while (t < end && !level(t)) t += bit / 16;  // wait for idle
    while (t < end && level(t)) t += bit / 16;   // then for a start bit
    if (t >= end) break;
    unsigned value = 0;
    for (int k = 0; k < 8; ++k)
      if (level(t + (k + 1.5) * bit)) value |= 1u << k;
    const bool stop = level(t + 9.5 * bit);
    out.push_back(static_cast<char>(stop ? value : 0u));
    t += 9.5 * bit;
  }
  return out;
}

struct Device {
  std::string file;      // <file>.log
  std::string name;      // what it simulates
  std::string protocol;  // decoder registry name
  int baud;
  std::uint32_t seed;
  std::function<std::string(std::size_t, const Motion&)> frame;  // the device's bytes for one sample
};

// `options`: the decoder options the log needs, written as "# option.<key>: <value>".
void write_log(const Device& d, const std::vector<Motion>& motion, const std::string& source, const std::string& dir,
               const std::vector<std::pair<std::string, std::string>>& options = {}) {
  std::mt19937 rng(d.seed);
  const auto pick = [&](std::size_t n) { return static_cast<std::size_t>(rng() % n); };
  std::string data;
  std::string faults;
  // The log begins mid-frame: the tail of a frame sent before the capture started.
  const std::string first = d.frame(0, motion[0]);
  data += first.substr(first.size() / 2);
  faults += "starts with the last " + std::to_string(first.size() - first.size() / 2) + " bytes of a frame";
  // The port opened at the wrong baud rate first: five frames sent at 9600 read at the
  // device's rate (or at 9600 when that is the device's rate, read at 115200).
  std::string early;
  for (std::size_t i = 0; i < 5; ++i) early += d.frame(i, motion[i]);
  const double wrong = d.baud == 9600 ? 115200.0 : 9600.0;
  const std::string noise = uart_misread(early, wrong, d.baud);
  data += noise;
  faults += "; " + std::to_string(noise.size()) + " bytes of five frames sent at " + std::to_string(static_cast<int>(wrong)) +
            " baud read at " + std::to_string(d.baud);
  int flipped = 0, dropped = 0;
  for (std::size_t i = 0; i < motion.size(); ++i) {
    std::string f = d.frame(i, motion[i]);
    if (i % 41 == 17) {
      f[pick(f.size())] ^= static_cast<char>(1u << pick(8));
      ++flipped;
    } else if (i % 59 == 29) {
      f.erase(pick(f.size()), 1);
      ++dropped;
    }
    if (i == motion.size() / 2) {
      for (int k = 0; k < 96; ++k) data.push_back(static_cast<char>(rng() & 0xFF));
    }
    data += f;
  }
  faults += "; one bit flipped in " + std::to_string(flipped) + " frames; one byte dropped from " + std::to_string(dropped) +
            " frames; a burst of 96 random bytes before frame " + std::to_string(motion.size() / 2);

  const std::string path = dir + "/" + d.file + ".log";
  std::ofstream out(path, std::ios::binary);
  char rate[32];
  std::snprintf(rate, sizeof rate, "%.1f Hz", kRateHz);
  out << "# posefair golden replay log (tests/replay/README.md)\n"
      << "# device: " << d.name << "\n"
      << "# protocol: " << d.protocol << "\n"
      << "# baud: " << d.baud << "\n"
      << "# rate: " << rate << "\n";
  for (const auto& [key, value] : options) out << "# option." << key << ": " << value << "\n";
  out << "# source: " << source << ", every " << kStride << "rd row from the first, " << motion.size()
      << " frames (BROAD trial 07, CC BY 4.0, see data/demo/SOURCE.md)\n"
      << "# made: make_replay_logs (tests/replay/make_replay_logs.cpp), seed " << d.seed
      << "; encoded with the protocol's own encoder, not captured from a device\n"
      << "# faults: " << faults << "\n"
      << "# data:\n"
      << data;
  if (!out) throw std::runtime_error("cannot write " + path);
  std::cout << path << ": " << data.size() << " bytes\n";
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 3) {
    std::cerr << "usage: make_replay_logs <data/demo/broad-07-excerpt.csv> <tests/replay>\n";
    return 64;
  }
  try {
    posefair::formats::ReadOptions ro;
    ro.csv_prefix = "gt_";
    const posefair::PoseSequence seq = posefair::formats::read_pose_file(argv[1], ro).poses();
    const std::vector<Vec3> gyro = read_gyro_columns(argv[1]);
    std::vector<Motion> motion;
    for (std::size_t i = 0; i < kFrames; ++i) {
      const std::size_t k = i * kStride;
      if (k >= seq.size() || k >= gyro.size()) throw std::runtime_error("the source has too few samples");
      const Quat& q = seq.orientation[k];
      motion.push_back({seq.time[k] - seq.time[0], q, seq.has_position() ? seq.position[k] : Vec3::Zero(), gyro[k],
                        q.conjugate() * Vec3(0.0, 0.0, 9.81)});  // ENU: +g up at rest
    }
    const auto us = [](double t, double start) {  // a µs device clock that wraps at 2^32
      return static_cast<std::uint32_t>(static_cast<std::uint64_t>(std::llround(start + t * 1e6)) & 0xFFFFFFFFu);
    };
    const double near_wrap = 4294967296.0 - 1.5e6;  // wraps 1.5 s into the log

    const std::vector<Device> devices = {
        {"witmotion-wt901", "WitMotion WT901 (RSW: time, acceleration, quaternion)", "witmotion", 115200, 11,
         [](std::size_t, const Motion& m) {
           const double s = 10.0 + m.t;
           const int ms = static_cast<int>(std::fmod(s, 1.0) * 1000.0);
           return text(drv::encode_witmotion_time(26, 12, 1, 18, 30, static_cast<int>(s), ms)) +
                  text(drv::encode_witmotion_frame(0x51, {0x00, 0x00, 0x00, 0x00, 0x00, 0x08, 0xB8, 0x0B})) + text(drv::encode_witmotion_quaternion(m.q));
         }},
        {"bno085-rvc", "Bosch/CEVA BNO085 in UART-RVC mode (PS0 high)", "bno08x-rvc", 115200, 12,
         [](std::size_t i, const Motion& m) {
           const auto a = ypr(m.q);
           return text(drv::encode_bno08x_rvc(static_cast<std::uint8_t>(i & 0xFF), a[0], a[1], a[2]));
         }},
        {"vectornav-vn100", "VectorNav VN-100: $VNQMR with 8-bit checksum, then $VNYMR with CRC-16", "vectornav", 115200, 13,
         [](std::size_t i, const Motion& m) {
           if (i < kFrames / 2) return drv::encode_vectornav_vnqmr(m.q, false);
           const auto a = ypr(m.q);
           return drv::encode_vectornav_vnymr(a[0], a[1], a[2], true);
         }},
        {"xsens-mti", "Xsens MTi-3 MTData2: PacketCounter, SampleTimeFine, Quaternion (Float32)", "xsens", 115200, 14,
         [](std::size_t i, const Motion& m) {
           const auto counter = static_cast<std::uint16_t>((65400 + i) & 0xFFFF);  // wraps in the log
           const auto fine = static_cast<std::uint32_t>(std::llround(1000000.0 + m.t * 10000.0));
           return text(drv::encode_xsens_mtdata2(m.q, counter, fine));
         }},
        {"yost-3space", "Yost Labs 3-Space: streaming slot 0 = tared quaternion, header 0x4F", "yost", 115200, 15,
         [&](std::size_t, const Motion& m) { return text(drv::encode_yost_quaternion_packet(m.q, us(m.t, near_wrap))); }},
        {"posefair-text", "a posefair microcontroller tracker, $PFQ text sentences with position", "posefair", 115200, 16,
         [&](std::size_t, const Motion& m) { return drv::encode_posefair_sentence(us(m.t, near_wrap), m.q, &m.p); }},
        {"posefair-binary", "a posefair microcontroller tracker, binary frames with position", "posefair", 921600, 17,
         [&](std::size_t, const Motion& m) { return text(drv::encode_posefair_frame(us(m.t, near_wrap), m.q, &m.p)); }},
        {"posefair-imu",
         "a posefair microcontroller tracker with an IMU: binary frames with quaternion, gyroscope and accelerometer, "
         "every 5th raw-only, and $PFI sentences (gyroscope: the excerpt's gyr columns; accelerometer: gravity at the "
         "orientation)",
         "posefair", 921600, 18,
         [&](std::size_t i, const Motion& m) {
           const drv::PosefairImuReading imu{m.gyro, m.accel};
           if (i % 7 == 3) return drv::encode_posefair_imu_sentence(us(m.t, near_wrap), m.gyro, m.accel, nullptr);
           return text(drv::encode_posefair_frame(us(m.t, near_wrap), i % 5 == 4 ? nullptr : &m.q, nullptr, &imu, nullptr));
         }},
    };
    for (const Device& d : devices) write_log(d, motion, "data/demo/broad-07-excerpt.csv", argv[2]);
    // A Yost streaming its corrected sensor data in slot 1 (yost_slots): the excerpt's gyroscope,
    // gravity in g and an earth field (0, 20, -40) µT (ENU) in gauss, at the orientation.
    const Device yost_imu{
        "yost-3space-imu",
        "Yost Labs 3-Space: slot 0 = tared quaternion, slot 1 = corrected gyro, accelerometer and compass (0x25), "
        "header 0x4F",
        "yost", 115200, 19, [&](std::size_t, const Motion& m) {
          drv::YostPacketFields f;
          f.extra = drv::encode_yost_vectors(
              {m.gyro, m.accel / 9.80665, m.q.conjugate() * Vec3(0.0, 0.20, -0.40)});
          return text(drv::encode_yost_quaternion_packet(m.q, us(m.t, near_wrap), f));
        }};
    write_log(yost_imu, motion, "data/demo/broad-07-excerpt.csv", argv[2], {{"yost_slots", "0x00,0x25"}});
  } catch (const std::exception& e) {
    std::cerr << "make_replay_logs: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
