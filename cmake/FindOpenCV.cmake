# FindOpenCV: OpenCV's modules from Debian's per-module packages
# (libopencv-<module>-dev: headers and the library, nothing else). Debian ships
# OpenCVConfig.cmake and opencv4.pc only in libopencv-dev, which depends on
# every module's -dev package (dnn, viz with VTK, contrib, ...); the rig needs
# three (docs/packages.md). A machine that has the whole libopencv-dev gets
# the same libraries from here.
#
#   find_package(OpenCV 4 REQUIRED COMPONENTS core imgproc calib3d)
#   target_link_libraries(t PRIVATE OpenCV::core OpenCV::imgproc OpenCV::calib3d)
#
# Sets OpenCV_FOUND, OpenCV_VERSION, OpenCV_<component>_FOUND and, per found
# component, the imported target OpenCV::<component>.
find_path(OpenCV_INCLUDE_DIR opencv2/core.hpp PATH_SUFFIXES opencv4)
mark_as_advanced(OpenCV_INCLUDE_DIR)

if(OpenCV_INCLUDE_DIR AND EXISTS "${OpenCV_INCLUDE_DIR}/opencv2/core/version.hpp")
  file(STRINGS "${OpenCV_INCLUDE_DIR}/opencv2/core/version.hpp" OpenCV_VERSION_LINES
       REGEX "^#define CV_VERSION_(MAJOR|MINOR|REVISION) +[0-9]+")
  foreach(part MAJOR MINOR REVISION)
    string(REGEX REPLACE ".*#define CV_VERSION_${part} +([0-9]+).*" "\\1" OpenCV_VERSION_${part} "${OpenCV_VERSION_LINES}")
  endforeach()
  set(OpenCV_VERSION "${OpenCV_VERSION_MAJOR}.${OpenCV_VERSION_MINOR}.${OpenCV_VERSION_REVISION}")
endif()

foreach(component IN LISTS OpenCV_FIND_COMPONENTS)
  find_library(OpenCV_${component}_LIBRARY opencv_${component})
  mark_as_advanced(OpenCV_${component}_LIBRARY)
  # Each module's headers are opencv2/<module>.hpp beside core's.
  if(OpenCV_${component}_LIBRARY AND OpenCV_INCLUDE_DIR AND EXISTS "${OpenCV_INCLUDE_DIR}/opencv2/${component}.hpp")
    set(OpenCV_${component}_FOUND TRUE)
    if(NOT TARGET OpenCV::${component})
      add_library(OpenCV::${component} UNKNOWN IMPORTED)
      # Imported include directories are system ones: OpenCV's headers do not
      # meet the rig's warning flags and are not the rig's to fix.
      set_target_properties(OpenCV::${component} PROPERTIES IMPORTED_LOCATION "${OpenCV_${component}_LIBRARY}"
                                                            INTERFACE_INCLUDE_DIRECTORIES "${OpenCV_INCLUDE_DIR}")
    endif()
  else()
    set(OpenCV_${component}_FOUND FALSE)
  endif()
endforeach()

include(FindPackageHandleStandardArgs)
find_package_handle_standard_args(OpenCV REQUIRED_VARS OpenCV_INCLUDE_DIR VERSION_VAR OpenCV_VERSION HANDLE_COMPONENTS
                                  REASON_FAILURE_MESSAGE "install libopencv-<component>-dev (scripts/debian-packages.txt)")
