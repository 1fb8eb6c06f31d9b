#pragma once

#include <string>
#include <vector>

#include <CLI/CLI.hpp>

namespace autograv::cli {

/// Adds `flag` to `command`: one of `names`, turned into `value` by `parse` (which keeps its value
/// when the option is not given), the default shown by its toString. The one shape of the
/// options that name a level or a mode (--friction, --servo-timing).
template <typename Value, typename Parse>
CLI::Option* addChoiceOption(CLI::App& command, const std::string& flag, Value& value, Parse parse,
                             const std::vector<std::string>& names, const std::string& help) {
  return command
      .add_option_function<std::string>(
          flag, [&value, parse](const std::string& name) { value = parse(name); }, help)
      ->check(CLI::IsMember(names))
      ->default_str(toString(value));
}

}  // namespace autograv::cli
