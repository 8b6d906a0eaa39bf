# Cortex-M4F (single-precision FPU, hard-float ABI) on the MPS2-AN386 board
# (QEMU -M mps2-an386). Used by the `cortex-m4f` presets.
set(VINES_MCU_CPU_FLAGS "-mcpu=cortex-m4 -mthumb -mfloat-abi=hard -mfpu=fpv4-sp-d16")
set(VINES_MCU_BOARD mps2-an386)
# The firmware core is a template on the scalar; the FPU is single precision.
set(VINES_MCU_SCALAR float CACHE STRING "Scalar type of the firmware core on the MCU")
set(VINES_MCU_TARGET cortex-m4f)  # the preset, and `vines hil --node qemu:cortex-m4f`
set(VINES_MCU_HIL_TOL 1e-5 CACHE STRING
  "Largest deviation [m] of a clean `vines hil` slice on this board from the host run")
include(${CMAKE_CURRENT_LIST_DIR}/arm-none-eabi-common.cmake)
