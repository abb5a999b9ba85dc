# Unity batches (docs/BUILD_COST.md). The front ends' and the libraries' files each
# parsed the same heavy headers (CLI11, nlohmann/json, pybind11, Eigen, TBB) and compiled
# the same inline code again (CLI11 2.1 is header-only: about 250 KB of each subcommand's
# object was CLI11's). Built as batches of `batch` files, each batch parses and compiles it
# once. Files with compile options of their own are never batched (CMake leaves them out),
# and neither are the rasterizer's kernels nor the OpenVDB grid (their CMakeLists say
# why). Within a batched target no two files may define file-local functions of the same
# name (their unnamed namespaces merge in a batch): scripts/unity_names.py, run by the
# test command, checks it.
option(SARESGS_UNITY "Build the libraries, the command line, the Python module and the tests as unity batches" ON)
function(saresgs_unity target batch)
  if(SARESGS_UNITY)
    set_target_properties(${target} PROPERTIES UNITY_BUILD ON UNITY_BUILD_MODE BATCH UNITY_BUILD_BATCH_SIZE ${batch})
  endif()
endfunction()
# Keeps the library files (paths relative to the source root) out of the batches: the
# property is set in each library's folder, where the file's target was made.
function(saresgs_unity_skip)
  foreach(f IN LISTS ARGN)
    set_source_files_properties(${PROJECT_SOURCE_DIR}/${f}
                                TARGET_DIRECTORY saresgs_geometry saresgs_splat saresgs_nbv saresgs_nbv_eval
                                PROPERTIES SKIP_UNITY_BUILD_INCLUSION ON)
  endforeach()
endfunction()
