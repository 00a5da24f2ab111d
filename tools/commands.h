// The table of subcommands; each lives in its own cmd_*.cc file.
#pragma once

#include <vector>

#include "tools/cli_common.h"

namespace omnical::cli {

Command ProjectCommand();
Command UnprojectCommand();

inline std::vector<Command> AllCommands() { return {ProjectCommand(), UnprojectCommand()}; }

}  // namespace omnical::cli
