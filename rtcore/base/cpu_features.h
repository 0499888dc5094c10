// What the processor offers beyond the x86-64 baseline the build targets, asked at run time: the
// kernels with an AVX2 path build it with a function attribute and take it only where it runs.
#pragma once

namespace resecto {

/// Whether this processor runs AVX2 code (asked once).
inline bool cpu_has_avx2() {
  static const bool has = __builtin_cpu_supports("avx2");
  return has;
}

}  // namespace resecto
