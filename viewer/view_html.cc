#include "viewer/view_html.h"

#include <fmt/format.h>

#include <fstream>
#include <sstream>
#include <string>
#include <vector>

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

// The timeline is 150 px high; its strip and scrubber start GUTTER (64) px in
// (viewer_strip.js), so the strip's time axis lines up with the scrubber.
constexpr const char* kStyle = R"(
html, body { margin: 0; height: 100%; overflow: hidden; font: 13px sans-serif; background: #fff; }
#view { position: absolute; inset: 0 0 150px 0; }
#panel { position: absolute; top: 8px; left: 8px; background: rgba(255,255,255,0.92);
  border: 1px solid #ccc; padding: 6px 10px; max-width: 340px; max-height: calc(100% - 180px);
  overflow-y: auto; font-size: 12px; }
#panel h1 { font-size: 14px; margin: 0 0 4px 0; }
#panel .warning { color: #b00000; font-weight: bold; margin: 2px 0 4px 0; }
#panel .sec { font-weight: bold; margin: 6px 0 2px 0; border-bottom: 1px solid #ddd; }
#panel .sub { margin-left: 18px; }
#panel .gloss { color: #555; }
#panel #legend { margin-left: 18px; }
#panel .rule { display: inline-block; margin: 1px 10px 1px 0; white-space: nowrap; }
#panel details { margin-left: 18px; }
#panel summary { cursor: pointer; color: #333; }
#panel .hint { color: #777; margin-top: 6px; }
.sw { display: inline-block; width: 10px; height: 10px; margin-right: 4px; vertical-align: middle; }
.sw.line { height: 3px; width: 14px; }
.sw.dot { border-radius: 50%; width: 7px; height: 7px; }
.sw.tick { width: 2px; height: 10px; }
.sw.ramp { width: 14px; height: 4px; }
.ramp-bar { display: inline-block; width: 150px; height: 8px; vertical-align: middle; }
.ramp-ticks { display: inline-flex; justify-content: space-between; width: 190px; }
#scalebar { position: absolute; right: 12px; bottom: 160px; background: rgba(255,255,255,0.85);
  padding: 2px 6px; font-size: 12px; text-align: center; }
#scalebar-bar { height: 5px; border: 2px solid #000; border-top: none; margin: 0 auto 1px auto; }
#timeline { position: absolute; left: 0; right: 0; bottom: 0; height: 150px; background: #f4f4f4;
  border-top: 1px solid #ccc; padding: 3px 10px; box-sizing: border-box; }
#striplegend { font-size: 11px; white-space: nowrap; overflow: hidden; text-overflow: ellipsis;
  height: 15px; }
#striplegend .entry { margin-right: 12px; }
#striplegend .note { color: #777; }
#strip { width: 100%; height: 78px; display: block; }
#scrub { margin: 0 0 0 64px; width: calc(100% - 64px); box-sizing: border-box; }
#frameinfo { white-space: nowrap; overflow: hidden; text-overflow: ellipsis; }
)";

}  // namespace

namespace {

// The page's scripts in load order: three.js, its OrbitControls, then pkslam's (viewer.js last:
// it draws with the helpers the others define).
constexpr const char* kViewerScripts[] = {"viewer/viewer_scene.js", "viewer/viewer_legend.js",
                                          "viewer/viewer_strip.js", "viewer/viewer.js"};

std::vector<fs::path> FindScripts(const ViewPageOptions& options) {
  const std::string hint = "install Debian's libjs-three, or pass --three-js DIR";
  std::vector<fs::path> s{options.three_dir / "three.min.js",
                          options.three_dir / "examples/js/controls/OrbitControls.js"};
  for (const fs::path& f : s) {
    if (!fs::exists(f)) throw Error(fmt::format("{} not found ({})", f.string(), hint));
  }
  for (const char* name : kViewerScripts) {
    s.push_back(FindProjectFile(name));
    if (!fs::exists(s.back())) throw Error(s.back().string() + " not found (the source tree's)");
  }
  return s;
}

// Copies each script into dir unless an identical copy is there (a folder shared by many
// pages stays as it is; one made by an older version gets the scripts this page needs).
void CopyScripts(const std::vector<fs::path>& scripts, const fs::path& dir) {
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec) throw OutputError(dir, "cannot create: " + ec.message());
  for (const fs::path& f : scripts) {
    const std::string text = ReadAll(f, "viewer script");
    const fs::path target = dir / f.filename();
    if (fs::exists(target) && ReadAll(target, "shared viewer script") == text) continue;
    WriteFileAtomically(target, text);
  }
}

}  // namespace

void CopyViewScripts(const fs::path& dir, const ViewPageOptions& options) {
  CopyScripts(FindScripts(options), dir);
}

std::string LiveViewPage(const ViewPageOptions& options) {
  options.Check();
  const std::vector<fs::path> scripts = FindScripts(options);
  const fs::path live = FindProjectFile("viewer/viewer_live.js");
  if (!fs::exists(live)) throw Error(live.string() + " not found (the source tree's)");
  std::string page =
      "<!DOCTYPE html>\n<html><head><meta charset=\"utf-8\">\n<title>pkslam run (live)</title>\n"
      "<style>";
  page += kStyle;
  page +=
      "#frame { position: absolute; left: 0; bottom: 0; height: 150px; background: #222; }\n"
      "#live-info { margin: 2px 0 4px 0; }\n"
      "</style>\n</head><body>\n<div id=\"view\"></div>\n"
      "<div id=\"panel\"><h1>pkslam run (live)</h1><div id=\"live-info\">waiting for the run"
      "</div><div class=\"sec\">Legend</div>"
      "<div><span class=\"sw line\" style=\"background:#1f77b4\"></span>camera path so far "
      "(map frame)</div>"
      "<div><span class=\"sw line\" style=\"background:#d62728\"></span>keyframes</div>"
      "<div><span class=\"sw dot\" style=\"background:#2828c8\"></span>map points</div>"
      "<div><span class=\"sw dot\" style=\"background:#00c000\"></span>tracked keypoints "
      "(bottom: the current left image)</div>"
      "<div>axes: <span style=\"color:#f00\">x</span> <span style=\"color:#0b0\">y</span> "
      "<span style=\"color:#00f\">z</span> at the map origin; grey grid; scale bar lower right"
      "</div><div class=\"hint\">drag: orbit · right-drag: pan · wheel: zoom</div></div>\n"
      "<div id=\"scalebar\"><div id=\"scalebar-bar\"></div><div id=\"scalebar-text\"></div>"
      "</div>\n<canvas id=\"frame\"></canvas>\n"
      "<div id=\"status\" data-state=\"loading\" hidden></div>\n";
  for (std::size_t i = 0; i < 2; ++i) {
    page += "<script>\n" + ScriptSafe(ReadAll(scripts[i], "three.js")) + "\n</script>\n";
  }
  for (const fs::path& f : {FindProjectFile("viewer/viewer_scene.js"), live}) {
    page += "<script>\n" + ScriptSafe(ReadAll(f, "viewer script")) + "\n</script>\n";
  }
  page += "</body></html>\n";
  return page;
}

void WriteViewPage(const ViewData& data, const fs::path& file, const ViewPageOptions& options) {
  options.Check();
  const std::vector<fs::path> scripts = FindScripts(options);
  const bool inline_scripts = options.shared_scripts.empty();
  if (!inline_scripts) {
    fs::path page_dir = file.parent_path();
    if (page_dir.empty()) page_dir = ".";
    CopyScripts(scripts, page_dir / options.shared_scripts);
  }
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
      "<div id=\"scalebar\"><div id=\"scalebar-bar\"></div><div id=\"scalebar-text\"></div>"
      "</div>\n"
      "<div id=\"timeline\"><div id=\"striplegend\"></div><canvas id=\"strip\"></canvas>"
      "<input id=\"scrub\" type=\"range\" min=\"0\" max=\"0\" value=\"0\">"
      "<div id=\"frameinfo\"></div></div>\n"
      "<div id=\"status\" data-state=\"loading\" hidden></div>\n";
  // three.js and OrbitControls, the data, then pkslam's scripts.
  for (std::size_t i = 0; i < 2; ++i) page += script(scripts[i]);
  page += "<script>\nconst PKSLAM_DATA = " + ScriptSafe(ViewDataJson(data)) + ";\n</script>\n";
  for (std::size_t i = 2; i < scripts.size(); ++i) page += script(scripts[i]);
  page += "</body></html>\n";
  WriteFileAtomically(file, page);
}

}  // namespace pkslam
