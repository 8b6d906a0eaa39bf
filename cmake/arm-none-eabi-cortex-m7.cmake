# Cortex-M7 (double-precision FPU fpv5-d16, hard-float ABI) on the MPS2-AN500
# board (QEMU -M mps2-an500). Used by the `cortex-m7` presets.
set(VINES_MCU_CPU_FLAGS "-mcpu=cortex-m7 -mthumb -mfloat-abi=hard -mfpu=fpv5-d16")
set(VINES_MCU_BOARD mps2-an500)
# The FPU does double in hardware: the core runs in double, as on the host.
set(VINES_MCU_SCALAR double CACHE STRING "Scalar type of the firmware core on the MCU")
# Agreement required with the host run of the same scene in the same scalar
# (double): within 1e-9 relative of the host double run, counts exact.
# Measured on El Centro: 1.5e-11 at most (E_e of the VI NES); not bit-exact
# (the host build sums over the modes in AVX2 packs, with FMA in Eigen's
# kernels; the MCU sums in order).
set(VINES_MCU_RTOL_tmd 1e-9 CACHE STRING "TMD scene: largest relative difference from the host run")
set(VINES_MCU_COUNT_RTOL_tmd 0 CACHE STRING "TMD scene: largest relative difference in counts")
set(VINES_MCU_RTOL_vines 1e-9 CACHE STRING "VI NES scene: largest relative difference from the host run")
set(VINES_MCU_COUNT_RTOL_vines 0 CACHE STRING "VI NES scene: largest relative difference in counts")
include(${CMAKE_CURRENT_LIST_DIR}/arm-none-eabi-common.cmake)
