# The rooms' include order is enforced (cmake/RigRooms.cmake): the check run by
# the build, on a small tree of its own (tests/data/rooms/) with a
# back-include, an include of the reference controller and one of a file of
# no room, must fail naming each; on the same tree without them it must pass;
# and every room of the real harness must pass it (the build runs the same
# check before each room's library).
#   cmake -DCHECKER=cmake/CheckRoomIncludes.cmake -DFIXTURE=tests/data/rooms
#         -DREAL_MANIFEST=build/harness/rooms.manifest -DSOURCE_DIR=. -DWORK=<dir> -P rooms_test.cmake
foreach(required CHECKER FIXTURE REAL_MANIFEST SOURCE_DIR WORK)
  if(NOT DEFINED ${required})
    message(FATAL_ERROR "rooms_test: -D${required}=... is required")
  endif()
endforeach()
file(MAKE_DIRECTORY ${WORK})

function(check manifest room source_dir result_var output_var)
  execute_process(COMMAND ${CMAKE_COMMAND} -DMANIFEST=${manifest} -DROOM=${room} -DSOURCE_DIR=${source_dir}
                          -DPREFIX=harness/ -DFORBIDDEN=controller/ -P ${CHECKER}
                  RESULT_VARIABLE result ERROR_VARIABLE output OUTPUT_VARIABLE ignored)
  set(${result_var} ${result} PARENT_SCOPE)
  string(REGEX REPLACE "[ \n]+" " " output "${output}")
  set(${output_var} "${output}" PARENT_SCOPE)
endfunction()

function(expect_failure manifest room part)
  check(${manifest} ${room} ${FIXTURE} result output)
  if(result EQUAL 0)
    message(FATAL_ERROR "room ${room} of ${manifest} passed the check; expected it to fail with '${part}'")
  endif()
  string(FIND "${output}" "${part}" at)
  if(at EQUAL -1)
    message(FATAL_ERROR "room ${room}: the check failed, but without '${part}':\n${output}")
  endif()
endfunction()

# low may not include high; neither may include controller/; high includes a file of no room.
set(broken ${WORK}/broken.manifest)
file(WRITE ${broken} "file low harness/low/low.h\nfile low harness/low/back_include.cpp\nfile low harness/low/reference_controller.cpp\n"
                     "file high harness/high/high.h\nfile high harness/high/unknown.cpp\nuses high low\n")
expect_failure(${broken} low "harness/low/back_include.cpp:2: includes harness/high/high.h of room high, above room low (which may include: low)")
expect_failure(${broken} low "harness/low/reference_controller.cpp:2: includes controller/spray_controller.h: room low may not include controller/* at all")
expect_failure(${broken} high "harness/high/unknown.cpp:2: includes harness/nowhere/lost.h, a file of no room")

# Without those files both rooms pass: high may include low.
set(clean ${WORK}/clean.manifest)
file(WRITE ${clean} "file low harness/low/low.h\nfile high harness/high/high.h\nuses high low\n")
foreach(room low high)
  check(${clean} ${room} ${FIXTURE} result output)
  if(NOT result EQUAL 0)
    message(FATAL_ERROR "room ${room} of the clean tree failed the check:\n${output}")
  endif()
endforeach()

# Every room of the harness.
file(STRINGS ${REAL_MANIFEST} lines REGEX "^uses |^file ")
set(rooms)
foreach(line IN LISTS lines)
  string(REPLACE " " ";" fields "${line}")
  list(GET fields 1 room)
  list(APPEND rooms ${room})
endforeach()
list(REMOVE_DUPLICATES rooms)
list(LENGTH rooms count)
if(count LESS 10)
  message(FATAL_ERROR "the harness manifest ${REAL_MANIFEST} lists ${count} rooms; expected the harness's rooms")
endif()
foreach(room IN LISTS rooms)
  check(${REAL_MANIFEST} ${room} ${SOURCE_DIR} result output)
  if(NOT result EQUAL 0)
    message(FATAL_ERROR "room ${room} of the harness failed the check:\n${output}")
  endif()
endforeach()
message(STATUS "rooms_test: the broken tree was refused three ways, the clean tree and ${count} rooms of the harness pass")
