#include "io/track_file.h"

#include <fmt/format.h>

#include <fstream>
#include <set>
#include <sstream>
#include <string>

#include "core/util/error.h"
#include "core/util/output_file.h"
#include "io/text_rows.h"

namespace pkslam {
namespace {

constexpr const char* kHeader = "# pkslam tracks v1";

}  // namespace

TrackSet ReadTrackFile(const std::filesystem::path& file) {
  {
    std::ifstream in(file);
    if (!in) throw InputError(file, "cannot open tracks file");
    std::string first;
    std::getline(in, first);
    if (first.rfind(kHeader, 0) != 0) {
      throw InputError(file, 1, fmt::format("not a tracks file (expected '{}')", kHeader));
    }
  }
  TrackSet out;
  bool have_camera = false;
  std::set<int> tracks_in_frame;
  ForEachDataRow(file, FieldSeparator::kWhitespace, [&](const TextRow& row) {
    if (row.fields[0] == "camera") {
      if (have_camera) throw InputError(file, row.line, "second camera line");
      RequireFieldCount(row, 7, file, "camera FX FY CX CY WIDTH HEIGHT");
      out.camera.fx = DoubleField(row.fields[1], file, row.line, "fx");
      out.camera.fy = DoubleField(row.fields[2], file, row.line, "fy");
      out.camera.cx = DoubleField(row.fields[3], file, row.line, "cx");
      out.camera.cy = DoubleField(row.fields[4], file, row.line, "cy");
      out.width = static_cast<int>(Int64Field(row.fields[5], file, row.line, "width"));
      out.height = static_cast<int>(Int64Field(row.fields[6], file, row.line, "height"));
      if (!(out.camera.fx > 0 && out.camera.fy > 0 && out.width > 0 && out.height > 0)) {
        throw InputError(file, row.line, "camera: focal lengths and image size must be > 0");
      }
      have_camera = true;
      return;
    }
    if (!have_camera) throw InputError(file, row.line, "observation before the camera line");
    RequireFieldCount(row, 5, file, "frame time_s track u v");
    TrackObservation o;
    o.frame = static_cast<int>(Int64Field(row.fields[0], file, row.line, "frame"));
    o.t_s = DoubleField(row.fields[1], file, row.line, "time_s");
    o.track = static_cast<int>(Int64Field(row.fields[2], file, row.line, "track"));
    o.u = DoubleField(row.fields[3], file, row.line, "u");
    o.v = DoubleField(row.fields[4], file, row.line, "v");
    if (o.frame < 0 || o.track < 0) throw InputError(file, row.line, "negative frame or track");
    if (!out.observations.empty()) {
      const TrackObservation& p = out.observations.back();
      if (o.frame < p.frame) throw InputError(file, row.line, "frames must not decrease");
      if (o.frame == p.frame && o.t_s != p.t_s) {
        throw InputError(file, row.line, "one frame with two times");
      }
      if (o.frame > p.frame && o.t_s <= p.t_s) {
        throw InputError(file, row.line, "time must increase from frame to frame");
      }
      if (o.frame > p.frame) tracks_in_frame.clear();
    }
    if (!tracks_in_frame.insert(o.track).second) {
      throw InputError(file, row.line, fmt::format("track {} twice in frame {}", o.track, o.frame));
    }
    out.observations.push_back(o);
  });
  if (!have_camera) throw InputError(file, "no camera line");
  return out;
}

void WriteTrackFile(const TrackSet& tracks, const std::filesystem::path& file) {
  std::string text =
      fmt::format("{}\ncamera {:.9g} {:.9g} {:.9g} {:.9g} {} {}\n# frame time_s track u v\n",
                  kHeader, tracks.camera.fx, tracks.camera.fy, tracks.camera.cx, tracks.camera.cy,
                  tracks.width, tracks.height);
  const TrackObservation* previous = nullptr;
  for (const TrackObservation& o : tracks.observations) {
    PKSLAM_CHECK(previous == nullptr || o.frame >= previous->frame, "tracks out of frame order");
    text += fmt::format("{} {:.9f} {} {:.6f} {:.6f}\n", o.frame, o.t_s, o.track, o.u, o.v);
    previous = &o;
  }
  WriteFileAtomically(file, text);
}

TrackPoints ReadTrackPoints(const std::filesystem::path& file) {
  TrackPoints points;
  std::set<int> seen;
  ForEachDataRow(file, FieldSeparator::kWhitespace, [&](const TextRow& row) {
    RequireFieldCount(row, 4, file, "track x y z");
    const int id = static_cast<int>(Int64Field(row.fields[0], file, row.line, "track"));
    if (!seen.insert(id).second) {
      throw InputError(file, row.line, fmt::format("track {} listed twice", id));
    }
    points.emplace_back(id, Eigen::Vector3d(DoubleField(row.fields[1], file, row.line, "x"),
                                            DoubleField(row.fields[2], file, row.line, "y"),
                                            DoubleField(row.fields[3], file, row.line, "z")));
  });
  return points;
}

void WriteTrackPoints(const TrackPoints& points, const std::filesystem::path& file,
                      const std::string& comment) {
  std::string text = "# " + comment + "\n";
  for (const auto& [id, p] : points) {
    text += fmt::format("{} {:.9g} {:.9g} {:.9g}\n", id, p.x(), p.y(), p.z());
  }
  WriteFileAtomically(file, text);
}

}  // namespace pkslam
