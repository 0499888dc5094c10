// The counting operator new and pthread_mutex_lock behind RealtimeProbe. Kept in their own
// translation unit so the compiler never sees a malloc'd pointer reach the matching delete inline.
#include "tests/support/realtime_probe.h"

#include <dlfcn.h>
#include <pthread.h>

#include <atomic>
#include <cstdlib>
#include <new>

namespace {

std::atomic<int> g_open_probes{0};  // probes counting every thread
thread_local int t_open_probes = 0;  // probes counting only the thread they were opened on
std::atomic<long> g_allocations{0};
std::atomic<long> g_locks{0};

bool counting() { return g_open_probes.load(std::memory_order_relaxed) > 0 || t_open_probes > 0; }

void* counted_allocation(std::size_t size) {
  if (counting()) g_allocations.fetch_add(1, std::memory_order_relaxed);
  if (void* p = std::malloc(size ? size : 1)) return p;
  throw std::bad_alloc();
}

}  // namespace

// Every form that allocates with the plain alignment, so that whatever new is paired with whatever
// delete the library picks, both are these (the standard library's temporary buffers, for one, take
// the nothrow new and give back through the sized delete; a sanitizer reports a mixed pair).
void* operator new(std::size_t size) { return counted_allocation(size); }
void* operator new[](std::size_t size) { return counted_allocation(size); }
void* operator new(std::size_t size, const std::nothrow_t&) noexcept {
  try {
    return counted_allocation(size);
  } catch (const std::bad_alloc&) {
    return nullptr;
  }
}
void* operator new[](std::size_t size, const std::nothrow_t& tag) noexcept { return operator new(size, tag); }
void operator delete(void* p) noexcept { std::free(p); }
void operator delete[](void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t) noexcept { std::free(p); }
void operator delete(void* p, const std::nothrow_t&) noexcept { std::free(p); }
void operator delete[](void* p, const std::nothrow_t&) noexcept { std::free(p); }

extern "C" int pthread_mutex_lock(pthread_mutex_t* mutex) {
  using Lock = int (*)(pthread_mutex_t*);
  static const Lock real = reinterpret_cast<Lock>(dlsym(RTLD_NEXT, "pthread_mutex_lock"));
  if (counting()) g_locks.fetch_add(1, std::memory_order_relaxed);
  return real(mutex);
}

namespace resecto::testing {

RealtimeProbe::RealtimeProbe(Threads threads) : this_thread_only_(threads == Threads::kThisOne) {
  g_allocations.store(0);
  g_locks.store(0);
  if (this_thread_only_) {
    ++t_open_probes;
  } else {
    g_open_probes.fetch_add(1);
  }
}
RealtimeProbe::~RealtimeProbe() {
  if (this_thread_only_) {
    --t_open_probes;
  } else {
    g_open_probes.fetch_sub(1);
  }
}
long RealtimeProbe::allocations() const { return g_allocations.load(); }
long RealtimeProbe::locks() const { return g_locks.load(); }

}  // namespace resecto::testing
