# Finds the OpenCV modules planarvo uses from Debian's per-module -dev packages
# (libopencv-{core,imgproc,imgcodecs,videoio,calib3d,video}-dev). Debian ships OpenCVConfig.cmake only
# with the libopencv-dev metapackage, which pulls in VTK and every contrib module; this avoids that.
# Defines PlanarvoOpenCV::OpenCV. Falls back to OpenCVConfig.cmake where one exists.
set(_pv_cv_modules core imgproc imgcodecs videoio calib3d video)
find_path(PlanarvoOpenCV_INCLUDE_DIR opencv2/core.hpp PATH_SUFFIXES opencv4)
set(PlanarvoOpenCV_LIBRARIES)
foreach(m IN LISTS _pv_cv_modules)
  find_library(PlanarvoOpenCV_${m}_LIBRARY NAMES opencv_${m})
  if(PlanarvoOpenCV_${m}_LIBRARY)
    list(APPEND PlanarvoOpenCV_LIBRARIES ${PlanarvoOpenCV_${m}_LIBRARY})
  endif()
  list(APPEND _pv_cv_vars PlanarvoOpenCV_${m}_LIBRARY)
endforeach()
include(FindPackageHandleStandardArgs)
find_package_handle_standard_args(PlanarvoOpenCV REQUIRED_VARS PlanarvoOpenCV_INCLUDE_DIR ${_pv_cv_vars})
if(PlanarvoOpenCV_FOUND AND NOT TARGET PlanarvoOpenCV::OpenCV)
  add_library(PlanarvoOpenCV::OpenCV INTERFACE IMPORTED)
  set_target_properties(PlanarvoOpenCV::OpenCV PROPERTIES
    INTERFACE_INCLUDE_DIRECTORIES "${PlanarvoOpenCV_INCLUDE_DIR}"
    INTERFACE_LINK_LIBRARIES "${PlanarvoOpenCV_LIBRARIES}")
endif()
