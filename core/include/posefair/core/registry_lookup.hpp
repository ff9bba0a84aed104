#pragma once
// The lookups every registry table answers (decoder_registry.cpp, can_decoder_registry.cpp,
// hid_decoder_registry.cpp): an entry by name, and every name. An entry is any struct with a
// `name` member; a table is an array of pointers to entries.
#include <algorithm>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace posefair {

// The entry registered under name, nullptr when none is.
template <class Entry>
const Entry* find_entry(std::span<const Entry* const> table, std::string_view name) {
  for (const Entry* e : table)
    if (e->name == name) return e;
  return nullptr;
}

// Every registered name, sorted.
template <class Entry>
std::vector<std::string> entry_names(std::span<const Entry* const> table) {
  std::vector<std::string> names;
  for (const Entry* e : table) names.emplace_back(e->name);
  std::sort(names.begin(), names.end());
  return names;
}

}  // namespace posefair
