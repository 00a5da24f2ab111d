// `omnical design fit`: the options and the run, registered by cmd_design.cc beside `ode`.
#pragma once

#include <string>

#include "tools/cli_common.h"

namespace omnical::cli {

struct DesignFitOptions {
  std::string profile, characteristic, compare_path, out_dir;
  int terms = 3;
  double rim_omega_deg = 135.0, rim_theta_deg = 12.0;
  double rim_radius_mm = 43.9;  // the shipped Table 1 sensors' rim
  int image_size_px = 1000;
};

void AddDesignFitOptions(CLI::App* fit, DesignFitOptions* options);
void RunDesignFit(const DesignFitOptions& options, const Context& context);

}  // namespace omnical::cli
