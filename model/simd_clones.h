// Batch kernels (many points, one sensor) are compiled twice on x86-64: for the
// baseline ISA every build targets, and for x86-64-v3 (AVX2 + FMA, 4 doubles per
// vector), chosen once at load time by the CPU (a GNU ifunc). Only the annotated
// function and what is inlined into it are cloned, so nothing built for AVX2 can run
// on a CPU without it. GCC only: clang 14 cannot clone function templates, and builds
// the baseline alone. OMNICAL_NO_CPU_CLONES (the sanitizer build) builds the baseline
// alone too, so that the tests exercise it on an AVX2 machine.
#pragma once

#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__) && !defined(OMNICAL_NO_CPU_CLONES)
#define OMNICAL_CLONE_FOR_AVX2 __attribute__((target_clones("arch=x86-64-v3", "default")))
#else
#define OMNICAL_CLONE_FOR_AVX2
#endif
