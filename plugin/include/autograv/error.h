#pragma once

#include <stdexcept>
#include <string>

namespace autograv {

/// The one exception type of the project. Thrown only by set-up and I/O code (constructors, map
/// loading, option parsing), never by the servo path, which returns status enums instead. The
/// message says what was wrong and what the user can do about it (file, field, expected value).
class Error : public std::runtime_error {
 public:
  /// `message` says what went wrong and what to change (file, line, parameter, value).
  explicit Error(const std::string& message) : std::runtime_error(message) {}
};

}  // namespace autograv
