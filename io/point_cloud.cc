#include "io/point_cloud.h"

#include <fmt/format.h>

#include <algorithm>
#include <bit>
#include <cstring>
#include <fstream>
#include <optional>
#include <sstream>

#include "core/util/error.h"
#include "core/util/output_file.h"

namespace pkslam {
namespace {

static_assert(std::endian::native == std::endian::little,
              "binary PLY I/O assumes a little-endian machine");

enum class PlyType { kInt8, kUint8, kInt16, kUint16, kInt32, kUint32, kFloat32, kFloat64 };

std::optional<PlyType> ParsePlyType(const std::string& name) {
  if (name == "char" || name == "int8") return PlyType::kInt8;
  if (name == "uchar" || name == "uint8") return PlyType::kUint8;
  if (name == "short" || name == "int16") return PlyType::kInt16;
  if (name == "ushort" || name == "uint16") return PlyType::kUint16;
  if (name == "int" || name == "int32") return PlyType::kInt32;
  if (name == "uint" || name == "uint32") return PlyType::kUint32;
  if (name == "float" || name == "float32") return PlyType::kFloat32;
  if (name == "double" || name == "float64") return PlyType::kFloat64;
  return std::nullopt;
}

std::size_t TypeSize(PlyType type) {
  switch (type) {
    case PlyType::kInt8:
    case PlyType::kUint8:
      return 1;
    case PlyType::kInt16:
    case PlyType::kUint16:
      return 2;
    case PlyType::kInt32:
    case PlyType::kUint32:
    case PlyType::kFloat32:
      return 4;
    case PlyType::kFloat64:
      return 8;
  }
  return 0;
}

double ReadBinaryValue(const char* p, PlyType type) {
  auto get = [p]<typename T>(T) {
    T v;
    std::memcpy(&v, p, sizeof(T));
    return static_cast<double>(v);
  };
  switch (type) {
    case PlyType::kInt8:
      return get(std::int8_t{});
    case PlyType::kUint8:
      return get(std::uint8_t{});
    case PlyType::kInt16:
      return get(std::int16_t{});
    case PlyType::kUint16:
      return get(std::uint16_t{});
    case PlyType::kInt32:
      return get(std::int32_t{});
    case PlyType::kUint32:
      return get(std::uint32_t{});
    case PlyType::kFloat32:
      return get(float{});
    case PlyType::kFloat64:
      return get(double{});
  }
  return 0;
}

struct Property {
  std::string name;
  PlyType type;
  std::size_t offset;  // within a binary vertex record
};

struct Header {
  bool binary = false;
  std::size_t vertices = 0;
  std::vector<Property> properties;
  std::size_t stride = 0;
  std::size_t lines = 0;  // header lines, for ASCII vertex line numbers
};

Header ReadHeader(std::istream& in, const std::filesystem::path& file) {
  Header h;
  std::string line;
  std::size_t n = 0;
  bool have_format = false;
  bool in_vertex = false;
  bool vertex_seen = false;
  while (std::getline(in, line)) {
    ++n;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    std::istringstream words(line);
    std::string key;
    words >> key;
    if (n == 1) {
      if (key != "ply") throw InputError(file, 1, "not a PLY file (first line is not 'ply')");
      continue;
    }
    if (key.empty() || key == "comment" || key == "obj_info") continue;
    if (key == "format") {
      std::string format, version;
      words >> format >> version;
      if (format == "binary_little_endian") {
        h.binary = true;
      } else if (format != "ascii") {
        throw InputError(file, n, fmt::format("unsupported PLY format '{}'", format));
      }
      have_format = true;
    } else if (key == "element") {
      std::string name;
      long long count = -1;
      words >> name >> count;
      if (!words || count < 0) throw InputError(file, n, "malformed element line");
      in_vertex = name == "vertex";
      if (in_vertex) {
        if (vertex_seen) throw InputError(file, n, "two vertex elements");
        if (h.vertices != 0 || !h.properties.empty()) {
          throw InputError(file, n, "the vertex element must come first");
        }
        vertex_seen = true;
        h.vertices = static_cast<std::size_t>(count);
      } else if (!vertex_seen) {
        throw InputError(file, n, fmt::format("element '{}' before the vertex element", name));
      }
    } else if (key == "property") {
      if (!in_vertex) continue;  // properties of elements after the vertices
      std::string type_name, name;
      words >> type_name >> name;
      if (type_name == "list") throw InputError(file, n, "list property in the vertex element");
      const auto type = ParsePlyType(type_name);
      if (!type || name.empty()) throw InputError(file, n, "malformed property line");
      h.properties.push_back({name, *type, h.stride});
      h.stride += TypeSize(*type);
    } else if (key == "end_header") {
      if (!have_format) throw InputError(file, n, "no format line before end_header");
      if (!vertex_seen) throw InputError(file, n, "no vertex element");
      h.lines = n;
      return h;
    } else {
      throw InputError(file, n, fmt::format("unexpected header line '{}'", line));
    }
  }
  throw InputError(file, n, "header has no end_header line");
}

int FindProperty(const Header& h, std::initializer_list<const char*> names) {
  for (const char* name : names) {
    for (std::size_t i = 0; i < h.properties.size(); ++i) {
      if (h.properties[i].name == name) return static_cast<int>(i);
    }
  }
  return -1;
}

std::uint8_t ToByte(double v) {
  return static_cast<std::uint8_t>(std::clamp(std::lround(v), 0L, 255L));
}

}  // namespace

void PointCloud::CheckSizes() const {
  PKSLAM_CHECK(colours.empty() || colours.size() == points.size(), "{} colours for {} points",
               colours.size(), points.size());
  PKSLAM_CHECK(views.empty() || views.size() == points.size(), "{} views for {} points",
               views.size(), points.size());
  PKSLAM_CHECK(normals.empty() || normals.size() == points.size(), "{} normals for {} points",
               normals.size(), points.size());
}

PointCloud ReadPly(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw InputError(file, "cannot open the PLY file");
  const Header h = ReadHeader(in, file);
  const int ix = FindProperty(h, {"x"}), iy = FindProperty(h, {"y"}), iz = FindProperty(h, {"z"});
  if (ix < 0 || iy < 0 || iz < 0) throw InputError(file, "vertex element has no x, y, z");
  const int ir = FindProperty(h, {"red", "r"}), ig = FindProperty(h, {"green", "g"}),
            ib = FindProperty(h, {"blue", "b"});
  const bool rgb = ir >= 0 && ig >= 0 && ib >= 0;
  const int igrey = rgb ? -1 : FindProperty(h, {"intensity", "grey", "gray"});
  const int iviews = FindProperty(h, {"views"});
  const int inx = FindProperty(h, {"nx"}), iny = FindProperty(h, {"ny"}),
            inz = FindProperty(h, {"nz"});
  const bool normals = inx >= 0 && iny >= 0 && inz >= 0;

  PointCloud cloud;
  cloud.points.resize(h.vertices);
  if (rgb || igrey >= 0) cloud.colours.resize(h.vertices);
  if (iviews >= 0) cloud.views.resize(h.vertices);
  if (normals) cloud.normals.resize(h.vertices);
  std::vector<double> values(h.properties.size());
  std::vector<char> record(h.stride);
  std::string line;
  for (std::size_t v = 0; v < h.vertices; ++v) {
    if (h.binary) {
      if (!in.read(record.data(), static_cast<std::streamsize>(h.stride))) {
        throw InputError(file, fmt::format("file ends at vertex {} of {}", v, h.vertices));
      }
      for (std::size_t k = 0; k < h.properties.size(); ++k) {
        values[k] = ReadBinaryValue(record.data() + h.properties[k].offset, h.properties[k].type);
      }
    } else {
      const std::size_t line_no = h.lines + v + 1;
      if (!std::getline(in, line)) {
        throw InputError(file, line_no, fmt::format("file ends at vertex {} of {}", v, h.vertices));
      }
      std::istringstream words(line);
      for (double& value : values) {
        if (!(words >> value)) throw InputError(file, line_no, "too few or non-numeric values");
      }
    }
    cloud.points[v] =
        Eigen::Vector3f(static_cast<float>(values[ix]), static_cast<float>(values[iy]),
                        static_cast<float>(values[iz]));
    if (!cloud.points[v].allFinite()) {
      throw InputError(file, h.binary ? 0 : h.lines + v + 1,
                       fmt::format("vertex {} has a non-finite coordinate", v));
    }
    if (rgb) {
      cloud.colours[v] = {ToByte(values[ir]), ToByte(values[ig]), ToByte(values[ib])};
    } else if (igrey >= 0) {
      const std::uint8_t g = ToByte(values[igrey]);
      cloud.colours[v] = {g, g, g};
    }
    if (iviews >= 0) cloud.views[v] = ToByte(values[iviews]);
    if (normals) {
      Eigen::Vector3f n(static_cast<float>(values[inx]), static_cast<float>(values[iny]),
                        static_cast<float>(values[inz]));
      const float norm = n.norm();
      if (!(norm > 0.5f && norm < 1.5f)) {
        throw InputError(file, h.binary ? 0 : h.lines + v + 1,
                         fmt::format("vertex {} has a normal of length {}", v, norm));
      }
      cloud.normals[v] = n / norm;
    }
  }
  return cloud;
}

void WritePly(const PointCloud& cloud, const std::filesystem::path& file, PlyColour colour,
              const std::string& comment) {
  WritePly(cloud, file, colour,
           comment.empty() ? std::vector<std::string>{} : std::vector<std::string>{comment});
}

void WritePly(const PointCloud& cloud, const std::filesystem::path& file, PlyColour colour,
              const std::vector<std::string>& comments) {
  cloud.CheckSizes();
  PKSLAM_CHECK(colour == PlyColour::kNone || cloud.has_colour(), "colour output needs colours");
  std::string header = "ply\nformat binary_little_endian 1.0\n";
  for (const std::string& comment : comments) {
    PKSLAM_CHECK(comment.find('\n') == std::string::npos, "multi-line PLY comment");
    header += "comment " + comment + '\n';
  }
  header += fmt::format("element vertex {}\nproperty float x\nproperty float y\n", cloud.size());
  header += "property float z\n";
  if (cloud.has_normals()) header += "property float nx\nproperty float ny\nproperty float nz\n";
  if (colour == PlyColour::kGrey) header += "property uchar intensity\n";
  if (colour == PlyColour::kRgb) {
    header += "property uchar red\nproperty uchar green\nproperty uchar blue\n";
  }
  if (cloud.has_views()) header += "property uchar views\n";
  header += "end_header\n";
  std::vector<char> buffer;
  buffer.reserve(header.size() + cloud.size() * (cloud.has_normals() ? 29 : 17));
  buffer.insert(buffer.end(), header.begin(), header.end());
  auto put = [&buffer](const void* p, std::size_t n) {
    const char* c = static_cast<const char*>(p);
    buffer.insert(buffer.end(), c, c + n);
  };
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    put(cloud.points[i].data(), 3 * sizeof(float));
    if (cloud.has_normals()) put(cloud.normals[i].data(), 3 * sizeof(float));
    if (colour == PlyColour::kGrey) {
      const Rgb& c = cloud.colours[i];
      const auto grey = static_cast<std::uint8_t>((c[0] + c[1] + c[2] + 1) / 3);
      put(&grey, 1);
    } else if (colour == PlyColour::kRgb) {
      put(cloud.colours[i].data(), 3);
    }
    if (cloud.has_views()) put(&cloud.views[i], 1);
  }
  WriteFileAtomically(file, std::string_view(buffer.data(), buffer.size()));
}

}  // namespace pkslam
