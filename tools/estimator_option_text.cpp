#include "estimator_option_text.hpp"

#include <cstdlib>
#include <stdexcept>

namespace posefair::tools {

OptionMap parse_estimator_settings(const OrientationEstimatorEntry& entry, const std::vector<std::string>& settings) {
  OptionMap map;
  for (const std::string& s : settings) {
    const auto eq = s.find('=');
    if (eq == std::string::npos) throw std::invalid_argument(s + ": expected KEY=VALUE");
    const std::string key = s.substr(0, eq), value = s.substr(eq + 1);
    const OptionSpec* spec = find_option(entry.options, key);
    if (spec == nullptr) {
      std::string known;
      for (const OptionSpec& o : entry.options) {
        known += ' ';
        known += o.name;  // not `" " + std::string(...)`: GCC 12's -Wstringop-overflow misfires on it at -O3
      }
      throw std::invalid_argument(s + ": " + std::string(entry.name) + " has no option '" + key + "'; it has:" + known);
    }
    char* end = nullptr;
    switch (spec->type) {
      case OptionType::Float: {
        const double v = std::strtod(value.c_str(), &end);
        if (value.empty() || *end != '\0') throw std::invalid_argument(s + ": not a number");
        map[key] = v;
        break;
      }
      case OptionType::Integer: {
        const long long v = std::strtoll(value.c_str(), &end, 10);
        if (value.empty() || *end != '\0') throw std::invalid_argument(s + ": not an integer");
        map[key] = static_cast<std::int64_t>(v);
        break;
      }
      case OptionType::Boolean:
        if (value != "true" && value != "false") throw std::invalid_argument(s + ": expected true or false");
        map[key] = value == "true";
        break;
      default:
        map[key] = value;
    }
  }
  return map;
}

}  // namespace posefair::tools
