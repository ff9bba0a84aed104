// Reading declared options; see options.hpp.
#include "posefair/core/options.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdlib>

namespace posefair {

std::string_view to_string(OptionType type) {
  switch (type) {
    case OptionType::String: return "a string";
    case OptionType::Integer: return "an integer";
    case OptionType::Float: return "a number";
    case OptionType::Boolean: return "a boolean";
    case OptionType::IntegerOrString: return "an integer or a string";
    case OptionType::IntegerArray: return "an array of integers";
    case OptionType::StringArray: return "an array of strings";
  }
  return "a value";
}

OptionError::OptionError(std::string key, std::string message, std::string related_key)
    : std::invalid_argument(key + ": " + message),
      key_(std::move(key)),
      message_(std::move(message)),
      related_key_(std::move(related_key)) {}

OptionError::OptionError(std::string key, std::string message, std::string related_key, const std::string& what)
    : std::invalid_argument(what), key_(std::move(key)), message_(std::move(message)), related_key_(std::move(related_key)) {}

const OptionSpec* find_option(std::span<const OptionSpec> specs, std::string_view key) {
  for (const OptionSpec& s : specs)
    if (s.name == key) return &s;
  return nullptr;
}

namespace {

bool fits(const OptionValue& v, OptionType type) {
  switch (type) {
    case OptionType::String:
    case OptionType::IntegerOrString: return std::holds_alternative<std::string>(v);
    case OptionType::Integer: return std::holds_alternative<std::int64_t>(v);
    case OptionType::Float: return std::holds_alternative<double>(v) || std::holds_alternative<std::int64_t>(v);
    case OptionType::Boolean: return std::holds_alternative<bool>(v);
    case OptionType::IntegerArray: return std::holds_alternative<std::vector<std::int64_t>>(v);
    case OptionType::StringArray: return std::holds_alternative<std::vector<std::string>>(v);
  }
  return false;
}

}  // namespace

OptionReader::OptionReader(std::span<const OptionSpec> specs, const OptionMap& given) : specs_(specs), given_(given) {
  for (const auto& [key, value] : given_) {
    const OptionSpec* s = find_option(specs_, key);
    if (s == nullptr) throw OptionError(key, "not an option of this protocol");
    if (!fits(value, s->type)) throw OptionError(key, "expected " + std::string(to_string(s->type)));
  }
}

const OptionSpec& OptionReader::spec(std::string_view key) const {
  const OptionSpec* s = find_option(specs_, key);
  if (s == nullptr) throw std::logic_error("option " + std::string(key) + " is not declared");
  return *s;
}

const OptionValue* OptionReader::given(std::string_view key) const {
  (void)spec(key);
  const auto it = given_.find(key);
  return it == given_.end() ? nullptr : &it->second;
}

bool OptionReader::has(std::string_view key) const { return given(key) != nullptr; }

std::string OptionReader::text(std::string_view key) const {
  if (const OptionValue* v = given(key)) return std::get<std::string>(*v);
  return std::string(spec(key).default_value);
}

std::size_t OptionReader::choice(std::string_view key) const {
  const std::string value = text(key);
  const std::span<const std::string_view> choices = spec(key).choices;
  const auto it = std::find(choices.begin(), choices.end(), value);
  if (it != choices.end()) return static_cast<std::size_t>(it - choices.begin());
  std::string list;
  for (std::string_view c : choices) list += (list.empty() ? "'" : ", '") + std::string(c) + "'";
  throw OptionError(std::string(key), "expected one of " + list + ", got '" + value + "'");
}

std::int64_t OptionReader::integer(std::string_view key, std::int64_t lo, std::int64_t hi) const {
  std::int64_t v = 0;
  if (const OptionValue* given_value = given(key)) {
    v = std::get<std::int64_t>(*given_value);
  } else {
    const std::string_view d = spec(key).default_value;
    const auto [end, ec] = std::from_chars(d.data(), d.data() + d.size(), v);
    if (d.empty() || ec != std::errc() || end != d.data() + d.size()) throw OptionError(std::string(key), "missing required key");
    return v;  // a default is taken as declared
  }
  if (v < lo || v > hi)
    throw OptionError(std::string(key), "out of range: must be in [" + std::to_string(lo) + ", " + std::to_string(hi) +
                                            "], got " + std::to_string(v));
  return v;
}

double OptionReader::real(std::string_view key) const {
  if (const OptionValue* v = given(key))
    return std::holds_alternative<double>(*v) ? std::get<double>(*v) : static_cast<double>(std::get<std::int64_t>(*v));
  const std::string d(spec(key).default_value);
  char* end = nullptr;
  const double v = std::strtod(d.c_str(), &end);
  if (d.empty() || end != d.c_str() + d.size()) throw OptionError(std::string(key), "missing required key");
  return v;
}

bool OptionReader::boolean(std::string_view key) const {
  if (const OptionValue* v = given(key)) return std::get<bool>(*v);
  const std::string_view d = spec(key).default_value;
  if (d != "true" && d != "false") throw OptionError(std::string(key), "missing required key");
  return d == "true";
}

std::vector<std::int64_t> OptionReader::integers(std::string_view key) const {
  if (const OptionValue* v = given(key)) return std::get<std::vector<std::int64_t>>(*v);
  throw OptionError(std::string(key), "missing required key");
}

std::vector<std::string> OptionReader::strings(std::string_view key) const {
  if (const OptionValue* v = given(key)) return std::get<std::vector<std::string>>(*v);
  throw OptionError(std::string(key), "missing required key");
}

}  // namespace posefair
