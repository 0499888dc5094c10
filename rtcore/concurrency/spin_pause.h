// One turn of a spin-wait, for the threads that spin rather than sleep (the real-time scheduler's
// last stretch before a tick, the physics loop helper).
#pragma once

namespace resecto {

/// Tells the core (and a hypervisor) that this is a spin.
inline void spin_pause() {
#if defined(__x86_64__) || defined(__i386__)
  __builtin_ia32_pause();
#endif
}

}  // namespace resecto
