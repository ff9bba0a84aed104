#pragma once
// The options of a registered item (a device protocol decoder, an output encoding): each declares
// the keys it reads (OptionSpec: name, TOML value type, default, one line of doc) in its own
// file, and its registry entry carries that list. The configuration hands it only a small map of
// the values it was given (OptionMap); it reads them with OptionReader and judges them itself,
// throwing OptionError, which names the key, so the configuration can point at it. Nothing
// outside the item's file knows its keys by name. Pure types: no I/O, so they live in core.
#include <cstdint>
#include <initializer_list>
#include <map>
#include <span>
#include <stdexcept>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

namespace posefair {

// The TOML type a key takes.
enum class OptionType {
  String,
  Integer,
  Float,            // an integer is taken as a float
  Boolean,
  IntegerOrString,  // a number written either way (0x4F, "0x4F", 16): the decoder reads the text
  IntegerArray,
  StringArray,      // one value per item, e.g. a name per stream an output carries
};
// "a string", "an integer", ... (for messages and the docs).
std::string_view to_string(OptionType type);

struct OptionSpec {
  std::string_view name;
  OptionType type = OptionType::String;
  std::string_view default_value;  // as TOML would write it (strings unquoted); empty: none or computed
  std::string_view doc;            // one line
  std::span<const std::string_view> choices = {};  // String only: the values accepted, when a fixed set
};

// A value as the configuration gave it: IntegerOrString values arrive as their text (an integer
// as its decimal digits), Float values as double even when written as an integer.
using OptionValue = std::variant<std::string, std::int64_t, double, bool, std::vector<std::int64_t>, std::vector<std::string>>;
using OptionMap = std::map<std::string, OptionValue, std::less<>>;

// A value a decoder refuses. key() is the option's name, with "[n]" (1-based) for an element of
// an array option; related_key() is another key the problem involves (a conflict), or empty.
// what() is "key: message".
class OptionError : public std::invalid_argument {
 public:
  OptionError(std::string key, std::string message, std::string related_key = {});
  const std::string& key() const { return key_; }
  const std::string& message() const { return message_; }
  const std::string& related_key() const { return related_key_; }

 protected:
  // For a derived error whose what() says more than "key: message".
  OptionError(std::string key, std::string message, std::string related_key, const std::string& what);

 private:
  std::string key_, message_, related_key_;
};

// Reads one decoder's options: the value given, else the declared default. Every getter names
// a declared key (asking for another one is a programming error: std::logic_error).
class OptionReader {
 public:
  // Throws OptionError for a key `given` holds that `specs` does not declare, or a value of the
  // wrong type.
  OptionReader(std::span<const OptionSpec> specs, const OptionMap& given);

  bool has(std::string_view key) const;
  // String and IntegerOrString keys.
  std::string text(std::string_view key) const;
  // The index of the value in the key's choices; OptionError "expected one of ..." otherwise.
  std::size_t choice(std::string_view key) const;
  // Integer keys, checked against [lo, hi] ("out of range: must be in [lo, hi], got v").
  std::int64_t integer(std::string_view key, std::int64_t lo, std::int64_t hi) const;
  double real(std::string_view key) const;  // Float keys
  bool boolean(std::string_view key) const;
  std::vector<std::int64_t> integers(std::string_view key) const;  // IntegerArray keys, given only
  std::vector<std::string> strings(std::string_view key) const;     // StringArray keys, given only

 private:
  const OptionSpec& spec(std::string_view key) const;
  const OptionValue* given(std::string_view key) const;

  std::span<const OptionSpec> specs_;
  const OptionMap& given_;
};

// The spec named `key` in `specs`, or nullptr.
const OptionSpec* find_option(std::span<const OptionSpec> specs, std::string_view key);

}  // namespace posefair
