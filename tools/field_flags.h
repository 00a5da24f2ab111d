// Library errors name the field ("distance_mm: must be > 0"); the command line names the
// flag ("--distance-mm: must be > 0"). A subcommand lists the fields it sets from flags
// and runs its library call through NamingFlags.
#pragma once

#include <cctype>
#include <map>
#include <vector>
#include <string>
#include <utility>

#include "model/input_error.h"

namespace omnical::cli {

// Library field -> command-line flag.
using FlagTable = std::map<std::string, std::string>;

// The table for fields spelled as their flags ("--" + field with '_' -> '-'), plus the
// `renamed` ones (e.g. v0_mm -> --v0).
FlagTable FlagsOf(std::initializer_list<const char*> fields, const FlagTable& renamed = {});

// The message with its leading "field: " (or "field/field: ") replaced by the flags when
// every field is in `flags`; otherwise unchanged.
std::string FlagMessage(const std::string& message, const FlagTable& flags);

// Calls job(); an InputError from it is rethrown with FlagMessage.
template <typename Job>
auto NamingFlags(const FlagTable& flags, Job&& job) -> decltype(job()) {
  try {
    return std::forward<Job>(job)();
  } catch (const InputError& error) {
    throw InputError(FlagMessage(error.what(), flags));
  }
}

// For messages that name fields inside the text too ("rim_omega_deg: must lie between
// rim_theta_deg and 180"): every whole-word field replaced by its flag.
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
