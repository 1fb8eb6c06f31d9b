#pragma once

// Seeds drawn from names and numbers alone: the same unit (or session of a unit) is the same
// hardware in every run, whatever the noise seed.

#include <cstdint>
#include <initializer_list>
#include <string>

namespace autograv::sim {

/// FNV-1a over `text`, then the four bytes of each number, least significant first.
inline std::uint64_t unitSeed(const std::string& text,
                              std::initializer_list<int> numbers) noexcept {
  std::uint64_t hash = 0xcbf29ce484222325ULL;
  const auto mix = [&hash](unsigned char byte) {
    hash ^= byte;
    hash *= 0x100000001b3ULL;
  };
  for (const char c : text) mix(static_cast<unsigned char>(c));
  for (const int number : numbers) {
    for (int shift = 0; shift < 32; shift += 8) {
      mix(static_cast<unsigned char>((static_cast<unsigned>(number) >> shift) & 0xffU));
    }
  }
  return hash;
}

}  // namespace autograv::sim
