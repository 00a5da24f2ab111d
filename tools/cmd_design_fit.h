// `omnical design fit`: the flags and the run, registered by cmd_design.cc beside `ode`.
#pragma once

#include <string>

#include "model/design/design_fit_job.h"
#include "tools/cli_common.h"

namespace omnical::cli {

struct DesignFitFlags {
  std::string profile, characteristic, compare_path, out_dir;
  DesignFitOptions job;
};

void AddDesignFitOptions(CLI::App* fit, DesignFitFlags* flags);
void RunDesignFit(DesignFitFlags& flags, const Context& context);

}  // namespace omnical::cli
