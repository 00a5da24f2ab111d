// Outputs are written to a temporary file beside the target and renamed into place,
// so an interrupted or failed run never leaves a half-written result.
#pragma once

#include <functional>
#include <ostream>
#include <string>

namespace omnical {

// Calls write(stream) on a temporary file in the target's directory, checks the stream,
// then renames it over path. Throws InputError naming path if anything fails; the
// temporary file is removed on failure.
void WriteFileAtomically(const std::string& path, const std::function<void(std::ostream&)>& write);

}  // namespace omnical
