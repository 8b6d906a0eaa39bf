# Cortex-M4F (single-precision FPU, hard-float ABI) on the MPS2-AN386 board
# (QEMU -M mps2-an386). Used by the `cortex-m4f` presets.
set(VINES_MCU_CPU_FLAGS "-mcpu=cortex-m4 -mthumb -mfloat-abi=hard -mfpu=fpv4-sp-d16")
set(VINES_MCU_BOARD mps2-an386)
# The firmware core is a template on the scalar; the FPU is single precision.
set(VINES_MCU_SCALAR float CACHE STRING "Scalar type of the firmware core on the MCU")
set(VINES_MCU_TARGET cortex-m4f)  # the preset, and `vines hil --node qemu:cortex-m4f`
set(VINES_MCU_HIL_TOL 1e-5 CACHE STRING
  "Largest deviation [m] of a clean `vines hil` slice on this board from the host run")
# The real-time step budget [timer ticks; QEMU -icount shift=3: 5 instructions
# a tick], 84,000 instructions: a 1 kHz step at 168 MHz with a 50 % margin.
set(VINES_MCU_STEP_BUDGET_TICKS 16800 CACHE STRING
  "Deadline budget of one step of the bounded contact scheme on this board [25 MHz ticks]")
include(${CMAKE_CURRENT_LIST_DIR}/arm-none-eabi-common.cmake)
