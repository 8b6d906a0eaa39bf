# Cortex-M7 (double-precision FPU fpv5-d16, hard-float ABI) on the MPS2-AN500
# board (QEMU -M mps2-an500). Used by the `cortex-m7` presets.
set(VINES_MCU_CPU_FLAGS "-mcpu=cortex-m7 -mthumb -mfloat-abi=hard -mfpu=fpv5-d16")
set(VINES_MCU_BOARD mps2-an500)
# The FPU does double in hardware: the core runs in double, as on the host.
set(VINES_MCU_SCALAR double CACHE STRING "Scalar type of the firmware core on the MCU")
set(VINES_MCU_TARGET cortex-m7)  # the preset, and `vines hil --node qemu:cortex-m7`
set(VINES_MCU_HIL_TOL 1e-12 CACHE STRING
  "Largest deviation [m] of a clean `vines hil` slice on this board from the host run")
# The real-time step budget [timer ticks; QEMU -icount shift=3: 5 instructions
# a tick], 117,000 instructions: a 2048 Hz step at 480 MHz with a 50 % margin.
set(VINES_MCU_STEP_BUDGET_TICKS 23400 CACHE STRING
  "Deadline budget of one step of the bounded contact scheme on this board [25 MHz ticks]")
include(${CMAKE_CURRENT_LIST_DIR}/arm-none-eabi-common.cmake)
