# Rules shared by every bare-metal image (the images here and the heap probe
# in heap_probe/): startup code, the board's linker script (VINES_MCU_BOARD,
# the QEMU machine of the board's line in boards.txt, set by the toolchain
# file: hal/mcu/<machine>.ld with - as _), and the heap ban.
set(VINES_MCU_DIR ${CMAKE_CURRENT_LIST_DIR})
if(NOT VINES_MCU_BOARD)
  message(FATAL_ERROR "VINES_MCU_BOARD is not set: configure with a board's preset (hal/mcu/boards.txt)")
endif()
string(REPLACE "-" "_" VINES_MCU_LINKER_SCRIPT ${VINES_MCU_BOARD})
set(VINES_MCU_LINKER_SCRIPT ${VINES_MCU_DIR}/${VINES_MCU_LINKER_SCRIPT}.ld)
if(NOT EXISTS ${VINES_MCU_LINKER_SCRIPT})
  message(FATAL_ERROR "board machine '${VINES_MCU_BOARD}': no linker script ${VINES_MCU_LINKER_SCRIPT} "
    "(a new QEMU machine needs one: hal/mcu/boards.txt)")
endif()
find_program(VINES_MCU_SIZE_TOOL arm-none-eabi-size REQUIRED)

# The port (vines/hal/port.hpp) of the board's chip, for the images that use
# it: the MPS2's CMSDK peripherals, or the STM32F405's (netduinoplus2), each
# beside what every Cortex-M board shares.
if(VINES_MCU_BOARD MATCHES "^mps2-")
  set(VINES_MCU_PORT_SOURCES ${VINES_MCU_DIR}/port_mps2.cpp)
elseif(VINES_MCU_BOARD STREQUAL "netduinoplus2")
  set(VINES_MCU_PORT_SOURCES ${VINES_MCU_DIR}/port_stm32f405.cpp ${VINES_MCU_DIR}/stm32f405_board.cpp)
else()
  message(FATAL_ERROR "board machine '${VINES_MCU_BOARD}': no port for its chip (hal/mcu/port_*.cpp)")
endif()
list(APPEND VINES_MCU_PORT_SOURCES ${VINES_MCU_DIR}/port_cortex_m.cpp)
option(VINES_STM32F405_PHYSICAL
  "STM32F405 images for a physical board: bring up its crystal and PLL (QEMU models no clock tree)" OFF)

# Heap ban. Every allocator entry point of newlib and every C++ operator
# new/delete (size_t is `unsigned int`, mangled `j`, on arm-none-eabi) is
# wrapped: ld --wrap=SYM turns each undefined reference to SYM into one to
# __wrap_SYM, and nothing defines __wrap_SYM. So any use of the heap, direct
# or from inside newlib/libstdc++ (printf's stdio buffers, std::vector, ...),
# fails the link with "undefined reference to `__wrap_malloc'" (or _Znwj...).
# heap_probe/ proves this on every build.
set(VINES_MCU_HEAP_SYMBOLS
  malloc free calloc realloc reallocf memalign aligned_alloc posix_memalign valloc pvalloc
  _malloc_r _free_r _calloc_r _realloc_r _reallocf_r _memalign_r _sbrk _sbrk_r
  _Znwj _Znaj _ZnwjRKSt9nothrow_t _ZnajRKSt9nothrow_t
  _ZnwjSt11align_val_t _ZnajSt11align_val_t
  _ZnwjSt11align_val_tRKSt9nothrow_t _ZnajSt11align_val_tRKSt9nothrow_t
  _ZdlPv _ZdaPv _ZdlPvj _ZdaPvj _ZdlPvRKSt9nothrow_t _ZdaPvRKSt9nothrow_t
  _ZdlPvSt11align_val_t _ZdaPvSt11align_val_t _ZdlPvjSt11align_val_t _ZdaPvjSt11align_val_t
  _ZdlPvSt11align_val_tRKSt9nothrow_t _ZdaPvSt11align_val_tRKSt9nothrow_t
  _ZdlPvjSt11align_val_tRKSt9nothrow_t _ZdaPvjSt11align_val_tRKSt9nothrow_t)
set(VINES_MCU_NO_HEAP_LINK_OPTIONS ${VINES_MCU_HEAP_SYMBOLS})
list(TRANSFORM VINES_MCU_NO_HEAP_LINK_OPTIONS PREPEND "-Wl,--wrap=")

# Makes `target` (an add_executable) a bootable image NAME.elf with a map file,
# and prints its size after each link.
function(vines_mcu_image target)
  target_sources(${target} PRIVATE ${VINES_MCU_DIR}/startup.c)
  target_include_directories(${target} PRIVATE ${VINES_MCU_DIR})
  target_compile_definitions(${target} PRIVATE VINES_STM32F405_PHYSICAL=$<BOOL:${VINES_STM32F405_PHYSICAL}>)
  target_link_options(${target} PRIVATE
    -nostartfiles -L${VINES_MCU_DIR} -T${VINES_MCU_LINKER_SCRIPT}
    -Wl,-Map=$<TARGET_FILE_DIR:${target}>/${target}.map
    ${VINES_MCU_NO_HEAP_LINK_OPTIONS})
  set_target_properties(${target} PROPERTIES
    SUFFIX .elf LINK_DEPENDS "${VINES_MCU_LINKER_SCRIPT};${VINES_MCU_DIR}/sections.ld")
  add_custom_command(TARGET ${target} POST_BUILD
    COMMAND ${VINES_MCU_SIZE_TOOL} $<TARGET_FILE:${target}>)
endfunction()
