// Library errors name option fields ("rim_omega_deg: ..."); the command line names its
// flags ("--rim-omega: ..."). One map per subcommand, applied to the library's message.
#pragma once

#include <cctype>
#include <string>
#include <utility>
#include <vector>

#include "model/input_error.h"

namespace omnical::cli {

using FieldFlags = std::vector<std::pair<std::string, std::string>>;  // {field, flag}

// Every whole-word occurrence of a field replaced by its flag.
inline std::string FieldsAsFlags(std::string message, const FieldFlags& names) {
  auto word = [](char c) { return std::isalnum(static_cast<unsigned char>(c)) || c == '_'; };
  for (const auto& [field, flag] : names) {
    for (size_t at = message.find(field); at != std::string::npos; at = message.find(field, at)) {
      const size_t end = at + field.size();
      if ((at > 0 && (word(message[at - 1]) || message[at - 1] == '-')) ||
          (end < message.size() && word(message[end]))) {
        at = end;
        continue;
      }
      message.replace(at, field.size(), flag);
      at += flag.size();
    }
  }
  return message;
}

// Runs a library call, rethrowing its InputError with the fields named as flags.
template <typename Call>
auto WithFlags(const FieldFlags& names, Call&& call) -> decltype(call()) {
  try {
    return call();
  } catch (const InputError& e) {
    throw InputError(FieldsAsFlags(e.what(), names));
  }
}

}  // namespace omnical::cli
