#include "io/frame_source.h"

#include <fmt/format.h>

#include <chrono>
#include <cmath>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>
#include <utility>
#include <vector>

#include "core/util/error.h"
#include "io/text_rows.h"

namespace pkslam {
namespace {

cv::Mat Grey(const cv::Mat& image) {
  if (image.channels() == 1) return image;
  cv::Mat grey;
  cv::cvtColor(image, grey, image.channels() == 4 ? cv::COLOR_BGRA2GRAY : cv::COLOR_BGR2GRAY);
  return grey;
}

class VideoFileSource : public FrameSource {
 public:
  VideoFileSource(std::filesystem::path file, std::optional<double> fps)
      : file_(std::move(file)), fps_(fps) {
    if (!std::filesystem::is_regular_file(file_)) throw InputError(file_, "video file not found");
    if (fps_ && !(*fps_ > 0 && *fps_ < 10000)) {
      throw OptionError(fmt::format("--fps {}: must be in (0, 10000)", *fps_));
    }
    capture_.open(file_.string(), cv::CAP_ANY);
    if (!capture_.isOpened()) throw InputError(file_, "cannot open as a video (OpenCV videoio)");
    nominal_fps_ = capture_.get(cv::CAP_PROP_FPS);
    const double count = capture_.get(cv::CAP_PROP_FRAME_COUNT);
    if (count > 0) count_ = static_cast<std::size_t>(count);
  }

  std::optional<SourceFrame> Next() override {
    cv::Mat image;
    if (!capture_.read(image) || image.empty()) return std::nullopt;
    SourceFrame frame;
    frame.image = Grey(image);
    if (fps_) {
      frame.t_ns = std::llround(static_cast<double>(index_) / *fps_ * 1e9);
    } else {
      const double ms = capture_.get(cv::CAP_PROP_POS_MSEC);
      std::int64_t t_ns = std::llround(ms * 1e6);
      if (!(ms >= 0) || (index_ > 0 && t_ns <= last_t_ns_)) {
        if (!(nominal_fps_ > 0)) {
          throw InputError(file_, fmt::format("frame {}: the container gives no increasing "
                                              "timestamps and no frame rate (pass --fps)",
                                              index_));
        }
        t_ns = std::llround(static_cast<double>(index_) / nominal_fps_ * 1e9);
      }
      frame.t_ns = t_ns;
    }
    if (index_ > 0 && frame.t_ns <= last_t_ns_) {
      throw InputError(file_,
                       fmt::format("frame {}: time {} ns does not increase", index_, frame.t_ns));
    }
    last_t_ns_ = frame.t_ns;
    ++index_;
    return frame;
  }
  std::optional<std::size_t> Count() const override { return count_; }
  std::string Name() const override { return file_.string(); }

 private:
  std::filesystem::path file_;
  std::optional<double> fps_;
  cv::VideoCapture capture_;
  double nominal_fps_ = 0;
  std::optional<std::size_t> count_;
  std::size_t index_ = 0;
  std::int64_t last_t_ns_ = 0;
};

class CameraSource : public FrameSource {
 public:
  explicit CameraSource(int index) : index_(index) {
    capture_.open(index, cv::CAP_ANY);
    if (!capture_.isOpened()) {
      throw InputError(Name(), "cannot open the camera (is a device /dev/video* present?)");
    }
  }
  std::optional<SourceFrame> Next() override {
    cv::Mat image;
    if (!capture_.read(image) || image.empty()) return std::nullopt;  // unplugged
    const auto now = std::chrono::steady_clock::now();
    if (!start_) start_ = now;
    SourceFrame frame;
    frame.image = Grey(image);
    frame.t_ns = std::chrono::duration_cast<std::chrono::nanoseconds>(now - *start_).count();
    if (frame.t_ns <= last_t_ns_ && frames_ > 0) frame.t_ns = last_t_ns_ + 1;
    last_t_ns_ = frame.t_ns;
    ++frames_;
    return frame;
  }
  std::optional<std::size_t> Count() const override { return std::nullopt; }
  std::string Name() const override { return fmt::format("camera {}", index_); }

 private:
  int index_;
  cv::VideoCapture capture_;
  std::optional<std::chrono::steady_clock::time_point> start_;
  std::int64_t last_t_ns_ = 0;
  std::size_t frames_ = 0;
};

class ImageFolderSource : public FrameSource {
 public:
  ImageFolderSource(const std::filesystem::path& dir, const std::filesystem::path& timestamps)
      : timestamps_(timestamps) {
    if (!std::filesystem::is_directory(dir)) throw InputError(dir, "image folder not found");
    std::optional<std::int64_t> previous;
    ForEachDataRow(timestamps, FieldSeparator::kWhitespace, [&](const TextRow& row) {
      if (row.fields.size() != 1 && row.fields.size() != 2) {
        throw InputError(timestamps, row.line,
                         fmt::format("expected 't' or 't name', got {} fields", row.fields.size()));
      }
      const std::string_view t = row.fields[0];
      const std::int64_t t_ns = t.find('.') != std::string_view::npos
                                    ? SecondsFieldToNs(t, timestamps, row.line, "time (s)")
                                    : Int64Field(t, timestamps, row.line, "time (ns)");
      RequireIncreasing(previous, t_ns, timestamps, row.line);
      previous = t_ns;
      std::filesystem::path image = row.fields.size() == 2
                                        ? dir / std::string(row.fields[1])
                                        : dir / (std::string(row.fields[0]) + ".png");
      if (!image.has_extension()) image += ".png";
      entries_.push_back({t_ns, std::move(image), row.line});
    });
    if (entries_.empty()) throw InputError(timestamps, "no frames listed");
  }
  std::optional<SourceFrame> Next() override {
    if (next_ >= entries_.size()) return std::nullopt;
    const Entry& e = entries_[next_++];
    cv::Mat image = cv::imread(e.image.string(), cv::IMREAD_UNCHANGED);
    if (image.empty()) {
      throw InputError(timestamps_, e.line,
                       fmt::format("image {} is missing or unreadable", e.image.string()));
    }
    return SourceFrame{e.t_ns, Grey(image)};
  }
  std::optional<std::size_t> Count() const override { return entries_.size(); }
  std::string Name() const override { return timestamps_.string(); }
  std::vector<std::int64_t> ListedTimes() const override {
    std::vector<std::int64_t> t_ns;
    for (const Entry& e : entries_) t_ns.push_back(e.t_ns);
    return t_ns;
  }

 private:
  struct Entry {
    std::int64_t t_ns;
    std::filesystem::path image;
    std::size_t line;
  };
  std::filesystem::path timestamps_;
  std::vector<Entry> entries_;
  std::size_t next_ = 0;
};

}  // namespace

std::unique_ptr<FrameSource> OpenVideoFile(const std::filesystem::path& file,
                                           std::optional<double> fps) {
  return std::make_unique<VideoFileSource>(file, fps);
}

std::unique_ptr<FrameSource> OpenCamera(int index) { return std::make_unique<CameraSource>(index); }

std::unique_ptr<FrameSource> OpenImageFolder(const std::filesystem::path& dir,
                                             const std::filesystem::path& timestamps) {
  return std::make_unique<ImageFolderSource>(dir, timestamps);
}

}  // namespace pkslam
