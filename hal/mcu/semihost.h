/* ARM semihosting: console output and exit status through the debug host
 * (QEMU with -semihosting-config enable=on, or an attached debugger). Without
 * a host the BKPT instruction faults, so these are for the QEMU images only.
 * Usable from C and C++; no heap, no stdio. */
#pragma once

#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

enum {
  kVinesSysWrite0 = 0x04,        /* SYS_WRITE0: print a NUL-terminated string */
  kVinesSysExitExtended = 0x20,  /* SYS_EXIT_EXTENDED: {reason, exit code} */
  kVinesAppExit = 0x20026        /* ADP_Stopped_ApplicationExit */
};

static inline int vines_semihost_call(int op, const void* arg) {
  int ret;
  __asm__ volatile("mov r0, %1\n\tmov r1, %2\n\tbkpt 0xAB\n\tmov %0, r0"
                   : "=r"(ret)
                   : "r"(op), "r"(arg)
                   : "r0", "r1", "memory");
  return ret;
}

static inline void vines_semihost_puts(const char* s) { vines_semihost_call(kVinesSysWrite0, s); }

/* Prints a signed decimal integer. */
static inline void vines_semihost_put_int(long long v) {
  char buf[24];
  char* p = buf + sizeof buf;
  unsigned long long u = v < 0 ? 0ull - (unsigned long long)v : (unsigned long long)v;
  *--p = '\0';
  do {
    *--p = (char)('0' + (int)(u % 10u));
    u /= 10u;
  } while (u != 0u);
  if (v < 0) *--p = '-';
  vines_semihost_puts(p);
}

/* Ends the QEMU run with `code` as its exit status. */
__attribute__((noreturn)) static inline void vines_semihost_exit(int code) {
  uint32_t block[2] = {(uint32_t)kVinesAppExit, (uint32_t)code};
  vines_semihost_call(kVinesSysExitExtended, block);
  for (;;) {
  }
}

#ifdef __cplusplus
}
#endif
