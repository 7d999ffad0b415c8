#include "sim/renderer.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "core/util/error.h"
#include "sim/intersect.h"

namespace pkslam::sim {

CameraRays::CameraRays(const CameraModel& camera, int supersample)
    : width_(camera.width()), height_(camera.height()), supersample_(supersample) {
  PKSLAM_CHECK(width_ > 0 && height_ > 0, "camera has no size");
  PKSLAM_CHECK(supersample >= 1 && supersample <= 4, "supersample {} not in [1, 4]", supersample);
  samples_ = supersample * supersample;
  rays_.resize(static_cast<std::size_t>(width_) * height_ * samples_);
  // Pixel centres are integer coordinates (camera_model.h); sub-samples on a regular grid.
  for (int y = 0; y < height_; ++y) {
    for (int x = 0; x < width_; ++x) {
      for (int k = 0; k < samples_; ++k) {
        const int sx = k % supersample;
        const int sy = k / supersample;
        const double ox = (sx + 0.5) / supersample - 0.5;
        const double oy = (sy + 0.5) / supersample - 0.5;
        const Eigen::Vector3d r = camera.Unproject(Eigen::Vector2d(x + ox, y + oy));
        rays_[(static_cast<std::size_t>(y) * width_ + x) * samples_ + k] =
            r.normalized().cast<float>();
      }
    }
  }
  // Pixel angular size from the centre rays of neighbours (one-sided at the border). With one
  // sample per pixel the centre rays are the rays already computed.
  std::vector<Eigen::Vector3f> centres;
  if (samples_ > 1) {
    centres.resize(static_cast<std::size_t>(width_) * height_);
    for (int y = 0; y < height_; ++y) {
      for (int x = 0; x < width_; ++x) {
        centres[static_cast<std::size_t>(y) * width_ + x] =
            camera.Unproject(Eigen::Vector2d(x, y)).normalized().cast<float>();
      }
    }
  }
  auto centre = [&](int x, int y) -> const Eigen::Vector3f& {
    return samples_ > 1 ? centres[static_cast<std::size_t>(y) * width_ + x] : Ray(x, y, 0);
  };
  pixel_angle_.resize(static_cast<std::size_t>(width_) * height_);
  for (int y = 0; y < height_; ++y) {
    for (int x = 0; x < width_; ++x) {
      const Eigen::Vector3f& c = centre(x, y);
      const Eigen::Vector3f& rx = centre(x + 1 < width_ ? x + 1 : x - 1, y);
      const Eigen::Vector3f& ry = centre(x, y + 1 < height_ ? y + 1 : y - 1);
      pixel_angle_[y * width_ + x] = std::sqrt((rx - c).norm() * (ry - c).norm());
    }
  }
  for (int y0 = 0; y0 < height_; y0 += kTileSize) {
    for (int x0 = 0; x0 < width_; x0 += kTileSize) {
      Tile tile{x0,
                y0,
                std::min(x0 + kTileSize, width_),
                std::min(y0 + kTileSize, height_),
                Eigen::Vector3f::Zero(),
                1.0f,
                0.0f};
      for (int y = tile.y0; y < tile.y1; ++y) {
        for (int x = tile.x0; x < tile.x1; ++x) {
          for (int k = 0; k < samples_; ++k) tile.axis += Ray(x, y, k);
        }
      }
      tile.axis.normalize();
      float min_cos = 1.0f;
      for (int y = tile.y0; y < tile.y1; ++y) {
        for (int x = tile.x0; x < tile.x1; ++x) {
          for (int k = 0; k < samples_; ++k)
            min_cos = std::min(min_cos, tile.axis.dot(Ray(x, y, k)));
        }
      }
      // Small margin against float rounding in the cone test.
      const float half = std::acos(std::clamp(min_cos, -1.0f, 1.0f)) + 1e-3f;
      tile.cos_half = std::cos(half);
      tile.sin_half = std::sin(half);
      tiles_.push_back(tile);
    }
  }
}

SurfaceVisibility::SurfaceVisibility(const Scene& scene, float cell_m, float max_depth_m)
    : cell_m_(cell_m), max_depth_m_(max_depth_m) {
  PKSLAM_CHECK(cell_m > 0.0f, "visibility cell must be > 0");
  PKSLAM_CHECK(max_depth_m >= 0.0f, "visibility max depth {} < 0", max_depth_m);
  std::size_t words = 0;
  faces_.resize(scene.shapes.size());
  for (std::size_t s = 0; s < scene.shapes.size(); ++s) {
    const Shape& shape = scene.shapes[s];
    for (int f = 0; f < shape.num_faces(); ++f) {
      const Scene::FaceFrame frame = Scene::Face(shape, f);
      FaceGrid g;
      g.cols = std::max(1, static_cast<int>(std::ceil(frame.size.x() / cell_m)));
      g.rows = std::max(1, static_cast<int>(std::ceil(frame.size.y() / cell_m)));
      g.first_word = words;
      words += (static_cast<std::size_t>(g.cols) * g.rows + 63) / 64;
      faces_[s].push_back(g);
    }
  }
  bits_ = std::vector<std::atomic<std::uint64_t>>(words);
}

bool SurfaceVisibility::Index(int shape, int face, const Eigen::Vector2f& uv, std::size_t* word,
                              std::uint64_t* bit) const {
  const FaceGrid& g = faces_[shape][face];
  const int c = static_cast<int>(uv.x() / cell_m_);
  const int r = static_cast<int>(uv.y() / cell_m_);
  if (c < 0 || r < 0 || c >= g.cols || r >= g.rows) return false;
  const std::size_t cell = static_cast<std::size_t>(r) * g.cols + c;
  *word = g.first_word + cell / 64;
  *bit = std::uint64_t{1} << (cell % 64);
  return true;
}

void SurfaceVisibility::Mark(int shape, int face, const Eigen::Vector2f& uv, float depth_m) {
  if (max_depth_m_ > 0.0f && depth_m > max_depth_m_) return;
  std::size_t word = 0;
  std::uint64_t bit = 0;
  if (!Index(shape, face, uv, &word, &bit)) return;
  // Read first: most cells are already marked and a plain load avoids cache-line contention.
  if ((bits_[word].load(std::memory_order_relaxed) & bit) == 0) {
    bits_[word].fetch_or(bit, std::memory_order_relaxed);
  }
}

bool SurfaceVisibility::Seen(int shape, int face, const Eigen::Vector2f& uv) const {
  std::size_t word = 0;
  std::uint64_t bit = 0;
  if (!Index(shape, face, uv, &word, &bit)) return false;
  return (bits_[word].load(std::memory_order_relaxed) & bit) != 0;
}

void RenderOptions::Check() const {
  PKSLAM_CHECK_OPTION(lod_bias >= -10.0f && lod_bias <= 4.0f, "render.lod_bias", "{}", lod_bias);
  PKSLAM_CHECK_OPTION(max_distance > 0.0f, "render.max_distance", "{}", max_distance);
}

Renderer::Renderer(const Scene& scene, const RenderOptions& options)
    : scene_(scene), options_(options) {
  options_.Check();
  for (const Material& m : scene_.materials) {
    PKSLAM_CHECK(m.texture >= 0 && m.texture < static_cast<int>(scene_.textures.size()),
                 "material texture index {} out of range", m.texture);
    PKSLAM_CHECK(m.macro_texture < static_cast<int>(scene_.textures.size()),
                 "macro texture index {} out of range", m.macro_texture);
  }
  for (const Shape& s : scene_.shapes) {
    for (int f = 0; f < s.num_faces(); ++f) {
      PKSLAM_CHECK(s.material[f] >= 0 && s.material[f] < static_cast<int>(scene_.materials.size()),
                   "shape {} face {} material {} out of range", s.name, f, s.material[f]);
    }
  }
}

namespace {

// Per-frame data of one shape: the camera ray -> shape-local transform and the bounding
// sphere as seen from the camera (direction + angular radius) for tile culling.
struct FrameShape {
  int index = 0;
  Eigen::Matrix3f local_from_camera;
  Eigen::Vector3f origin_local;
  Eigen::Vector3f sphere_dir_camera;  // unit
  float cos_rho = 0.0f;
  float sin_rho = 0.0f;
  bool contains_camera = false;
  // No point of the shape is nearer the camera than this (the bounding sphere's near side; 0
  // when the camera is inside it). Rays are unit vectors, so hit distances compare with it.
  float near = 0.0f;
};

}  // namespace

void Renderer::Render(const CameraRays& rays, const SE3d& world_from_camera, RenderBuffers* out,
                      std::span<SurfaceVisibility* const> visibility) const {
  const int w = rays.width();
  const int h = rays.height();
  const int channels = options_.colour ? 3 : 1;
  out->radiance.create(h, w, options_.colour ? CV_32FC3 : CV_32FC1);
  if (options_.depth) {
    out->depth.create(h, w, CV_32F);
  } else {
    out->depth.release();
  }
  const Eigen::Matrix3f r_wc = world_from_camera.RotationMatrix().cast<float>();
  const Eigen::Vector3f o_w = world_from_camera.translation().cast<float>();

  const Shape* room = nullptr;
  FrameShape room_frame;
  std::vector<FrameShape> shapes;
  for (int i = 0; i < static_cast<int>(scene_.shapes.size()); ++i) {
    const Shape& s = scene_.shapes[i];
    FrameShape f;
    f.index = i;
    const Eigen::Matrix3f rt = s.world_from_local.transpose();
    f.local_from_camera = rt * r_wc;
    f.origin_local = rt * (o_w - s.center);
    if (s.type == ShapeType::kRoom) {
      room = &s;
      room_frame = f;
      continue;
    }
    const Eigen::Vector3f to_centre = r_wc.transpose() * (s.center - o_w);
    const float dist = to_centre.norm();
    const float radius = s.bound_radius();
    if (dist <= radius * 1.001f) {
      f.contains_camera = true;
    } else {
      f.near = std::max(dist - radius * 1.001f, 0.0f);
      f.sphere_dir_camera = to_centre / dist;
      f.sin_rho = radius / dist;
      f.cos_rho = std::sqrt(1.0f - f.sin_rho * f.sin_rho);
    }
    shapes.push_back(f);
  }
  // Nearest first, so a ray stops testing once its hit is nearer than the next shape can be
  // (dense scenes: most rays hit something close). Ties in `near` keep the scene order, and a
  // shape is only skipped when it cannot be hit before the current hit, so the image is the
  // same as testing every shape.
  std::stable_sort(shapes.begin(), shapes.end(),
                   [](const FrameShape& a, const FrameShape& b) { return a.near < b.near; });

  const auto& tiles = rays.tiles();
  const int samples = rays.supersample() * rays.supersample();
  const float inv_samples = 1.0f / static_cast<float>(samples);
  tbb::parallel_for(
      tbb::blocked_range<int>(0, static_cast<int>(tiles.size())),
      [&](const tbb::blocked_range<int>& range) {
        std::vector<const FrameShape*> candidates;
        candidates.reserve(shapes.size() + 1);
        for (int ti = range.begin(); ti != range.end(); ++ti) {
          const CameraRays::Tile& tile = tiles[ti];
          candidates.clear();
          if (room) candidates.push_back(&room_frame);
          for (const FrameShape& f : shapes) {
            if (f.contains_camera) {
              candidates.push_back(&f);
              continue;
            }
            // Cone (axis a, half-angle alpha) meets sphere (direction c, angular radius rho)
            // iff angle(a, c) < alpha + rho.
            const float cos_sum = tile.cos_half * f.cos_rho - tile.sin_half * f.sin_rho;
            const bool wide =
                tile.sin_half * f.cos_rho + tile.cos_half * f.sin_rho < 0.0f || cos_sum < -0.999f;
            if (wide || tile.axis.dot(f.sphere_dir_camera) >= cos_sum) candidates.push_back(&f);
          }
          for (int y = tile.y0; y < tile.y1; ++y) {
            float* rad = out->radiance.ptr<float>(y);
            float* dep = options_.depth ? out->depth.ptr<float>(y) : nullptr;
            for (int x = tile.x0; x < tile.x1; ++x) {
              float acc[3] = {0.0f, 0.0f, 0.0f};
              float depth_acc = 0.0f;
              const float pixel_angle = rays.PixelAngle(x, y);
              for (int k = 0; k < samples; ++k) {
                const Eigen::Vector3f& rc = rays.Ray(x, y, k);
                float t = options_.max_distance;
                const FrameShape* best = nullptr;
                int face = 0;
                Eigen::Vector2f uv;
                Eigen::Vector3f n_local;
                Eigen::Vector3f d_best;
                for (const FrameShape* f : candidates) {
                  if (f->near >= t) break;  // sorted: no later shape can be hit sooner
                  const Eigen::Vector3f d = f->local_from_camera * rc;
                  if (HitLocal(scene_.shapes[f->index], f->origin_local, d, 1e-4f, &t, &face)) {
                    best = f;
                    d_best = d;
                  }
                }
                if (best == nullptr) continue;
                const Shape& shape = scene_.shapes[best->index];
                SurfaceAtLocal(shape, best->origin_local, d_best, t, face, &uv, &n_local);
                const Material& mat = scene_.materials[shape.material[face]];
                const MipTexture& tex = scene_.textures[mat.texture];
                const float cos_inc = std::max(std::abs(n_local.dot(d_best)), 0.05f);
                const float footprint = t * pixel_angle / std::sqrt(cos_inc);
                const Eigen::Vector2f st = TextureCoords(shape, mat, uv);
                const float texels = footprint * static_cast<float>(tex.width()) /
                                     (mat.stretch ? 2.0f * shape.half.x() : mat.tile_m);
                const float lod = FastLog2(std::max(texels, 1e-6f)) + options_.lod_bias;
                float albedo_scale = mat.albedo;
                if (mat.macro_texture >= 0) {
                  const MipTexture& macro = scene_.textures[mat.macro_texture];
                  const float inv_macro = 1.0f / mat.macro_tile_m;
                  // The macro texture is smooth (no fine octaves): level 0 does not alias.
                  const float m =
                      macro.SampleGrey((uv.x() + shape.uv_offset.y()) * inv_macro,
                                       -(uv.y() + shape.uv_offset.x()) * inv_macro, 0.0f);
                  albedo_scale *= 1.0f + mat.macro_strength * 2.0f * (m - 0.5f);
                }
                // Lighting at the hit point (world frame).
                const Eigen::Vector3f p = o_w + t * (r_wc * rc);
                const Eigen::Vector3f n_w = shape.world_from_local * n_local;
                float light = scene_.ambient;
                for (const Light& l : scene_.lights) {
                  const Eigen::Vector3f to_light = l.position - p;
                  const float d2 = to_light.squaredNorm();
                  const float cos_l = n_w.dot(to_light);
                  if (cos_l <= 0.0f) continue;
                  light +=
                      l.intensity * (cos_l / std::sqrt(d2)) / (1.0f + d2 / (l.range_m * l.range_m));
                }
                const float shade = albedo_scale * light + mat.emission;
                if (channels == 1) {
                  acc[0] += shade * tex.SampleGrey(st.x(), st.y(), lod);
                } else {
                  const Eigen::Vector3f c = tex.SampleColour(st.x(), st.y(), lod);
                  for (int ch = 0; ch < 3; ++ch) acc[ch] += shade * c[ch];
                }
                const float hit_depth = t * rc.z();
                depth_acc += hit_depth;
                for (SurfaceVisibility* v : visibility) {
                  if (v != nullptr) v->Mark(best->index, face, uv, hit_depth);
                }
              }
              for (int ch = 0; ch < channels; ++ch) rad[x * channels + ch] = acc[ch] * inv_samples;
              if (dep) dep[x] = depth_acc * inv_samples;
            }
          }
        }
      });
}

}  // namespace pkslam::sim
