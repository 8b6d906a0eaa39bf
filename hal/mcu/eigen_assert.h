/* Force-included (-include) in every MCU translation unit, before Eigen:
 * eigen_assert stays active in release builds (NDEBUG would otherwise turn
 * it off) and reports through semihosting (startup.c), then ends the run.
 * EIGEN_NO_MALLOC routes any run-time allocation attempt into it too. */
#pragma once

#ifdef __cplusplus
extern "C" [[noreturn]] void vines_eigen_assert_fail(const char* expr, const char* file, int line);
#define eigen_assert(x) ((x) ? static_cast<void>(0) : vines_eigen_assert_fail(#x, __FILE__, __LINE__))
#endif
