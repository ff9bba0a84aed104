#pragma once
// The publisher: turns faired poses into datagrams, each output through the encoder its config
// chose (daemon/output_encoder.hpp: wire protocol v1 binary or JSON lines, docs/protocol.md), and
// sends each to every destination of every output that carries its stream. A pose is encoded
// once per encoder (and angular-velocity choice), however many outputs share it. Owns the per-stream wire sequence numbers (0 at session start, +1 per pose; carried
// over a SIGHUP reload) and the previous pose per stream for the optional angular velocity.
// publish() runs for one stream on one thread at a time, and for different streams on several
// threads at once: each stream's engine role holder (its driver thread with fair_on = "driver",
// or the engine thread) publishes that stream's poses, or the publisher thread all of them with
// publish_on = "publisher". So everything publish() writes is the stream's own (its sequence,
// its previous pose, its lane: the encoders' buffers and the subscriber view); the sockets are
// shared (the kernel serialises sends) and non-blocking, so a slow network never stalls it (a
// full socket buffer is a counted send failure).
#include <cstdint>
#include <map>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "posefair/daemon/client_frames.hpp"
#include "posefair/daemon/config.hpp"
#include "posefair/daemon/output_encoder.hpp"
#include "posefair/daemon/output_rate_limit.hpp"
#include "posefair/daemon/ring_items.hpp"
#include "posefair/daemon/subscriber_table.hpp"
#include "posefair/daemon/udp_socket.hpp"
#include "posefair/daemon/wire_protocol.hpp"

namespace posefair::daemon {

class Publisher {
 public:
  // `stream_ids[i]` is the wire id of stream index i. `first_sequence` gives, per wire stream
  // id, the sequence number to continue from (missing: 0). `frames[i]` is stream i's mounting and
  // world correction (missing: none), applied before any encoding. `subscribers` (may be null):
  // the clients that signed themselves up on the subscription port, sent to as well. Opens the
  // sockets now; throws std::system_error when one cannot be opened.
  Publisher(std::uint32_t session, std::vector<std::uint32_t> stream_ids, const std::vector<OutputConfig>& outputs,
            const std::map<std::uint32_t, std::uint64_t>& first_sequence, const std::vector<StreamFrame>& frames = {},
            std::shared_ptr<SubscriberTable> subscribers = nullptr);

  struct Result {
    bool carried = false;           // at least one output carries this stream
    std::size_t failures = 0;       // failed sends (one per destination)
    std::uint64_t encode_ns = 0;    // time spent encoding (every datagram of the pose)
    std::uint64_t send_ns = 0;      // time spent sending (every send of the pose)
  };
  // Sends one pose now; send_time is CLOCK_REALTIME at the call.
  Result publish(const RingPose& pose);

  // Continue each listed stream's sequence from the given number (a reload, before any publish).
  void continue_from(const std::map<std::uint32_t, std::uint64_t>& next_sequence);
  // The next wire sequence number of every stream (for a reload to continue from).
  std::map<std::uint32_t, std::uint64_t> next_sequences() const;
  std::uint32_t session() const { return session_; }

 private:
  struct Output {
    std::size_t encoded;  // index into encoders_ (and each stream's encoded): this output's encoder
    bool angular_velocity;
    std::vector<char> carries;  // per stream index
    UdpSender sender;
    OutputRateLimit rate_limit;  // max_rate_hz
  };
  // One per distinct encoder among the outputs, per stream: its datagram for the pose being published.
  struct Encoded {
    std::shared_ptr<const OutputEncoder> encoder;
    std::vector<std::uint8_t> buffer;  // kMaxDatagramSize bytes, allocated once
    std::size_t size = 0;              // 0: not encoded for this pose yet
    bool with_rate = false;            // encoded with the angular velocity
  };
  struct StreamState {
    std::uint32_t id = 0;
    StreamFrame frame;
    std::uint64_t next_sequence = 0;
    bool have_previous = false;
    double previous_time = 0.0;
    Quat previous = Quat::Identity();
    // The stream's lane: scratch that only the thread publishing this stream touches.
    std::vector<Encoded> encoded;          // indexed like encoders_
    SubscriberTable::View subscriber_view;  // its own copy of the subscriber table's entries
  };
  // The encoders_ index of this encoder, added on first use (outputs sharing an encoder share it).
  std::size_t encoder_index(const std::shared_ptr<const OutputEncoder>& encoder);
  // The datagram of st.encoded[index] for m, encoded on first use for this pose.
  static std::span<const std::uint8_t> datagram(StreamState& st, std::size_t index, PoseMessage& m, const std::optional<Vec3>& rate,
                                                bool with_rate);
  // Sends m to the subscribers that carry its stream and whose lease runs; returns failed sends.
  std::size_t publish_to_subscribers(StreamState& st, PoseMessage& m, const std::optional<Vec3>& rate, Result& timing);

  std::uint32_t session_;
  std::vector<Output> outputs_;
  std::vector<StreamState> streams_;
  std::vector<std::shared_ptr<const OutputEncoder>> encoders_;  // the distinct encoders
  // Subscribers (subscriber_table.hpp): the table, the encoders_ index of each registered
  // encoding, and a socket per family to send from.
  std::shared_ptr<SubscriberTable> subscribers_;
  std::vector<std::size_t> subscriber_encoded_;
  UdpSocket subscriber_v4_, subscriber_v6_;
};

}  // namespace posefair::daemon
