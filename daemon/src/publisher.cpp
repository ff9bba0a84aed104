#include "posefair/daemon/publisher.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <string>
#include <system_error>


namespace posefair::daemon {

Publisher::Publisher(std::uint32_t session, std::vector<std::uint32_t> stream_ids,
                     const std::vector<OutputConfig>& outputs,
                     const std::map<std::uint32_t, std::uint64_t>& first_sequence, const std::vector<StreamFrame>& frames,
                     std::shared_ptr<SubscriberTable> subscribers)
    : session_(session), subscribers_(std::move(subscribers)) {
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
    outputs_.push_back(Output{encoder_index(oc.encoder), oc.angular_velocity, std::move(carries), UdpSender(oc.destinations, oc.send),
                              OutputRateLimit(oc.max_rate_hz, stream_ids.size())});
  }
  if (subscribers_) {
    for (const auto& encoder : subscribers_->encoders())  // an encoding not offered is never asked for
      subscriber_encoded_.push_back(encoder ? encoder_index(encoder) : 0);
    subscriber_v4_ = UdpSocket::open(AF_INET);
    try {
      subscriber_v6_ = UdpSocket::open(AF_INET6);
    } catch (const std::system_error&) {
      // a host without IPv6: IPv6 subscribers are counted as failed sends
    }
  }
  for (StreamState& st : streams_) {  // each stream's lane, allocated now
    for (const auto& encoder : encoders_) {
      Encoded e;
      e.encoder = encoder;
      e.buffer.resize(kMaxDatagramSize);
      st.encoded.push_back(std::move(e));
    }
    if (subscribers_) st.subscriber_view = subscribers_->make_view();
  }
}

std::size_t Publisher::encoder_index(const std::shared_ptr<const OutputEncoder>& encoder) {
  const auto shared = std::find(encoders_.begin(), encoders_.end(), encoder);
  if (shared != encoders_.end()) return static_cast<std::size_t>(shared - encoders_.begin());
  encoders_.push_back(encoder);
  return encoders_.size() - 1;
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
  if (pose.flags & kNotMeasured) m.flags |= kFlagBridged;  // a held outlier's pose too
  // Body rate between consecutive emitted poses: q_prev⁻¹ q = exp(ω dt / 2) in the papers'
  // half-angle convention, so ω = 2 log(q_prev⁻¹ q) / dt (the stream is hemisphere-continuous).
  // dt is the time the samples were taken apart (FairedPose::step): samples read together and
  // stamped 1 µs apart are still an interval apart. A resampled pose has none: its grid step.
  std::optional<Vec3> rate;
  const double dt = pose.step > 0.0 ? pose.step : pose.time - st.previous_time;
  if (st.have_previous && pose.time > st.previous_time && dt > 0.0)
    rate = 2.0 * so3::log(st.previous.conjugate() * m.orientation) / dt;
  st.have_previous = true;
  st.previous_time = pose.time;
  st.previous = m.orientation;

  m.send_time = std::chrono::duration<double>(std::chrono::system_clock::now().time_since_epoch()).count();
  for (Encoded& e : st.encoded) e.size = 0;
  for (Output& out : outputs_) {
    if (!out.carries[pose.stream_index]) continue;
    result.carried = true;
    if (!out.rate_limit.admit(pose.stream_index, pose.time, pose.step)) continue;
    const OutputEncoder& encoder = *encoders_[out.encoded];
    const std::uint64_t t0 = monotonic_ns();
    if (encoder.delivers()) {  // its own transport (DDS): no datagram, no destinations; counted as sending
      m.angular_velocity = out.angular_velocity ? rate : std::nullopt;
      if (!encoder.deliver(m)) ++result.failures;
      result.send_ns += monotonic_ns() - t0;
      continue;
    }
    const std::span<const std::uint8_t> bytes = datagram(st, out.encoded, m, rate, out.angular_velocity);
    const std::uint64_t t1 = monotonic_ns();
    const std::size_t sent = out.sender.send(bytes);
    result.encode_ns += t1 - t0;
    result.send_ns += monotonic_ns() - t1;
    result.failures += out.sender.destinations().size() - sent;
  }
  if (subscribers_) result.failures += publish_to_subscribers(st, m, rate, result);
  return result;
}

std::span<const std::uint8_t> Publisher::datagram(StreamState& st, std::size_t index, PoseMessage& m,
                                                  const std::optional<Vec3>& rate, bool with_rate) {
  m.angular_velocity = with_rate ? rate : std::nullopt;
  with_rate = m.angular_velocity.has_value();
  Encoded& e = st.encoded[index];
  if (e.size == 0 || e.with_rate != with_rate) {
    e.size = e.encoder->encode(m, e.buffer);
    e.with_rate = with_rate;
  }
  return {e.buffer.data(), e.size};
}

std::size_t Publisher::publish_to_subscribers(StreamState& st, PoseMessage& m, const std::optional<Vec3>& rate,
                                              Result& timing) {
  SubscriberTable::View& view = st.subscriber_view;
  subscribers_->refresh(view);
  const auto now = static_cast<std::int64_t>(monotonic_ns());
  std::size_t failures = 0;
  for (std::size_t i = 0; i < view.count; ++i) {
    const Subscriber& s = view.entries[i];
    if (s.expires_ns <= now || !s.carries(m.stream)) continue;
    UdpSocket& socket = s.address.family() == AF_INET6 ? subscriber_v6_ : subscriber_v4_;
    const std::uint64_t t0 = monotonic_ns();
    const std::span<const std::uint8_t> bytes = datagram(st, subscriber_encoded_[s.encoding], m, rate, s.angular_velocity);
    const std::uint64_t t1 = monotonic_ns();
    const bool sent = socket.is_open() && socket.send_to(bytes, s.address);
    timing.encode_ns += t1 - t0;
    timing.send_ns += monotonic_ns() - t1;
    if (sent)
      subscribers_->count_sent(view.slot[i], 1);
    else
      ++failures;
  }
  return failures;
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
