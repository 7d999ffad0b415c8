// pkslam tracks end to end: simulate -> reconstruct writes the documented outputs with the
// accuracy against truth and a report whose images exist; export of a pkslam run's keyframe
// observations (a hand-made sparse model) and of a simulated sequence without tracks; bad
// input is one line naming the file and line.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <regex>
#include <string>

#include "io/sparse_model.h"
#include "io/track_file.h"
#include "tests/support/test_data.h"

namespace pkslam {
namespace {

namespace fs = std::filesystem;
using testing::RunPkslam;

TEST(TracksCli, SimulateReconstructReport) {
  const fs::path dir = testing::MakeTempDir("tracks_cli");
  const auto sim = RunPkslam("tracks simulate --out " + (dir / "t").string() + " --noise 1");
  ASSERT_EQ(sim.exit_code, 0) << sim.output;
  const fs::path out = dir / "r";
  const auto rec = RunPkslam("tracks reconstruct " + (dir / "t").string() + " --out " +
                             out.string() + " --keyframes interval --interval 10");
  ASSERT_EQ(rec.exit_code, 0) << rec.output;
  EXPECT_NE(rec.output.find("60 of 60 frames tracked"), std::string::npos) << rec.output;
  for (const char* f :
       {"trajectory.txt", "keyframes.txt", "map.ply", "frames.csv", "reprojection_errors.csv",
        "stats.json", "report.html", "histogram_frame_1.png", "histogram_frame_49.png",
        "mean_error_per_frame.png", "trajectory.png"}) {
    EXPECT_TRUE(fs::exists(out / f)) << f;
  }
  EXPECT_EQ(testing::JsonIntField(out / "stats.json", "tracked_frames"), 60);
  const std::string stats = testing::ReadFileBytes(out / "stats.json");
  EXPECT_NE(stats.find("\"ate_sim3\""), std::string::npos);
  EXPECT_NE(stats.find("\"interval\": "), std::string::npos);  // keyframe reasons
  // Every image the report shows exists.
  const std::string report = testing::ReadFileBytes(out / "report.html");
  const std::regex img("src='([^']+)'");
  int images = 0;
  for (auto it = std::sregex_iterator(report.begin(), report.end(), img);
       it != std::sregex_iterator(); ++it) {
    EXPECT_TRUE(fs::exists(out / (*it)[1].str())) << (*it)[1].str();
    ++images;
  }
  EXPECT_EQ(images, 4);
}

TEST(TracksCli, BadInputIsOneLineNamingFileAndLine) {
  const fs::path dir = testing::MakeTempDir("tracks_bad");
  {
    std::ofstream f(dir / "tracks.txt");
    f << "# pkslam tracks v1\ncamera 700 700 640 360 1280 720\n0 0.0 1 10 10\n0 0.0 1 11 11\n";
  }
  const auto r = RunPkslam("tracks reconstruct " + (dir / "tracks.txt").string() + " --out " +
                           (dir / "r").string());
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.output.find("tracks.txt:4"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("twice"), std::string::npos) << r.output;
  // A sequence simulated without --tracks has nothing to export.
  fs::create_directories(dir / "seq");
  const auto e = RunPkslam("tracks export --simulated " + (dir / "seq").string() + " --out " +
                           (dir / "e").string());
  EXPECT_NE(e.exit_code, 0);
  EXPECT_NE(e.output.find("tracks_exact.txt"), std::string::npos) << e.output;
  EXPECT_NE(e.output.find("--tracks"), std::string::npos) << e.output;
  // Unknown rule.
  const auto k = RunPkslam("tracks reconstruct " + (dir / "tracks.txt").string() +
                           " --out x --keyframes sometimes");
  EXPECT_NE(k.exit_code, 0);
  EXPECT_NE(k.output.find("sometimes"), std::string::npos) << k.output;
}

TEST(TracksCli, ExportsAKeyframeObservationPerMapPoint) {
  const fs::path dir = testing::MakeTempDir("tracks_export");
  SparseModel model;
  model.camera = {752, 480, 458, 457, 367, 248, 0};
  for (int k = 0; k < 3; ++k) {
    SparseKeyframe kf;
    kf.id = 10 + k;
    kf.t_ns = 1'000'000'000LL * (3 - k);  // ids and times in opposite orders
    kf.keypoints = {{100.0f + k, 50.0f, 0, 7}, {200.0f, 60.0f + k, 1, -1}, {300.0f, 70.0f, 0, 9}};
    model.keyframes.push_back(kf);
  }
  for (std::int64_t id : {7, 9}) {
    SparsePoint p;
    p.id = id;
    for (int k = 0; k < 3; ++k) p.observations.emplace_back(10 + k, id == 7 ? 0 : 2);
    model.points.push_back(p);
  }
  fs::create_directories(dir / "run");
  WriteSparseModel(model, dir / "run" / "sparse_model.txt");
  const auto r =
      RunPkslam("tracks export --run " + (dir / "run").string() + " --out " + (dir / "t").string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const TrackSet t = ReadTrackFile(dir / "t" / "tracks.txt");
  ASSERT_EQ(t.observations.size(), 6u);  // 3 keyframes x 2 map points; unmatched skipped
  EXPECT_EQ(t.NumFrames(), 3);
  // Frames in time order: the first frame is keyframe 12 (t = 1 s) with u = 102.
  EXPECT_EQ(t.observations[0].t_s, 1.0);
  EXPECT_EQ(t.observations[0].track, 7);
  EXPECT_EQ(t.observations[0].u, 102.0);
  EXPECT_EQ(t.camera.fx, 458.0);
  EXPECT_FALSE(fs::exists(dir / "t" / "truth_trajectory.txt"));
}

TEST(TracksCli, EveryFrameTracksOfARun) {
  PKSLAM_REQUIRE_SHARED_DATA(shared);
  const fs::path dataset = shared / "euroc" / "V1_01_easy_static";
  const fs::path dir = testing::MakeTempDir("tracks_frames");
  const auto r =
      RunPkslam("run --dataset " + dataset.string() + " --sensor stereo --out " +
                (dir / "run").string() + " --quiet --max-frames 30 --deterministic --frame-tracks");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const TrackSet frames = ReadTrackFile(dir / "run" / "frame_tracks.txt");
  EXPECT_EQ(frames.NumFrames(), testing::JsonIntField(dir / "run" / "stats.json", "frames"));
  EXPECT_GT(frames.observations.size(), 30u * 100u);  // every frame tracks its map points
  // (The static recording has no ground truth: no --dataset, no truth file.)
  const auto e = RunPkslam("tracks export --run " + (dir / "run").string() +
                           " --every-frame --out " + (dir / "t").string());
  ASSERT_EQ(e.exit_code, 0) << e.output;
  const TrackSet exported = ReadTrackFile(dir / "t" / "tracks.txt");
  EXPECT_EQ(exported.observations.size(), frames.observations.size());
  EXPECT_FALSE(fs::exists(dir / "t" / "truth_trajectory.txt"));
  // Without --frame-tracks there is nothing to export frame by frame.
  fs::remove(dir / "run" / "frame_tracks.txt");
  const auto missing = RunPkslam("tracks export --run " + (dir / "run").string() +
                                 " --every-frame --out " + (dir / "t2").string());
  EXPECT_NE(missing.exit_code, 0);
  EXPECT_NE(missing.output.find("frame_tracks.txt"), std::string::npos) << missing.output;
}

}  // namespace
}  // namespace pkslam
