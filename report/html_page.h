#pragma once
// One self-contained HTML page: the report's shell, shared by the run page and the grid
// page. Everything the page shows travels inside it as data (JSON and base64 in
// non-executing <script> elements), and the page's own script (report/web/app.js, compiled
// into the library) draws it; nothing from the data is ever written into the markup, so a
// file or view name holding "</script>" or quotes stays text. A Content-Security-Policy
// forbids any request outside the file.
#include <nlohmann/json.hpp>

#include <cstddef>
#include <string>
#include <string_view>

namespace saresgs {

// Standard base64 (RFC 4648, with padding).
std::string base64Encode(std::string_view bytes);
// "data:<mime>;base64,...".
std::string dataUrl(std::string_view mime, std::string_view bytes);

// JSON text that is safe inside a <script> element: "<", ">", "&" and every non-ASCII
// character (U+2028 and U+2029 included) are written as \u escapes, so the text cannot
// close the element or open a comment, and parses back to the same value.
std::string jsonForScript(const nlohmann::json& j);

// "&", "<", ">", '"' and "'" as character references.
std::string htmlEscape(std::string_view s);

// The bundled viewer (three.js + Spark + report/web/viewer.js, built by
// scripts/install_node_tools.sh). Looked for at `explicit_path` when given, else at
// $SARESGS_REPORT_VIEWER, else where the install script puts it
// (<repo>/build/node_tools/report/viewer.js). `path` is where it was looked for last;
// `script` is empty when it is not there.
struct ViewerScript {
  std::string path;
  std::string script;
};
ViewerScript findViewerScript(const std::string& explicit_path = "");

struct PageParts {
  std::string title;          // plain text
  nlohmann::json data;        // what app.js draws, as window.SARESGS_DATA-like JSON
  std::string model_base64;   // the model's bytes for the viewer, or empty
  std::string viewer_script;  // ViewerScript::script, or empty (the page says so)
};
// The whole page. The viewer script is inlined as is except that any "</script" in it is
// written "<\/script" (the same string to JavaScript).
std::string pageHtml(const PageParts& parts);

// The page's own script and style sheet (report/web/app.js and style.css).
std::string_view reportAppScript();
std::string_view reportStyleSheet();

}  // namespace saresgs
