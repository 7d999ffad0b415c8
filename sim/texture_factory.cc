#include "sim/texture_factory.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <vector>

#include "core/util/error.h"
#include "core/util/log.h"
#include "sim/random.h"

namespace pkslam::sim {
namespace {

bool IsPowerOfTwo(int v) { return v > 0 && (v & (v - 1)) == 0; }

// Periodic value noise octave: a cells x cells grid of uniform values, bicubically upsampled
// to size x size with wrap-around so the texture tiles seamlessly.
cv::Mat NoiseOctave(int cells, int size, Rng* rng) {
  cv::Mat grid(cells, cells, CV_32F);
  for (int y = 0; y < cells; ++y) {
    for (int x = 0; x < cells; ++x) grid.at<float>(y, x) = static_cast<float>(rng->Uniform());
  }
  if (cells == size) return grid;
  const int pad = 3;
  cv::Mat padded;
  cv::copyMakeBorder(grid, padded, pad, pad, pad, pad, cv::BORDER_WRAP);
  const int scale = size / cells;
  cv::Mat up;
  cv::resize(padded, up, cv::Size(padded.cols * scale, padded.rows * scale), 0, 0, cv::INTER_CUBIC);
  return up(cv::Rect(pad * scale, pad * scale, size, size)).clone();
}

// Multi-octave noise, zero mean, unit standard deviation.
cv::Mat Fbm(int size, int base_cells, int max_cells, double persistence, Rng* rng) {
  cv::Mat sum = cv::Mat::zeros(size, size, CV_32F);
  double amplitude = 1.0;
  for (int cells = base_cells; cells <= max_cells && cells <= size; cells *= 2) {
    sum += amplitude * NoiseOctave(cells, size, rng);
    amplitude *= persistence;
  }
  cv::Scalar mean;
  cv::Scalar stddev;
  cv::meanStdDev(sum, mean, stddev);
  sum = (sum - mean[0]) / std::max(stddev[0], 1e-6);
  return sum;
}

// Small dark/bright dots, wrapped at the borders (carpet, concrete).
void AddSpeckle(cv::Mat* img, double per_1000, Rng* rng) {
  const int size = img->cols;
  const int count = static_cast<int>(per_1000 * size * size / 1000.0);
  for (int i = 0; i < count; ++i) {
    const double x = rng->Uniform(0, size);
    const double y = rng->Uniform(0, size);
    const double r = rng->Uniform(0.6, 2.5);
    const double value = rng->Uniform() < 0.5 ? rng->Uniform(-3.0, -1.0) : rng->Uniform(1.0, 3.0);
    for (int dy = -1; dy <= 1; ++dy) {
      for (int dx = -1; dx <= 1; ++dx) {
        const cv::Point centre(static_cast<int>((x + dx * size) * 16),
                               static_cast<int>((y + dy * size) * 16));
        cv::circle(*img, centre, static_cast<int>(r * 16), cv::Scalar(value), cv::FILLED,
                   cv::LINE_AA, 4);
      }
    }
  }
}

cv::Mat GreyOf(const cv::Mat& rgb) {
  cv::Mat grey;
  cv::cvtColor(rgb, grey, cv::COLOR_RGB2GRAY);
  return grey;
}

// Rescale to mean 0.5 and the requested standard deviation.
cv::Mat Normalise(const cv::Mat& grey, double contrast) {
  cv::Scalar mean;
  cv::Scalar stddev;
  cv::meanStdDev(grey, mean, stddev);
  return (grey - mean[0]) * (contrast / std::max(stddev[0], 1e-6)) + 0.5;
}

cv::Mat To8U(const cv::Mat& f) {
  cv::Mat out;
  f.convertTo(out, f.channels() == 1 ? CV_8UC1 : CV_8UC3, 255.0);
  return out;
}

// Colour following a new grey: scale the RGB so its luminance becomes `grey`.
cv::Mat Recolour(const cv::Mat& rgb, const cv::Mat& old_grey, const cv::Mat& grey) {
  cv::Mat out(rgb.size(), CV_32FC3);
  for (int y = 0; y < rgb.rows; ++y) {
    for (int x = 0; x < rgb.cols; ++x) {
      const float ratio = grey.at<float>(y, x) / std::max(old_grey.at<float>(y, x), 0.02f);
      out.at<cv::Vec3f>(y, x) = rgb.at<cv::Vec3f>(y, x) * ratio;
    }
  }
  return out;
}

cv::Mat LoadPhoto(const std::filesystem::path& file, int size) {
  cv::Mat bgr = cv::imread(file.string(), cv::IMREAD_COLOR);
  if (bgr.empty()) return {};
  const int side = std::min(bgr.cols, bgr.rows);
  cv::Mat square = bgr(cv::Rect((bgr.cols - side) / 2, (bgr.rows - side) / 2, side, side));
  cv::Mat resized;
  cv::resize(square, resized, cv::Size(size, size), 0, 0,
             side >= size ? cv::INTER_AREA : cv::INTER_CUBIC);
  cv::Mat rgb;
  cv::cvtColor(resized, rgb, cv::COLOR_BGR2RGB);
  rgb.convertTo(rgb, CV_32FC3, 1.0 / 255.0);
  return rgb;
}

MipTexture Finish(const cv::Mat& grey_f, const cv::Mat& rgb_f, bool colour, bool repeat) {
  cv::Mat grey = To8U(grey_f);
  cv::Mat rgb;
  if (colour) rgb = To8U(rgb_f.empty() ? cv::Mat() : rgb_f);
  if (colour && rgb.empty()) cv::cvtColor(grey, rgb, cv::COLOR_GRAY2RGB);
  return MipTexture(grey, rgb, repeat);
}

cv::Mat Tinted(const cv::Mat& grey, const Eigen::Vector3d& tint) {
  cv::Mat rgb;
  cv::merge(std::vector<cv::Mat>{grey * tint.x(), grey * tint.y(), grey * tint.z()}, rgb);
  return rgb;
}

MipTexture BuildChecker(const TextureSpec& spec, bool colour) {
  const int s = spec.checker_square_px;
  const int w = (spec.checker_cols + 2) * s;
  const int h = (spec.checker_rows + 2) * s;
  cv::Mat grey(h, w, CV_32F, cv::Scalar(0.92));
  for (int r = 0; r < spec.checker_rows; ++r) {
    for (int c = 0; c < spec.checker_cols; ++c) {
      if ((r + c) % 2 == 0) grey(cv::Rect((c + 1) * s, (r + 1) * s, s, s)).setTo(0.06);
    }
  }
  return Finish(grey, {}, colour, false);
}

// Padded fabric: each channel bulges (lit centre, shaded flanks) between narrow seams, over a
// faint weave of the finest noise octaves. Channels run along the texture's v axis.
cv::Mat Quilted(const TextureSpec& spec, int max_cells, Rng* rng) {
  const int n = spec.size;
  const cv::Mat weave = Fbm(n, std::max(n / 8, 4), max_cells, 0.9, rng);
  const cv::Mat lumps = Fbm(n, std::max(spec.base_cells, 2), std::max(n / 32, 4), 0.6, rng);
  cv::Mat grey(n, n, CV_32F);
  const double period = static_cast<double>(n) / std::min(spec.stripes, std::max(n / 4, 1));
  const double seam_width = std::max(1.0, 0.04 * period);
  for (int y = 0; y < n; ++y) {
    for (int x = 0; x < n; ++x) {
      const double u = std::fmod(x + 0.5, period) / period;       // 0..1 across a channel
      const double bulge = 0.5 - 0.5 * std::cos(2.0 * M_PI * u);  // 0 at the seams
      const double to_seam = std::min(u, 1.0 - u) * period;
      const double seam = std::exp(-0.5 * (to_seam / seam_width) * (to_seam / seam_width));
      const double shade = 0.85 + 0.15 * bulge - spec.seam_depth * seam;
      grey.at<float>(y, x) = static_cast<float>(
          0.5 * shade + spec.contrast * (weave.at<float>(y, x) + 0.5 * lumps.at<float>(y, x)));
    }
  }
  return grey;
}

// Dark tape with bright flakes: small rotated rectangles of random size, wrapped at the
// borders so the texture tiles.
cv::Mat Confetti(const TextureSpec& spec, Rng* rng) {
  const int n = spec.size;
  cv::Mat grey(n, n, CV_32F, cv::Scalar(0.07));
  const cv::Mat grain = Fbm(n, std::max(n / 16, 4), n / 2, 0.8, rng);
  grey += 0.015 * grain;
  for (int i = 0; i < spec.flakes; ++i) {
    const double cx = rng->Uniform(0, n);
    const double cy = rng->Uniform(0, n);
    const double length = spec.flake_size * n * rng->Uniform(0.5, 1.5);
    const double width = length * rng->Uniform(0.25, 0.6);
    const double angle = rng->Uniform(0.0, 180.0);
    const double level = rng->Uniform(0.75, 0.95);
    for (int dy = -1; dy <= 1; ++dy) {
      for (int dx = -1; dx <= 1; ++dx) {
        const cv::RotatedRect r(
            cv::Point2f(static_cast<float>(cx + dx * n), static_cast<float>(cy + dy * n)),
            cv::Size2f(static_cast<float>(length), static_cast<float>(width)),
            static_cast<float>(angle));
        cv::Point2f corners[4];
        r.points(corners);
        std::vector<cv::Point> poly;
        for (const auto& c : corners)
          poly.emplace_back(cv::Point(static_cast<int>(c.x * 16), static_cast<int>(c.y * 16)));
        cv::fillConvexPoly(grey, poly, cv::Scalar(level), cv::LINE_AA, 4);
      }
    }
  }
  return grey;
}

}  // namespace

void TextureSpec::Check() const {
  PKSLAM_CHECK_OPTION(IsPowerOfTwo(size) && size >= 16 && size <= 8192, "texture.size", "{}", size);
  PKSLAM_CHECK_OPTION(contrast >= 0.0 && contrast <= 0.5, "texture.contrast", "{}", contrast);
  PKSLAM_CHECK_OPTION(detail >= 0.0 && detail <= 1.0, "texture.detail", "{}", detail);
  PKSLAM_CHECK_OPTION(IsPowerOfTwo(base_cells) && base_cells <= size, "texture.base_cells", "{}",
                      base_cells);
  PKSLAM_CHECK_OPTION(max_cells == 0 || IsPowerOfTwo(max_cells), "texture.max_cells", "{}",
                      max_cells);
  PKSLAM_CHECK_OPTION(speckle >= 0.0, "texture.speckle", "{}", speckle);
  PKSLAM_CHECK_OPTION(stripes >= 1 && stripes <= 1024, "texture.stripes", "{}", stripes);
  PKSLAM_CHECK_OPTION(seam_depth >= 0.0 && seam_depth <= 1.0, "texture.seam_depth", "{}",
                      seam_depth);
  PKSLAM_CHECK_OPTION(flakes >= 0 && flakes <= 100000, "texture.flakes", "{}", flakes);
  PKSLAM_CHECK_OPTION(flake_size > 0.0 && flake_size <= 0.25, "texture.flake_size", "{}",
                      flake_size);
  PKSLAM_CHECK_OPTION(checker_cols >= 2 && checker_rows >= 2 && checker_square_px >= 2,
                      "texture.checker", "{}x{} squares of {} px", checker_cols, checker_rows,
                      checker_square_px);
}

std::filesystem::path DefaultPhotoDir() {
  if (const char* env = std::getenv("PKSLAM_TEXTURE_DIR"); env != nullptr && *env != '\0') {
    return env;
  }
  return "/usr/share/doc/opencv-doc/examples/data";
}

MipTexture BuildTexture(const TextureSpec& spec, const std::filesystem::path& photo_dir,
                        bool colour, bool* used_fallback) {
  spec.Check();
  if (used_fallback) *used_fallback = false;
  if (spec.kind == TextureKind::kChecker) return BuildChecker(spec, colour);
  Rng rng(spec.seed);
  const int n = spec.size;
  const int max_cells = spec.max_cells > 0 ? spec.max_cells : n / 2;

  cv::Mat photo;
  if (spec.kind == TextureKind::kPhoto || spec.kind == TextureKind::kRepetitive) {
    const int load_size = spec.kind == TextureKind::kRepetitive ? n / 8 : n;
    photo = LoadPhoto(photo_dir / spec.photo, load_size);
    if (photo.empty()) {
      PKSLAM_LOG_WARN("texture photo {} not found; using procedural noise instead",
                      (photo_dir / spec.photo).string());
      if (used_fallback) *used_fallback = true;
    }
  }

  switch (spec.kind) {
    case TextureKind::kPhoto: {
      if (photo.empty()) break;
      // Tiles meet at visible seams (like wall panels or mats); cross-fading them instead
      // produced ghosted double images.
      const cv::Mat grey0 = GreyOf(photo);
      cv::Mat grey = Normalise(grey0, spec.contrast);
      // Fine procedural grain multiplies the photo so close-ups below the photo's own
      // resolution stay textured; only the finest octaves, so it does not blotch the photo.
      const cv::Mat detail = Fbm(n, std::max(n / 32, 4), max_cells, 0.9, &rng);
      cv::Mat modulated = grey.mul(1.0 + spec.detail * 0.5 * detail);
      if (spec.speckle > 0.0) {
        cv::Mat dots = cv::Mat::zeros(n, n, CV_32F);
        AddSpeckle(&dots, spec.speckle, &rng);
        modulated += 0.08 * dots;
      }
      grey = Normalise(modulated, spec.contrast);
      cv::Mat rgb = colour ? Recolour(photo, grey0, grey) : cv::Mat();
      return Finish(grey, rgb, colour, true);
    }
    case TextureKind::kRepetitive: {
      // One motif (photo crop or noise) on an 8 x 8 grid with grout lines.
      const int cell = n / 8;
      cv::Mat motif = photo.empty() ? Tinted(Fbm(cell, 4, cell / 2, 0.6, &rng), spec.tint) : photo;
      cv::Mat motif_grey = Normalise(GreyOf(motif), spec.contrast);
      const int grout = std::max(1, cell / 32);
      motif_grey.rowRange(0, grout).setTo(0.15);
      motif_grey.colRange(0, grout).setTo(0.15);
      cv::Mat grey;
      cv::repeat(motif_grey, 8, 8, grey);
      cv::Mat rgb;
      if (colour) {
        cv::Mat motif_rgb = Recolour(motif, GreyOf(motif), motif_grey);
        cv::repeat(motif_rgb, 8, 8, rgb);
      }
      return Finish(grey, rgb, colour, true);
    }
    case TextureKind::kWeak: {
      const cv::Mat noise =
          Fbm(n, spec.base_cells, std::min(max_cells, spec.base_cells * 4), 0.5, &rng);
      const cv::Mat grey = 0.5 + spec.contrast * noise;
      return Finish(grey, colour ? Tinted(grey, spec.tint) : cv::Mat(), colour, true);
    }
    case TextureKind::kQuilted: {
      const cv::Mat grey = Quilted(spec, max_cells, &rng);
      return Finish(grey, colour ? Tinted(grey, spec.tint) : cv::Mat(), colour, true);
    }
    case TextureKind::kConfetti: {
      const cv::Mat grey = Confetti(spec, &rng);
      return Finish(grey, colour ? Tinted(grey, spec.tint) : cv::Mat(), colour, true);
    }
    case TextureKind::kNoise:
    case TextureKind::kChecker:
      break;
  }
  // Procedural noise (also the fallback for a missing photo).
  cv::Mat noise = Fbm(n, spec.base_cells, max_cells, 0.7, &rng);
  if (spec.speckle > 0.0) AddSpeckle(&noise, spec.speckle, &rng);
  const cv::Mat grey = Normalise(noise, spec.contrast);
  return Finish(grey, colour ? Tinted(grey, spec.tint) : cv::Mat(), colour, true);
}

}  // namespace pkslam::sim
