#pragma once

// Private to autograv::viz: one table of names per enum of the public headers, read both ways, so
// that a name and its parse never disagree.

#include <cstddef>
#include <string>
#include <utility>

namespace autograv::viz::detail {

/// An enum's values and their names; the first entry is the default.
template <typename Enum, std::size_t Count>
using NameTable = std::pair<Enum, const char*>[Count];

/// The name of `value` in `table`; the first entry's name for a value not in it.
template <typename Enum, std::size_t Count>
const char* nameIn(const NameTable<Enum, Count>& table, Enum value) noexcept {
  for (const auto& [candidate, name] : table) {
    if (candidate == value) return name;
  }
  return table[0].second;
}

/// Sets `value` to the entry of `table` called `name`; false (and `value` unchanged) when none is.
template <typename Enum, std::size_t Count>
bool parseIn(const NameTable<Enum, Count>& table, const std::string& name, Enum& value) noexcept {
  for (const auto& [candidate, candidate_name] : table) {
    if (name == candidate_name) {
      value = candidate;
      return true;
    }
  }
  return false;
}

}  // namespace autograv::viz::detail
