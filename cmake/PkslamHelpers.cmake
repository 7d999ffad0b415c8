# Shared compile settings and the folder-library / beside-the-code test helpers.

add_library(pkslam_options INTERFACE)
target_compile_options(pkslam_options INTERFACE -Wall -Wextra)
if(PKSLAM_WERROR)
  target_compile_options(pkslam_options INTERFACE -Werror)
endif()
if(PKSLAM_NATIVE)
  target_compile_options(pkslam_options INTERFACE -march=native)
endif()
if(PKSLAM_SANITIZE STREQUAL "address")
  target_compile_options(pkslam_options INTERFACE -fsanitize=address,undefined -fno-omit-frame-pointer -g)
  target_link_options(pkslam_options INTERFACE -fsanitize=address,undefined)
  # GCC 12's flow analysis under ASan instrumentation reports std::function inside std::regex
  # (io/opencv_yaml.cc) as maybe uninitialised; a false positive that -Werror would turn into
  # a failed sanitizer build. The optimised build keeps the warning.
  if(CMAKE_CXX_COMPILER_ID STREQUAL "GNU")
    target_compile_options(pkslam_options INTERFACE -Wno-maybe-uninitialized)
  endif()
elseif(PKSLAM_SANITIZE STREQUAL "thread")
  target_compile_options(pkslam_options INTERFACE -fsanitize=thread -g)
  target_link_options(pkslam_options INTERFACE -fsanitize=thread)
elseif(NOT PKSLAM_SANITIZE STREQUAL "")
  message(FATAL_ERROR "PKSLAM_SANITIZE must be '', 'address' or 'thread'")
endif()
target_compile_definitions(pkslam_options INTERFACE
  PKSLAM_SOURCE_DIR="${PROJECT_SOURCE_DIR}" PKSLAM_VERSION="${PROJECT_VERSION}")

# pkslam_unity_sources(OUT_VAR TARGET SOURCES...): the sources in batches of
# PKSLAM_UNITY_BATCH, each batch one generated file in the build tree that includes them by
# their path from the repository root (test and benchmark executables: their files share the
# heavy headers, gtest, Eigen, OpenCV, Ceres, which then are parsed once a batch instead of once
# a file; this halves their compile time). CMake's own UNITY_BUILD would include them by
# absolute path, which ccache (CCACHE_BASEDIR) cannot share between clones. A batch's files
# share one translation unit, so their file-local names (anonymous namespaces) must differ.
# tests/layering/check_thread_safety.py analyses the batches (compile_commands.json lists them,
# not the files in them).
function(pkslam_unity_sources out target)
  if(PKSLAM_UNITY_BATCH LESS_EQUAL 1 OR NOT ARGN)
    set(${out} ${ARGN} PARENT_SCOPE)
    return()
  endif()
  set(sources ${ARGN})
  list(LENGTH sources total)
  math(EXPR last "${total} - 1")
  set(batches "")
  foreach(first RANGE 0 ${last} ${PKSLAM_UNITY_BATCH})
    list(SUBLIST sources ${first} ${PKSLAM_UNITY_BATCH} members)
    set(content "// Generated (pkslam_unity_sources).\n")
    foreach(source IN LISTS members)
      get_filename_component(absolute ${source} ABSOLUTE)
      file(RELATIVE_PATH relative ${PROJECT_SOURCE_DIR} ${absolute})
      string(APPEND content "#include \"${relative}\"\n")
    endforeach()
    math(EXPR index "${first} / ${PKSLAM_UNITY_BATCH}")
    set(batch ${CMAKE_CURRENT_BINARY_DIR}/unity/${target}_${index}.cc)
    file(CONFIGURE OUTPUT ${batch} CONTENT "${content}")
    list(APPEND batches ${batch})
  endforeach()
  set(${out} ${batches} PARENT_SCOPE)
endfunction()

# pkslam_library(NAME SOURCES ... DEPS ... [TESTS ...] [TEST_DEPS ...] [BENCHMARKS ...])
# One static library per folder; the folder's *_test.cc files form one gtest executable
# NAME_test registered with CTest (label = folder name), *_benchmark.cc files one
# Google Benchmark executable NAME_benchmark.
function(pkslam_library NAME)
  cmake_parse_arguments(ARG "" "LABEL" "SOURCES;DEPS;TESTS;TEST_DEPS;BENCHMARKS" ${ARGN})
  add_library(${NAME} STATIC ${ARG_SOURCES})
  target_include_directories(${NAME} PUBLIC ${PROJECT_SOURCE_DIR})
  target_link_libraries(${NAME} PUBLIC ${ARG_DEPS} PRIVATE pkslam_options)
  if(NOT ARG_LABEL)
    get_filename_component(ARG_LABEL ${CMAKE_CURRENT_SOURCE_DIR} NAME)
  endif()
  if(ARG_TESTS AND PKSLAM_BUILD_TESTS)
    pkslam_unity_sources(test_sources ${NAME}_test ${ARG_TESTS})
    add_executable(${NAME}_test ${test_sources})
    target_link_libraries(${NAME}_test PRIVATE ${NAME} ${ARG_TEST_DEPS} pkslam_testsupport
                          pkslam_options GTest::gtest GTest::gmock GTest::gtest_main)
    set_target_properties(${NAME}_test PROPERTIES RUNTIME_OUTPUT_DIRECTORY ${PROJECT_BINARY_DIR}/tests)
    gtest_discover_tests(${NAME}_test DISCOVERY_MODE PRE_TEST
                         PROPERTIES LABELS ${ARG_LABEL}
                         WORKING_DIRECTORY ${PROJECT_BINARY_DIR})
  endif()
  if(ARG_BENCHMARKS AND PKSLAM_BUILD_BENCHMARKS)
    pkslam_unity_sources(benchmark_sources ${NAME}_benchmark ${ARG_BENCHMARKS})
    add_executable(${NAME}_benchmark ${benchmark_sources})
    target_link_libraries(${NAME}_benchmark PRIVATE ${NAME} ${ARG_TEST_DEPS} pkslam_testsupport
                          pkslam_options benchmark::benchmark benchmark::benchmark_main)
    set_target_properties(${NAME}_benchmark PROPERTIES RUNTIME_OUTPUT_DIRECTORY ${PROJECT_BINARY_DIR}/benchmarks)
  endif()
endfunction()
