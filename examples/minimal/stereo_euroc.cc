// Stereo SLAM on a EuRoC sequence through the installed library: the whole public API in one
// page (pkslam/pkslam.h).
//
//   stereo_euroc SEQUENCE SETTINGS.yaml [TRAJECTORY_OUT]
// SEQUENCE holds mav0/cam0 and mav0/cam1 (data.csv + data/*.png); SETTINGS is an ORB-SLAM3
// stereo settings file (e.g. the settings.yaml `pkslam simulate` writes).
#include <pkslam/pkslam.h>

#include <Eigen/Geometry>

#include <cstdio>
#include <fstream>
#include <iostream>
#include <opencv2/imgcodecs.hpp>
#include <sstream>
#include <string>
#include <vector>

int main(int argc, char** argv) {
  if (argc < 3) {
    std::cerr << "usage: stereo_euroc SEQUENCE SETTINGS.yaml [TRAJECTORY_OUT]\n";
    return 2;
  }
  const std::string seq = argv[1];
  try {
    pkslam::api::SlamOptions options;
    options.settings = argv[2];
    options.vocabulary = PKSLAM_VOCABULARY;  // installed with the package
    options.sensor = "stereo";
    pkslam::api::Slam slam(options);

    std::ifstream list(seq + "/mav0/cam0/data.csv");
    if (!list) throw std::runtime_error(seq + "/mav0/cam0/data.csv: cannot open");
    int frames = 0;
    int tracked = 0;
    for (std::string line; std::getline(list, line);) {
      if (line.empty() || line[0] == '#') continue;
      const std::string stamp = line.substr(0, line.find(','));
      const cv::Mat left =
          cv::imread(seq + "/mav0/cam0/data/" + stamp + ".png", cv::IMREAD_GRAYSCALE);
      const cv::Mat right =
          cv::imread(seq + "/mav0/cam1/data/" + stamp + ".png", cv::IMREAD_GRAYSCALE);
      if (left.empty() || right.empty()) continue;  // cam1 may miss a frame
      const auto state = slam.TrackStereo(left, right, std::stoll(stamp));
      ++frames;
      if (state == pkslam::api::SlamState::kOk) ++tracked;
    }
    slam.Shutdown();
    // Body (IMU) poses: the frame EuRoC ground truth describes (CameraTrajectory() for the
    // left camera's).
    const std::vector<pkslam::api::StampedBodyPose> trajectory = slam.BodyTrajectory();
    std::printf("frames %d tracked %d keyframes %d map points %d trajectory %zu poses\n", frames,
                tracked, slam.NumKeyFrames(), slam.NumMapPoints(), trajectory.size());
    if (argc > 3) {
      // TUM format: t[s] x y z qx qy qz qw (pkslam eval, evo_ape tum).
      std::ofstream out(argv[3]);
      out.precision(9);
      for (const auto& p : trajectory) {
        const Eigen::Vector3d t = p.world_from_body.block<3, 1>(0, 3);
        const Eigen::Quaterniond q(Eigen::Matrix3d(p.world_from_body.block<3, 3>(0, 0)));
        out << std::fixed << 1e-9 * static_cast<double>(p.t_ns) << ' ' << t.x() << ' ' << t.y()
            << ' ' << t.z() << ' ' << q.x() << ' ' << q.y() << ' ' << q.z() << ' ' << q.w()
            << '\n';
      }
    }
    return tracked > 0 ? 0 : 1;
  } catch (const std::exception& e) {
    std::cerr << "stereo_euroc: " << e.what() << "\n";
    return 1;
  }
}
