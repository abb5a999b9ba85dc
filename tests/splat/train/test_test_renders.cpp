#include <gtest/gtest.h>

#include <filesystem>
#include <set>

#include "common/test_support.h"
#include "common/tiny_dataset.h"
#include "splat/train/test_renders.h"

using namespace saresgs;
namespace fs = std::filesystem;

namespace {
Evaluation evaluationOf(const std::vector<int>& views) {
  Evaluation e;
  for (int v : views) e.views.push_back({v, 20.0, 0.5});
  return e;
}
}  // namespace

// A view's pair is named after its image's stem; views from two folders with the same
// stem, or a view named like the sheet (all.png), get names of their own, since the pairs
// are written side by side.
TEST(TestRenders, ViewsSharingAStemOrTheSheetsNameGetNamesOfTheirOwn) {
  Scene s;
  for (const char* name : {"cam1/0001.png", "cam2/0001.png", "0002.png", "all.png", "x/0003.jpg"}) {
    SceneView v;
    v.name = name;
    s.views.push_back(v);
  }
  const std::vector<std::string> names = testRenderNames(s, evaluationOf({0, 1, 2, 3, 4}));
  EXPECT_EQ(names, (std::vector<std::string>{"cam1_0001", "cam2_0001", "0002", "all_3", "0003"}));
  // Without a clash, every name is the plain stem.
  EXPECT_EQ(testRenderNames(s, evaluationOf({0, 2, 4})), (std::vector<std::string>{"0001", "0002", "0003"}));
}

// End to end on a trained model: two views renamed into folders with one stem each get
// a file each, and the sheet is still there.
TEST(TestRenders, WritesOneFilePerViewWhenStemsClash) {
  Scene s = test::tinyDataset();
  ASSERT_GE(s.views.size(), 3u);
  s.views[0].name = "left/frame.png";
  s.views[1].name = "right/frame.png";
  TrainerOptions opt;
  opt.seed = 3;
  const Trainer t(s, opt);
  const Evaluation ev = t.evaluate({0, 1, 2}, /*keep_renders=*/true);
  test::TempDir d;
  writeTestRenders(t, ev, d.str());
  std::set<std::string> files;
  for (const auto& e : fs::directory_iterator(d.path())) files.insert(e.path().filename().string());
  EXPECT_TRUE(files.count("left_frame.png"));
  EXPECT_TRUE(files.count("right_frame.png"));
  EXPECT_TRUE(files.count("all.png"));
  EXPECT_EQ(files.size(), 4u);  // and view 2's own
}
