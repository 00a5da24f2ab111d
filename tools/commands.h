// The table of subcommands; each lives in its own cmd_*.cc file.
#pragma once

#include <vector>

#include "tools/cli_common.h"

namespace omnical::cli {

Command ProjectCommand();
Command UnprojectCommand();
Command CharacterizeCommand();
Command ParallaxCommand();
Command TargetCommand();
Command RenderCommand();
Command DetectCommand();
Command CalibrateCommand();
Command DiffCommand();
Command RemapCommand();
Command UnwarpCommand();
Command ExportCentralCommand();
Command DesignCommand();

inline std::vector<Command> AllCommands() {
  return {ProjectCommand(), UnprojectCommand(), CharacterizeCommand(), ParallaxCommand(), TargetCommand(),
          RenderCommand(),  DetectCommand(),    CalibrateCommand(), DiffCommand(), RemapCommand(),    UnwarpCommand(),
          ExportCentralCommand(), DesignCommand()};
}

}  // namespace omnical::cli
