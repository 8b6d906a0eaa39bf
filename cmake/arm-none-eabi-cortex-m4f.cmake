# Cross toolchain: bare-metal Cortex-M4F (single-precision FPU, hard-float ABI)
# with Debian's gcc-arm-none-eabi + libnewlib-arm-none-eabi +
# libstdc++-arm-none-eabi-newlib. Used by the `cortex-m4f` preset.
set(CMAKE_SYSTEM_NAME Generic)   # no OS; also makes CMAKE_CROSSCOMPILING true
set(CMAKE_SYSTEM_PROCESSOR arm)

set(CMAKE_C_COMPILER arm-none-eabi-gcc)
set(CMAKE_CXX_COMPILER arm-none-eabi-g++)
set(CMAKE_ASM_COMPILER arm-none-eabi-gcc)

# Compiler checks cannot link a bare-metal executable (no startup, no script).
set(CMAKE_TRY_COMPILE_TARGET_TYPE STATIC_LIBRARY)

set(VINES_MCU_CPU_FLAGS "-mcpu=cortex-m4 -mthumb -mfloat-abi=hard -mfpu=fpv4-sp-d16")
# One function/object per section so --gc-sections drops what is unused.
set(CMAKE_C_FLAGS_INIT "${VINES_MCU_CPU_FLAGS} -ffunction-sections -fdata-sections")
# No exceptions/RTTI; single-threaded, so local statics need no guard calls.
set(CMAKE_CXX_FLAGS_INIT
  "${CMAKE_C_FLAGS_INIT} -fno-exceptions -fno-rtti -fno-threadsafe-statics")
set(CMAKE_ASM_FLAGS_INIT "${VINES_MCU_CPU_FLAGS}")
# newlib-nano, syscalls stubbed (nosys). Startup, linker script and the heap
# ban are per image: hal/mcu/mcu_image.cmake.
set(CMAKE_EXE_LINKER_FLAGS_INIT
  "${VINES_MCU_CPU_FLAGS} --specs=nano.specs --specs=nosys.specs -Wl,--gc-sections")

# The firmware core is a template on the scalar; the FPU is single precision.
set(VINES_MCU_SCALAR float CACHE STRING "Scalar type of the firmware core on the MCU")

# Never pick up host libraries or headers (Eigen is found explicitly, see the
# top-level find_path with NO_CMAKE_FIND_ROOT_PATH).
set(CMAKE_FIND_ROOT_PATH_MODE_PROGRAM NEVER)
set(CMAKE_FIND_ROOT_PATH_MODE_LIBRARY ONLY)
set(CMAKE_FIND_ROOT_PATH_MODE_INCLUDE ONLY)
set(CMAKE_FIND_ROOT_PATH_MODE_PACKAGE ONLY)
