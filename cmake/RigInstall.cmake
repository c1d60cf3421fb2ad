# What `cmake --install` puts into the prefix: the controller SDK (docs/sdk.md).
#   lib/librig_node.a, lib/librig_idl.a, lib/librig_nmea.a   rig::node, rig::idl, rig::nmea
#   include/rig/runtime/*.h                                  the runtime's headers
#   include/rig/nmea/*.h                                     the NMEA parser and encoder
#   include/rig/papers/*.h                                   each seed's paper's shared numbers
#   include/rig/idl/*.h                                      generated topic types, msg_traits.h, topics.h
#   share/rig/idl/*.idl, share/rig/idl/topics.json           the types and the topic table for other languages
#   share/rig/docs/*.md                                      the documents: the contract, the SDK, metrics, the
#                                                            trace, each seed's pages (their links stay whole)
#   share/rig/examples/                                      the out-of-tree example controllers with their cases
#   lib/cmake/rig/rigConfig.cmake (+ version, targets)       find_package(rig)
#   bin/rig, bin/rig-controller, bin/rig-boundary-controller the harness and every reference controller a case
#                                                            runs when it names none (full build)
#   lib/rig/rig-controller-plugin.so                         the reference controller as a plugin (rig run --in-process)
#   share/bash-completion/completions/rig                    bash completion for `rig` (scripts/rig-completion.bash)
include(CMakePackageConfigHelpers)

install(TARGETS rig_runtime rig_idl rig_nmea EXPORT rigTargets
        ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
        LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR})
install(DIRECTORY ${PROJECT_SOURCE_DIR}/rig/runtime/ DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/rig/runtime
        FILES_MATCHING PATTERN "*.h")
install(FILES ${PROJECT_BINARY_DIR}/include/rig/runtime/version.h DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/rig/runtime)
install(DIRECTORY ${PROJECT_SOURCE_DIR}/rig/nmea/ DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/rig/nmea
        FILES_MATCHING PATTERN "*.h")
install(DIRECTORY ${PROJECT_SOURCE_DIR}/rig/papers/ DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/rig/papers
        FILES_MATCHING PATTERN "*.h")
install(FILES ${RIG_IDL_GENERATED_HEADERS} ${PROJECT_SOURCE_DIR}/idl/msg_traits.h ${PROJECT_SOURCE_DIR}/idl/topics.h
        DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/rig/idl)
file(GLOB RIG_IDL_FILES ${PROJECT_SOURCE_DIR}/idl/*.idl)
install(FILES ${RIG_IDL_FILES} ${PROJECT_SOURCE_DIR}/idl/topics.json DESTINATION ${CMAKE_INSTALL_DATADIR}/rig/idl)
# Every document, not a chosen few: they link to each other.
file(GLOB RIG_DOC_FILES ${PROJECT_SOURCE_DIR}/docs/*.md)
install(FILES ${RIG_DOC_FILES} DESTINATION ${CMAKE_INSTALL_DATADIR}/rig/docs)
# The examples as a team copies them: sources and cases, never a build of them.
install(DIRECTORY ${PROJECT_SOURCE_DIR}/examples/ DESTINATION ${CMAKE_INSTALL_DATADIR}/rig/examples
        PATTERN build EXCLUDE)

install(EXPORT rigTargets NAMESPACE rig:: DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/rig)
set(RIG_IDL_INSTALL_DIR ${CMAKE_INSTALL_DATADIR}/rig/idl)
configure_package_config_file(${PROJECT_SOURCE_DIR}/cmake/rigConfig.cmake.in
                              ${PROJECT_BINARY_DIR}/rigConfig.cmake
                              INSTALL_DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/rig
                              PATH_VARS RIG_IDL_INSTALL_DIR)
write_basic_package_version_file(${PROJECT_BINARY_DIR}/rigConfigVersion.cmake COMPATIBILITY SameMinorVersion)
install(FILES ${PROJECT_BINARY_DIR}/rigConfig.cmake ${PROJECT_BINARY_DIR}/rigConfigVersion.cmake
        DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/rig)

if(TARGET rig AND TARGET rig-controller)
  # Each system's reference controller beside `rig`, where it looks for the one
  # a case runs when its `controller:` names no command (harness/systems/*/).
  install(TARGETS rig rig-controller rig-boundary-controller RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
  # The reference controller as a plugin, where `rig` looks for it (lib/rig/ beside bin/).
  install(TARGETS rig-controller-plugin LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR}/rig)
  # Where bash-completion looks for a command's completion when it is first completed.
  install(FILES ${PROJECT_SOURCE_DIR}/scripts/rig-completion.bash
          DESTINATION ${CMAKE_INSTALL_DATADIR}/bash-completion/completions RENAME rig)
endif()
