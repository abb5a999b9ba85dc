// OpenVDB is loaded through its module (geometry/occupancy/vdb_backend.h) by the first
// grid a process makes: the program does not load libopenvdb at start, a command that
// makes a grid finds the module, and a missing module is a clear error.
#include <gtest/gtest.h>

#include <filesystem>

#include "common/run_command.h"
#include "common/test_support.h"

using saresgs::test::runCli;
using saresgs::test::runCommand;
using saresgs::test::TempDir;
namespace fs = std::filesystem;

TEST(VdbModule, TheProgramDoesNotLoadOpenVdbAtStart) {
  // The loader's own list of what it maps at start (what ldd prints).
  const auto r = runCommand(std::string("LD_TRACE_LOADED_OBJECTS=1 ") + SARESGS_CLI);
  ASSERT_EQ(r.code, 0) << r.output;
  EXPECT_NE(r.output.find("libtbb"), std::string::npos) << r.output;  // the list is the real one
  EXPECT_EQ(r.output.find("libopenvdb"), std::string::npos) << r.output;
}

TEST(VdbModule, ACommandThatMakesAGridLoadsItAndAMissingModuleIsAClearError) {
  TempDir d;
  ASSERT_EQ(runCli("scene --layout object --views 8 --width 48 --height 36 --out " + d.file("s")).code, 0);
  const std::string coverage = "coverage --dataset " + d.file("s") + " --views 0,3 --resolution 16 --out ";
  auto r = runCli(coverage + d.file("c"));
  ASSERT_EQ(r.code, 0) << r.output;
  EXPECT_TRUE(fs::exists(d.path() / "c" / "coverage.json"));

  const std::string missing = d.file("nowhere/libsaresgs_vdb.so");
  r = runCommand("SARESGS_VDB_MODULE=" + missing + " " + SARESGS_CLI + " " + coverage + d.file("c2"));
  EXPECT_NE(r.code, 0) << r.output;
  EXPECT_NE(r.output.find("OpenVDB module"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find(missing), std::string::npos) << r.output;  // names the path it tried
  EXPECT_FALSE(fs::exists(d.path() / "c2" / "coverage.json"));

  // A shared library that is not the module (TBB's, where the loader finds it) is refused.
  const auto trace = runCommand(std::string("LD_TRACE_LOADED_OBJECTS=1 ") + SARESGS_CLI).output;
  const auto at = trace.find("libtbb.so.12 => ");
  ASSERT_NE(at, std::string::npos) << trace;
  const auto from = at + std::string("libtbb.so.12 => ").size();
  const std::string tbb = trace.substr(from, trace.find(' ', from) - from);
  r = runCommand("SARESGS_VDB_MODULE=" + tbb + " " + SARESGS_CLI + " " + coverage + d.file("c3"));
  EXPECT_NE(r.code, 0) << r.output;
  EXPECT_NE(r.output.find("not this build's OpenVDB module"), std::string::npos) << r.output;
}
