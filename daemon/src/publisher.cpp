#include "posefair/daemon/publisher.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <string>

#include "posefair/daemon/json_lines.hpp"

namespace posefair::daemon {

Publisher::Publisher(std::uint32_t session, std::vector<std::uint32_t> stream_ids,
                     const std::vector<OutputConfig>& outputs,
                     const std::map<std::uint32_t, std::uint64_t>& first_sequence)
    : session_(session), binary_(kMaxDatagramSize) {
  streams_.resize(stream_ids.size());
  for (std::size_t i = 0; i < stream_ids.size(); ++i) {
    streams_[i].id = stream_ids[i];
    if (auto it = first_sequence.find(stream_ids[i]); it != first_sequence.end()) streams_[i].next_sequence = it->second;
  }
  outputs_.reserve(outputs.size());
  for (const OutputConfig& oc : outputs) {
    std::vector<char> carries(stream_ids.size(), oc.streams.empty() ? 1 : 0);
    for (std::uint32_t id : oc.streams)
      for (std::size_t i = 0; i < stream_ids.size(); ++i)
        if (stream_ids[i] == id) carries[i] = 1;
    outputs_.push_back(Output{oc.encoding, oc.angular_velocity, std::move(carries), UdpSender(oc.destinations, oc.send)});
  }
}

Publisher::Result Publisher::publish(const RingPose& pose) {
  Result result;
  StreamState& st = streams_[pose.stream_index];
  PoseMessage m;
  m.session = session_;
  m.stream = st.id;
  m.sequence = st.next_sequence++;
  m.sample_time = pose.time;
  m.orientation = Quat(pose.q[0], pose.q[1], pose.q[2], pose.q[3]);
  if (pose.flags & kHasPosition) m.position = Vec3(pose.p[0], pose.p[1], pose.p[2]);
  if (pose.flags & kClamped) m.flags |= kFlagClamped;
  if (pose.flags & kBridged) m.flags |= kFlagBridged;
  // Body rate between consecutive emitted poses: q_prev⁻¹ q = exp(ω dt / 2) in the papers'
  // half-angle convention, so ω = 2 log(q_prev⁻¹ q) / dt (the stream is hemisphere-continuous).
  std::optional<Vec3> rate;
  if (st.have_previous && pose.time > st.previous_time)
    rate = 2.0 * so3::log(st.previous.conjugate() * m.orientation) / (pose.time - st.previous_time);
  st.have_previous = true;
  st.previous_time = pose.time;
  st.previous = m.orientation;

  m.send_time = std::chrono::duration<double>(std::chrono::system_clock::now().time_since_epoch()).count();
  std::size_t binary_size = 0;
  bool binary_with_rate = false;
  std::string json;
  bool json_with_rate = false;
  bool json_done = false;
  for (Output& out : outputs_) {
    if (!out.carries[pose.stream_index]) continue;
    result.carried = true;
    m.angular_velocity = out.angular_velocity ? rate : std::nullopt;
    const bool with_rate = m.angular_velocity.has_value();
    std::span<const std::uint8_t> datagram;
    if (out.encoding == WireEncoding::kBinary) {
      if (binary_size == 0 || binary_with_rate != with_rate) {
        binary_size = encode_binary(m, binary_);
        binary_with_rate = with_rate;
      }
      datagram = std::span<const std::uint8_t>(binary_.data(), binary_size);
    } else {
      // JSON lines are for convenience, not for the real-time path's allocation budget.
      if (!json_done || json_with_rate != with_rate) {
        json = encode_json(m);
        json_with_rate = with_rate;
        json_done = true;
      }
      datagram = std::span<const std::uint8_t>(reinterpret_cast<const std::uint8_t*>(json.data()), json.size());
    }
    const std::size_t sent = out.sender.send(datagram);
    result.failures += out.sender.destinations().size() - sent;
  }
  return result;
}

void Publisher::continue_from(const std::map<std::uint32_t, std::uint64_t>& next_sequence) {
  for (StreamState& s : streams_)
    if (auto it = next_sequence.find(s.id); it != next_sequence.end()) s.next_sequence = it->second;
}

std::map<std::uint32_t, std::uint64_t> Publisher::next_sequences() const {
  std::map<std::uint32_t, std::uint64_t> m;
  for (const StreamState& s : streams_) m[s.id] = s.next_sequence;
  return m;
}

}  // namespace posefair::daemon
