// The report page's shell (report/html_page.h): what keeps data from running as code.
#include <gtest/gtest.h>

#include <string>

#include "report/html_page.h"

using namespace saresgs;

namespace {

std::size_t count(const std::string& s, const std::string& what) {
  std::size_t n = 0;
  for (std::size_t p = s.find(what); p != std::string::npos; p = s.find(what, p + 1)) ++n;
  return n;
}

}  // namespace

TEST(HtmlPage, Base64MatchesRfc4648Vectors) {
  EXPECT_EQ(base64Encode(""), "");
  EXPECT_EQ(base64Encode("f"), "Zg==");
  EXPECT_EQ(base64Encode("fo"), "Zm8=");
  EXPECT_EQ(base64Encode("foo"), "Zm9v");
  EXPECT_EQ(base64Encode("foob"), "Zm9vYg==");
  EXPECT_EQ(base64Encode("fooba"), "Zm9vYmE=");
  EXPECT_EQ(base64Encode("foobar"), "Zm9vYmFy");
  EXPECT_EQ(base64Encode(std::string("\xff\xfe\x00", 3)), "//4A");
  EXPECT_EQ(dataUrl("image/png", "foo"), "data:image/png;base64,Zm9v");
}

TEST(HtmlPage, JsonForScriptCannotCloseTheElementAndParsesBack) {
  const std::string hostile =
      "</script><script>alert(1)</script><!-- & \xe2\x80\xa8 \xe2\x80\xa9 \"quoted\" 'x' \xc3\xa9";
  const nlohmann::json j = {{"name", hostile}, {hostile, {1, 2.5, hostile}}};
  const std::string text = jsonForScript(j);
  for (const char c : text) {
    EXPECT_NE(c, '<');
    EXPECT_NE(c, '>');
    EXPECT_NE(c, '&');
    EXPECT_LT(static_cast<unsigned char>(c), 0x80) << "non-ASCII byte in the script text";
  }
  EXPECT_EQ(nlohmann::json::parse(text), j);
}

TEST(HtmlPage, HtmlEscapeEscapesMarkupAndQuotes) {
  EXPECT_EQ(htmlEscape("<a href=\"x\">'&'</a>"), "&lt;a href=&quot;x&quot;&gt;&#39;&amp;&#39;&lt;/a&gt;");
}

TEST(HtmlPage, DataAndScriptsCannotEndTheirElements) {
  PageParts p;
  p.title = "</title><script>alert(1)</script>";
  p.data = {{"name", "</script><script>alert(2)</script>"}};
  p.model_base64 = base64Encode("model bytes");
  p.viewer_script = "var s = \"</script><b>3\"; var t = '</SCRIPT >'; var u = '<!-- x';";
  const std::string html = pageHtml(p);
  // exactly the page's own elements: data, model, viewer, app (the viewer's "<!--" and
  // "<script" would put the parser in its double-escaped state, where our "</script>" would
  // not end the element)
  EXPECT_EQ(count(html, "<script"), 4u);
  EXPECT_EQ(count(html, "</script>"), 4u);
  EXPECT_EQ(count(html, "</title>"), 1u);
  EXPECT_NE(html.find("&lt;/title&gt;&lt;script&gt;alert(1)&lt;/script&gt;"), std::string::npos);
  // the viewer's string keeps its meaning: "<\/script" is "</script" to JavaScript
  EXPECT_NE(html.find("var s = \"<\\/script><b>3\"; var t = '<\\/SCRIPT >'; var u = '<\\!-- x';"), std::string::npos);
  // nothing leaves the file
  EXPECT_NE(html.find("default-src 'none'"), std::string::npos);
}

TEST(HtmlPage, AppScriptAndStyleAreCompiledIn) {
  EXPECT_NE(reportAppScript().find("saresgs-data"), std::string_view::npos);
  EXPECT_NE(reportStyleSheet().find("body"), std::string_view::npos);
}

TEST(HtmlPage, ViewerScriptNotFoundSaysWhere) {
  const ViewerScript v = findViewerScript("/nonexistent/viewer.js");
  EXPECT_EQ(v.path, "/nonexistent/viewer.js");
  EXPECT_TRUE(v.script.empty());
}
