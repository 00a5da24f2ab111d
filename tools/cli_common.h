// Shared pieces of the omnical command line: the context every subcommand gets and
// the output helpers that keep the error and data-safety policy in one place.
#pragma once

#include <CLI/CLI.hpp>
#include <opencv2/core.hpp>

#include <cstdlib>
#include <functional>
#include <iosfwd>
#include <string>
#include <vector>

#include "calib/calibration_warning.h"
#include "tools/field_flags.h"

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

// Number checks with plain messages (CLI11's PositiveNumber prints its range up to
// DBL_MAX in full). Non-finite numbers never get here (main.cc refuses them).
inline const CLI::Validator kPositive(
    [](std::string& text) { return std::strtod(text.c_str(), nullptr) > 0.0 ? std::string() : "must be > 0 (got " + text + ")"; },
    "> 0");
inline const CLI::Validator kNonNegative(
    [](std::string& text) { return std::strtod(text.c_str(), nullptr) >= 0.0 ? std::string() : "must be >= 0 (got " + text + ")"; },
    ">= 0");

// Writes to path atomically, or to stdout when path is empty or "-".
void WriteOutput(const std::string& path, const std::function<void(std::ostream&)>& write);

// cv::imread with a check first that a PNG is complete (calib/image_file.h).
cv::Mat ReadImage(const std::string& path, int flags);

// "omnical: warning: text" on stderr for each (those about skipped views only without --quiet).
void PrintWarnings(const std::vector<CalibrationWarning>& warnings, const Context& context);

}  // namespace omnical::cli
