#pragma once
// The x86 vector kernels chosen at run time (internal): whether they are built, their intrinsics,
// and the switch around AVX-512 code for GCC 12's own uninitialised-value warnings, which its
// AVX-512 headers trip (_mm512_undefined_* in casts, reductions and conversions).
#if defined(__x86_64__) && defined(__GNUC__)
#define RWCALC_X86_DISPATCH 1
#include <immintrin.h>
#else
#define RWCALC_X86_DISPATCH 0
#endif

#if defined(__GNUC__) && !defined(__clang__)
#define RWCALC_AVX512_WARNINGS_OFF                                 \
  _Pragma("GCC diagnostic push")                                   \
      _Pragma("GCC diagnostic ignored \"-Wuninitialized\"")        \
          _Pragma("GCC diagnostic ignored \"-Wmaybe-uninitialized\"")
#define RWCALC_AVX512_WARNINGS_ON _Pragma("GCC diagnostic pop")
#else
#define RWCALC_AVX512_WARNINGS_OFF
#define RWCALC_AVX512_WARNINGS_ON
#endif
