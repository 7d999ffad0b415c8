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

std::vector<BoundSphere> SegmentSpheres(const Shape& shape) {
  if (shape.type == ShapeType::kRoom) return {};
  const Eigen::Vector3f& h = shape.half;
  if (shape.type == ShapeType::kCylinder) {
    // Along its axis (local z), in pieces about as long as the radius.
    const float r = h.x();
    const int n = std::clamp(static_cast<int>(std::ceil(h.z() / std::max(r, 1e-3f))), 1, 8);
    if (n == 1) return {{Eigen::Vector3f::Zero(), shape.bound_radius()}};
    std::vector<BoundSphere> spheres;
    const float piece = h.z() / static_cast<float>(n);  // half length of a piece
    for (int k = 0; k < n; ++k) {
      spheres.push_back(
          {Eigen::Vector3f(0.0f, 0.0f, -h.z() + (2.0f * k + 1.0f) * piece), std::hypot(r, piece)});
    }
    return spheres;
  }
  // Box or quad: a grid of at most 4 x 4 cells over its two largest axes, cells about as
  // wide as the box is thick (or a quarter of its length, for thin slabs and quads).
  int order[3] = {0, 1, 2};
  std::sort(order, order + 3, [&](int i, int j) { return h[i] > h[j]; });
  const float cell = std::max(h[order[2]], 0.25f * h[order[0]]);
  int n[3] = {1, 1, 1};
  for (int i = 0; i < 2; ++i) {
    n[order[i]] =
        std::clamp(static_cast<int>(std::ceil(h[order[i]] / std::max(cell, 1e-3f))), 1, 4);
  }
  if (n[0] * n[1] * n[2] == 1) return {{Eigen::Vector3f::Zero(), shape.bound_radius()}};
  const Eigen::Vector3f piece(h.x() / n[0], h.y() / n[1], h.z() / n[2]);  // half cell
  std::vector<BoundSphere> spheres;
  for (int i = 0; i < n[0]; ++i) {
    for (int j = 0; j < n[1]; ++j) {
      for (int k = 0; k < n[2]; ++k) {
        const Eigen::Vector3f centre =
            -h +
            Eigen::Vector3f(2.0f * i + 1.0f, 2.0f * j + 1.0f, 2.0f * k + 1.0f).cwiseProduct(piece);
        spheres.push_back({centre, piece.norm()});
      }
    }
  }
  return spheres;
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
    // A shape one sphere fits is culled by its bounding sphere alone (the same sphere).
    std::vector<BoundSphere> parts = SegmentSpheres(s);
    if (parts.size() == 1) parts.clear();
    bounds_.push_back(std::move(parts));
  }
}

namespace {

// A bounding sphere as seen from the camera: direction and angular radius, for the tile test.
struct ViewSphere {
  Eigen::Vector3f dir_camera = Eigen::Vector3f::UnitZ();  // unit
  float cos_rho = 0.0f;
  float sin_rho = 0.0f;
  bool contains_camera = false;
  // No point of the sphere is nearer the camera than this (its near side; 0 when the camera is
  // inside it). Rays are unit vectors, so hit distances compare with it.
  float near = 0.0f;
};

ViewSphere SeeSphere(const Eigen::Vector3f& centre_camera, float radius) {
  ViewSphere v;
  const float dist = centre_camera.norm();
  if (dist <= radius * 1.001f) {
    v.contains_camera = true;
    return v;
  }
  v.near = std::max(dist - radius * 1.001f, 0.0f);
  v.dir_camera = centre_camera / dist;
  v.sin_rho = radius / dist;
  v.cos_rho = std::sqrt(1.0f - v.sin_rho * v.sin_rho);
  return v;
}

// Whether some ray of the tile can meet the sphere: cone (axis a, half-angle alpha) meets
// sphere (direction c, angular radius rho) iff angle(a, c) < alpha + rho.
bool TileSees(const CameraRays::Tile& tile, const ViewSphere& s) {
  if (s.contains_camera) return true;
  const float cos_sum = tile.cos_half * s.cos_rho - tile.sin_half * s.sin_rho;
  const bool wide =
      tile.sin_half * s.cos_rho + tile.cos_half * s.sin_rho < 0.0f || cos_sum < -0.999f;
  return wide || tile.axis.dot(s.dir_camera) >= cos_sum;
}

// Per-frame data of one shape: the camera ray -> shape-local transform, its bounding sphere
// and its part spheres (SegmentSpheres; none when one sphere fits it) as seen from the camera.
struct FrameShape {
  int index = 0;
  Eigen::Matrix3f local_from_camera;
  Eigen::Vector3f origin_local;
  ViewSphere bound;
  int first_part = 0;  // into the frame's part list
  int num_parts = 0;
};

// A shape some ray of a tile may hit, and the nearest such a hit can be (the nearest part
// sphere the tile sees, no nearer than the whole shape's bound).
struct TileCandidate {
  const FrameShape* shape = nullptr;
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

  // The part spheres were taken from the scene when the Renderer was made.
  PKSLAM_CHECK(bounds_.size() == scene_.shapes.size(),
               "the scene changed after its Renderer was made ({} shapes, {} then)",
               scene_.shapes.size(), bounds_.size());
  const Shape* room = nullptr;
  FrameShape room_frame;
  std::vector<FrameShape> shapes;
  std::vector<ViewSphere> parts;
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
    f.bound = SeeSphere(r_wc.transpose() * (s.center - o_w), s.bound_radius());
    f.first_part = static_cast<int>(parts.size());
    for (const BoundSphere& b : bounds_[i]) {
      const Eigen::Vector3f centre_world = s.center + s.world_from_local * b.centre_local;
      parts.push_back(SeeSphere(r_wc.transpose() * (centre_world - o_w), b.radius));
    }
    f.num_parts = static_cast<int>(parts.size()) - f.first_part;
    shapes.push_back(f);
  }
  // Nearest first, so a ray stops testing once its hit is nearer than the next shape can be
  // (dense scenes: most rays hit something close). Ties in `near` keep the scene order, and a
  // shape is only skipped when it cannot be hit before the current hit, so the image is the
  // same as testing every shape.
  std::stable_sort(shapes.begin(), shapes.end(), [](const FrameShape& a, const FrameShape& b) {
    return a.bound.near < b.bound.near;
  });

  const auto& tiles = rays.tiles();
  const int samples = rays.supersample() * rays.supersample();
  const float inv_samples = 1.0f / static_cast<float>(samples);
  tbb::parallel_for(
      tbb::blocked_range<int>(0, static_cast<int>(tiles.size())),
      [&](const tbb::blocked_range<int>& range) {
        std::vector<TileCandidate> candidates;
        candidates.reserve(shapes.size() + 1);
        for (int ti = range.begin(); ti != range.end(); ++ti) {
          const CameraRays::Tile& tile = tiles[ti];
          candidates.clear();
          if (room) candidates.push_back({&room_frame, 0.0f});
          // The order stays the frame's (by the whole shape's bound): culling by the parts
          // only drops shapes no ray of the tile can hit and raises the bound a ray skips by,
          // so the image is the same as without the parts.
          for (const FrameShape& f : shapes) {
            if (!TileSees(tile, f.bound)) continue;
            if (f.num_parts == 0) {
              candidates.push_back({&f, f.bound.near});
              continue;
            }
            float near = std::numeric_limits<float>::infinity();
            for (int p = f.first_part; p < f.first_part + f.num_parts; ++p) {
              if (TileSees(tile, parts[p])) near = std::min(near, parts[p].near);
            }
            if (near == std::numeric_limits<float>::infinity()) continue;
            candidates.push_back({&f, std::max(near, f.bound.near)});
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
                for (const TileCandidate& c : candidates) {
                  const FrameShape* f = c.shape;
                  if (f->bound.near >= t) break;  // sorted: no later shape can be hit sooner
                  if (c.near >= t) continue;
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
