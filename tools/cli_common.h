// Shared pieces of the omnical command line: the context every subcommand gets and
// the output helpers that keep the error and data-safety policy in one place.
#pragma once

#include <CLI/CLI.hpp>

#include <functional>
#include <iosfwd>
#include <string>

namespace omnical::cli {

struct Context {
  bool quiet = false;
};

// A subcommand registers its options and returns the action to run when chosen.
using CommandAction = std::function<void()>;
struct Command {
  const char* name;
  const char* summary;
  std::function<CommandAction(CLI::App& sub, const Context& context)> add;
};

// Writes to path atomically, or to stdout when path is empty or "-".
void WriteOutput(const std::string& path, const std::function<void(std::ostream&)>& write);

}  // namespace omnical::cli
