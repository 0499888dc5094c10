// Subnormal numbers off for the core's arithmetic: results that would be subnormal are zero (x86's
// flush-to-zero, ARM's FZ) and subnormal operands read as zero (x86's denormals-are-zero).
//
// Why: a tissue coming to rest drives its velocities and forces down through the subnormal range,
// where every operation costs a microcode assist of ~100 cycles. A trainee pausing for two minutes
// found the refit ten times and the physics step twice as slow from then on (audit 10, finding 1).
// The mode is part of the core's arithmetic like -ffp-contract=off: the step sets it for its own
// duration, and the threads the core hands work to (JobThread, LoopHelper) run with it from their
// start, so every run, batch or real time, replay or test, computes the same bits.
#pragma once

#if defined(__x86_64__) || defined(__SSE2__)
#include <xmmintrin.h>
#endif

namespace resecto {
namespace float_mode {

#if defined(__x86_64__) || defined(__SSE2__)
using Word = unsigned;
inline constexpr Word kFlushBits = 0x8040u;  // MXCSR: FTZ (bit 15) and DAZ (bit 6)
inline Word read() { return _mm_getcsr(); }
inline void write(Word mode) { _mm_setcsr(mode); }
#elif defined(__aarch64__)
using Word = unsigned long;
inline constexpr Word kFlushBits = 1ul << 24;  // FPCR.FZ: subnormal operands and results are zero
inline Word read() {
  Word mode;
  asm volatile("mrs %0, fpcr" : "=r"(mode));
  return mode;
}
inline void write(Word mode) { asm volatile("msr fpcr, %0" : : "r"(mode)); }
#else
#error "flush_denormals.h: no flush-to-zero control known for this processor"
#endif

}  // namespace float_mode

/// Whether this thread computes with subnormals flushed.
inline bool denormals_flushed() { return (float_mode::read() & float_mode::kFlushBits) == float_mode::kFlushBits; }

/// For a thread that runs only the core's work: flushes subnormals for the rest of its life.
inline void flush_denormals_on_this_thread() { float_mode::write(float_mode::read() | float_mode::kFlushBits); }

/// Flushes subnormals for a scope and gives the caller back the mode it had.
class FlushDenormals {
 public:
  FlushDenormals() : saved_(float_mode::read()) { float_mode::write(saved_ | float_mode::kFlushBits); }
  ~FlushDenormals() { float_mode::write(saved_); }
  FlushDenormals(const FlushDenormals&) = delete;
  FlushDenormals& operator=(const FlushDenormals&) = delete;

 private:
  float_mode::Word saved_;
};

}  // namespace resecto
