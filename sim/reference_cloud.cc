#include "sim/reference_cloud.h"

#include <fmt/format.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <numbers>
#include <vector>

#include "core/util/error.h"
#include "io/point_cloud.h"

namespace pkslam::sim {
namespace {

// Albedo (grey, 0..1) of a face point, from the finest texture level.
float Albedo(const Scene& scene, const Shape& shape, int face, const Eigen::Vector2f& uv) {
  const Material& m = scene.materials[shape.material[face]];
  const MipTexture& tex = scene.textures[m.texture];
  const Eigen::Vector2f st = TextureCoords(shape, m, uv);
  return std::min(1.0f, m.albedo * tex.SampleGrey(st.x(), st.y(), 0.0f));
}

}  // namespace

std::size_t WriteReferenceCloud(const Scene& scene, const SurfaceVisibility* visibility,
                                double spacing_m, const std::filesystem::path& file,
                                const std::string& description) {
  PKSLAM_CHECK(spacing_m > 0.0, "cloud spacing must be > 0");
  const float step = static_cast<float>(spacing_m);
  PointCloud points;
  for (int si = 0; si < static_cast<int>(scene.shapes.size()); ++si) {
    const Shape& shape = scene.shapes[si];
    for (int f = 0; f < shape.num_faces(); ++f) {
      const Scene::FaceFrame frame = Scene::Face(shape, f);
      const int nu = std::max(1, static_cast<int>(std::floor(frame.size.x() / step)));
      const int nv = std::max(1, static_cast<int>(std::floor(frame.size.y() / step)));
      for (int iv = 0; iv < nv; ++iv) {
        for (int iu = 0; iu < nu; ++iu) {
          const Eigen::Vector2f uv((iu + 0.5f) * frame.size.x() / nu,
                                   (iv + 0.5f) * frame.size.y() / nv);
          if (visibility != nullptr && !visibility->Seen(si, f, uv)) continue;
          Eigen::Vector3f p;
          Eigen::Vector3f n;
          if (!Scene::SurfacePoint(shape, f, uv, &p, &n)) continue;
          const float a = Albedo(scene, shape, f, uv);
          const auto grey = static_cast<std::uint8_t>(std::lround(255.0f * a));
          points.points.push_back(p);
          points.normals.push_back(n);
          points.colours.push_back({grey, grey, grey});
        }
      }
    }
  }
  std::vector<std::string> comments = {fmt::format("pkslam simulate {}", description),
                                       fmt::format("spacing_m {}", spacing_m)};
  if (visibility != nullptr && visibility->max_depth_m() > 0) {
    comments.push_back(fmt::format("visibility_cell_m {}", visibility->cell_m()));
    comments.push_back(fmt::format("max_depth_m {}", visibility->max_depth_m()));
  }
  // x y z, nx ny nz, intensity (io/point_cloud.h).
  WritePly(points, file, PlyColour::kGrey, comments);
  return points.size();
}

}  // namespace pkslam::sim
