# The board table, hal/mcu/boards.txt, for CMake: the toolchain
# (arm-none-eabi.cmake) reads its board's line, the host build the whole
# table (sim_host/CMakeLists.txt, for `vines hil --node qemu:TARGET`).
set(VINES_BOARDS_FILE ${CMAKE_CURRENT_LIST_DIR}/../hal/mcu/boards.txt)
set_property(DIRECTORY APPEND PROPERTY CMAKE_CONFIGURE_DEPENDS ${VINES_BOARDS_FILE})

# vines_boards(<var>): the table's targets, in its order.
function(vines_boards var)
  file(STRINGS ${VINES_BOARDS_FILE} _lines REGEX "^[a-z0-9-]+ *\\|")
  set(_targets "")
  foreach(_line ${_lines})
    string(REGEX REPLACE " *\\|.*" "" _t "${_line}")
    list(APPEND _targets ${_t})
  endforeach()
  set(${var} ${_targets} PARENT_SCOPE)
endfunction()

# vines_board(<target> <prefix>): the line of <target> as <prefix>_MACHINE,
# _SCALAR, _CPU_FLAGS, _SENSOR_HZ, _CLOCK_HZ, _HIL_TOL and _BUDGET_TICKS.
function(vines_board target prefix)
  file(STRINGS ${VINES_BOARDS_FILE} _lines REGEX "^${target} *\\|")
  list(LENGTH _lines _n)
  if(NOT _n EQUAL 1)
    vines_boards(_all)
    message(FATAL_ERROR "board '${target}': not one line of ${VINES_BOARDS_FILE} (boards: ${_all})")
  endif()
  string(REPLACE "|" ";" _fields "${_lines}")
  list(LENGTH _fields _n)
  if(NOT _n EQUAL 8)
    message(FATAL_ERROR "${VINES_BOARDS_FILE}: board '${target}': ${_n} fields, 8 expected")
  endif()
  set(_i 1)
  foreach(_name MACHINE SCALAR CPU_FLAGS SENSOR_HZ CLOCK_HZ HIL_TOL BUDGET_TICKS)
    list(GET _fields ${_i} _v)
    string(STRIP "${_v}" _v)
    set(${prefix}_${_name} "${_v}" PARENT_SCOPE)
    math(EXPR _i "${_i} + 1")
  endforeach()
endfunction()
