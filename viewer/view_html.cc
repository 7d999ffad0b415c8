#include "viewer/view_html.h"

#include <fmt/format.h>

#include <fstream>
#include <sstream>
#include <string>

#include "core/util/error.h"
#include "core/util/output_file.h"
#include "core/util/project_file.h"

namespace pkslam {

namespace fs = std::filesystem;

void ViewPageOptions::Check() const {
  PKSLAM_CHECK_OPTION(!three_dir.empty(), "--three-js", "{}", "empty");
}

namespace {

std::string ReadAll(const fs::path& file, const std::string& hint) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw Error(fmt::format("cannot read {} ({})", file.string(), hint));
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

// An inline script ends at the first "</script" (any case): escape that sequence only (inside
// the strings where it can occur, "<\/" means the same to JavaScript and JSON).
std::string ScriptSafe(const std::string& text) {
  std::string out;
  out.reserve(text.size());
  for (std::size_t i = 0; i < text.size(); ++i) {
    if (text[i] == '<' && i + 7 < text.size() && text[i + 1] == '/' &&
        (text.compare(i + 2, 6, "script") == 0 || text.compare(i + 2, 6, "SCRIPT") == 0)) {
      out += "<\\/";
      ++i;
    } else {
      out += text[i];
    }
  }
  return out;
}

constexpr const char* kStyle = R"(
html, body { margin: 0; height: 100%; overflow: hidden; font: 13px sans-serif; background: #fff; }
#view { position: absolute; inset: 0 0 110px 0; }
#panel { position: absolute; top: 8px; left: 8px; background: rgba(255,255,255,0.92);
  border: 1px solid #ccc; padding: 6px 10px; max-width: 320px; }
#panel h1 { font-size: 14px; margin: 0 0 4px 0; }
#panel .warning { color: #b00000; font-weight: bold; margin: 2px 0 4px 0; }
#legend span { display: inline-block; width: 10px; height: 10px; margin-right: 4px; }
#timeline { position: absolute; left: 0; right: 0; bottom: 0; height: 110px; background: #f4f4f4;
  border-top: 1px solid #ccc; padding: 4px 10px; box-sizing: border-box; }
#scrub { width: 100%; }
#strip { width: 100%; height: 46px; display: block; }
#frameinfo { white-space: nowrap; overflow: hidden; text-overflow: ellipsis; }
)";

}  // namespace

namespace {

struct Scripts {
  fs::path three, orbit, viewer;
};

Scripts FindScripts(const ViewPageOptions& options) {
  const std::string hint = "install Debian's libjs-three, or pass --three-js DIR";
  Scripts s{options.three_dir / "three.min.js",
            options.three_dir / "examples/js/controls/OrbitControls.js",
            FindProjectFile("viewer/viewer.js")};
  for (const fs::path& f : {s.three, s.orbit}) {
    if (!fs::exists(f)) throw Error(fmt::format("{} not found ({})", f.string(), hint));
  }
  if (!fs::exists(s.viewer)) throw Error(s.viewer.string() + " not found (the source tree's)");
  return s;
}

}  // namespace

void CopyViewScripts(const fs::path& dir, const ViewPageOptions& options) {
  const Scripts s = FindScripts(options);
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec) throw OutputError(dir, "cannot create: " + ec.message());
  for (const fs::path& f : {s.three, s.orbit, s.viewer}) {
    WriteFileAtomically(dir / f.filename(), ReadAll(f, "viewer script"));
  }
}

void WriteViewPage(const ViewData& data, const fs::path& file, const ViewPageOptions& options) {
  options.Check();
  const Scripts scripts = FindScripts(options);
  const bool inline_scripts = options.shared_scripts.empty();
  auto script = [&](const fs::path& f) {
    if (!inline_scripts) {
      return fmt::format("<script src=\"{}\"></script>\n",
                         (options.shared_scripts / f.filename()).generic_string());
    }
    return "<script>\n" + ScriptSafe(ReadAll(f, "viewer script")) + "\n</script>\n";
  };
  std::string page;
  page += "<!DOCTYPE html>\n<html><head><meta charset=\"utf-8\">\n<title>pkslam view: ";
  for (char c : data.title) page += (c == '<' || c == '&') ? '_' : c;
  page += "</title>\n<style>";
  page += kStyle;
  page +=
      "</style>\n</head><body>\n"
      "<div id=\"view\"></div>\n<div id=\"panel\"></div>\n"
      "<div id=\"timeline\"><canvas id=\"strip\"></canvas><input id=\"scrub\" "
      "type=\"range\" min=\"0\" max=\"0\" value=\"0\"><div id=\"frameinfo\"></div></div>\n"
      "<div id=\"status\" data-state=\"loading\" hidden></div>\n";
  page += script(scripts.three);
  page += script(scripts.orbit);
  page += "<script>\nconst PKSLAM_DATA = " + ScriptSafe(ViewDataJson(data)) + ";\n</script>\n";
  page += script(scripts.viewer);
  page += "</body></html>\n";
  WriteFileAtomically(file, page);
}

}  // namespace pkslam
