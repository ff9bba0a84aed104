// Xsens/Movella MTi CAN output (MTi 600-series, Avior, Sirius): registry name "xsens-can".
//
// Reference documents
// - Xsens, "MT CAN Protocol Documentation", MTi 600-series, document MT1604P, revision A
//   (16 Sept 2019), and its current online form, Movella's "CAN Messages" page
//   (mtidocs.movella.com/canmessages): the message list. Each message is one classic CAN frame
//   (at most 8 bytes, up to 1 Mbit/s) with an 11- or 29-bit identifier; by default the
//   identifier is the message's data identifier; MT Manager (SetCanOutputConfig) can change
//   each identifier and the format.
//     XCID_Error       0x001  uint8 error code
//     XCID_SampleTime  0x005  uint32; Xbus equivalent XDI_SampleTimeFine (see the choice below)
//     XCID_GroupCounter 0x006 uint16; a CAN group counter, independent of the Xbus PacketCounter
//     XCDI_Quaternion  0x021  q0, q1, q2, q3: int16 each, 8 bytes
// - Xsens' SDK header xscandataidentifier.h (enum XsCanDataIdentifier, shipped in the MT SDK
//   sources) for the identifier values.
// - Byte order: big-endian, as all Xsens binary data ("MTi User Manual" MT0605P.E 5.7.1).
// - Scale: value = raw / 32767 (factor 3.05185094759972e-05 in Xsens' .dbc for the 600-series,
//   as quoted by users of that file; Movella's page notes to "be careful when converting the
//   value 1": 1.0 is 0x7FFF, -1.0 is 0x8001). The decoder normalises the quaternion, so the
//   choice between 1/32767 and 1/32768 changes no sample.
//
// What posefair reads and the choices where the documents are open
// - q0 is the scalar (Xsens' q_LS rotates sensor coordinates into the local earth frame,
//   ENU by default): posefair's convention, no conjugate.
// - SampleTime: Movella's current page says 10 kHz ticks (100 µs, like XDI_SampleTimeFine);
//   the SDK header's comment says µs. Option xsens_sample_time_unit: "100us" (default) or
//   "1us". Unwrapped forward-only at 2^32. GroupCounter: u16, unwrapped into frame_counter.
// - Pairing: an MTi sends the messages of one output group one after the other, the timestamp
//   messages first (their identifiers are lower, so they also win arbitration). A quaternion
//   frame takes the SampleTime and GroupCounter received since the previous quaternion frame;
//   a newer one of the same kind replaces an older one (which counts as ignored). A quaternion
//   without them is a sample without device time / counter. Every valid SampleTime advances
//   the unwrapping.
// - Checks: the DLC must be 8, 4 and 2 (malformed otherwise; the documents fix each message's
//   size). A quaternion with a component -32768 (outside ±1), or whose norm differs from 1 by
//   more than 1e-3 (an int16-rounded unit quaternion is within 3e-5), is malformed; otherwise it
//   is normalised. Only the three configured identifiers (in the configured format) are read;
//   every other frame on the bus is foreign.
// - No checksum in the payload: the CAN frame's CRC-15 protects it on the bus.
// - Raw readings (issue 17; option xsens_raw lists those the MTi was set to send, default none):
//     XCDI_RateOfTurn   0x032  gyrX, gyrY, gyrZ: int16 BE, 2^-9 rad/s      -> gyro (kHasGyro)
//     XCDI_Acceleration 0x034  accX, accY, accZ: int16 BE, 2^-8 m/s²      -> accel (kHasAccel)
//     XCDI_MagneticField 0x041 magX, magY, magZ: int16 BE, 2^-10 a.u.     -> mag (kHasMag), µT
//   (6 bytes each; identifiers from xscandataidentifier.h, layout and scaling from the .dbc
//   figures and Movella's page as quoted by users of them; "a.u.": 1 is the field strength
//   where the magnetic field mapping was done, scaled by xsens_mag_field µT as in the serial
//   decoder). The high-rate variants (0x061/0x062) are not read: the sources disagree on which
//   of the two is the rate of turn, and they come at rates the quaternion does not.
// - Groups with raw readings: an MTi sends a group's messages in increasing identifier order
//   (the order arbitration gives messages queued together; the timestamp messages come first
//   for the same reason), so the raw messages come after the quaternion. A group's sample is
//   emitted as soon as its quaternion and every listed raw message are in, so a complete group
//   costs no extra latency. A quaternion or raw frame whose identifier is not above the last
//   one of the group being gathered starts a new group: the unfinished one is emitted with what
//   it has (a group without its quaternion as a raw-only sample, kNoOrientation), so a lost
//   frame costs that reading, never the rest. List only messages sent in every group (at the
//   quaternion's rate): one that comes less often holds each group without it back until the
//   next group starts. A group takes the SampleTime and GroupCounter received before its first
//   data frame.
#include "posefair/drivers/xsens_can_decoder.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "posefair/drivers/byte_order.hpp"
#include "posefair/drivers/counter_unwrap.hpp"

namespace posefair::drivers {
namespace {

constexpr std::uint32_t kDefaultQuaternion = 0x021, kDefaultSampleTime = 0x005, kDefaultGroupCounter = 0x006;
constexpr double kScale = 32767.0;
constexpr double kUnitTolerance = 1e-3;

// The raw messages: rate of turn, acceleration, magnetic field (in this order throughout).
constexpr std::size_t kRawKinds = 3;
constexpr std::uint32_t kDefaultRaw[kRawKinds] = {0x032, 0x034, 0x041};
constexpr double kRawScale[kRawKinds] = {1.0 / 512.0, 1.0 / 256.0, 1.0 / 1024.0};  // 2^-9, 2^-8, 2^-10
constexpr std::uint32_t kRawFlag[kRawKinds] = {kHasGyro, kHasAccel, kHasMag};

struct XsensIds {
  std::uint32_t quaternion, sample_time, group_counter;
  bool extended;
  std::array<std::uint32_t, kRawKinds> raw{};
  std::array<bool, kRawKinds> raw_read{};  // listed in xsens_raw
};

class XsensCanDecoder final : public CanDecoder {
 public:
  XsensCanDecoder(const XsensIds& ids, double tick, double mag_ut_per_au)
      : ids_(ids), tick_(tick), mag_ut_per_au_(mag_ut_per_au) {
    for (std::size_t k = 0; k < kRawKinds; ++k)
      if (ids_.raw_read[k]) expected_raw_ |= kRawFlag[k];
  }

  std::string_view protocol() const override { return "xsens-can"; }

  std::vector<CanFilter> filters() const override {
    const std::uint32_t flag = ids_.extended ? CanFrame::kEffFlag : 0u;
    const std::uint32_t mask = (ids_.extended ? CanFrame::kEffMask : CanFrame::kSffMask) | CanFrame::kEffFlag | CanFrame::kRtrFlag;
    std::vector<CanFilter> out = {{ids_.sample_time | flag, mask}, {ids_.group_counter | flag, mask}, {ids_.quaternion | flag, mask}};
    for (std::size_t k = 0; k < kRawKinds; ++k)
      if (ids_.raw_read[k]) out.push_back({ids_.raw[k] | flag, mask});
    return out;
  }

  void reset() override {
    time_.reset();
    counter_.reset();
    pending_time_.reset();
    pending_counter_.reset();
    group_.reset();
  }

 protected:
  bool reads(const CanFrame& f) const override {
    const std::uint32_t id = f.id();
    return f.extended() == ids_.extended &&
           (id == ids_.quaternion || id == ids_.sample_time || id == ids_.group_counter || raw_kind(id) < kRawKinds);
  }

  void decode(const CanFrame& f, DecodedSink& sink) override {
    const std::uint32_t id = f.id();
    if (id == ids_.quaternion) {
      quaternion(f, sink);
    } else if (const std::size_t kind = raw_kind(id); kind < kRawKinds) {
      raw(kind, f, sink);
    } else if (id == ids_.sample_time) {
      if (f.len != 4) return malformed(f.len);
      ++counters_.frames;
      if (pending_time_) ++counters_.ignored_frames;
      pending_time_ = time_.update(bytes::be_u32(f.data.data()));
    } else {
      if (f.len != 2) return malformed(f.len);
      ++counters_.frames;
      if (pending_counter_) ++counters_.ignored_frames;
      pending_counter_ = counter_.update(bytes::be_u16(f.data.data()));
    }
  }

 private:
  void malformed(std::size_t len) {
    ++counters_.malformed;
    counters_.skipped_bytes += len;
  }

  // The listed raw message `id` is (kRawKinds: none).
  std::size_t raw_kind(std::uint32_t id) const {
    for (std::size_t k = 0; k < kRawKinds; ++k)
      if (ids_.raw_read[k] && id == ids_.raw[k]) return k;
    return kRawKinds;
  }

  void quaternion(const CanFrame& f, DecodedSink& sink) {
    if (f.len != 8) return malformed(f.len);
    std::array<double, 4> c{};
    for (std::size_t k = 0; k < 4; ++k) {
      const std::int16_t v = bytes::be_i16(&f.data[2 * k]);
      if (v == -32768) return malformed(f.len);
      c[k] = v / kScale;
    }
    const Quat q(c[0], c[1], c[2], c[3]);
    const double n = q.norm();
    if (!(std::abs(n - 1.0) <= kUnitTolerance)) return malformed(f.len);
    ++counters_.frames;
    Group& g = group_for(f.id(), sink);
    g.sample.orientation = Quat(q.coeffs() / n);
    g.sample.flags &= ~static_cast<std::uint32_t>(kNoOrientation);
    complete_if_whole(sink);
  }

  void raw(std::size_t kind, const CanFrame& f, DecodedSink& sink) {
    if (f.len != 6) return malformed(f.len);
    ++counters_.frames;
    const double scale = kRawScale[kind] * (kind == 2 ? mag_ut_per_au_ : 1.0);
    const Vec3 v = scale * Vec3(bytes::be_i16(&f.data[0]), bytes::be_i16(&f.data[2]), bytes::be_i16(&f.data[4]));
    Group& g = group_for(f.id(), sink);
    (kind == 0 ? g.sample.gyro : kind == 1 ? g.sample.accel : g.sample.mag) = v;
    g.sample.flags |= kRawFlag[kind];
    complete_if_whole(sink);
  }

  // The group a data frame `id` belongs to: the one being gathered, unless `id` does not come
  // after its last frame (then that one is emitted and a new group starts with the SampleTime
  // and GroupCounter received since).
  struct Group {
    DecodedSample sample;
    std::uint32_t last_id = 0;
  };
  Group& group_for(std::uint32_t id, DecodedSink& sink) {
    if (group_ && id <= group_->last_id) emit(sink);
    if (!group_) {
      group_.emplace();
      group_->sample.flags = kNoOrientation;
      if (pending_time_) {
        group_->sample.flags |= kHasDeviceTime;
        group_->sample.device_time = static_cast<double>(*pending_time_) * tick_;
      }
      if (pending_counter_) {
        group_->sample.frame_counter = *pending_counter_;
        group_->sample.has_frame_counter = true;
      }
      pending_time_.reset();
      pending_counter_.reset();
    }
    group_->last_id = id;
    return *group_;
  }

  void complete_if_whole(DecodedSink& sink) {
    const std::uint32_t flags = group_->sample.flags;
    if ((flags & kNoOrientation) == 0 && (flags & expected_raw_) == expected_raw_) emit(sink);
  }

  void emit(DecodedSink& sink) {
    ++counters_.samples;
    sink.on_sample(group_->sample);
    group_.reset();
  }

  XsensIds ids_;
  double tick_;
  double mag_ut_per_au_;
  std::uint32_t expected_raw_ = 0;  // the kHasGyro/Accel/Mag flags a whole group has
  std::optional<Group> group_;      // the group being gathered
  CounterUnwrapper time_{32};
  CounterUnwrapper counter_{16};
  std::optional<std::uint64_t> pending_time_;
  std::optional<std::uint64_t> pending_counter_;
};

}  // namespace

namespace {
constexpr std::string_view kIdFormats[] = {"standard", "extended"};
constexpr std::string_view kTimeUnits[] = {"100us", "1us"};
constexpr std::string_view kRawNames[kRawKinds] = {"rate_of_turn", "acceleration", "magnetic_field"};
constexpr const char* kRawIdKeys[kRawKinds] = {"xsens_rate_of_turn_id", "xsens_acceleration_id", "xsens_magnetic_field_id"};
constexpr OptionSpec kOptions[] = {
    {"xsens_quaternion_id", OptionType::IntegerOrString, "0x021", "the identifier of the Quaternion message"},
    {"xsens_sample_time_id", OptionType::IntegerOrString, "0x005", "the identifier of the SampleTime message"},
    {"xsens_group_counter_id", OptionType::IntegerOrString, "0x006", "the identifier of the GroupCounter message"},
    {"xsens_id_format", OptionType::String, "standard", "standard (11-bit) or extended (29-bit) identifiers", kIdFormats},
    {"xsens_sample_time_unit", OptionType::String, "100us",
     "the unit of SampleTime: 100us (Xsens' current CAN documentation) or 1us", kTimeUnits},
    {"xsens_raw", OptionType::StringArray, "",
     "the raw messages the MTi sends in every group, read into the samples: rate_of_turn, acceleration, magnetic_field"},
    {"xsens_rate_of_turn_id", OptionType::IntegerOrString, "0x032", "the identifier of the RateOfTurn message"},
    {"xsens_acceleration_id", OptionType::IntegerOrString, "0x034", "the identifier of the Acceleration message"},
    {"xsens_magnetic_field_id", OptionType::IntegerOrString, "0x041", "the identifier of the MagneticField message"},
    {"xsens_mag_field", OptionType::Float, "50.0",
     "µT that one arbitrary unit of the MagneticField message stands for (the field strength where the magnetic field mapping was done)"},
};
}  // namespace

const CanDecoderEntry kXsensCanDecoder{"xsens-can",
                                       "Xsens MTi CAN output: Quaternion, SampleTime, GroupCounter and (xsens_raw) "
                                       "RateOfTurn, Acceleration, MagneticField messages",
                                       kOptions, make_xsens_can_decoder};

std::unique_ptr<CanDecoder> make_xsens_can_decoder(const OptionMap& options) {
  const OptionReader read(kOptions, options);
  XsensIds ids{};
  ids.extended = parse_can_id_format_option("xsens_id_format", read.text("xsens_id_format"));
  const std::uint32_t max = ids.extended ? CanFrame::kEffMask : CanFrame::kSffMask;
  ids.quaternion = parse_can_id_option("xsens_quaternion_id", read.text("xsens_quaternion_id"), max);
  ids.sample_time = parse_can_id_option("xsens_sample_time_id", read.text("xsens_sample_time_id"), max);
  ids.group_counter = parse_can_id_option("xsens_group_counter_id", read.text("xsens_group_counter_id"), max);
  if (ids.quaternion == ids.sample_time || ids.quaternion == ids.group_counter || ids.sample_time == ids.group_counter) {
    // Blame a key that was given (the defaults differ among themselves).
    const char* key = read.has("xsens_quaternion_id") ? "xsens_quaternion_id"
                      : read.has("xsens_sample_time_id") ? "xsens_sample_time_id"
                                                         : "xsens_group_counter_id";
    throw OptionError(key, "xsens_quaternion_id, xsens_sample_time_id and xsens_group_counter_id must differ");
  }
  if (read.has("xsens_raw")) {
    for (const std::string& name : read.strings("xsens_raw")) {
      std::size_t k = 0;
      while (k < kRawKinds && kRawNames[k] != name) ++k;
      if (k == kRawKinds)
        throw OptionError("xsens_raw", "\"" + name + "\" is not rate_of_turn, acceleration or magnetic_field");
      if (ids.raw_read[k]) throw OptionError("xsens_raw", "\"" + name + "\" is listed twice");
      ids.raw_read[k] = true;
    }
  }
  std::vector<std::pair<std::uint32_t, const char*>> used = {{ids.quaternion, "xsens_quaternion_id"},
                                                             {ids.sample_time, "xsens_sample_time_id"},
                                                             {ids.group_counter, "xsens_group_counter_id"}};
  for (std::size_t k = 0; k < kRawKinds; ++k) {
    ids.raw[k] = parse_can_id_option(kRawIdKeys[k], read.text(kRawIdKeys[k]), max);
    if (!ids.raw_read[k]) continue;
    for (const auto& [other, other_key] : used)
      if (other == ids.raw[k])
        throw OptionError(read.has(kRawIdKeys[k]) ? kRawIdKeys[k] : other_key,
                          std::string(kRawIdKeys[k]) + " must differ from " + other_key);
    used.emplace_back(ids.raw[k], kRawIdKeys[k]);
  }
  const double field = read.real("xsens_mag_field");
  if (!(field > 0.0 && field < 1000.0)) throw OptionError("xsens_mag_field", "must be a field strength in µT, above 0 and below 1000");
  const std::string unit = read.text("xsens_sample_time_unit");
  double tick = 0;
  if (unit == "100us")
    tick = 1e-4;
  else if (unit == "1us")
    tick = 1e-6;
  else
    throw OptionError("xsens_sample_time_unit", "\"" + unit + "\" is not \"100us\" or \"1us\"");
  return std::make_unique<XsensCanDecoder>(ids, tick, field);
}

std::vector<CanFrame> encode_xsens_can(const Quat& q, std::optional<std::uint32_t> sample_time,
                                       std::optional<std::uint16_t> group_counter, double timestamp) {
  std::vector<CanFrame> frames;
  if (group_counter) {
    std::array<std::uint8_t, 2> d{};
    bytes::put_be_u16(d.data(), *group_counter);
    frames.push_back(CanFrame::make(kDefaultGroupCounter, false, d, timestamp));
  }
  if (sample_time) {
    std::array<std::uint8_t, 4> d{};
    bytes::put_be_u32(d.data(), *sample_time);
    frames.push_back(CanFrame::make(kDefaultSampleTime, false, d, timestamp));
  }
  std::array<std::uint8_t, 8> d{};
  const double c[4] = {q.w(), q.x(), q.y(), q.z()};
  for (int k = 0; k < 4; ++k) {
    const double r = std::round(c[k] * kScale);
    bytes::put_be_u16(&d[2 * k], static_cast<std::uint16_t>(static_cast<std::int16_t>(r > kScale ? kScale : (r < -kScale ? -kScale : r))));
  }
  frames.push_back(CanFrame::make(kDefaultQuaternion, false, d, timestamp));
  return frames;
}

std::vector<CanFrame> encode_xsens_can_raw(const std::optional<Vec3>& rate_of_turn, const std::optional<Vec3>& acceleration,
                                           const std::optional<Vec3>& magnetic_field_au, double timestamp) {
  std::vector<CanFrame> frames;
  const std::optional<Vec3>* values[kRawKinds] = {&rate_of_turn, &acceleration, &magnetic_field_au};
  for (std::size_t k = 0; k < kRawKinds; ++k) {
    if (!*values[k]) continue;
    std::array<std::uint8_t, 6> d{};
    for (int i = 0; i < 3; ++i) {
      const double r = std::clamp(std::round((**values[k])[i] / kRawScale[k]), -32768.0, 32767.0);
      bytes::put_be_u16(&d[2 * static_cast<std::size_t>(i)], static_cast<std::uint16_t>(static_cast<std::int16_t>(r)));
    }
    frames.push_back(CanFrame::make(kDefaultRaw[k], false, d, timestamp));
  }
  return frames;
}

}  // namespace posefair::drivers
