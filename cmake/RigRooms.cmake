# Rooms: the parts of a folder that show the flow (harness/: spec -> trace ->
# judge -> session -> systems -> run -> report -> commands), each a library
# target of its own whose dependencies are declared, and whose includes the
# build checks: a file may include the headers of its own room and of the
# rooms its room uses (directly or through them), never of a room above. A
# back-include fails the build, naming the file, the line and the rule.
#
#   rig_room(<target> ROOM <name> [SOURCES <.cpp>...] [HEADERS <.h>...]
#            [PROGRAMS <.cpp>...] [USES <rooms>...] [LIBS <link libraries>...])
#       A static library of SOURCES (an INTERFACE one without), linking the
#       targets of the rooms it USES and LIBS. PROGRAMS are the room's
#       executables' own sources (built by add_executable), checked like the
#       rest. Paths are relative to the calling CMakeLists.txt's folder.
#   rig_check_rooms(<prefix> <forbidden prefix>...)
#       Once every room is declared: a check per room, run before its target
#       builds, over every include of <prefix>/... in its files (an include of
#       a file of no room fails too), and of each forbidden prefix (the harness
#       never includes the reference controllers: "controller/").

function(rig_room target)
  cmake_parse_arguments(R "" "ROOM" "SOURCES;HEADERS;PROGRAMS;USES;LIBS" ${ARGN})
  if(NOT R_ROOM)
    message(FATAL_ERROR "rig_room(${target}): ROOM <name> is required")
  endif()
  set(files)
  foreach(file IN LISTS R_SOURCES R_HEADERS R_PROGRAMS)
    get_filename_component(absolute ${file} ABSOLUTE BASE_DIR ${CMAKE_CURRENT_SOURCE_DIR})
    # Generated sources (in the build tree) include nothing of the rooms.
    string(FIND "${absolute}" "${PROJECT_BINARY_DIR}/" generated)
    if(NOT generated EQUAL 0)
      list(APPEND files ${absolute})
    endif()
  endforeach()
  if(R_SOURCES)
    add_library(${target} STATIC ${R_SOURCES})
    rig_target_defaults(${target})
    set(scope PUBLIC)
  else()
    add_library(${target} INTERFACE)
    set(scope INTERFACE)
  endif()
  target_include_directories(${target} ${scope} ${PROJECT_SOURCE_DIR})
  set(used_targets)
  foreach(used IN LISTS R_USES)
    get_property(used_target GLOBAL PROPERTY RIG_ROOM_${used}_TARGET)
    if(NOT used_target)
      message(FATAL_ERROR "rig_room(${target}): room '${used}' is not declared yet; declare the rooms bottom up")
    endif()
    list(APPEND used_targets ${used_target})
  endforeach()
  target_link_libraries(${target} ${scope} ${used_targets} ${R_LIBS})
  set_property(GLOBAL APPEND PROPERTY RIG_ROOMS ${R_ROOM})
  set_property(GLOBAL PROPERTY RIG_ROOM_${R_ROOM}_TARGET ${target})
  set_property(GLOBAL PROPERTY RIG_ROOM_${R_ROOM}_FILES ${files})
  set_property(GLOBAL PROPERTY RIG_ROOM_${R_ROOM}_USES ${R_USES})
endfunction()

function(rig_check_rooms prefix)
  set(forbidden ${ARGN})
  get_property(rooms GLOBAL PROPERTY RIG_ROOMS)
  # The manifest the check reads: one line per file ("file <room> <path>") and
  # per use ("uses <room> <used room>"), paths relative to the project.
  set(manifest "")
  foreach(room IN LISTS rooms)
    get_property(files GLOBAL PROPERTY RIG_ROOM_${room}_FILES)
    get_property(uses GLOBAL PROPERTY RIG_ROOM_${room}_USES)
    foreach(file IN LISTS files)
      file(RELATIVE_PATH relative ${PROJECT_SOURCE_DIR} ${file})
      string(APPEND manifest "file ${room} ${relative}\n")
    endforeach()
    foreach(used IN LISTS uses)
      string(APPEND manifest "uses ${room} ${used}\n")
    endforeach()
  endforeach()
  set(manifest_file ${CMAKE_CURRENT_BINARY_DIR}/rooms.manifest)
  file(WRITE ${manifest_file} "${manifest}")
  foreach(room IN LISTS rooms)
    get_property(target GLOBAL PROPERTY RIG_ROOM_${room}_TARGET)
    get_property(files GLOBAL PROPERTY RIG_ROOM_${room}_FILES)
    string(REPLACE "/" "_" stem ${room})
    set(stamp ${CMAKE_CURRENT_BINARY_DIR}/rooms/${stem}.checked)
    add_custom_command(
      OUTPUT ${stamp}
      COMMAND ${CMAKE_COMMAND} -DMANIFEST=${manifest_file} -DROOM=${room} -DSOURCE_DIR=${PROJECT_SOURCE_DIR}
              "-DPREFIX=${prefix}" "-DFORBIDDEN=${forbidden}" -DSTAMP=${stamp}
              -P ${PROJECT_SOURCE_DIR}/cmake/CheckRoomIncludes.cmake
      DEPENDS ${files} ${manifest_file} ${PROJECT_SOURCE_DIR}/cmake/CheckRoomIncludes.cmake
      COMMENT "rooms: includes of ${room}"
      VERBATIM)
    add_custom_target(${target}_includes DEPENDS ${stamp})
    add_dependencies(${target} ${target}_includes)
  endforeach()
endfunction()
