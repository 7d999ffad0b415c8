// The viewer page of `pkslam view`: one self-contained HTML file (no network at view time) with
// Debian's three.js (libjs-three) and its OrbitControls inlined, the run's data as JSON, and
// viewer/viewer.js, which draws it (trajectories coloured by ATE, keyframe frustums coloured
// by the rule that created them, map points, dense cloud, layer toggles, a timeline scrubber).
#pragma once

#include <filesystem>

#include "viewer/view_data.h"

namespace pkslam {

struct ViewPageOptions {
  // Where libjs-three installs three.min.js and examples/js/controls/OrbitControls.js.
  std::filesystem::path three_dir = "/usr/share/javascript/three";
  // Empty: inline the scripts (one self-contained file). Otherwise the page loads them from
  // this folder (relative to the page) and CopyViewScripts must have put them there; many
  // pages (a bench's runs) then share one copy.
  std::filesystem::path shared_scripts;
  void Check() const;
};

// Copies three.min.js, OrbitControls.js and viewer.js into dir (for shared_scripts).
void CopyViewScripts(const std::filesystem::path& dir, const ViewPageOptions& options = {});

// Writes the page atomically. Throws Error when three.js or viewer.js cannot be found (with
// the package to install), OutputError when the file cannot be written.
void WriteViewPage(const ViewData& data, const std::filesystem::path& file,
                   const ViewPageOptions& options = {});

}  // namespace pkslam
