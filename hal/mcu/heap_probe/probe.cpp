// Heap-ban probes: PROBE_OK must link; the others use the heap (directly or
// through newlib's stdio) and must fail with an undefined __wrap_* symbol.
#include <cstdio>
#include <cstdlib>

int main() {
#if defined(PROBE_MALLOC)
  void* volatile p = std::malloc(16);
  std::free(p);
#elif defined(PROBE_NEW)
  int* volatile p = new int(1);
  delete p;
#elif defined(PROBE_PRINTF)
  std::printf("%d\n", 42);
#endif
  return 0;
}
