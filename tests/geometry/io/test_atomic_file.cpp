#include <gtest/gtest.h>

#include <filesystem>
#include <stdexcept>

#include "common/test_support.h"
#include "geometry/io/atomic_file.h"

using namespace saresgs;
namespace fs = std::filesystem;

TEST(AtomicFile, AFailedWriteKeepsTheOldFileAndLeavesNoTemporary) {
  test::TempDir d;
  const std::string path = d.file("out.txt");
  writeFileAtomic(path, "good");
  EXPECT_THROW(writeStreamAtomic(path,
                                 [](std::ostream& o) {
                                   o << "half";
                                   throw std::runtime_error("interrupted");
                                 }),
               std::runtime_error);
  EXPECT_EQ(readFile(path), "good");
  int files = 0;
  for (const auto& e : fs::directory_iterator(d.path())) files += e.is_regular_file();
  EXPECT_EQ(files, 1);
}

TEST(AtomicFile, CreatesFoldersAndReplaces) {
  test::TempDir d;
  const std::string path = d.file("a/b/c.bin");
  writeFileAtomic(path, std::string("x\0y", 3));
  EXPECT_EQ(readFile(path), std::string("x\0y", 3));
  writeFileAtomic(path, "z");
  EXPECT_EQ(readFile(path), "z");
  EXPECT_TRUE(test::throwsInputError([&] { readFile(d.file("none")); }, "none", "file"));
}
