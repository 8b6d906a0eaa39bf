# cmake -P script: configures heap_probe/ in PROBE_BIN with the MCU toolchain,
# then requires probe_ok to link and each heap probe to fail with the expected
# undefined __wrap_* reference. Touches STAMP on success.
execute_process(
  COMMAND ${CMAKE_COMMAND} -S ${PROBE_SRC} -B ${PROBE_BIN} -G ${GENERATOR}
    -DCMAKE_MAKE_PROGRAM=${MAKE_PROGRAM} -DCMAKE_TOOLCHAIN_FILE=${TOOLCHAIN} -DVINES_BOARD=${BOARD}
    -DCMAKE_BUILD_TYPE=${BUILD_TYPE}
  RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE out)
if(rc)
  message(FATAL_ERROR "heap probe: configure failed:\n${out}")
endif()

function(probe_build target)
  execute_process(COMMAND ${CMAKE_COMMAND} --build ${PROBE_BIN} --target ${target}
    RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE out)
  set(rc ${rc} PARENT_SCOPE)
  set(out "${out}" PARENT_SCOPE)
endfunction()

probe_build(probe_ok)
if(rc)
  message(FATAL_ERROR "heap probe: the heap-free control image did not link:\n${out}")
endif()

foreach(pair "malloc:__wrap_malloc" "new:__wrap__Znwj" "printf:__wrap__malloc_r")
  string(REPLACE ":" ";" pair ${pair})
  list(GET pair 0 probe)
  list(GET pair 1 symbol)
  probe_build(probe_${probe})
  if(NOT rc)
    message(FATAL_ERROR "heap ban broken: probe_${probe} (uses the heap) LINKED")
  endif()
  if(NOT out MATCHES "undefined reference to `${symbol}'")
    message(FATAL_ERROR "heap probe: probe_${probe} failed, but not on ${symbol}:\n${out}")
  endif()
  message(STATUS "heap ban: probe_${probe} refused (undefined ${symbol})")
endforeach()
file(TOUCH ${STAMP})
