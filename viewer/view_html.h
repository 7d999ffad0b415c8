// The viewer page of `pkslam view`: one self-contained HTML file (no network at view time) with
// Debian's three.js (libjs-three) and its OrbitControls inlined, the run's data as JSON, and
// viewer/viewer_scene.js, viewer_legend.js, viewer_strip.js and viewer.js, which draw it
// (trajectories coloured by ATE, further runs and trajectories in their own colours, keyframe
// frustums coloured by the rule that created them, map points, dense cloud, axes, grid, scale
// bar, legends and layer toggles, a timeline scrubber under a strip with time axis and legend).
#pragma once

#include <filesystem>

#include "viewer/view_data.h"

namespace pkslam {

struct ViewPageOptions {
  // Where libjs-three installs three.min.js and examples/js/controls/OrbitControls.js.
  std::filesystem::path three_dir = "/usr/share/javascript/three";
  // Empty: inline the scripts (one self-contained file). Otherwise the page loads them from
  // this folder (relative to the page), where WriteViewPage puts any that are missing or
  // differ; many pages (a bench's runs) then share one copy.
  std::filesystem::path shared_scripts;
  void Check() const;
};

// Copies three.min.js, OrbitControls.js and the viewer*.js scripts into dir (for
// shared_scripts), each unless an identical copy is there.
void CopyViewScripts(const std::filesystem::path& dir, const ViewPageOptions& options = {});

// Writes the page atomically. Throws Error when three.js or a viewer script cannot be found
// (with the package to install), OutputError when the file cannot be written.
void WriteViewPage(const ViewData& data, const std::filesystem::path& file,
                   const ViewPageOptions& options = {});

// The live page of `pkslam run --live-view`: three.js, OrbitControls, viewer_scene.js and
// viewer_live.js inlined; it polls data.json and frame.jpg from the server that sent it.
// Throws Error when a script cannot be found.
std::string LiveViewPage(const ViewPageOptions& options = {});

}  // namespace pkslam
