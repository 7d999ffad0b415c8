// Builds the simulator's textures: natural photographs (OpenCV's sample images) tiled and
// modulated by fine multi-octave procedural grain so surfaces have detail from
// millimetres to metres; procedural-only, weak (low-contrast), repetitive and checkerboard
// variants. Deterministic in the spec's seed.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <filesystem>
#include <string>

#include "sim/texture.h"

namespace pkslam::sim {

enum class TextureKind {
  kPhoto,       // photograph + procedural detail
  kNoise,       // multi-octave value noise (+ optional speckle)
  kWeak,        // low-contrast, low-frequency noise only (hard case for feature trackers)
  kRepetitive,  // one motif repeated on a regular grid (hard case: ambiguous matches)
  kChecker,     // black/white checkerboard with a one-square white border, not tiled
  kQuilted,     // foam mat / padded fabric: faint weave, padded channels between soft seams
  kConfetti     // dark tape strewn with small bright flakes (EuRoC's floor markers)
};

struct TextureSpec {
  TextureKind kind = TextureKind::kNoise;
  std::string photo;       // file name in the photo directory (kPhoto, kRepetitive)
  int size = 1024;         // base resolution (power of two) of tiled kinds
  double contrast = 0.18;  // standard deviation of the grey texture (mean 0.5)
  double detail = 0.25;    // strength of fine procedural grain modulating a photo (0..1)
  int base_cells = 4;      // coarsest noise octave: cells per texture
  int max_cells = 0;       // finest noise octave (0: size/2, i.e. texel scale)
  double speckle = 0.0;    // speckle dots per 1000 texels (0: none)
  Eigen::Vector3d tint = Eigen::Vector3d::Ones();  // RGB colour of procedural textures
  int checker_cols = 9;        // kChecker: squares across (inner corners: cols-1)
  int checker_rows = 7;        // kChecker: squares down (inner corners: rows-1)
  int checker_square_px = 64;  // kChecker: texels per square (a power of two keeps mips exact)
  int stripes = 8;             // kQuilted: padded channels across the texture
  double seam_depth = 0.25;    // kQuilted: darkening at a seam (0..1)
  int flakes = 300;            // kConfetti: flakes per texture
  double flake_size = 0.02;    // kConfetti: flake length as a fraction of the texture side
  std::uint64_t seed = 1;

  void Check() const;
};

// Where the photographs live (Debian package opencv-doc); $PKSLAM_TEXTURE_DIR overrides.
std::filesystem::path DefaultPhotoDir();

// Builds the texture; `colour` also builds the RGB pyramid. A missing photograph falls back
// to procedural noise with a warning (set *used_fallback when given).
MipTexture BuildTexture(const TextureSpec& spec, const std::filesystem::path& photo_dir,
                        bool colour, bool* used_fallback = nullptr);

}  // namespace pkslam::sim
