// LocalMapper's keyframe queue is bounded (LocalMappingOptions::max_queued_keyframes): a full
// queue is reported (tracking declines keyframes then), an insert into it waits for room, and
// neither a finish nor a reset leaves the waiting inserter hanging.
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <memory>
#include <thread>
#include <vector>

#include "map_model/keyframe.h"
#include "map_model/testing/synthetic_map.h"
#include "mapping/local_mapper.h"

namespace pkslam {
namespace {

using namespace std::chrono_literals;

// Three keyframes of a synthetic stereo map.
struct QueueFixture {
  Atlas atlas;
  std::shared_ptr<CameraRig> rig = testing::MakeStereoRig();
  testing::SyntheticMap map;
  std::atomic<int> processed{0};

  QueueFixture() {
    const testing::SyntheticScene scene = testing::MakeScene(300, 3);
    std::vector<SE3d> camera_from_world;
    for (int k = 0; k < 3; ++k) {
      camera_from_world.push_back(SE3d(SO3d(), Eigen::Vector3d(-0.1 * k, 0.0, 0.0)));
    }
    map = testing::MakeMap(&atlas, scene, rig, camera_from_world, testing::FrameOptions());
  }

  std::unique_ptr<LocalMapper> MakeMapper(int bound) {
    LocalMappingOptions options;
    options.cull_keyframes = false;
    options.max_queued_keyframes = bound;
    auto mapper = std::make_unique<LocalMapper>(&atlas, rig, options);
    mapper->SetKeyFrameConsumer([this](const KeyFramePtr&) { ++processed; });
    return mapper;
  }

  // A started mapper held by a stop request (as loop closing holds it), bound 2, and its queue
  // full with the first two keyframes.
  std::unique_ptr<LocalMapper> HeldWithFullQueue() {
    auto mapper = MakeMapper(2);
    mapper->Start();
    HoldMapping(mapper.get());
    mapper->InsertKeyFrame(map.keyframes[0]);
    mapper->InsertKeyFrame(map.keyframes[1]);
    return mapper;
  }

  // Stops a started mapper and waits until it is held.
  static void HoldMapping(LocalMapper* mapper) {
    mapper->RequestStop();
    while (!mapper->IsStopped()) std::this_thread::sleep_for(1ms);
  }
};

// Inserts `kf` from a thread of its own (tracking's), noting when the insert has returned.
struct Inserter {
  std::atomic<bool> inserted{false};
  std::thread thread;
  Inserter(LocalMapper* mapper, KeyFramePtr kf)
      : thread([this, mapper, kf] {
          mapper->InsertKeyFrame(kf);
          inserted = true;
        }) {}
};

TEST(LocalMapperQueue, AFullQueueIsReportedAndAnInsertWaitsForRoom) {
  QueueFixture f;
  auto mapper = f.MakeMapper(2);
  mapper->Start();
  QueueFixture::HoldMapping(mapper.get());
  mapper->InsertKeyFrame(f.map.keyframes[0]);
  EXPECT_FALSE(mapper->QueueFull());
  mapper->InsertKeyFrame(f.map.keyframes[1]);
  EXPECT_TRUE(mapper->QueueFull());

  Inserter inserter(mapper.get(), f.map.keyframes[2]);
  std::this_thread::sleep_for(200ms);
  EXPECT_FALSE(inserter.inserted.load());  // mapping is held: no room
  EXPECT_EQ(mapper->QueueSize(), 2);

  mapper->Release();
  inserter.thread.join();
  EXPECT_TRUE(inserter.inserted.load());
  mapper->WaitUntilIdle();
  EXPECT_EQ(f.processed.load(), 3);
  EXPECT_EQ(mapper->stats().max_queued_keyframes, 2);
  mapper->Finish();
}

TEST(LocalMapperQueue, FinishReleasesAWaitingInserter) {
  QueueFixture f;
  auto mapper = f.HeldWithFullQueue();
  Inserter inserter(mapper.get(), f.map.keyframes[2]);
  std::this_thread::sleep_for(50ms);
  mapper->Finish();  // processes what is queued; the inserter must not wait forever
  inserter.thread.join();
  EXPECT_GE(f.processed.load(), 2);
}

TEST(LocalMapperQueue, ResetReleasesAWaitingInserter) {
  QueueFixture f;
  auto mapper = f.HeldWithFullQueue();
  Inserter inserter(mapper.get(), f.map.keyframes[2]);
  std::this_thread::sleep_for(50ms);
  EXPECT_FALSE(inserter.inserted.load());
  std::thread resetter([&] { mapper->ResetQueue(); });
  inserter.thread.join();  // the reset request releases it
  EXPECT_TRUE(inserter.inserted.load());
  mapper->Release();
  resetter.join();
  mapper->Finish();
}

TEST(LocalMapperQueue, WithoutAThreadTheInserterProcessesTheOldest) {
  QueueFixture f;
  auto mapper = f.MakeMapper(2);
  mapper->InsertKeyFrame(f.map.keyframes[0]);
  mapper->InsertKeyFrame(f.map.keyframes[1]);
  EXPECT_EQ(f.processed.load(), 0);
  mapper->InsertKeyFrame(f.map.keyframes[2]);
  EXPECT_EQ(f.processed.load(), 1);
  EXPECT_EQ(mapper->QueueSize(), 2);
  EXPECT_EQ(mapper->stats().max_queued_keyframes, 2);
}

TEST(LocalMapperQueue, ABoundBelowTwoIsRefused) {
  LocalMappingOptions options;
  options.max_queued_keyframes = 1;
  EXPECT_THROW(options.Check(), std::exception);
  options.max_queued_keyframes = 2;
  EXPECT_NO_THROW(options.Check());
}

}  // namespace
}  // namespace pkslam
