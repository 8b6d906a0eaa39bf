# Cortex-M4F (single-precision FPU, hard-float ABI) on the MPS2-AN386 board
# (QEMU -M mps2-an386). Used by the `cortex-m4f` presets.
set(VINES_MCU_CPU_FLAGS "-mcpu=cortex-m4 -mthumb -mfloat-abi=hard -mfpu=fpv4-sp-d16")
set(VINES_MCU_BOARD mps2-an386)
# The firmware core is a template on the scalar; the FPU is single precision.
set(VINES_MCU_SCALAR float CACHE STRING "Scalar type of the firmware core on the MCU")
# Agreement required with the host run of the same scene in the same scalar
# (float: see README (MCU targets) for the measured differences).
set(VINES_MCU_RTOL 1e-3 CACHE STRING "Largest relative difference from the host run (MCU tests)")
set(VINES_MCU_COUNT_TOL 0 CACHE STRING "Largest difference in counts (contacts, steps) from the host run")
include(${CMAKE_CURRENT_LIST_DIR}/arm-none-eabi-common.cmake)
