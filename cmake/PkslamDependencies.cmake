# Every dependency is a Debian 12 package (scripts/setup installs them).
find_package(Threads REQUIRED)
find_package(Eigen3 3.4 REQUIRED NO_MODULE)
find_package(OpenCV 4 REQUIRED COMPONENTS core imgproc imgcodecs features2d calib3d videoio)
find_package(Ceres 2.1 REQUIRED)
find_package(opengv REQUIRED)
find_package(yaml-cpp REQUIRED)
find_package(CLI11 REQUIRED)
find_package(fmt REQUIRED)
find_package(spdlog REQUIRED)
find_package(TBB REQUIRED)
find_package(ZLIB REQUIRED)    # map file checksums (map_model/storage)
find_package(cereal REQUIRED)  # map file payloads (map_model/storage)
find_package(Open3D REQUIRED)  # TSDF fusion and meshes (dense/mesh.h)
find_package(PkgConfig REQUIRED)
# pkslam run --live-view's HTTP server (apps/live_view.h): Debian's libcpp-httplib-dev.
pkg_check_modules(HTTPLIB REQUIRED IMPORTED_TARGET cpp-httplib)

# nanoflann ships no CMake config in Debian 12; it is a single header.
find_path(NANOFLANN_INCLUDE_DIR nanoflann.hpp REQUIRED)
add_library(pkslam_nanoflann INTERFACE)
target_include_directories(pkslam_nanoflann SYSTEM INTERFACE ${NANOFLANN_INCLUDE_DIR})

# OpenCV's exported include dirs are not SYSTEM in every config; make them so for -Werror.
add_library(pkslam_opencv INTERFACE)
target_include_directories(pkslam_opencv SYSTEM INTERFACE ${OpenCV_INCLUDE_DIRS})
target_link_libraries(pkslam_opencv INTERFACE ${OpenCV_LIBS})

if(PKSLAM_BUILD_TESTS)
  find_package(GTest REQUIRED)
endif()
if(PKSLAM_BUILD_BENCHMARKS)
  find_package(benchmark REQUIRED)
endif()

# Debian's interpreter: it has python3-opencv, numpy, pytest and the pybind11 headers'
# Python (scripts/setup); a python3 earlier on PATH (pyenv, a venv) may not. The Python module
# (python/) is built for it and the Python tests run with it.
find_program(PKSLAM_SYSTEM_PYTHON NAMES python3 PATHS /usr/bin NO_DEFAULT_PATH)
if(NOT PKSLAM_SYSTEM_PYTHON)
  find_program(PKSLAM_SYSTEM_PYTHON NAMES python3 REQUIRED)
endif()
