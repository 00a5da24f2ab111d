// The virtual-screen options `remap` and `unwarp` share: flags filling a ViewRequest
// (correction/view_request.h), and the table naming its fields as flags in errors.
#pragma once

#include <CLI/CLI.hpp>

#include "correction/view_request.h"
#include "tools/field_flags.h"

namespace omnical::cli {

// Registers the options; `required_view` makes --view and a distance mandatory.
void AddViewOptions(CLI::App& sub, ViewRequest* request, bool required_view);
// True if any view option was given on the command line.
bool AnyViewOptionGiven(const CLI::App& sub);
// ViewRequest field -> flag (v0_mm is --v0).
const FlagTable& ViewFlags();

}  // namespace omnical::cli
