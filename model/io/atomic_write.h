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

// The same for writers that open files themselves and pick the format from the name
// (cv::FileStorage, cv::VideoWriter): write(temporary_path) gets a temporary path in the
// target's directory that ends with the target's file name; it is renamed over path on
// return and removed if write throws.
void WriteFileAtomicallyByPath(const std::string& path, const std::function<void(const std::string&)>& write);

// create_directories with omnical's error: InputError "dir: cannot create output
// directory (reason)" instead of a filesystem_error.
void CreateOutputDirectory(const std::string& dir);

// Installs handlers for SIGINT, SIGTERM and SIGHUP that delete the temporary files being
// written at that moment, then let the signal end the process as it would have: Ctrl-C
// leaves the previous outputs and no stray temporary file (the CLI calls it first).
void RemoveTemporaryFilesOnInterrupt();
// What those handlers do, for a front end's own handler: async-signal-safe.
void RemoveTemporaryFilesAndDie(int signal_number);

}  // namespace omnical
