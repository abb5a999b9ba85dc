# The fuzz targets (fuzz/): built with clang as an external project of their own against
# this build's libraries, and run for a bounded number of inputs each by CTest (label
# `fuzz`). Needs clang and libFuzzer (Debian: clang, libclang-rt-14-dev; both installed
# by scripts/install_deps.sh); without them the targets are left out with a warning.
option(SARESGS_FUZZ "Build the libFuzzer targets (fuzz/) with clang and run them in CTest (scripts/test.sh turns it on)" OFF)
if(NOT SARESGS_FUZZ)
  return()
endif()

find_program(SARESGS_FUZZ_CXX NAMES clang++-14 clang++)
set(_fuzz_ok FALSE)
if(SARESGS_FUZZ_CXX)
  execute_process(COMMAND ${SARESGS_FUZZ_CXX} -print-runtime-dir OUTPUT_VARIABLE _rt_dir
                  OUTPUT_STRIP_TRAILING_WHITESPACE ERROR_QUIET)
  if(EXISTS "${_rt_dir}/libclang_rt.fuzzer-${CMAKE_SYSTEM_PROCESSOR}.a")
    set(_fuzz_ok TRUE)
  endif()
endif()
if(NOT _fuzz_ok)
  message(WARNING "fuzz targets left out: no clang++ with libFuzzer (install clang and libclang-rt-14-dev, "
                  "scripts/install_deps.sh) or configure with -DSARESGS_FUZZ=OFF")
  return()
endif()

include(ExternalProject)
include(${PROJECT_SOURCE_DIR}/fuzz/targets.cmake)
set(_main_libs saresgs_nbv_eval saresgs_nbv saresgs_splat saresgs_geometry saresgs_geometry_cgal)
set(_main_lib_files "")
foreach(l IN LISTS _main_libs)
  list(APPEND _main_lib_files "$<TARGET_FILE:${l}>")
endforeach()
string(REPLACE ";" "|" _main_lib_files "${_main_lib_files}")
set(SARESGS_FUZZ_BINARY_DIR ${PROJECT_BINARY_DIR}/fuzz)
ExternalProject_Add(saresgs_fuzz
  SOURCE_DIR ${PROJECT_SOURCE_DIR}/fuzz
  BINARY_DIR ${SARESGS_FUZZ_BINARY_DIR}
  LIST_SEPARATOR |
  CMAKE_ARGS -DCMAKE_CXX_COMPILER=${SARESGS_FUZZ_CXX}
             -DCMAKE_CXX_COMPILER_LAUNCHER=${CMAKE_CXX_COMPILER_LAUNCHER}
             -DSARESGS_SOURCE_DIR=${PROJECT_SOURCE_DIR}
             -DSARESGS_MAIN_LIBS=${_main_lib_files}
  BUILD_ALWAYS ON
  INSTALL_COMMAND ""
  DEPENDS ${_main_libs})

if(BUILD_TESTING AND SARESGS_BUILD_TESTS)
  foreach(name IN LISTS SARESGS_FUZZ_TARGETS)
    # fuzz/run_bounded.sh: the seeds must read, the committed regression inputs run clean,
    # then 4000 fuzzed inputs.
    add_test(NAME fuzz.${name}
             COMMAND bash ${PROJECT_SOURCE_DIR}/fuzz/run_bounded.sh ${SARESGS_FUZZ_BINARY_DIR}/fuzz_${name}
                     ${PROJECT_SOURCE_DIR}/fuzz/corpus/${name} ${PROJECT_SOURCE_DIR}/tests
                     ${SARESGS_FUZZ_BINARY_DIR}/work/${name} 4000)
    set_tests_properties(fuzz.${name} PROPERTIES LABELS fuzz TIMEOUT 300)
  endforeach()
endif()
