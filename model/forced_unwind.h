// A thread ended by pthread_exit unwinds its stack with abi::__forced_unwind, which a
// catch (...) must rethrow, or the process aborts ("FATAL: exception not rethrown").
// CPython ends a daemon thread that way when it takes the GIL back while the interpreter
// exits: a Python job's progress callback can do so between its check and the GIL
// (tests/python/test_hostile_input.py, 1 in ~30 runs before this). Put before catch (...):
//   try { ... } OMNICAL_RETHROW_FORCED_UNWIND catch (...) { ... }
#pragma once

#if defined(__GLIBCXX__)
#include <cxxabi.h>
#define OMNICAL_RETHROW_FORCED_UNWIND \
  catch (abi::__forced_unwind&) {     \
    throw;                            \
  }
#else
#define OMNICAL_RETHROW_FORCED_UNWIND
#endif
