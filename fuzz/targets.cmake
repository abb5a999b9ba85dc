# The fuzz targets (fuzz/fuzz_<name>.cpp, seeds in fuzz/corpus/<name>/), one per reader;
# read by fuzz/CMakeLists.txt (the targets) and cmake/fuzz.cmake (their CTest tests).
set(SARESGS_FUZZ_TARGETS
  colmap_text colmap_binary blender ply points_ply pfm manifest
  trainer_checkpoint active_checkpoint ablation_config matches)
