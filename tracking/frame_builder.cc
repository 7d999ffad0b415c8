#include "tracking/frame_builder.h"

#include <algorithm>
#include <cmath>

#include "core/sensor/depth_uncertainty.h"
#include "core/util/error.h"

namespace pkslam {
namespace {

OrbOptions Doubled(OrbOptions o) {
  o.n_features *= 2;
  return o;
}

FrameFeatures ToFrameFeatures(OrbFeatures&& f) {
  FrameFeatures out;
  out.keypoints = std::move(f.keypoints);
  out.descriptors = std::move(f.descriptors);
  return out;
}

}  // namespace

FrameBuilder::FrameBuilder(std::shared_ptr<const CameraRig> rig, const OrbOptions& orb,
                           StereoMatcherOptions stereo)
    : rig_(std::move(rig)), extractor_(orb), init_extractor_(Doubled(orb)), stereo_(stereo) {
  stereo_.Check();
}

Frame FrameBuilder::BuildStereo(FrameId id, std::int64_t t_ns, const cv::Mat& left,
                                const cv::Mat& right) const {
  OrbFeatures lf;
  OrbFeatures rf;
  extractor_.ExtractStereo(left, right, &lf, &rf);
  const StereoMatches m = MatchStereo(lf, rf, rig_->bf, rig_->fx, stereo_);
  FrameFeatures f = ToFrameFeatures(std::move(lf));
  f.right_u = m.u_right;
  f.depth = m.depth;
  return Frame(id, t_ns, rig_, std::move(f));
}

Frame FrameBuilder::BuildRgbd(FrameId id, std::int64_t t_ns, const cv::Mat& grey,
                              const cv::Mat& depth) const {
  PKSLAM_CHECK(depth.size() == grey.size(), "depth {}x{} vs image {}x{}", depth.cols, depth.rows,
               grey.cols, grey.rows);
  FrameFeatures f = ToFrameFeatures(extractor_.Extract(grey));
  const std::size_t n = f.keypoints.size();
  f.depth.assign(n, -1.0f);
  f.depth_sigma.assign(n, -1.0f);
  const bool metric = depth.type() == CV_32F;
  PKSLAM_CHECK(metric || depth.type() == CV_16U, "depth image type {} (want CV_16U or CV_32F)",
               depth.type());
  const double scale = metric ? 1.0 : 1.0 / rig_->depth_factor;
  const ScalePyramid& pyramid = rig_->pyramid;
  for (std::size_t i = 0; i < n; ++i) {
    // Depth is looked up at the raw (distorted) keypoint, where the registered depth lives;
    // the keypoint's location sigma is its octave's scale (ORB-SLAM's sigma per level).
    const cv::KeyPoint& kp = f.keypoints[i];
    const int octave = std::clamp(kp.octave, 0, static_cast<int>(pyramid.scale.size()) - 1);
    const DepthReading r = ReadKeypointDepth(depth, scale, kp.pt.x, kp.pt.y, rig_->depth_noise_k,
                                             pyramid.scale[octave], rig_->bf);
    f.depth[i] = r.depth;
    f.depth_sigma[i] = r.sigma;
  }
  return Frame(id, t_ns, rig_, std::move(f));
}

Frame FrameBuilder::BuildMonocular(FrameId id, std::int64_t t_ns, const cv::Mat& grey,
                                   bool initialisation) const {
  const OrbExtractor& e = initialisation ? init_extractor_ : extractor_;
  return Frame(id, t_ns, rig_, ToFrameFeatures(e.Extract(grey)));
}

}  // namespace pkslam
