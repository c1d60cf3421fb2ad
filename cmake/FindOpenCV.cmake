# FindOpenCV: OpenCV modules from Debian's per-module packages
# (libopencv-<module>-dev), which carry the headers and the library but no
# CMake package file: Debian ships OpenCVConfig.cmake only in libopencv-dev,
# which pulls in every module and their dependencies.
#
#   find_package(OpenCV 4 REQUIRED COMPONENTS core imgproc)
#   target_link_libraries(t PRIVATE OpenCV::core OpenCV::imgproc)
#
# Sets OpenCV_FOUND, OpenCV_VERSION, OpenCV_<module>_FOUND and the imported
# target OpenCV::<module> for each module found.
find_path(OpenCV_INCLUDE_DIR opencv2/core.hpp PATH_SUFFIXES opencv4)
mark_as_advanced(OpenCV_INCLUDE_DIR)

set(OpenCV_VERSION "")
if(OpenCV_INCLUDE_DIR)
  file(STRINGS "${OpenCV_INCLUDE_DIR}/opencv2/core/version.hpp" version_defines
       REGEX "#define CV_VERSION_(MAJOR|MINOR|REVISION) ")
  set(version_parts)
  foreach(define IN LISTS version_defines)
    string(REGEX MATCH "[0-9]+$" number "${define}")
    list(APPEND version_parts ${number})
  endforeach()
  list(JOIN version_parts "." OpenCV_VERSION)
endif()

foreach(module IN LISTS OpenCV_FIND_COMPONENTS)
  find_library(OpenCV_${module}_LIBRARY opencv_${module})
  mark_as_advanced(OpenCV_${module}_LIBRARY)
  set(OpenCV_${module}_FOUND FALSE)
  if(OpenCV_INCLUDE_DIR AND OpenCV_${module}_LIBRARY AND EXISTS "${OpenCV_INCLUDE_DIR}/opencv2/${module}.hpp")
    set(OpenCV_${module}_FOUND TRUE)
    if(NOT TARGET OpenCV::${module})
      add_library(OpenCV::${module} UNKNOWN IMPORTED)
      set_target_properties(OpenCV::${module} PROPERTIES
        IMPORTED_LOCATION "${OpenCV_${module}_LIBRARY}"
        INTERFACE_INCLUDE_DIRECTORIES "${OpenCV_INCLUDE_DIR}")
    endif()
  endif()
endforeach()

include(FindPackageHandleStandardArgs)
find_package_handle_standard_args(OpenCV
  REQUIRED_VARS OpenCV_INCLUDE_DIR
  VERSION_VAR OpenCV_VERSION
  HANDLE_COMPONENTS)
