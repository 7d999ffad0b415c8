// Uncertainty of RGB-D depth readings at keypoints, and the information it gives the virtual
// disparity d = bf / z that RGB-D observations carry (ORB-SLAM's virtual right coordinate).
//
// A reading at a keypoint is off for two reasons: the sensor's own noise (structured-light
// sensors: sigma_z = k z^2, quadratic in depth; Kinect v1 k = 1.425e-3 1/m, Khoshelham &
// Elberink 2012) and the depth change across the keypoint's location uncertainty (the reading
// is taken at the rounded keypoint pixel; on a slanted surface or at a depth discontinuity
// that is not the depth of the feature). The second term is |grad z| * sigma_location.
// Because sigma_z grows with z^2, the disparity sigma bf sigma_z / z^2 of the sensor term is
// constant (bf k, ~0.05 px for TUM-like settings): an order of magnitude below the keypoint's
// pixel sigma that a stereo-style residual on the right coordinate would assign to it.
#pragma once

#include <opencv2/core.hpp>

namespace pkslam {

struct DepthReading {
  float depth = -1.0f;  // metres; <= 0: none (invalid, out of the image, or unusable)
  float sigma = -1.0f;  // metres (1 sigma)
};

// Readings whose disparity sigma exceeds this many pixels are dropped: only a depth
// discontinuity under the keypoint produces them (a slanted surface stays below ~0.3 px).
inline constexpr double kMaxDisparitySigmaPx = 1.0;

// The depth reading at raw pixel (x, y) (rounded to the nearest pixel) of a registered depth
// image (CV_16U with `scale` metres per unit, or CV_32F metres with scale 1), with its sigma:
// sqrt((noise_k z^2)^2 + |grad z|^2 (location_sigma_px^2 + 1/12)), the 1/12 px^2 being the
// rounding. The gradient is a central difference; a reading next to an invalid pixel (a hole
// border: shadows, out of range) or with a disparity sigma above kMaxDisparitySigmaPx is
// dropped. bf (pixels * metres) converts to disparity.
DepthReading ReadKeypointDepth(const cv::Mat& depth, double scale, double x, double y,
                               double noise_k, double location_sigma_px, double bf);

// Information (1 / px^2) of the measured disparity bf / depth given the depth's sigma (m);
// 0 when there is no usable reading.
double DisparityInformation(double bf, double depth, double depth_sigma);

}  // namespace pkslam
