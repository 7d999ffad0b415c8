// Colour over-segmentation of seed 001 (section 3-1-2): region growing in CIE L*a*b*.
// Pixels are visited in raster order; an unlabelled pixel seeds a segment and is pushed on an
// explicit stack; a popped pixel that is still unlabelled joins the segment when its Lab
// distance to the segment's running mean is below the threshold, the mean is updated by
// c(t+1) = c(t) + (x - c(t)) / (t + 1) (Eq. 5) and its 8 neighbours are pushed. A pixel that
// fails stays unlabelled and can seed or join a later segment.
#pragma once

#include <opencv2/core.hpp>

namespace pkslam::rgbd {

struct Segmentation {
  cv::Mat labels;  // CV_32SC1: segment id 0..count-1 per pixel, -1 = unlabelled
  int count = 0;
};

// CIE L*a*b* (D65, sRGB) as CV_32FC3 from an 8-bit BGR image: L in [0, 100], a and b about
// [-128, 127] -- the units of MATLAB's rgb2lab, in which seed 001's thresholds are given.
cv::Mat BgrToLab(const cv::Mat& bgr);

// lab: CV_32FC3. threshold > 0 (Euclidean Lab distance). mask (optional CV_8UC1): pixels where
// it is 0 are left unlabelled and never join.
Segmentation SegmentRegionGrowing(const cv::Mat& lab, double threshold, const cv::Mat& mask = {});

}  // namespace pkslam::rgbd
