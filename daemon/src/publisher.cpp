#include "posefair/daemon/publisher.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <string>


namespace posefair::daemon {

Publisher::Publisher(std::uint32_t session, std::vector<std::uint32_t> stream_ids,
                     const std::vector<OutputConfig>& outputs,
                     const std::map<std::uint32_t, std::uint64_t>& first_sequence, const std::vector<StreamFrame>& frames)
    : session_(session) {
  streams_.resize(stream_ids.size());
  for (std::size_t i = 0; i < stream_ids.size(); ++i) {
    streams_[i].id = stream_ids[i];
    if (i < frames.size()) streams_[i].frame = frames[i];
    if (auto it = first_sequence.find(stream_ids[i]); it != first_sequence.end()) streams_[i].next_sequence = it->second;
  }
  outputs_.reserve(outputs.size());
  for (const OutputConfig& oc : outputs) {
    std::vector<char> carries(stream_ids.size(), oc.streams.empty() ? 1 : 0);
    for (std::uint32_t id : oc.streams)
      for (std::size_t i = 0; i < stream_ids.size(); ++i)
        if (stream_ids[i] == id) carries[i] = 1;
    const auto shared = std::find_if(encoded_.begin(), encoded_.end(), [&](const Encoded& e) { return e.encoder == oc.encoder; });
    const auto encoded = static_cast<std::size_t>(shared - encoded_.begin());
    if (shared == encoded_.end()) {
      Encoded e;
      e.encoder = oc.encoder;
      e.buffer.resize(kMaxDatagramSize);
      encoded_.push_back(std::move(e));
    }
    outputs_.push_back(Output{encoded, oc.angular_velocity, std::move(carries), UdpSender(oc.destinations, oc.send),
                              OutputRateLimit(oc.max_rate_hz, stream_ids.size())});
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
  m.orientation = st.frame.orientation(Quat(pose.q[0], pose.q[1], pose.q[2], pose.q[3]));
  if (pose.flags & kHasPosition) m.position = st.frame.position(Vec3(pose.p[0], pose.p[1], pose.p[2]));
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
  for (Encoded& e : encoded_) e.size = 0;
  for (Output& out : outputs_) {
    if (!out.carries[pose.stream_index]) continue;
    result.carried = true;
    if (!out.rate_limit.admit(pose.stream_index, pose.time)) continue;
    m.angular_velocity = out.angular_velocity ? rate : std::nullopt;
    const bool with_rate = m.angular_velocity.has_value();
    Encoded& e = encoded_[out.encoded];
    if (e.encoder->delivers()) {  // its own transport (DDS): no datagram, no destinations
      if (!e.encoder->deliver(m)) ++result.failures;
      continue;
    }
    if (e.size == 0 || e.with_rate != with_rate) {
      e.size = e.encoder->encode(m, e.buffer);
      e.with_rate = with_rate;
    }
    const std::span<const std::uint8_t> datagram(e.buffer.data(), e.size);
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
