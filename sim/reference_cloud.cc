#include "sim/reference_cloud.h"

#include <fmt/format.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <numbers>
#include <vector>

#include "core/util/error.h"

namespace pkslam::sim {
namespace {

#pragma pack(push, 1)
struct PlyVertex {
  float x, y, z, nx, ny, nz;
  std::uint8_t intensity;
};
#pragma pack(pop)
static_assert(sizeof(PlyVertex) == 25);

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
  std::vector<PlyVertex> points;
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
          points.push_back({p.x(), p.y(), p.z(), n.x(), n.y(), n.z(),
                            static_cast<std::uint8_t>(std::lround(255.0f * a))});
        }
      }
    }
  }
  std::ofstream out(file, std::ios::binary | std::ios::trunc);
  if (!out) throw Error(fmt::format("cannot write {}", file.string()));
  out << "ply\nformat binary_little_endian 1.0\n"
      << fmt::format("comment pkslam simulate {}\n", description)
      << fmt::format("comment spacing_m {}\n", spacing_m);
  if (visibility != nullptr && visibility->max_depth_m() > 0) {
    out << fmt::format("comment visibility_cell_m {}\ncomment max_depth_m {}\n",
                       visibility->cell_m(), visibility->max_depth_m());
  }
  out << fmt::format("element vertex {}\n", points.size())
      << "property float x\nproperty float y\nproperty float z\n"
         "property float nx\nproperty float ny\nproperty float nz\n"
         "property uchar intensity\nend_header\n";
  out.write(reinterpret_cast<const char*>(points.data()),
            static_cast<std::streamsize>(points.size() * sizeof(PlyVertex)));
  if (!out) throw Error(fmt::format("cannot write {}", file.string()));
  return points.size();
}

}  // namespace pkslam::sim
