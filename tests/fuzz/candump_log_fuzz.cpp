// Fuzz target: the candump log parser (formats/src/candump_log.cpp). The input is the file's
// text. Every line is either a record or a problem (blank lines neither), line numbers rise,
// lengths fit the frame kind, and every record written back with format_candump_line parses to
// the same frame. abort() otherwise.
#include <cstdlib>
#include <string_view>

#include "posefair/formats/candump_log.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace posefair::formats;
  const CandumpLog log = parse_candump_log({reinterpret_cast<const char*>(data), size});
  if (log.records.size() + log.problems.size() > log.lines) std::abort();
  std::size_t last = 0;
  for (const CandumpRecord& r : log.records) {
    if (r.line <= last || r.line > log.lines) std::abort();
    last = r.line;
    const CanFrame& f = r.frame;
    if (f.len > (f.fd ? CanFrame::kMaxFd : CanFrame::kMaxClassic) || (f.fd && !valid_fd_length(f.len))) std::abort();
    std::string error;
    const std::string line = format_candump_line(f, "x");
    const std::optional<CanFrame> g = parse_candump_frame(std::string_view(line).substr(line.rfind(' ') + 1), error);
    if (!g || g->can_id != f.can_id || g->len != f.len || g->fd != f.fd) std::abort();
    for (std::size_t i = 0; i < (f.remote() ? 0u : f.len); ++i)
      if (g->data[i] != f.data[i]) std::abort();
  }
  for (const CandumpProblem& p : log.problems)
    if (p.line == 0 || p.line > log.lines || p.message.empty()) std::abort();
  return 0;
}
