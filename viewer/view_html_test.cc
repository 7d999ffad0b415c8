#include "viewer/view_html.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <fstream>

#include "tests/support/test_data.h"

namespace pkslam {
namespace {

using ::testing::HasSubstr;
using ::testing::Not;

bool HaveThreeJs() {
  return std::filesystem::exists(ViewPageOptions().three_dir / "three.min.js");
}

ViewData TinyData() {
  ViewData data;
  data.title = "run";
  data.alignment = "none";
  data.estimate = {{0.0, SE3d(), -1}, {0.1, SE3d(), -1}};
  return data;
}

// One file: three.js, OrbitControls, the data and every viewer script inline, in that order.
TEST(WriteViewPage, InlinesEveryScriptInOrder) {
  if (!HaveThreeJs()) GTEST_SKIP() << "libjs-three is not installed";
  const auto dir = testing::MakeTempDir("view_page_inline");
  WriteViewPage(TinyData(), dir / "view.html");
  const std::string page = testing::ReadFileBytes(dir / "view.html");
  EXPECT_THAT(page, Not(HasSubstr("<script src=")));
  std::size_t at = 0;
  for (const char* mark : {"const PKSLAM_DATA", "window.PkslamScene =", "window.PkslamLegend =",
                           "window.PkslamStrip =", "window.pkslamView ="}) {
    const std::size_t found = page.find(mark, at);
    ASSERT_NE(found, std::string::npos) << mark;
    at = found;
  }
  EXPECT_THAT(page, HasSubstr("<div id=\"scalebar\">"));
  EXPECT_THAT(page, HasSubstr("<div id=\"striplegend\">"));
}

// Shared scripts (the bench's OUT/viewer/): the page loads them by path, and the folder gets
// every one, also when an older version left a different viewer.js there.
TEST(WriteViewPage, SharedScriptsAreAllInTheFolder) {
  if (!HaveThreeJs()) GTEST_SKIP() << "libjs-three is not installed";
  const auto dir = testing::MakeTempDir("view_page_shared");
  std::filesystem::create_directories(dir / "viewer");
  std::filesystem::create_directories(dir / "runs/a");
  std::ofstream(dir / "viewer/viewer.js") << "// an older viewer\n";
  ViewPageOptions options;
  options.shared_scripts = "../../viewer";
  WriteViewPage(TinyData(), dir / "runs/a/view.html", options);
  const std::string page = testing::ReadFileBytes(dir / "runs/a/view.html");
  for (const char* name : {"three.min.js", "OrbitControls.js", "viewer_scene.js",
                           "viewer_legend.js", "viewer_strip.js", "viewer.js"}) {
    EXPECT_THAT(page, HasSubstr(std::string("<script src=\"../../viewer/") + name + "\">"));
    EXPECT_TRUE(std::filesystem::exists(dir / "viewer" / name)) << name;
  }
  EXPECT_THAT(testing::ReadFileBytes(dir / "viewer/viewer.js"), HasSubstr("window.pkslamView"));
}

}  // namespace
}  // namespace pkslam
