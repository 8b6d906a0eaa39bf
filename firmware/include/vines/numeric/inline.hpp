// The per-sample path is a chain of small helpers (exact step, particle
// flight, wall test, guards, peaks, energy). GCC keeps some of them out of
// line once `step` grows, and then a call with its register saves costs as
// much as the helper's own work; VINES_INLINE forces them in. Cold paths (a
// peak refined, a contact) stay ordinary functions. Not on 32-bit ARM: there
// GCC's own choice is better (tools/mcu_report.py, El Centro at 1 kHz, median
// free step 5005 against 5375 instructions forced on the M4F, 3245 against
// 3640 on the M7).
#pragma once

#if (defined(__GNUC__) || defined(__clang__)) && !defined(__arm__)
#define VINES_INLINE inline __attribute__((always_inline))
#else
#define VINES_INLINE inline
#endif

// A branch the per-sample path takes rarely (a peak refined, a contact, a
// guard tripped), or nearly always (the particle clear of the walls): the
// compiler then keeps the hot values in registers and spills around the rare
// branch's calls, not on every sample.
#if defined(__GNUC__) || defined(__clang__)
#define VINES_UNLIKELY(x) __builtin_expect(!!(x), 0)
#define VINES_LIKELY(x) __builtin_expect(!!(x), 1)
#else
#define VINES_UNLIKELY(x) (x)
#define VINES_LIKELY(x) (x)
#endif

// Kept out of line whatever the caller: see linear_steps in sim.hpp.
#if defined(__GNUC__) || defined(__clang__)
#define VINES_NOINLINE __attribute__((noinline))
#else
#define VINES_NOINLINE
#endif
