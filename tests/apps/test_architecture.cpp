// The tree's rules, checked on the sources: which room may include which, no app reaches
// into a detail header, the harness (nbv/eval) sits on top of the algorithm, and every
// document the code or docs/DESIGN.md cites exists.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

namespace {

namespace fs = std::filesystem;

const fs::path kRoot = SARESGS_SOURCE_DIR;

std::string read(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

// Source files under `room` (relative to the root), recursively.
std::vector<fs::path> sources(const std::string& room) {
  std::vector<fs::path> out;
  for (const auto& e : fs::recursive_directory_iterator(kRoot / room)) {
    const std::string ext = e.path().extension().string();
    if (e.is_regular_file() && (ext == ".h" || ext == ".cpp")) out.push_back(e.path());
  }
  return out;
}

// The project headers a file includes ("room/..." paths).
std::vector<std::string> includes(const fs::path& p) {
  static const std::regex inc(R"re(#include\s+"([^"]+)")re");
  std::vector<std::string> out;
  const std::string text = read(p);
  for (std::sregex_iterator it(text.begin(), text.end(), inc), end; it != end; ++it) out.push_back((*it)[1]);
  return out;
}

std::string rel(const fs::path& p) { return fs::relative(p, kRoot).string(); }

TEST(Architecture, RoomsIncludeOnlyWhatIsBelowThem) {
  int checked = 0;
  for (const auto& [room, forbidden] : std::vector<std::pair<std::string, std::vector<std::string>>>{
           {"geometry", {"splat/", "nbv/", "report/", "apps/", "python/", "fuzz/"}},
           {"splat", {"nbv/", "report/", "apps/", "python/", "fuzz/"}},
           {"nbv", {"report/", "apps/", "python/", "fuzz/"}},
           {"report", {"apps/", "python/", "fuzz/"}},
           {"apps", {"python/"}},
           {"python", {"apps/"}}})
    for (const fs::path& f : sources(room))
      for (const std::string& i : includes(f)) {
        ++checked;
        for (const std::string& bad : forbidden) EXPECT_NE(i.rfind(bad, 0), 0u) << rel(f) << " includes " << i;
      }
  EXPECT_GT(checked, 100);
}

TEST(Architecture, TheAlgorithmDoesNotIncludeItsEvaluationHarness) {
  for (const fs::path& f : sources("nbv")) {
    if (rel(f).rfind("nbv/eval/", 0) == 0) continue;
    for (const std::string& i : includes(f)) EXPECT_NE(i.rfind("nbv/eval/", 0), 0u) << rel(f) << " includes " << i;
  }
}

// The command line and the Python module are thin front ends over the libraries' public
// headers (and neither is built on the other).
TEST(Architecture, FrontEndsIncludeNoDetailHeader) {
  int checked = 0;
  for (const std::string room : {"apps", "python"})
    for (const fs::path& f : sources(room))
      for (const std::string& i : includes(f)) {
        ++checked;
        EXPECT_EQ(i.find("_detail.h"), std::string::npos) << rel(f) << " includes " << i;
      }
  EXPECT_GT(checked, 40);
}

// Paths cited in a text: `room/...` or docs/third_party_notes/results paths with a file
// extension, and any *.md name.
std::vector<std::string> citedPaths(const std::string& text) {
  static const std::regex path(
      R"re(\b((?:geometry|splat|nbv|report|apps|tests|scripts|docs|results|third_party_notes)/[A-Za-z0-9_./{},-]*[A-Za-z0-9_}]))re");
  static const std::regex md(R"re(([A-Za-z0-9_./-]*[A-Za-z0-9_]\.md)\b)re");
  std::vector<std::string> out;
  for (const std::regex* r : {&path, &md})
    for (std::sregex_iterator it(text.begin(), text.end(), *r), end; it != end; ++it) out.push_back((*it)[1]);
  return out;
}

// "a/{b,c}.h" names a/b.h and a/c.h.
std::vector<std::string> expandBraces(const std::string& p) {
  const auto open = p.find('{'), close = p.find('}');
  if (open == std::string::npos || close == std::string::npos || close < open) return {p};
  std::vector<std::string> out;
  std::stringstream alts(p.substr(open + 1, close - open - 1));
  for (std::string a; std::getline(alts, a, ',');)
    for (const std::string& rest : expandBraces(p.substr(close + 1))) out.push_back(p.substr(0, open) + a + rest);
  return out;
}

bool exists(const std::string& cited) {
  for (const std::string& p : expandBraces(cited))
    if (!fs::exists(kRoot / p)) return false;
  return true;
}

TEST(Architecture, DesignDocumentMapsThePaperToFilesThatExist) {
  const fs::path design = kRoot / "docs" / "DESIGN.md";
  ASSERT_TRUE(fs::exists(design));
  const std::string text = read(design);
  int paths = 0;
  for (const std::string& p : citedPaths(text)) {
    if (p.find('/') == std::string::npos) continue;  // a bare file name is checked below
    ++paths;
    EXPECT_TRUE(exists(p)) << "docs/DESIGN.md cites " << p;
  }
  EXPECT_GT(paths, 20);
  for (const char* term : {"SA-Point", "triangulation", "upsampl", "dilat", "frustum", "visible", "hash", "XOR",
                           "top-N", "Fisher", "residual", "AUSE", "protocol"})
    EXPECT_NE(text.find(term), std::string::npos) << term;
}

// The comment text of a source file (everything after "//" on each line).
std::string comments(const std::string& text) {
  std::string out;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);)
    if (const auto p = line.find("//"); p != std::string::npos) out += line.substr(p + 2) + "\n";
  return out;
}

TEST(Architecture, EveryDocumentTheCodeCitesExists) {
  static const std::regex doc(R"re(([A-Za-z0-9_./-]*(?:[A-Za-z0-9_]\.md\b|STACK_NOTES)))re");
  int cited = 0;
  for (const std::string room : {"geometry", "splat", "nbv", "report", "apps", "python", "tests", "fuzz"})
    for (const fs::path& f : sources(room)) {
      if (f.filename() == "test_architecture.cpp") continue;
      const std::string c = comments(read(f));
      for (std::sregex_iterator it(c.begin(), c.end(), doc), end; it != end; ++it) {
        const std::string p = (*it)[1];
        ++cited;
        EXPECT_TRUE(p.find('/') != std::string::npos && exists(p))
            << rel(f) << " cites " << p << " (cite a document by its path from the root)";
      }
    }
  EXPECT_GT(cited, 0);
}

}  // namespace
