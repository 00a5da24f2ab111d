// The omnical command line: one binary, one subcommand per job (tools/commands.h).
// Exit codes: 0 success, 2 bad input or usage (one line on stderr), 1 internal error.
#include <CLI/CLI.hpp>
#include <opencv2/core/utils/logger.hpp>

#include <iostream>
#include <map>

#include "model/input_error.h"
#include "tools/commands.h"

int main(int argc, char** argv) {
  // Unreadable inputs get omnical's one-line errors; OpenCV's own warnings would add lines.
  cv::utils::logging::setLogLevel(cv::utils::logging::LOG_LEVEL_ERROR);
  using namespace omnical;
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
  } catch (const InputError& error) {
    std::cerr << "omnical: error: " << error.what() << "\n";
    return 2;
  } catch (const std::exception& error) {
    std::cerr << "omnical: internal error: " << error.what() << "\n";
    return 1;
  }
  return 0;
}
