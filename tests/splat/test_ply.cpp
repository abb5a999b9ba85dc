#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <functional>
#include <limits>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "common/test_support.h"
#include "splat/ply.h"

using namespace saresgs;
using saresgs::test::TempDir;
using saresgs::test::throwsInputError;

namespace {

Gaussians randomModel(std::size_t n, int degree, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<float> nd(0.0f, 2.0f);
  Gaussians g;
  g.max_sh_degree = degree;
  g.resize(n);
  g.forEachArray([&](std::vector<float>& a, std::size_t) {
    for (auto& v : a) v = nd(rng);
  });
  return g;
}

void expectBitEqual(const Gaussians& a, const Gaussians& b) {
  ASSERT_EQ(a.max_sh_degree, b.max_sh_degree);
  ASSERT_EQ(a.size(), b.size());
  std::vector<const std::vector<float>*> av, bv;
  a.forEachArray([&](const std::vector<float>& v, std::size_t) { av.push_back(&v); });
  b.forEachArray([&](const std::vector<float>& v, std::size_t) { bv.push_back(&v); });
  for (std::size_t k = 0; k < av.size(); ++k) {
    ASSERT_EQ(av[k]->size(), bv[k]->size()) << "array " << k;
    EXPECT_EQ(std::memcmp(av[k]->data(), bv[k]->data(), av[k]->size() * sizeof(float)), 0) << "array " << k;
  }
}

// ---- an independent little PLY writer for hand-made files -------------------------

struct Column {
  std::string name;
  std::string type;  // float, double, uchar or int
  std::function<double(std::size_t)> value;
};

template <typename T>
void put(std::string& out, T v) {
  char b[sizeof(T)];
  std::memcpy(b, &v, sizeof(T));  // the test hosts are little-endian (x86-64)
  out.append(b, sizeof(T));
}

std::string makePly(const std::vector<Column>& cols, std::size_t n,
                    const std::string& format = "binary_little_endian 1.0", const std::string& extra_header = "") {
  std::string s = "ply\nformat " + format + "\n" + extra_header;
  s += "element vertex " + std::to_string(n) + "\n";
  for (const auto& c : cols) s += "property " + c.type + " " + c.name + "\n";
  s += "end_header\n";
  for (std::size_t i = 0; i < n; ++i)
    for (const auto& c : cols) {
      const double v = c.value(i);
      if (c.type == "float")
        put(s, static_cast<float>(v));
      else if (c.type == "double")
        put(s, v);
      else if (c.type == "uchar")
        put(s, static_cast<std::uint8_t>(v));
      else if (c.type == "int")
        put(s, static_cast<std::int32_t>(v));
      else
        ADD_FAILURE() << "test writer: type " << c.type;
    }
  return s;
}

// The standard 3DGS columns of a model, written out from the layout's definition.
std::vector<Column> modelColumns(const Gaussians& g) {
  const int K = g.shCoeffs();
  std::vector<Column> cols;
  for (int a = 0; a < 3; ++a)
    cols.push_back({std::string(1, "xyz"[a]), "float", [&g, a](std::size_t i) { return g.means[3 * i + a]; }});
  for (int c = 0; c < 3; ++c)
    cols.push_back({"f_dc_" + std::to_string(c), "float", [&g, c, K](std::size_t i) { return g.sh[(i * K) * 3 + c]; }});
  for (int c = 0; c < 3; ++c)
    for (int k = 1; k < K; ++k)
      cols.push_back({"f_rest_" + std::to_string(c * (K - 1) + k - 1), "float",
                      [&g, c, k, K](std::size_t i) { return g.sh[(i * K + k) * 3 + c]; }});
  cols.push_back({"opacity", "float", [&g](std::size_t i) { return g.opacities[i]; }});
  for (int a = 0; a < 3; ++a)
    cols.push_back({"scale_" + std::to_string(a), "float", [&g, a](std::size_t i) { return g.log_scales[3 * i + a]; }});
  for (int a = 0; a < 4; ++a)
    cols.push_back({"rot_" + std::to_string(a), "float", [&g, a](std::size_t i) { return g.rotations[4 * i + a]; }});
  return cols;
}

// An independent reader of a float-only binary PLY: property names and the data.
struct RawPly {
  std::vector<std::string> names;
  std::string format;
  std::size_t count = 0;
  std::vector<float> data;
  float at(std::size_t vertex, const std::string& name) const {
    const auto it = std::find(names.begin(), names.end(), name);
    EXPECT_NE(it, names.end()) << name;
    return data[vertex * names.size() + static_cast<std::size_t>(it - names.begin())];
  }
};

RawPly readRaw(const std::string& path) {
  RawPly r;
  std::istringstream in(saresgs::test::readBytes(path));
  std::string line;
  while (std::getline(in, line) && line != "end_header") {
    std::istringstream ls(line);
    std::string key, a, b;
    ls >> key >> a >> b;
    if (key == "format") r.format = a;
    if (key == "element") r.count = std::stoul(b);
    if (key == "property") {
      EXPECT_EQ(a, "float") << b;
      r.names.push_back(b);
    }
  }
  r.data.resize(r.count * r.names.size());
  in.read(reinterpret_cast<char*>(r.data.data()), static_cast<std::streamsize>(r.data.size() * 4));
  EXPECT_EQ(static_cast<std::size_t>(in.gcount()), r.data.size() * 4);
  return r;
}

}  // namespace

TEST(GaussiansPly, RoundTripIsBitExactForEveryShDegree) {
  TempDir dir;
  for (int degree = 0; degree <= 3; ++degree) {
    const Gaussians g = randomModel(57, degree, 100 + degree);
    const std::string path = dir.file("model" + std::to_string(degree) + ".ply");
    writeGaussiansPly(path, g);
    expectBitEqual(g, readGaussiansPly(path));
  }
  // Atomic write: nothing but the four outputs in the folder.
  std::size_t files = 0;
  for (const auto& e : std::filesystem::directory_iterator(dir.path())) {
    ++files;
    EXPECT_EQ(e.path().extension(), ".ply") << e.path();
  }
  EXPECT_EQ(files, 4u);
}

TEST(GaussiansPly, EmptyModelRoundTrips) {
  TempDir dir;
  Gaussians g;
  g.max_sh_degree = 3;
  writeGaussiansPly(dir.file("empty.ply"), g);
  const Gaussians r = readGaussiansPly(dir.file("empty.ply"));
  EXPECT_EQ(r.size(), 0u);
  EXPECT_EQ(r.max_sh_degree, 3);
}

TEST(GaussiansPly, WrittenLayoutIsTheStandardOne) {
  TempDir dir;
  const Gaussians g = randomModel(5, 1, 7);
  writeGaussiansPly(dir.file("m.ply"), g);
  const RawPly raw = readRaw(dir.file("m.ply"));
  EXPECT_EQ(raw.format, "binary_little_endian");
  std::vector<std::string> expected = {"x", "y", "z", "nx", "ny", "nz", "f_dc_0", "f_dc_1", "f_dc_2"};
  for (int i = 0; i < 9; ++i) expected.push_back("f_rest_" + std::to_string(i));
  for (const char* p : {"opacity", "scale_0", "scale_1", "scale_2", "rot_0", "rot_1", "rot_2", "rot_3"})
    expected.push_back(p);
  EXPECT_EQ(raw.names, expected);
  ASSERT_EQ(raw.count, 5u);
  for (std::size_t i = 0; i < 5; ++i) {
    EXPECT_EQ(raw.at(i, "nx"), 0.0f);
    EXPECT_EQ(raw.at(i, "y"), g.means[3 * i + 1]);
    EXPECT_EQ(raw.at(i, "opacity"), g.opacities[i]);
    EXPECT_EQ(raw.at(i, "scale_2"), g.log_scales[3 * i + 2]);
    EXPECT_EQ(raw.at(i, "rot_0"), g.rotations[4 * i]);  // w first, as stored
  }
}

TEST(GaussiansPly, FRestIsChannelMajor) {
  TempDir dir;
  Gaussians g;
  g.max_sh_degree = 2;  // K = 9, 24 f_rest
  g.resize(3);
  const int K = 9;
  // Coefficient k = 3 of channel c = 2 of Gaussian 1 -> f_rest_{2*8 + 2} = f_rest_18.
  g.sh[(1 * K + 3) * 3 + 2] = 7.0f;
  // DC of channel 1 of Gaussian 2 -> f_dc_1.
  g.sh[(2 * K + 0) * 3 + 1] = -3.0f;
  // Coefficient k = 1 of channel 0 of Gaussian 0 -> f_rest_0.
  g.sh[(0 * K + 1) * 3 + 0] = 5.0f;
  writeGaussiansPly(dir.file("m.ply"), g);
  const RawPly raw = readRaw(dir.file("m.ply"));
  for (std::size_t i = 0; i < 3; ++i)
    for (int r = 0; r < 24; ++r) {
      const std::string name = "f_rest_" + std::to_string(r);
      const float want = (i == 1 && r == 18) ? 7.0f : (i == 0 && r == 0) ? 5.0f : 0.0f;
      EXPECT_EQ(raw.at(i, name), want) << "vertex " << i << " " << name;
    }
  EXPECT_EQ(raw.at(2, "f_dc_1"), -3.0f);
  EXPECT_EQ(raw.at(2, "f_dc_0"), 0.0f);
  expectBitEqual(g, readGaussiansPly(dir.file("m.ply")));
}

TEST(GaussiansPly, ReadsPropertiesByNameInAnyOrderFloatOrDoubleWithExtras) {
  TempDir dir;
  for (int degree : {0, 3}) {
    const Gaussians g = randomModel(23, degree, 200 + degree);
    std::vector<Column> cols = modelColumns(g);
    std::mt19937_64 rng(300 + degree);
    std::shuffle(cols.begin(), cols.end(), rng);
    // Some as double, and properties the reader must skip (other types included).
    for (std::size_t k = 0; k < cols.size(); k += 3) cols[k].type = "double";
    cols.insert(cols.begin() + 2, {"red", "uchar", [](std::size_t i) { return double(i % 256); }});
    cols.push_back({"segment", "int", [](std::size_t i) { return -double(i); }});
    cols.insert(cols.begin() + 5, {"nx", "double", [](std::size_t) { return 0.25; }});
    const std::string path = dir.file("shuffled" + std::to_string(degree) + ".ply");
    saresgs::test::writeBytes(
        path, makePly(cols, g.size(), "binary_little_endian 1.0", "comment hand-made\nobj_info test\n"));
    expectBitEqual(g, readGaussiansPly(path));
  }
}

TEST(GaussiansPly, SkipsFixedSizeElementsBeforeTheVertices) {
  TempDir dir;
  const Gaussians g = randomModel(4, 1, 9);
  std::string body = makePly(modelColumns(g), g.size());
  // Insert "element camera 2 / property double f" before the vertex element and its data.
  const std::string head = "ply\nformat binary_little_endian 1.0\n";
  ASSERT_EQ(body.rfind(head, 0), 0u);
  const std::size_t end = body.find("end_header\n") + 11;
  std::string file = head + "element camera 2\nproperty double f\n" + body.substr(head.size(), end - head.size());
  put(file, 1.5);
  put(file, 2.5);
  file += body.substr(end);
  saresgs::test::writeBytes(dir.file("cam.ply"), file);
  expectBitEqual(g, readGaussiansPly(dir.file("cam.ply")));
}

TEST(GaussiansPly, MalformedFilesGiveInputErrorsNamingFileAndField) {
  TempDir dir;
  const Gaussians g = randomModel(6, 1, 11);
  const std::string good = dir.file("good.ply");
  writeGaussiansPly(good, g);
  const std::string bytes = saresgs::test::readBytes(good);

  const std::string missing = dir.file("nowhere.ply");
  EXPECT_TRUE(throwsInputError([&] { readGaussiansPly(missing); }, missing, "file"));

  const std::string truncated = dir.file("truncated.ply");
  saresgs::test::writeBytes(truncated, bytes.substr(0, bytes.size() - 5));
  EXPECT_TRUE(throwsInputError([&] { readGaussiansPly(truncated); }, truncated, "vertex data"));

  const std::string notply = dir.file("notply.ply");
  saresgs::test::writeBytes(notply, "solid cube\nfacet normal 0 0 1\n");
  EXPECT_TRUE(throwsInputError([&] { readGaussiansPly(notply); }, notply, "header"));

  const std::string ascii = dir.file("ascii.ply");
  saresgs::test::writeBytes(ascii, "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nend_header\n1\n");
  EXPECT_TRUE(throwsInputError([&] { readGaussiansPly(ascii); }, ascii, "format"));
  try {
    readGaussiansPly(ascii);
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("ascii"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("binary_little_endian"), std::string::npos) << e.what();
  }

  const std::string big = dir.file("big.ply");
  saresgs::test::writeBytes(big, makePly(modelColumns(g), g.size(), "binary_big_endian 1.0"));
  EXPECT_TRUE(throwsInputError([&] { readGaussiansPly(big); }, big, "format"));
  try {
    readGaussiansPly(big);
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("binary_big_endian"), std::string::npos) << e.what();
  }

  std::vector<Column> cols = modelColumns(g);
  {
    auto c = cols;
    c.erase(std::find_if(c.begin(), c.end(), [](const Column& x) { return x.name == "opacity"; }));
    const std::string p = dir.file("noopacity.ply");
    saresgs::test::writeBytes(p, makePly(c, g.size()));
    EXPECT_TRUE(throwsInputError([&] { readGaussiansPly(p); }, p, "opacity"));
  }
  {
    // Degree 1 has 9 f_rest; keep only 5.
    auto c = cols;
    c.erase(std::remove_if(
                c.begin(), c.end(),
                [](const Column& x) { return x.name.rfind("f_rest_", 0) == 0 && std::stoi(x.name.substr(7)) >= 5; }),
            c.end());
    const std::string p = dir.file("rest5.ply");
    saresgs::test::writeBytes(p, makePly(c, g.size()));
    EXPECT_TRUE(throwsInputError([&] { readGaussiansPly(p); }, p, "f_rest"));
  }
  {
    auto c = cols;
    for (auto& x : c)
      if (x.name == "scale_1")
        x.value = [&g](std::size_t i) {
          return i == 3 ? std::numeric_limits<double>::quiet_NaN() : double(g.log_scales[3 * i + 1]);
        };
    const std::string p = dir.file("nan.ply");
    saresgs::test::writeBytes(p, makePly(c, g.size()));
    EXPECT_TRUE(throwsInputError([&] { readGaussiansPly(p); }, p, "scale_1"));
    EXPECT_TRUE(throwsInputError([&] { readGaussiansPly(p); }, p, "vertex 3"));
  }
  {
    auto c = cols;
    for (auto& x : c)
      if (x.name == "x") {
        x.type = "double";
        x.value = [](std::size_t i) { return i == 2 ? std::numeric_limits<double>::infinity() : 0.0; };
      }
    const std::string p = dir.file("inf.ply");
    saresgs::test::writeBytes(p, makePly(c, g.size()));
    EXPECT_TRUE(throwsInputError([&] { readGaussiansPly(p); }, p, "x"));
    EXPECT_TRUE(throwsInputError([&] { readGaussiansPly(p); }, p, "vertex 2"));
  }
  {
    // A required property stored as an integer type.
    auto c = cols;
    for (auto& x : c)
      if (x.name == "rot_2") x.type = "int";
    const std::string p = dir.file("introt.ply");
    saresgs::test::writeBytes(p, makePly(c, g.size()));
    EXPECT_TRUE(throwsInputError([&] { readGaussiansPly(p); }, p, "rot_2"));
  }
}

// Found by fuzz/fuzz_ply.cpp (UBSan: the reader pointed into the arrays of an empty model,
// whose data() is null, before reading any vertex). The committed input is what
// writeGaussiansPly writes for an empty model; the sanitizers check it in the test
// command's fuzz run (fuzz/run_bounded.sh runs every tests/**/fuzz_regressions/<target>/ input).
TEST(Ply, AFileWithoutVerticesReadsAsAnEmptyModel) {
  const std::string p = std::string(SARESGS_SOURCE_DIR) + "/tests/splat/fuzz_regressions/ply/empty_model.ply";
  const Gaussians g = readGaussiansPly(p);
  EXPECT_EQ(g.size(), 0u);
  EXPECT_EQ(g.max_sh_degree, 0);
  g.forEachArray([](const std::vector<float>& a, std::size_t) { EXPECT_TRUE(a.empty()); });
  TempDir d;
  writeGaussiansPly(d.file("empty.ply"), Gaussians{});
  EXPECT_EQ(saresgs::test::readBytes(d.file("empty.ply")), saresgs::test::readBytes(p));
  // Without vertices a missing property is still refused by name.
  std::string bytes = saresgs::test::readBytes(p);
  const std::string line = "property float opacity\n";
  ASSERT_NE(bytes.find(line), std::string::npos);
  bytes.erase(bytes.find(line), line.size());
  saresgs::test::writeBytes(d.file("no_opacity.ply"), bytes);
  EXPECT_TRUE(
      throwsInputError([&] { readGaussiansPly(d.file("no_opacity.ply")); }, d.file("no_opacity.ply"), "opacity"));
}
