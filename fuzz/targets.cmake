# The fuzz targets (fuzz/fuzz_<name>.cpp, seeds in fuzz/corpus/<name>/), one per reader;
# read by fuzz/CMakeLists.txt (the targets) and cmake/fuzz.cmake (their CTest tests).
set(SARESGS_FUZZ_TARGETS
  colmap_text colmap_binary blender ply points_ply pfm manifest
  trainer_checkpoint active_checkpoint ablation_config matches)

# The readers: what the fuzzer's coverage feedback and the sanitizers watch (the file
# formats and the dataset, checkpoint and config readers; not the geometry they call).
# The fuzz project compiles them again, instrumented (in unity batches of its own), and
# links them before the main build's archives, so each must be an archive member of its
# own there (the top-level CMakeLists.txt keeps them out of the libraries' batches).
set(SARESGS_FUZZ_READERS
  geometry/io/atomic_file.cpp geometry/io/colmap_binary.cpp geometry/io/colmap_models.cpp
  geometry/io/colmap_text.cpp geometry/io/colmap_validate.cpp geometry/io/json_file.cpp
  geometry/io/pfm.cpp geometry/io/point_ply.cpp geometry/scene/blender_dataset.cpp geometry/scene/colmap_dataset.cpp
  geometry/synth/from_manifest.cpp
  geometry/lifting/correspondence.cpp splat/ply.cpp splat/train/trainer.cpp
  nbv/active_run.cpp nbv/run_report.cpp nbv/eval/ablation.cpp)
