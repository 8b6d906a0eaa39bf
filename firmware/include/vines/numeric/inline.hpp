// The per-sample path is a chain of small helpers (exact step, particle
// flight, wall test, guards, peaks, energy). GCC keeps some of them out of
// line once `step` grows, and then a call with its register saves costs as
// much as the helper's own work; VINES_INLINE forces them in. Cold paths (a
// peak refined, a contact) stay ordinary functions.
#pragma once

#if defined(__GNUC__) || defined(__clang__)
#define VINES_INLINE inline __attribute__((always_inline))
#else
#define VINES_INLINE inline
#endif
