// Bad user input (tier 2 of the error policy): one actionable line that names the
// file and the field. The CLI prints it and exits with code 2.
#pragma once

#include <stdexcept>
#include <string>

namespace omnical {

class InputError : public std::runtime_error {
 public:
  explicit InputError(const std::string& message) : std::runtime_error(message) {}
};

// "file: field: problem" in one place so every message reads the same way.
inline std::string InputMessage(const std::string& file, const std::string& field,
                                const std::string& problem) {
  std::string message = file;
  if (!field.empty()) message += ": " + field;
  return message + ": " + problem;
}

}  // namespace omnical
