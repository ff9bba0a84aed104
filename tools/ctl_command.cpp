#include "ctl_command.hpp"

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include <poll.h>
#include <sys/socket.h>
#include <sys/un.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <iostream>
#include <memory>
#include <string>
#include <vector>

#include "posefair/core/error.hpp"
#include "posefair/daemon/control_command.hpp"

namespace posefair::tools {
namespace {

struct CtlOptions {
  std::string socket = "/run/posefaird/control";
  std::vector<std::string> words;
  bool json = false;
  double timeout = 10.0;  // s: a reload may take a while
};

// Sends one request line and returns the reply line; throws posefair::Error(Unavailable).
std::string ask(const CtlOptions& o, const std::string& line) {
  sockaddr_un addr{};
  addr.sun_family = AF_UNIX;
  if (o.socket.size() >= sizeof addr.sun_path) throw Error(ErrorKind::Usage, "--socket path too long: " + o.socket);
  std::memcpy(addr.sun_path, o.socket.c_str(), o.socket.size() + 1);
  const int fd = ::socket(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0);
  if (fd < 0) throw Error(ErrorKind::OsErr, std::string("socket: ") + std::strerror(errno));
  std::unique_ptr<int, void (*)(int*)> closer(new int(fd), [](int* p) {
    ::close(*p);
    delete p;
  });
  if (::connect(fd, reinterpret_cast<const sockaddr*>(&addr), sizeof addr) != 0) {
    const int e = errno;
    std::string why = std::strerror(e);
    if (e == EACCES) why += " (access is for the socket's owner and group: see docs/operations.md)";
    if (e == ENOENT || e == ECONNREFUSED) why += " (is posefaird running with [control]?)";
    throw Error(ErrorKind::Unavailable, "cannot connect to " + o.socket + ": " + why);
  }
  if (::send(fd, line.data(), line.size(), MSG_NOSIGNAL) != static_cast<ssize_t>(line.size()))
    throw Error(ErrorKind::Unavailable, std::string("cannot send to ") + o.socket + ": " + std::strerror(errno));
  std::string reply;
  char buf[4096];
  const int timeout_ms = static_cast<int>(o.timeout * 1000);
  for (;;) {
    pollfd p{fd, POLLIN, 0};
    if (::poll(&p, 1, timeout_ms) <= 0) throw Error(ErrorKind::Unavailable, "no reply from " + o.socket);
    const ssize_t n = ::recv(fd, buf, sizeof buf, 0);
    if (n <= 0) break;
    reply.append(buf, static_cast<std::size_t>(n));
  }
  return reply;
}

std::string num(const nlohmann::json& v, int decimals = 1) {
  if (v.is_null()) return "-";
  if (v.is_number_unsigned() || v.is_number_integer()) return std::to_string(v.get<long long>());
  if (v.is_boolean()) return v.get<bool>() ? "yes" : "no";
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*f", decimals, v.get<double>());
  return buf;
}

void print_streams(const nlohmann::json& streams) {
  std::printf("%-16s %5s %9s %10s %8s %9s %8s %8s %8s  %s\n", "stream", "id", "rate/s", "emitted", "dropped", "published",
              "p50 us", "p99 us", "max us", "adaptation (rotation: noise, motion, cutoff Hz)");
  for (const auto& s : streams) {
    const auto& l = s["latency_us"];
    const auto& r = s["engine"]["rotation"];
    const std::string adaptation = r["adaptive"].get<bool>() ? num(r["noise"], 4) + ", " + num(r["motion"], 3) + ", " +
                                                                   num(r["cutoff_hz"], 2)
                                                             : "fixed, cutoff " + num(r["cutoff_hz"], 2);
    std::printf("%-16s %5s %9s %10s %8s %9s %8s %8s %8s  %s\n", s["name"].get<std::string>().c_str(), num(s["id"]).c_str(),
                num(s["rate_hz"]).c_str(), num(s["emitted"]).c_str(), num(s["dropped"]).c_str(),
                num(s["published"]).c_str(), num(l["p50"]).c_str(), num(l["p99"]).c_str(), num(l["max"]).c_str(),
                adaptation.c_str());
  }
}

void print_subscribers(const nlohmann::json& subscribers) {
  std::printf("%-40s %-8s %-12s %9s %10s\n", "subscriber", "encoding", "streams", "lease s", "sent");
  for (const auto& s : subscribers) {
    std::string streams;
    for (const auto& id : s["streams"]) {
      if (!streams.empty()) streams += ',';
      streams += num(id);
    }
    std::printf("%-40s %-8s %-12s %9s %10s\n", s["address"].get<std::string>().c_str(), s["encoding"].get<std::string>().c_str(),
                streams.empty() ? "all" : streams.c_str(), num(s["lease_left_s"]).c_str(), num(s["sent"]).c_str());
  }
  if (subscribers.empty()) std::printf("(none)\n");
}

void print_human(const nlohmann::json& reply) {
  if (reply.contains("pid")) {
    std::printf("posefaird pid %s, session %s, up %s s, config %s\n", num(reply["pid"]).c_str(),
                reply["session"].get<std::string>().c_str(), num(reply["uptime_s"]).c_str(),
                reply["config"].get<std::string>().c_str());
    std::printf("streams %s, outputs %s, recording %s, subscribers %s\n", num(reply["streams"]).c_str(),
                num(reply["outputs"]).c_str(), reply["recording"].is_null() ? "not configured" : num(reply["recording"]).c_str(),
                reply["subscribers"].is_null() ? "port off" : num(reply["subscribers"]).c_str());
  }
  if (reply.contains("streams") && reply["streams"].is_array()) print_streams(reply["streams"]);
  if (reply.contains("stages")) {
    std::printf("%-10s %10s %8s %8s %8s %8s  (latency by stage since start, us)\n", "stage", "count", "p50", "p99", "p99.9", "max");
    for (const char* name : {"ring_wait", "engine", "hand_off", "encode", "send"}) {
      const auto& st = reply["stages"][name];
      std::printf("%-10s %10s %8s %8s %8s %8s\n", name, num(st["count"]).c_str(), num(st["p50"]).c_str(), num(st["p99"]).c_str(),
                  num(st["p999"]).c_str(), num(st["max"]).c_str());
    }
  }
  if (reply.contains("subscription")) {
    const auto& c = reply["subscription"];
    std::printf("subscription port %s: %s datagrams, %s cookies, %s subscribed, %s renewed, %s refused, dropped: %s not "
                "allowed, %s rate limited, %s malformed, %s unauthenticated, %s bad cookie; amplification %s\n",
                c["listen"].get<std::string>().c_str(), num(c["datagrams"]).c_str(), num(c["cookies_sent"]).c_str(),
                num(c["subscribed"]).c_str(), num(c["renewed"]).c_str(), num(c["refused"]).c_str(),
                num(c["not_allowed"]).c_str(), num(c["rate_limited"]).c_str(), num(c["malformed"]).c_str(),
                num(c["unauthenticated"]).c_str(), num(c["bad_cookie"]).c_str(), num(c["amplification"], 3).c_str());
  }
  if (reply.contains("subscribers") && reply["subscribers"].is_array()) print_subscribers(reply["subscribers"]);
  if (reply.contains("recording")) {
    if (!reply.contains("pid")) std::printf("recording %s\n", num(reply["recording"]).c_str());
  }
  if (reply.contains("previous_session"))
    std::printf("reloaded: session %s (was %s)\n", reply["session"].get<std::string>().c_str(),
                reply["previous_session"].get<std::string>().c_str());
}

int run_ctl(const CtlOptions& o) {
  std::string line;
  for (const std::string& w : o.words) {
    if (!line.empty()) line += ' ';
    line += w;
  }
  line += '\n';
  const auto command = daemon::parse_control_command(std::span(reinterpret_cast<const std::uint8_t*>(line.data()), line.size()));
  if (!command) {
    std::cerr << "posefair ctl: not a command: " << line.substr(0, line.size() - 1)
              << " (status, streams, subscribers, counters, reload, record start, record stop)\n";
    return exit_code(ErrorKind::Usage);
  }
  std::string text;
  try {
    text = ask(o, line);
  } catch (const Error& e) {
    std::cerr << "posefair ctl: " << e.what() << "\n";
    return e.exit_code();
  }
  const nlohmann::json reply = nlohmann::json::parse(text, nullptr, false);
  if (reply.is_discarded() || !reply.is_object() || !reply.contains("ok")) {
    std::cerr << "posefair ctl: the daemon's reply is not a JSON object: " << text.substr(0, 200) << "\n";
    return exit_code(ErrorKind::Software);
  }
  if (!reply["ok"].get<bool>()) {
    std::cerr << "posefair ctl: " << reply.value("error", std::string("failed")) << "\n";
    if (o.json) std::cout << text;
    return reply.value("exit", exit_code(ErrorKind::Software));
  }
  if (o.json)
    std::cout << text;
  else
    print_human(reply);
  return kExitOk;
}

}  // namespace

void add_ctl_command(CLI::App& app, int& exit_code) {
  auto o = std::make_shared<CtlOptions>();
  auto* cmd = app.add_subcommand("ctl", "Ask a running posefaird through its control socket: status, streams, subscribers, "
                                        "counters, reload, record start|stop");
  cmd->add_option("command", o->words, "status | streams | subscribers | counters | reload | record start | record stop")
      ->required();
  cmd->add_option("--socket", o->socket, "the daemon's control socket ([control] socket)")->capture_default_str();
  cmd->add_flag("--json", o->json, "print the daemon's JSON reply as it is");
  cmd->add_option("--timeout", o->timeout, "seconds to wait for the reply")->capture_default_str()->check(CLI::PositiveNumber);
  cmd->callback([o, &exit_code] { exit_code = run_ctl(*o); });
}

}  // namespace posefair::tools
