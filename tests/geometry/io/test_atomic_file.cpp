#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <random>
#include <sys/stat.h>
#include <thread>
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

namespace saresgs {
namespace {

// A killed writer's temporaries are cleaned up on the next start; a live process's
// (here, this test's own) and ordinary files are kept.
TEST(AtomicFile, StaleTemporariesOfDeadWritersAreRemoved) {
  test::TempDir d;
  // Above Linux's largest pid_max (2^22): no such process can exist.
  const std::string dead = d.file("checkpoint.json.trainer.4.tmp.4194999");
  const std::string live = d.file("checkpoint.json.tmp." + std::to_string(::getpid()));
  test::writeBytes(dead, std::string(1000, 'x'));
  test::writeBytes(live, "being written");
  test::writeBytes(d.file("results.json"), "{}");
  test::writeBytes(d.file("notes.tmp.abc"), "not a pid");
  EXPECT_EQ(removeStaleTemporaries(d.str()), 1);
  EXPECT_FALSE(std::filesystem::exists(dead));
  EXPECT_TRUE(std::filesystem::exists(live));
  EXPECT_TRUE(std::filesystem::exists(d.file("results.json")));
  EXPECT_TRUE(std::filesystem::exists(d.file("notes.tmp.abc")));
  EXPECT_EQ(removeStaleTemporaries(d.file("no_such_folder")), 0);
}

}  // namespace
}  // namespace saresgs

// A regular file is read at its size, anything else to its end: a file past the chunk
// size with every byte value, a pipe fed by a writer, an empty file; a folder is refused.
TEST(AtomicFile, ReadsLargeFilesAndPipesAndRefusesFolders) {
  test::TempDir d;
  std::string big(1 << 20 | 12345, '\0');
  std::mt19937 rng(7);
  for (char& c : big) c = static_cast<char>(rng() & 0xff);
  writeFileAtomic(d.file("big.bin"), big);
  EXPECT_EQ(readFile(d.file("big.bin")), big);
  writeFileAtomic(d.file("empty.bin"), "");
  EXPECT_EQ(readFile(d.file("empty.bin")), "");

  const std::string fifo = d.file("pipe");
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  std::thread writer([&] { std::ofstream(fifo, std::ios::binary) << big.substr(0, 300000); });
  const std::string got = readFile(fifo);
  writer.join();
  EXPECT_EQ(got, big.substr(0, 300000));

  fs::create_directories(d.file("folder"));
  EXPECT_TRUE(test::throwsInputError([&] { readFile(d.file("folder")); }, "folder", "file"));
}
