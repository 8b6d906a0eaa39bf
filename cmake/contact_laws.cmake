# The contact-law registry for CMake: the lines of its table (`    laws::Name,`
# in firmware/include/vines/model/contact_laws.hpp, in the order of the laws'
# codes). Read by the host's engine instances (sim_host/CMakeLists.txt) and
# the board's node images (firmware/app/CMakeLists.txt); editing the table
# reconfigures.
set(VINES_LAWS_HEADER ${CMAKE_CURRENT_LIST_DIR}/../firmware/include/vines/model/contact_laws.hpp)

# vines_contact_laws(<structs> <names>): the laws' struct names (Kuwabara) and
# their lower-case names (kuwabara, the scene's vines.law), in the table's order.
function(vines_contact_laws structs names)
  set_property(DIRECTORY APPEND PROPERTY CMAKE_CONFIGURE_DEPENDS ${VINES_LAWS_HEADER})
  file(STRINGS ${VINES_LAWS_HEADER} _lines REGEX "^    laws::[A-Za-z0-9_]+(,|>;)$")
  set(_structs "")
  set(_names "")
  foreach(_line ${_lines})
    string(REGEX REPLACE "^    laws::([A-Za-z0-9_]+).*" "\\1" _law "${_line}")
    string(TOLOWER ${_law} _name)
    list(APPEND _structs ${_law})
    list(APPEND _names ${_name})
  endforeach()
  if(NOT _structs)
    message(FATAL_ERROR "no contact law found in the table of ${VINES_LAWS_HEADER}")
  endif()
  set(${structs} ${_structs} PARENT_SCOPE)
  set(${names} ${_names} PARENT_SCOPE)
endfunction()
