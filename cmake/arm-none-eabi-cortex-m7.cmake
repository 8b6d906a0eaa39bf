# Cortex-M7 (double-precision FPU fpv5-d16, hard-float ABI) on the MPS2-AN500
# board (QEMU -M mps2-an500). Used by the `cortex-m7` presets.
set(VINES_MCU_CPU_FLAGS "-mcpu=cortex-m7 -mthumb -mfloat-abi=hard -mfpu=fpv5-d16")
set(VINES_MCU_BOARD mps2-an500)
# The FPU does double in hardware: the core runs in double, as on the host.
set(VINES_MCU_SCALAR double CACHE STRING "Scalar type of the firmware core on the MCU")
# Agreement required with the host run of the same scene in the same scalar
# (double, no FMA contraction on either side: the image must agree with the host double run to 1e-9 relative, counts exactly).
set(VINES_MCU_RTOL 1e-9 CACHE STRING "Largest relative difference from the host run (MCU tests)")
set(VINES_MCU_COUNT_TOL 0 CACHE STRING "Largest difference in counts (contacts, steps) from the host run")
include(${CMAKE_CURRENT_LIST_DIR}/arm-none-eabi-common.cmake)
