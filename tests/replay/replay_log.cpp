#include "replay_log.hpp"

#include <fstream>
#include <iterator>
#include <stdexcept>

namespace posefair::replay {

ReplayLog read_replay_log(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error(path.string() + ": cannot open");
  const std::string all((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  ReplayLog log;
  std::size_t pos = 0;
  int line = 0;
  while (pos < all.size()) {
    ++line;
    const std::size_t end = all.find('\n', pos);
    if (end == std::string::npos) break;
    const std::string text = all.substr(pos, end - pos);
    pos = end + 1;
    if (text == "# data:") {
      log.data = all.substr(pos);
      return log;
    }
    if (text.rfind("# ", 0) != 0) {
      throw std::runtime_error(path.string() + ":" + std::to_string(line) + ": header line without \"# \"");
    }
    const std::size_t colon = text.find(": ");
    if (colon == std::string::npos) continue;  // a comment line
    log.header[text.substr(2, colon - 2)] = text.substr(colon + 2);
  }
  throw std::runtime_error(path.string() + ": no \"# data:\" line ends the header");
}

}  // namespace posefair::replay
