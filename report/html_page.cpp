#include "report/html_page.h"

#include <cctype>
#include <cstdlib>
#include <filesystem>

#include "geometry/error.h"
#include "geometry/io/atomic_file.h"

namespace saresgs {

std::string base64Encode(std::string_view bytes) {
  static constexpr char kAlphabet[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  out.reserve((bytes.size() + 2) / 3 * 4);
  std::size_t i = 0;
  for (; i + 3 <= bytes.size(); i += 3) {
    const unsigned v = (static_cast<unsigned char>(bytes[i]) << 16) | (static_cast<unsigned char>(bytes[i + 1]) << 8) |
                       static_cast<unsigned char>(bytes[i + 2]);
    out += kAlphabet[(v >> 18) & 63];
    out += kAlphabet[(v >> 12) & 63];
    out += kAlphabet[(v >> 6) & 63];
    out += kAlphabet[v & 63];
  }
  const std::size_t rest = bytes.size() - i;
  if (rest > 0) {
    unsigned v = static_cast<unsigned char>(bytes[i]) << 16;
    if (rest == 2) v |= static_cast<unsigned char>(bytes[i + 1]) << 8;
    out += kAlphabet[(v >> 18) & 63];
    out += kAlphabet[(v >> 12) & 63];
    out += rest == 2 ? kAlphabet[(v >> 6) & 63] : '=';
    out += '=';
  }
  return out;
}

std::string dataUrl(std::string_view mime, std::string_view bytes) {
  return "data:" + std::string(mime) + ";base64," + base64Encode(bytes);
}

std::string jsonForScript(const nlohmann::json& j) {
  // ensure_ascii: every non-ASCII character as \uXXXX (U+2028/2029 among them)
  const std::string text = j.dump(-1, ' ', /*ensure_ascii=*/true, nlohmann::json::error_handler_t::replace);
  std::string out;
  out.reserve(text.size());
  for (char c : text) {
    // these occur only inside JSON strings, where the escape means the same character
    if (c == '<')
      out += "\\u003c";
    else if (c == '>')
      out += "\\u003e";
    else if (c == '&')
      out += "\\u0026";
    else
      out += c;
  }
  return out;
}

std::string htmlEscape(std::string_view s) {
  std::string out;
  out.reserve(s.size());
  for (char c : s) {
    switch (c) {
      case '&':
        out += "&amp;";
        break;
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '"':
        out += "&quot;";
        break;
      case '\'':
        out += "&#39;";
        break;
      default:
        out += c;
    }
  }
  return out;
}

ViewerScript findViewerScript(const std::string& explicit_path) {
  ViewerScript v;
  if (!explicit_path.empty())
    v.path = explicit_path;
  else if (const char* env = std::getenv("SARESGS_REPORT_VIEWER"); env && *env)
    v.path = env;
  else
    v.path = SARESGS_REPORT_VIEWER_DEFAULT;
  try {
    v.script = readFile(v.path);
  } catch (const InputError&) {
    // not there (or not readable): the page says where it was looked for
  }
  return v;
}

namespace {

// Inlined script text must not end its element early: "</script" (any case) is written
// "<\/script", and "<!--" (after which a "<script" would put the HTML parser in a state
// where our closing tag no longer closes the element) "<\!--". In JavaScript strings and
// template literals each escape means the same character.
std::string guardScript(std::string_view js) {
  const auto lower_at = [&](std::size_t i, std::string_view word) {
    if (i + word.size() > js.size()) return false;
    for (std::size_t k = 0; k < word.size(); ++k)
      if (std::tolower(static_cast<unsigned char>(js[i + k])) != word[k]) return false;
    return true;
  };
  std::string out;
  out.reserve(js.size());
  for (std::size_t i = 0; i < js.size(); ++i) {
    out += js[i];
    if (js[i] != '<') continue;
    if (lower_at(i + 1, "/script") || lower_at(i + 1, "!--")) out += '\\';
  }
  return out;
}

}  // namespace

std::string pageHtml(const PageParts& p) {
  std::string html;
  html.reserve(p.model_base64.size() + p.viewer_script.size() + (std::size_t{1} << 16));
  html += "<!doctype html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n";
  html += "<meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\n";
  // No request leaves the file: scripts and styles inline only, images from data: URLs,
  // Spark's sorter as a blob: worker with inlined WebAssembly.
  html +=
      "<meta http-equiv=\"Content-Security-Policy\" content=\"default-src 'none'; script-src 'unsafe-inline' "
      "'wasm-unsafe-eval' blob:; worker-src blob:; style-src 'unsafe-inline'; img-src data: blob:; "
      "connect-src data: blob:; font-src data:\">\n";
  html += "<meta name=\"generator\" content=\"saresgs report\">\n";
  html += "<title>" + htmlEscape(p.title) + "</title>\n";
  html += "<style>\n" + std::string(reportStyleSheet()) + "\n</style>\n</head>\n<body>\n";
  html += "<noscript>This report draws itself with JavaScript; please enable it.</noscript>\n";
  html += "<div id=\"app\"></div>\n";
  html += "<script type=\"application/json\" id=\"saresgs-data\">" + jsonForScript(p.data) + "</script>\n";
  if (!p.model_base64.empty())
    html += "<script type=\"application/octet-stream\" id=\"saresgs-model\">" + p.model_base64 + "</script>\n";
  if (!p.viewer_script.empty()) html += "<script>\n" + guardScript(p.viewer_script) + "\n</script>\n";
  html += "<script>\n" + guardScript(reportAppScript()) + "\n</script>\n</body>\n</html>\n";
  return html;
}

}  // namespace saresgs
