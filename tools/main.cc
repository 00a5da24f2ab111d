// The omnical command line: one binary, one subcommand per job (tools/commands.h).
// Exit codes: 0 success, 2 bad input or usage (one line on stderr), 1 internal error.
#include <CLI/CLI.hpp>
#include <glog/logging.h>
#include <opencv2/core/utils/logger.hpp>

#include <cmath>
#include <csignal>
#include <cstdlib>
#include <iostream>
#include <map>
#include <string>
#include <vector>

#include "model/io/atomic_write.h"
#include "model/input_error.h"
#include "tools/commands.h"
#include "tools/progress.h"

namespace {

// "1,nan,3" -> its parts (list options such as --elevation-deg take commas).
std::vector<std::string> SplitOnCommas(const std::string& text) {
  std::vector<std::string> parts(1);
  for (char c : text) {
    if (c == ',')
      parts.emplace_back();
    else
      parts.back().push_back(c);
  }
  return parts;
}

}  // namespace

int main(int argc, char** argv) {
  // Unreadable inputs get omnical's one-line errors; OpenCV's own warnings would add lines.
  cv::utils::logging::setLogLevel(cv::utils::logging::LOG_LEVEL_ERROR);
  // Ceres logs a solve it ends early ("Terminating: ...") at glog's ERROR level; omnical
  // reports each failed fit or alignment in its own words, so only fatal ones may print.
  FLAGS_minloglevel = google::GLOG_FATAL;
  using namespace omnical;
  // Ctrl-C: the outputs are renamed into place only when complete; this removes the one
  // being written, so an interrupted run leaves the previous results and nothing else.
  RemoveTemporaryFilesOnInterrupt();
  // SIGINT first asks the running job to stop through its progress callback.
  cli::InstallInterruptHandler();
  CLI::App app{"omnical: calibration and correction of non-central catadioptric cameras"};
  app.require_subcommand(1);
  cli::Context context;
  app.add_flag("-q,--quiet", context.quiet, "No progress output");
  std::map<CLI::App*, cli::CommandAction> actions;
  for (const cli::Command& command : cli::AllCommands()) {
    CLI::App* sub = app.add_subcommand(command.name, command.summary);
    sub->fallthrough();  // -q/--quiet also after the subcommand
    actions[sub] = command.add(*sub, context);
  }
  // CLI11's number checks (PositiveNumber, Range) let NaN through (every comparison with
  // NaN is false), and "1e400" parses as inf: no option of omnical takes a non-finite
  // number, so any argument that reads as one is refused here.
  for (int i = 1; i < argc; ++i) {
    std::string value = argv[i];
    if (value.rfind("--", 0) == 0 && value.find('=') != std::string::npos) value = value.substr(value.find('=') + 1);
    for (const std::string& part : SplitOnCommas(value)) {
      char* end = nullptr;
      const double number = std::strtod(part.c_str(), &end);
      if (!part.empty() && end == part.c_str() + part.size() && !std::isfinite(number)) {
        std::cerr << "omnical: error: argument '" << argv[i] << "' is not a finite number (see --help)\n";
        return 2;
      }
    }
  }
  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& help) {
    return app.exit(help);
  } catch (const CLI::CallForAllHelp& help) {
    return app.exit(help);
  } catch (const CLI::ParseError& error) {
    std::cerr << "omnical: error: " << error.what() << " (see --help)\n";
    return 2;
  }
  try {
    for (const auto& [sub, action] : actions)
      if (sub->parsed()) action();
    // Interrupted after the job's last progress report: its outputs are complete, but the
    // run still ends the way the signal would have.
    if (cli::InterruptRequested()) throw Cancelled("the last step");
  } catch (const InputError& error) {
    std::cerr << "omnical: error: " << error.what() << "\n";
    return 2;
  } catch (const Cancelled&) {
    // Stopped by Ctrl-C: end the way the signal would have (exit status 128 + SIGINT).
    std::signal(SIGINT, SIG_DFL);
    std::raise(SIGINT);
    return 130;
  } catch (const std::exception& error) {
    std::cerr << "omnical: internal error: " << error.what() << "\n";
    return 1;
  }
  return 0;
}
