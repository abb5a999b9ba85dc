# Unity batches (docs/BUILD_COST.md). The front ends' and the upper libraries' files each
# parsed the same heavy headers (CLI11, nlohmann/json, pybind11, Eigen, TBB) and compiled
# the same inline code again (CLI11 2.1 is header-only: about 250 KB of each subcommand's
# object was CLI11's). Built as batches of `batch` files, each batch parses and compiles it
# once. Files with compile options of their own are never batched (CMake leaves them out),
# and neither are the rasterizer's kernels (splat) nor geometry, whose files are few per
# shared header and keep file-local helpers of the same names. Within a batched target no
# two files may define file-local functions of the same name (their unnamed namespaces
# merge in a batch): scripts/unity_names.py, run by the test command, checks it.
option(SARESGS_UNITY "Build nbv, nbv/eval, report, the command line and the Python module as unity batches" ON)
function(saresgs_unity target batch)
  if(SARESGS_UNITY)
    set_target_properties(${target} PROPERTIES UNITY_BUILD ON UNITY_BUILD_MODE BATCH UNITY_BUILD_BATCH_SIZE ${batch})
  endif()
endfunction()
