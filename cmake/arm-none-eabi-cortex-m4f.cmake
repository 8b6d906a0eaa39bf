# Cortex-M4F (single-precision FPU, hard-float ABI) on the MPS2-AN386 board
# (QEMU -M mps2-an386). Used by the `cortex-m4f` presets.
set(VINES_MCU_CPU_FLAGS "-mcpu=cortex-m4 -mthumb -mfloat-abi=hard -mfpu=fpv4-sp-d16")
set(VINES_MCU_BOARD mps2-an386)
# The firmware core is a template on the scalar; the FPU is single precision.
set(VINES_MCU_SCALAR float CACHE STRING "Scalar type of the firmware core on the MCU")
# Agreement required with the host run of the same scene in the same scalar
# (float). Measured on El Centro: the TMD (linear) agrees to 3.9e-6 (peak),
# 3.0e-6 (E_e), 1.2e-6 (x_r, absolute).
set(VINES_MCU_RTOL_tmd 1e-4 CACHE STRING "TMD scene: largest relative difference from the host run")
set(VINES_MCU_COUNT_RTOL_tmd 0 CACHE STRING "TMD scene: largest relative difference in counts")
# Float VI NES: the host (AVX2, other summation order) and the M4F round
# differently and the impacts amplify it; the peak, x_r and the bare frame are
# compared to 1e-4 (measured 2.5e-5), E_e, E_r and the counts only reported.
set(VINES_MCU_RTOL_vines 1e-4 CACHE STRING "VI NES scene: largest relative difference from the host run")
set(VINES_MCU_COUNT_RTOL_vines 0.1 CACHE STRING "VI NES scene: largest relative difference in counts")
set(VINES_MCU_CHAOTIC_vines ON CACHE BOOL "VI NES scene: E_e, E_r and counts reported, not compared")
include(${CMAKE_CURRENT_LIST_DIR}/arm-none-eabi-common.cmake)
