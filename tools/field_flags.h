// Library errors name the field ("distance_mm: must be > 0"); the command line names the
// flag ("--distance-mm: must be > 0"). A subcommand lists the fields it sets from flags
// and runs its library call through NamingFlags.
#pragma once

#include <map>
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
// rim_theta_deg and 180"): every whole-word field replaced by its flag. Only for tables
// whose field names cannot be ordinary words (not "n").
std::string FlagWords(std::string message, const FlagTable& flags);

template <typename Job>
auto NamingFlagWords(const FlagTable& flags, Job&& job) -> decltype(job()) {
  try {
    return std::forward<Job>(job)();
  } catch (const InputError& error) {
    throw InputError(FlagWords(error.what(), flags));
  }
}

}  // namespace omnical::cli
