// Monocular frame sources beside the dataset readers: a video file (OpenCV VideoCapture;
// timestamps from the container, or a fixed --fps), a live camera (--camera N; the wall clock
// since the first frame), and a plain image folder with a timestamps file (ORB-SLAM3's
// mono_euroc layout: one image name stem or path per line with its time, or one time per line
// naming DIR/<time>.png). `pkslam run --video / --camera / --images` reads them
// (system/run_source.h); frames come out grey, in order, with strictly increasing stamps.
#pragma once

#include <cstdint>
#include <filesystem>
#include <memory>
#include <opencv2/core/mat.hpp>
#include <optional>
#include <string>
#include <vector>

namespace pkslam {

struct SourceFrame {
  std::int64_t t_ns = 0;
  cv::Mat image;  // CV_8UC1
};

class FrameSource {
 public:
  virtual ~FrameSource() = default;
  // The next frame, or nullopt at the end (a camera never ends by itself). Throws InputError
  // naming the source on a frame that cannot be read or a time that does not increase.
  virtual std::optional<SourceFrame> Next() = 0;
  // Frames expected in all (the container's count, the list's length); nullopt when unknown.
  virtual std::optional<std::size_t> Count() const = 0;
  // For logs and stats.json: the file, folder or "camera N".
  virtual std::string Name() const = 0;
  // Every frame's time when known before reading (a timestamp list): checked against the
  // settings' Camera.fps before the run (io/dataset_common.h CheckTimeBase).
  virtual std::vector<std::int64_t> ListedTimes() const { return {}; }
};

// `fps` > 0: stamps are frame_index / fps; otherwise the container's per-frame timestamps
// (CAP_PROP_POS_MSEC), falling back to its nominal rate when those do not increase.
std::unique_ptr<FrameSource> OpenVideoFile(const std::filesystem::path& file,
                                           std::optional<double> fps = std::nullopt);
std::unique_ptr<FrameSource> OpenCamera(int index);
// timestamps: rows "t_ns" (images DIR/t_ns.png) or "t_ns name" / "t_seconds name" (a
// decimal point marks seconds); '#' comments.
std::unique_ptr<FrameSource> OpenImageFolder(const std::filesystem::path& dir,
                                             const std::filesystem::path& timestamps);

}  // namespace pkslam
