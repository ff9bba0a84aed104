#include "sub_command.hpp"

#include <CLI/CLI.hpp>

#include <netinet/in.h>
#include <sys/socket.h>

#include <algorithm>
#include <cinttypes>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <iostream>
#include <limits>
#include <memory>
#include <optional>
#include <system_error>

#include "posefair/core/error.hpp"
#include "posefair/daemon/json_lines.hpp"
#include "posefair/daemon/output_encoder.hpp"
#include "posefair/daemon/subscription_client.hpp"
#include "posefair/daemon/udp_socket.hpp"

namespace posefair::tools {

// ---------------------------------------------------------------------------------------------
// SequenceTracker

SequenceTracker::Verdict SequenceTracker::observe(std::uint64_t s) {
  ++received_;
  if (!started_) {
    started_ = true;
    first_ = highest_ = s;
    mark(s);
    return Verdict::kFirst;
  }
  if (s > highest_) {
    const std::uint64_t gap = s - highest_ - 1;
    lost_ += gap;
    // Forget the window slots the new highest number takes over (at most the whole window).
    const std::uint64_t clear = std::min<std::uint64_t>(s - highest_, kWindow);
    for (std::uint64_t k = 0; k < clear; ++k) seen_[(s - k) % kWindow] = false;
    highest_ = s;
    mark(s);
    return gap == 0 ? Verdict::kNext : Verdict::kAfterGap;
  }
  if (highest_ - s < kWindow && seen(s)) {
    ++duplicates_;
    return Verdict::kDuplicate;
  }
  ++reordered_;
  if (highest_ - s < kWindow) mark(s);
  // It was counted lost when a higher number skipped over it, unless it precedes the first
  // number this subscriber saw.
  if (s > first_ && lost_ > 0) --lost_;
  return Verdict::kReordered;
}

// ---------------------------------------------------------------------------------------------
// LatencyStats

void LatencyStats::add(double seconds) {
  if (count_ == 0) {
    min_ = max_ = seconds;
  } else {
    min_ = std::min(min_, seconds);
    max_ = std::max(max_, seconds);
  }
  ++count_;
  if (samples_.size() < kMaxSamples) {
    samples_.push_back(seconds);
  } else {
    std::uniform_int_distribution<std::uint64_t> pick(0, count_ - 1);
    if (const std::uint64_t k = pick(rng_); k < kMaxSamples) samples_[k] = seconds;
  }
}

double LatencyStats::quantile(double q) const {
  if (samples_.empty()) return std::numeric_limits<double>::quiet_NaN();
  std::vector<double> s = samples_;
  const auto rank = static_cast<std::size_t>(std::ceil(q * static_cast<double>(s.size())));
  const std::size_t k = std::min(s.size() - 1, rank == 0 ? 0 : rank - 1);
  std::nth_element(s.begin(), s.begin() + static_cast<std::ptrdiff_t>(k), s.end());
  return s[k];
}

// ---------------------------------------------------------------------------------------------
// SubscriberStats

SequenceTracker::Verdict SubscriberStats::observe(const daemon::PoseMessage& m,
                                                  std::chrono::system_clock::time_point received_at) {
  if (m.send_time != 0.0) {
    const double now = std::chrono::duration<double>(received_at.time_since_epoch()).count();
    latency.add(now - m.send_time);
  }
  return streams[{m.session, m.stream}].observe(m.sequence);
}

namespace {
template <typename F>
std::uint64_t sum(const SubscriberStats& s, F f) {
  std::uint64_t n = 0;
  for (const auto& [key, t] : s.streams) n += f(t);
  return n;
}

std::string format(const char* fmt, auto... args) {
  char buf[512];
  std::snprintf(buf, sizeof buf, fmt, args...);
  return buf;
}
}  // namespace

std::uint64_t SubscriberStats::received() const { return sum(*this, [](const SequenceTracker& t) { return t.received(); }); }
std::uint64_t SubscriberStats::lost() const { return sum(*this, [](const SequenceTracker& t) { return t.lost(); }); }
std::uint64_t SubscriberStats::reordered() const { return sum(*this, [](const SequenceTracker& t) { return t.reordered(); }); }
std::uint64_t SubscriberStats::duplicates() const { return sum(*this, [](const SequenceTracker& t) { return t.duplicates(); }); }
std::uint64_t SubscriberStats::malformed_total() const {
  std::uint64_t n = 0;
  for (auto c : malformed) n += c;
  return n;
}

std::string SubscriberStats::summary_line() const {
  std::string line = format("stats: received %" PRIu64 ", lost %" PRIu64 ", reordered %" PRIu64 ", duplicates %" PRIu64
                            ", malformed %" PRIu64,
                            received(), lost(), reordered(), duplicates(), malformed_total());
  if (malformed_total() > 0) {
    std::string reasons;
    for (std::size_t e = 1; e < malformed.size(); ++e) {
      if (malformed[e] == 0) continue;
      if (!reasons.empty()) reasons += ", ";
      reasons += std::string(daemon::to_string(static_cast<daemon::DecodeError>(e))) + " " + std::to_string(malformed[e]);
    }
    line += " (" + reasons + ")";
  }
  if (latency.count() == 0) {
    line += ", latency n/a";
  } else {
    line += format(", latency min %.0f µs p50 %.0f µs p99 %.0f µs max %.0f µs", latency.min() * 1e6,
                   latency.quantile(0.5) * 1e6, latency.quantile(0.99) * 1e6, latency.max() * 1e6);
  }
  return line;
}

std::vector<std::string> SubscriberStats::stream_lines() const {
  std::vector<std::string> lines;
  for (const auto& [key, t] : streams)
    lines.push_back(format("stream %" PRIu32 " session %08" PRIx32 ": received %" PRIu64 ", lost %" PRIu64
                           ", reordered %" PRIu64 ", duplicates %" PRIu64 ", seq %" PRIu64 "..%" PRIu64,
                           key.second, key.first, t.received(), t.lost(), t.reordered(), t.duplicates(), t.first(),
                           t.highest()));
  return lines;
}

// ---------------------------------------------------------------------------------------------
// The subcommand

namespace {

struct SubOptions {
  std::string listen = "0.0.0.0:" + std::to_string(daemon::kDefaultPort);
  bool listen_given = false;
  std::string group;
  std::string interface;
  std::string format = "text";
  std::uint64_t count = 0;    // 0 = unlimited
  double duration = 0.0;      // 0 = unlimited
  double idle = 0.0;          // exit this long after the latest datagram (once one came); 0 = never
  std::uint64_t every = 1;    // print every N-th pose (statistics count all)
  bool quiet = false;
  bool stats = false;
  // --subscribe: sign up on a daemon's subscription port instead of waiting for configured poses.
  std::string subscribe;
  std::vector<std::uint32_t> streams;
  std::string encoding = "binary";
  double lease = 30.0;
  bool angular_velocity = false;
  std::string psk_file;
};

volatile std::sig_atomic_t g_stop = 0;
extern "C" void on_stop_signal(int) { g_stop = 1; }

// SIGINT/SIGTERM end the loop (the statistics are still printed); restored on scope exit.
class StopSignals {
 public:
  StopSignals() {
    g_stop = 0;
    struct sigaction sa {};
    sa.sa_handler = on_stop_signal;
    sigemptyset(&sa.sa_mask);
    sa.sa_flags = 0;  // no SA_RESTART: poll() returns EINTR at once
    sigaction(SIGINT, &sa, &old_int_);
    sigaction(SIGTERM, &sa, &old_term_);
  }
  ~StopSignals() {
    sigaction(SIGINT, &old_int_, nullptr);
    sigaction(SIGTERM, &old_term_, nullptr);
  }
  StopSignals(const StopSignals&) = delete;
  StopSignals& operator=(const StopSignals&) = delete;

 private:
  struct sigaction old_int_ {};
  struct sigaction old_term_ {};
};

void print_text(const daemon::PoseMessage& m) {
  const Quat& q = m.orientation;
  std::printf("session %08" PRIx32 " stream %" PRIu32 " seq %" PRIu64 " t %.6f q %.6f %.6f %.6f %.6f", m.session,
              m.stream, m.sequence, m.sample_time, q.w(), q.x(), q.y(), q.z());
  if (m.position) std::printf(" p %.6f %.6f %.6f", m.position->x(), m.position->y(), m.position->z());
  if (m.angular_velocity)
    std::printf(" w %.6f %.6f %.6f", m.angular_velocity->x(), m.angular_velocity->y(), m.angular_velocity->z());
  if (m.clamped()) std::printf(" clamped");
  if (m.bridged()) std::printf(" bridged");
  std::printf("\n");
}

constexpr const char* kCsvHeader = "session,stream,seq,t,sent,qw,qx,qy,qz,px,py,pz,wx,wy,wz,flags,latency_us\n";

void print_csv(const daemon::PoseMessage& m, std::chrono::system_clock::time_point received_at) {
  const Quat& q = m.orientation;
  std::printf("%" PRIu32 ",%" PRIu32 ",%" PRIu64 ",%.17g,%.17g,%.17g,%.17g,%.17g,%.17g", m.session, m.stream,
              m.sequence, m.sample_time, m.send_time, q.w(), q.x(), q.y(), q.z());
  for (const auto* v : {&m.position, &m.angular_velocity}) {
    if (*v)
      std::printf(",%.17g,%.17g,%.17g", (**v).x(), (**v).y(), (**v).z());
    else
      std::printf(",,,");
  }
  std::printf(",%u,", static_cast<unsigned>(m.flags));
  if (m.send_time != 0.0)
    std::printf("%.1f", (std::chrono::duration<double>(received_at.time_since_epoch()).count() - m.send_time) * 1e6);
  std::printf("\n");
}

// --subscribe and its options into a client; a usage error (64) as a message.
std::optional<daemon::SubscriptionClient> make_client(const SubOptions& o, std::string& error) {
  const auto server = daemon::Endpoint::parse(o.subscribe, daemon::kDefaultControlPort);
  if (!server || server->is_unspecified() || server->is_multicast()) {
    error = "--subscribe " + o.subscribe + " is not HOST:PORT or [IPV6]:PORT of a daemon's subscription port";
    return std::nullopt;
  }
  if (!daemon::find_output_encoder(o.encoding)) {
    error = "--encoding " + o.encoding + " is not a registered encoding";
    return std::nullopt;
  }
  if (o.streams.size() > daemon::kMaxRequestStreams) {
    error = "--streams lists more than " + std::to_string(daemon::kMaxRequestStreams) + " streams";
    return std::nullopt;
  }
  std::optional<daemon::PreSharedKey> psk;
  if (!o.psk_file.empty()) {
    std::ifstream in(o.psk_file);
    std::stringstream text;
    text << in.rdbuf();
    psk = daemon::parse_psk(text.str());
    if (!in || !psk) {
      error = "--psk-file " + o.psk_file + " does not hold a key (64 hex digits)";
      return std::nullopt;
    }
  }
  daemon::SubscriptionRequest r;
  r.encoding = o.encoding;
  r.streams = o.streams;
  r.lease_ms = static_cast<std::uint32_t>(std::min(o.lease, 86400.0) * 1000.0);
  r.angular_velocity = o.angular_velocity;
  return daemon::SubscriptionClient(*server, r, psk, daemon::SubscriptionClient::first_request_id_now());
}

// Ends the lease at exit: UNSUBSCRIBE with the last cookie, once more if the daemon answers
// with a fresh cookie; at most about half a second.
void unsubscribe(daemon::UdpSocket& socket, daemon::SubscriptionClient& client, std::vector<std::uint8_t>& buffer) {
  using namespace std::chrono;
  for (int attempt = 0; attempt < 2; ++attempt) {
    socket.send_to(client.unsubscribe(), client.server());
    const auto until = steady_clock::now() + milliseconds(250);
    bool answered = false;
    while (!answered && steady_clock::now() < until) {
      const auto d = socket.receive(buffer, milliseconds(50));
      if (!d || d->truncated || !(d->source == client.server())) continue;
      const auto reply = daemon::parse_reply(std::span<const std::uint8_t>(buffer.data(), d->size));
      if (!reply) continue;
      if (reply->type == daemon::ReplyType::Unsubscribed) return;
      client.on_reply(std::span<const std::uint8_t>(buffer.data(), d->size), d->source, steady_clock::now());
      answered = true;  // a new cookie: try again with it
    }
  }
}

int run_sub(const SubOptions& o) {
  using namespace std::chrono;
  std::optional<daemon::SubscriptionClient> client;
  if (!o.subscribe.empty()) {
    std::string error;
    client = make_client(o, error);
    if (!client) {
      std::cerr << "posefair sub: " << error << "\n";
      return exit_code(ErrorKind::Usage);
    }
  }
  // Addresses first: a malformed one is a usage error (64).
  std::optional<daemon::Endpoint> group;
  if (!o.group.empty()) {
    group = daemon::Endpoint::parse_address(o.group);
    if (!group || !group->is_multicast()) {
      std::cerr << "posefair sub: --group " << o.group << " is not a multicast address\n";
      return exit_code(ErrorKind::Usage);
    }
  }
  std::string listen_text = o.listen;
  if (group && group->family() == AF_INET6 && !o.listen_given) listen_text = "[::]:" + std::to_string(daemon::kDefaultPort);
  // A subscriber listens where it asks from: any free port of the daemon's family.
  if (client && !o.listen_given) listen_text = client->server().family() == AF_INET6 ? "[::]:0" : "0.0.0.0:0";
  const auto listen = daemon::Endpoint::parse(listen_text, daemon::kDefaultPort);
  if (!listen) {
    std::cerr << "posefair sub: --listen " << listen_text << " is not ADDR:PORT or [IPV6]:PORT\n";
    return exit_code(ErrorKind::Usage);
  }
  if (group && group->family() != listen->family()) {
    std::cerr << "posefair sub: --group " << o.group << " and --listen " << listen_text
              << " are of different address families\n";
    return exit_code(ErrorKind::Usage);
  }
  if (!o.interface.empty() && !group) {
    std::cerr << "posefair sub: --interface needs --group\n";
    return exit_code(ErrorKind::Usage);
  }

  daemon::UdpSocket socket;
  try {
    daemon::ReceiveOptions ro;
    ro.group = group;
    ro.interface.name_or_address = o.interface;
    ro.receive_buffer_bytes = 1 << 20;
    socket = daemon::UdpSocket::bind(*listen, ro);
  } catch (const std::system_error& e) {
    std::cerr << "posefair sub: " << e.what() << "\n";
    return exit_code(ErrorKind::Unavailable);  // the port cannot be bound or the group not joined
  }
  std::cerr << "posefair sub: listening on " << socket.local_endpoint().to_string();
  if (group) std::cerr << ", group " << group->address_string() << (o.interface.empty() ? "" : " on " + o.interface);
  std::cerr << std::endl;

  const bool csv = o.format == "csv", json = o.format == "json";
  if (csv && !o.quiet) std::fputs(kCsvHeader, stdout);

  StopSignals signals;
  SubscriberStats stats;
  std::uint64_t poses = 0;
  std::optional<steady_clock::time_point> deadline;
  if (o.duration > 0) deadline = steady_clock::now() + duration_cast<steady_clock::duration>(duration<double>(o.duration));
  // One byte more than the largest datagram we accept, so an oversized one is seen as such
  // even where the kernel cannot report the real size.
  std::vector<std::uint8_t> buffer(daemon::kMaxDatagramSize + 1);
  std::optional<steady_clock::time_point> last_datagram;
  const auto idle = duration_cast<steady_clock::duration>(duration<double>(o.idle));
  const auto started = steady_clock::now();
  int status = kExitOk;
  while (g_stop == 0 && (o.count == 0 || poses < o.count)) {
    milliseconds wait(200);
    if (client) {
      const auto now = steady_clock::now();
      if (auto request = client->due(now)) socket.send_to(*request, client->server());
      using State = daemon::SubscriptionClient::State;
      if (client->state() == State::Refused || client->state() == State::Failed) {
        if (client->state() == State::Refused)
          std::cerr << "posefair sub: " << client->server().to_string() << " refused the subscription: "
                    << daemon::to_string(client->refused_because()) << "\n";
        else
          std::cerr << "posefair sub: no answer from " << client->server().to_string() << "\n";
        status = exit_code(ErrorKind::Unavailable);
        break;
      }
      wait = milliseconds(50);
    }
    if (deadline) {
      const auto left = *deadline - steady_clock::now();
      if (left <= steady_clock::duration::zero()) break;
      wait = std::min(wait, ceil<milliseconds>(left));
    }
    if (o.idle > 0 && last_datagram) {
      const auto left = *last_datagram + idle - steady_clock::now();
      if (left <= steady_clock::duration::zero()) break;
      wait = std::min(wait, ceil<milliseconds>(left));
    }
    const auto d = socket.receive(buffer, wait);
    if (!d) continue;
    if (client && !d->truncated) {
      const bool was_subscribed = client->subscribed_once();
      if (client->on_reply(std::span<const std::uint8_t>(buffer.data(), d->size), d->source, steady_clock::now())) {
        if (!was_subscribed && client->subscribed_once())
          std::cerr << "posefair sub: subscribed to " << client->server().to_string() << ", lease "
                    << client->lease_ms() / 1000.0 << " s" << std::endl;
        continue;
      }
    }
    last_datagram = steady_clock::now();
    if (d->truncated || d->size > daemon::kMaxDatagramSize) {
      stats.reject(daemon::DecodeError::kOversized);
      continue;
    }
    const auto r = daemon::decode_datagram(std::span<const std::uint8_t>(buffer.data(), d->size));
    if (!r) {
      stats.reject(r.error);
      continue;
    }
    stats.observe(r.message, d->received_at);
    if (++poses == 1 && client)
      std::cerr << "posefair sub: first pose " << duration<double, std::milli>(steady_clock::now() - started).count()
                << " ms after the first SUBSCRIBE" << std::endl;
    if (o.quiet || (poses - 1) % o.every != 0) continue;
    if (csv)
      print_csv(r.message, d->received_at);
    else if (json)
      std::fputs(daemon::encode_json(r.message).c_str(), stdout);
    else
      print_text(r.message);
    std::fflush(stdout);
  }
  std::fflush(stdout);
  if (client && client->subscribed_once()) unsubscribe(socket, *client, buffer);
  if (o.stats)
    for (const auto& line : stats.stream_lines()) std::cerr << line << "\n";
  std::cerr << stats.summary_line() << std::endl;
  return status;
}

}  // namespace

void add_sub_command(CLI::App& app, int& exit_code) {
  auto o = std::make_shared<SubOptions>();
  auto* cmd = app.add_subcommand("sub", "Subscribe to posefair poses over UDP (wire protocol v1, binary or JSON lines) "
                                        "and print them with loss, reordering and latency statistics");
  auto* listen = cmd->add_option("--listen", o->listen, "local ADDR:PORT or [IPV6]:PORT to bind (port 0: any free port)")
                     ->capture_default_str();
  cmd->add_option("--group", o->group, "multicast group to join (e.g. 239.255.80.70 or ff12::5700)");
  cmd->add_option("--interface", o->interface, "interface (address or name) to join the group on");
  cmd->add_option("--format", o->format, "output: text, json (JSON lines) or csv (header first)")
      ->capture_default_str()
      ->check(CLI::IsMember({"text", "json", "csv"}));
  cmd->add_option("--count", o->count, "exit after N poses (0: no limit)")
      ->capture_default_str()
      ->check(CLI::NonNegativeNumber);
  cmd->add_option("--duration", o->duration, "exit after S seconds (0: no limit)")
      ->capture_default_str()
      ->check(CLI::NonNegativeNumber);
  cmd->add_option("--idle", o->idle, "exit S seconds after the latest datagram, once one has come (0: never)")
      ->capture_default_str()
      ->check(CLI::NonNegativeNumber);
  cmd->add_option("--every", o->every, "print only every N-th pose (statistics still count all)")
      ->capture_default_str()
      ->check(CLI::PositiveNumber);
  cmd->add_flag("--quiet", o->quiet, "print no poses, only the statistics");
  cmd->add_flag("--stats", o->stats, "also print one statistics line per (session, stream) at exit");
  auto* subscribe = cmd->add_option("--subscribe", o->subscribe,
                                    "sign up on a daemon's subscription port HOST:PORT (default port 5710) and keep the lease");
  cmd->add_option("--streams", o->streams, "with --subscribe: the stream ids wanted (default: every stream)")
      ->delimiter(',')
      ->needs(subscribe);
  cmd->add_option("--encoding", o->encoding, "with --subscribe: the encoding wanted (binary, json)")
      ->capture_default_str()
      ->needs(subscribe);
  cmd->add_option("--lease", o->lease, "with --subscribe: seconds of lease asked for (renewed at a third)")
      ->capture_default_str()
      ->check(CLI::Range(1.0, 86400.0))
      ->needs(subscribe);
  cmd->add_flag("--angular-velocity", o->angular_velocity, "with --subscribe: poses carry the body rate")->needs(subscribe);
  cmd->add_option("--psk-file", o->psk_file, "with --subscribe: the daemon's pre-shared key (64 hex digits)")->needs(subscribe);
  cmd->callback([o, listen, &exit_code] {
    o->listen_given = listen->count() > 0;
    exit_code = run_sub(*o);
  });
}

}  // namespace posefair::tools
