/* Startup for the MPS2 images (AN386 Cortex-M4F, AN500 Cortex-M7): vector
 * table, reset handler (FPU on, thread mode on the process stack, MPU stack
 * guard, .data/.bss, constructors, main), fault handlers, and the C/C++
 * runtime hooks that would otherwise pull stdio/heap code out of newlib and
 * libstdc++. Symbols come from sections.ld. Faults and failed checks end the run through
 * semihosting (semihost.h) with a non-zero exit status; main's return value is
 * the exit status. */
#include <stdint.h>

#include "semihost.h"

typedef void (*vines_handler)(void);

extern uint32_t __stack_top[], __handler_stack_top[];
extern uint32_t __stack_guard[], __stack_guard_size[];
extern uint32_t __data_load[], __data_start[], __data_end[];
extern uint32_t __bss_start[], __bss_end[];
extern vines_handler __preinit_array_start[], __preinit_array_end[];
extern vines_handler __init_array_start[], __init_array_end[];

int main(void);

__attribute__((noreturn)) static void vines_fail(const char* what, int code) {
  vines_semihost_puts("vines mcu: ");
  vines_semihost_puts(what);
  vines_semihost_puts("\n");
  vines_semihost_exit(code);
}

#define VINES_REG(addr) (*(volatile uint32_t*)(addr))

/* MPU region 0 = the stack guard, no access, never executable; everything else
 * keeps the default memory map (PRIVDEFENA; the code runs privileged). */
static void vines_enable_stack_guard(void) {
  const uint32_t size = (uint32_t)(uintptr_t)__stack_guard_size;  /* power of 2 */
  VINES_REG(0xE000ED98) = 0u;                                       /* MPU_RNR */
  VINES_REG(0xE000ED9C) = (uint32_t)(uintptr_t)__stack_guard;       /* MPU_RBAR */
  VINES_REG(0xE000EDA0) = (1u << 28)                                /* XN, AP = 0 */
                          | ((uint32_t)(__builtin_ctz(size) - 1) << 1) | 1u; /* SIZE, EN */
  VINES_REG(0xE000ED24) |= 7u << 16;  /* SHCSR: MEMFAULTENA, BUSFAULTENA, USGFAULTENA */
  VINES_REG(0xE000ED94) = (1u << 2) | 1u;      /* MPU_CTRL: PRIVDEFENA | ENABLE */
  __asm__ volatile("dsb\n\tisb" ::: "memory");
}

/* C part of the reset sequence, on the process stack (see Reset_Handler). */
__attribute__((used, noreturn)) void vines_start(void) {
  vines_enable_stack_guard();
  const uint32_t* src = __data_load;
  for (uint32_t* dst = __data_start; dst < __data_end;) *dst++ = *src++;
  for (uint32_t* dst = __bss_start; dst < __bss_end;) *dst++ = 0u;
  for (vines_handler* f = __preinit_array_start; f < __preinit_array_end; ++f) (*f)();
  for (vines_handler* f = __init_array_start; f < __init_array_end; ++f) (*f)();
  vines_semihost_exit(main());
}

/* Enables CP10/CP11 (the FPU) in SCB->CPACR before any C code can emit a
 * floating-point instruction, moves thread mode to the process stack (PSP;
 * exceptions keep the MSP from the vector table, so a fault handler still has
 * a stack when the PSP overflows), then continues in vines_start. */
__attribute__((naked, noreturn)) void Reset_Handler(void) {
  __asm__ volatile(
      "movw r0, #0xED88\n\t"  /* SCB->CPACR = 0xE000ED88 */
      "movt r0, #0xE000\n\t"
      "ldr  r1, [r0]\n\t"
      "orr  r1, r1, #(0xF << 20)\n\t"
      "str  r1, [r0]\n\t"
      "dsb\n\t"
      "isb\n\t"
      "ldr  r0, =__stack_top\n\t"
      "msr  psp, r0\n\t"
      "movs r0, #2\n\t"        /* CONTROL.SPSEL = 1: thread mode uses PSP */
      "msr  control, r0\n\t"
      "isb\n\t"
      "b    vines_start\n\t"
      ".ltorg\n\t");
}

/* Prints the fault status registers (CFSR, HFSR, MMFAR/BFAR) and the
 * faulting PC from the exception frame, then ends the run. */
static void vines_put_hex(uint32_t v) {
  char buf[11] = "0x";
  for (int i = 0; i < 8; ++i) buf[2 + i] = "0123456789abcdef"[(v >> (28 - 4 * i)) & 0xFu];
  buf[10] = '\0';
  vines_semihost_puts(buf);
}
__attribute__((noreturn)) static void vines_fault(const char* what, int code) {
  uint32_t psp;
  __asm__ volatile("mrs %0, psp" : "=r"(psp));
  vines_semihost_puts("vines mcu: ");
  vines_semihost_puts(what);
  vines_semihost_puts(": CFSR ");
  vines_put_hex(VINES_REG(0xE000ED28));
  vines_semihost_puts(" HFSR ");
  vines_put_hex(VINES_REG(0xE000ED2C));
  vines_semihost_puts(" MMFAR ");
  vines_put_hex(VINES_REG(0xE000ED34));
  vines_semihost_puts(" BFAR ");
  vines_put_hex(VINES_REG(0xE000ED38));
  vines_semihost_puts(" PSP ");
  vines_put_hex(psp);
  /* The PC stacked on the process stack, unless that stack is what overflowed. */
  if (psp >= (uint32_t)(uintptr_t)__stack_guard + (uint32_t)(uintptr_t)__stack_guard_size + 32u &&
      psp + 32u <= (uint32_t)(uintptr_t)__stack_top) {
    vines_semihost_puts(" stacked PC ");
    vines_put_hex(((const uint32_t*)(uintptr_t)psp)[6]);
  }
  vines_semihost_puts("\n");
  vines_semihost_exit(code);
}

void HardFault_Handler(void) { vines_fault("HardFault", 3); }
void MemManage_Handler(void) { vines_fault("MemManage fault (stack overflow into the guard?)", 8); }
void BusFault_Handler(void) { vines_fault("BusFault", 9); }
void UsageFault_Handler(void) { vines_fault("UsageFault", 10); }
void Default_Handler(void) { vines_fail("unexpected exception", 4); }
/* Peripheral handlers an image may define (port_mps2.cpp); unexpected otherwise. */
void TIMER0_Handler(void) __attribute__((weak, alias("Default_Handler")));

/* Cortex-M vector table: initial SP, 15 system exceptions, 32 IRQs. */
struct vines_vector_table {
  uint32_t* initial_sp;
  vines_handler handler[15 + 32];
};

__attribute__((section(".isr_vector"), used)) const struct vines_vector_table vines_vectors = {
    __handler_stack_top,
    {
        Reset_Handler,
        Default_Handler,    /* NMI */
        HardFault_Handler,
        MemManage_Handler,
        BusFault_Handler, UsageFault_Handler,
        0, 0, 0, 0,                                         /* reserved */
        Default_Handler,                                    /* SVCall */
        Default_Handler,                                    /* DebugMonitor */
        0,                                                  /* reserved */
        Default_Handler,                                    /* PendSV */
        Default_Handler,                                    /* SysTick */
        [15 ... 46] = Default_Handler,                      /* external IRQs */
        [15 + 8] = TIMER0_Handler,                          /* CMSDK timer 0 */
    },
};

/* Runtime hooks. newlib's versions print through stdio (which allocates) or
 * keep an atexit list; these report and stop instead. */
void __cxa_pure_virtual(void) { vines_fail("pure virtual call", 5); }
void abort(void) { vines_fail("abort", 6); }
void __assert_func(const char* file, int line, const char* func, const char* expr) {
  (void)func;
  vines_semihost_puts("vines mcu: assertion failed: ");
  vines_semihost_puts(expr);
  vines_semihost_puts(" at ");
  vines_semihost_puts(file);
  vines_semihost_puts(":");
  vines_semihost_put_int(line);
  vines_fail("", 7);
}
/* eigen_assert on the MCU (eigen_assert.h): stays active in release builds. */
__attribute__((noreturn)) void vines_eigen_assert_fail(const char* expr, const char* file, int line) {
  __assert_func(file, line, "", expr);
  for (;;) {
  }
}
/* Static destructors never run on bare metal: do not register them. */
void* __dso_handle = 0;
int __aeabi_atexit(void* obj, void (*fn)(void*), void* dso) {
  (void)obj, (void)fn, (void)dso;
  return 0;
}
int __cxa_atexit(void (*fn)(void*), void* obj, void* dso) {
  (void)obj, (void)fn, (void)dso;
  return 0;
}
