// Progress on a terminal for long work: the library reports through a ProgressCallback
// (model/progress.h); this draws it as a single updating line on stderr, only when stderr
// is a terminal and --quiet was not given, and cancels the job after Ctrl-C.
#pragma once

#include <atomic>
#include <chrono>
#include <mutex>
#include <string>

#include "model/progress.h"
#include "tools/cli_common.h"

namespace omnical::cli {

// A bar drawn directly (for loops still in the CLI; library jobs take TerminalProgress).
class Progress {
 public:
  Progress(std::string label, long total, bool quiet);
  ~Progress();
  void Advance(long amount = 1);

 private:
  void Draw(long done);
  std::string label_;
  long total_;
  bool enabled_;
  std::atomic<long> done_{0};
  std::mutex mutex_;
  std::chrono::steady_clock::time_point last_draw_;
};

// The callback the subcommands hand to the library.
ProgressCallback TerminalProgress(const Context& context);

// True once SIGINT arrived (main.cc installs the handler): the callbacks then return
// false, the library throws Cancelled, and main exits as the signal would have.
bool InterruptRequested();
void InstallInterruptHandler();

}  // namespace omnical::cli
