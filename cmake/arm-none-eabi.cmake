# The bare-metal Cortex-M toolchain, for every board of hal/mcu/boards.txt:
# VINES_BOARD (the preset's name, CMakePresets.json "mcu") picks its line:
# CPU flags, QEMU machine, the core's scalar, the HIL tolerance and the step
# budget. Debian's gcc-arm-none-eabi + libnewlib-arm-none-eabi +
# libstdc++-arm-none-eabi-newlib.
include(${CMAKE_CURRENT_LIST_DIR}/boards.cmake)
if(NOT VINES_BOARD)
  vines_boards(_all)
  message(FATAL_ERROR "VINES_BOARD not set: configure with a board's preset (${_all})")
endif()
# try_compile projects read this file again: they get the board too.
list(APPEND CMAKE_TRY_COMPILE_PLATFORM_VARIABLES VINES_BOARD)
vines_board(${VINES_BOARD} _board)
set(VINES_MCU_TARGET ${VINES_BOARD})       # the preset, and `vines hil --node qemu:TARGET`
set(VINES_MCU_BOARD ${_board_MACHINE})     # QEMU -M, and the linker script hal/mcu/<machine>.ld
set(VINES_MCU_CPU_FLAGS "${_board_CPU_FLAGS}")
# The firmware core is a template on the scalar: the FPU's precision.
set(VINES_MCU_SCALAR ${_board_SCALAR} CACHE STRING "Scalar type of the firmware core on the MCU")
set(VINES_MCU_HIL_TOL ${_board_HIL_TOL} CACHE STRING
  "Largest deviation [m] of a clean `vines hil` slice on this board from the host run")
# The real-time step budget [timer ticks; QEMU -icount shift=3: 5 instructions
# a tick]: a step at the sensor rate on the board's clock, half of it.
set(VINES_MCU_STEP_BUDGET_TICKS ${_board_BUDGET_TICKS} CACHE STRING
  "Deadline budget of one step of the bounded contact scheme on this board [25 MHz ticks]")

set(CMAKE_SYSTEM_NAME Generic)   # no OS; also makes CMAKE_CROSSCOMPILING true
set(CMAKE_SYSTEM_PROCESSOR arm)

set(CMAKE_C_COMPILER arm-none-eabi-gcc)
set(CMAKE_CXX_COMPILER arm-none-eabi-g++)
set(CMAKE_ASM_COMPILER arm-none-eabi-gcc)

# The toolchain whole, checked at every configure: a compiler without its C
# and C++ libraries passes CMake's checks (they build no executable) and the
# images' link then fails on the heap ban's symbols (__wrap_malloc), which
# says nothing of what is missing.
if(NOT CMAKE_IN_TRY_COMPILE)
  set(_fresh "install it (bash tools/setup.sh all), then configure again: cmake --preset ${VINES_BOARD} --fresh")
  find_program(VINES_ARM_GCC arm-none-eabi-gcc NO_CACHE)
  if(NOT VINES_ARM_GCC)
    message(FATAL_ERROR "${VINES_BOARD}: the Arm toolchain (arm-none-eabi-gcc, Debian gcc-arm-none-eabi) "
      "is not installed; ${_fresh}")
  endif()
  foreach(_lib libc_nano.a:libnewlib-arm-none-eabi libstdc++_nano.a:libstdc++-arm-none-eabi-newlib)
    string(REPLACE ":" ";" _pair ${_lib})
    list(GET _pair 0 _file)
    list(GET _pair 1 _package)
    separate_arguments(_cpu UNIX_COMMAND "${VINES_MCU_CPU_FLAGS}")
    execute_process(COMMAND ${VINES_ARM_GCC} ${_cpu} --specs=nano.specs -print-file-name=${_file}
      OUTPUT_VARIABLE _path OUTPUT_STRIP_TRAILING_WHITESPACE)
    if(NOT IS_ABSOLUTE "${_path}" OR NOT EXISTS "${_path}")
      message(FATAL_ERROR "${VINES_BOARD}: arm-none-eabi-gcc finds no ${_file} (Debian ${_package} is "
        "not installed); ${_fresh}")
    endif()
  endforeach()
endif()

# Compiler checks cannot link a bare-metal executable (no startup, no script).
set(CMAKE_TRY_COMPILE_TARGET_TYPE STATIC_LIBRARY)

# One function/object per section so --gc-sections drops what is unused.
# -ffp-contract=off: no fused multiply-adds, so every operation rounds as on
# the host (x86-64's baseline ISA has no FMA), and the MCU's results can be
# compared with the host's to the last bit. -fcallgraph-info=su: each
# object's call graph with every function's frame size (.ci files, next to
# the objects), from which tools/mcu_report.py computes the worst stack depth.
set(CMAKE_C_FLAGS_INIT
  "${VINES_MCU_CPU_FLAGS} -ffunction-sections -fdata-sections -ffp-contract=off -fcallgraph-info=su")
# No exceptions/RTTI; single-threaded, so local statics need no guard calls.
set(CMAKE_CXX_FLAGS_INIT
  "${CMAKE_C_FLAGS_INIT} -fno-exceptions -fno-rtti -fno-threadsafe-statics")
set(CMAKE_ASM_FLAGS_INIT "${VINES_MCU_CPU_FLAGS}")
# newlib-nano, syscalls stubbed (nosys). Startup, linker script and the heap
# ban are per image: hal/mcu/mcu_image.cmake.
set(CMAKE_EXE_LINKER_FLAGS_INIT
  "${VINES_MCU_CPU_FLAGS} --specs=nano.specs --specs=nosys.specs -Wl,--gc-sections")

# ctest runs the images in QEMU through this wrapper (timeout, semihosting
# exit status, a clear message when qemu-system-arm is missing).
set(CMAKE_CROSSCOMPILING_EMULATOR
  "${CMAKE_CURRENT_LIST_DIR}/../hal/mcu/qemu.sh;${VINES_MCU_BOARD}")

# Never pick up host libraries or headers (Eigen is found explicitly, see the
# top-level find_path with NO_CMAKE_FIND_ROOT_PATH).
set(CMAKE_FIND_ROOT_PATH_MODE_PROGRAM NEVER)
set(CMAKE_FIND_ROOT_PATH_MODE_LIBRARY ONLY)
set(CMAKE_FIND_ROOT_PATH_MODE_INCLUDE ONLY)
set(CMAKE_FIND_ROOT_PATH_MODE_PACKAGE ONLY)
