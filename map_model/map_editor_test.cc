#include "map_model/map_editor.h"

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <thread>

namespace pkslam {
namespace {

const MapEditStats& StatsOf(const MapEditTable& table, MapEdit edit) {
  return table[static_cast<std::size_t>(edit)];
}

TEST(MapEditorTest, EveryExclusiveHoldIsCountedOnceUnderItsKind) {
  Atlas atlas;
  const MapEditor editor(&atlas);
  { auto lock = editor.Write(MapEdit::kFuse); }
  {
    auto lock = editor.Write(MapEdit::kFuse);
    lock.unlock();  // released early: recorded now, not again at the end of the scope
    EXPECT_FALSE(lock.owns_lock());
  }
  {
    auto lock = editor.Write(MapEdit::kCullPoints);
    MapWriteLock moved = std::move(lock);  // the moved-from lock records nothing
    EXPECT_TRUE(moved.owns_lock());
    EXPECT_EQ(moved.edit(), MapEdit::kCullPoints);
  }
  { auto later = editor.WriteLater(MapEdit::kMergeMaps); }  // never locked: nothing to record
  const MapEditTable stats = atlas.EditStats();
  EXPECT_EQ(StatsOf(stats, MapEdit::kFuse).holds, 2);
  EXPECT_EQ(StatsOf(stats, MapEdit::kCullPoints).holds, 1);
  EXPECT_EQ(StatsOf(stats, MapEdit::kMergeMaps).holds, 0);
  EXPECT_EQ(StatsOf(stats, MapEdit::kApplyBundle).holds, 0);
  EXPECT_GE(StatsOf(stats, MapEdit::kFuse).total_s, StatsOf(stats, MapEdit::kFuse).max_s);
  EXPECT_GE(StatsOf(stats, MapEdit::kFuse).max_s, 0.0);
}

TEST(MapEditorTest, RelockingRecordsASecondHold) {
  Atlas atlas;
  auto lock = MapEditor(&atlas).Write(MapEdit::kInitialise);
  lock.unlock();
  lock.lock();
  lock.unlock();
  EXPECT_EQ(StatsOf(atlas.EditStats(), MapEdit::kInitialise).holds, 2);
}

TEST(MapEditorTest, EveryKindHasAName) {
  for (int k = 0; k < kNumMapEdits; ++k) {
    EXPECT_NE(MapEditName(static_cast<MapEdit>(k)), "unknown") << k;
  }
  EXPECT_EQ(MapEditName(MapEdit::kApplyBundle), "apply_bundle");
}

// Threaded (also under the sanitizers): a reader waits while a writer holds the map, readers
// share it, and a writer waits for the readers.
TEST(MapEditorThreaded, ReadersWaitForTheWriterAndTheWriterForTheReaders) {
  Atlas atlas;
  const MapEditor editor(&atlas);
  std::atomic<bool> read{false};
  auto write = editor.Write(MapEdit::kFixture);
  std::thread reader([&] {
    auto lock = MapReader(atlas).Lock();
    read = true;
  });
  std::this_thread::sleep_for(std::chrono::milliseconds(30));
  EXPECT_FALSE(read.load());  // still held by the writer
  write.unlock();
  reader.join();
  EXPECT_TRUE(read.load());

  auto shared1 = MapReader(atlas).Lock();
  auto shared2 = MapReader(atlas).Lock();  // readers share
  std::atomic<bool> written{false};
  std::thread writer([&] {
    auto lock = editor.Write(MapEdit::kFixture);
    written = true;
  });
  std::this_thread::sleep_for(std::chrono::milliseconds(30));
  EXPECT_FALSE(written.load());
  shared1.unlock();
  shared2.unlock();
  writer.join();
  EXPECT_TRUE(written.load());
  EXPECT_EQ(StatsOf(atlas.EditStats(), MapEdit::kFixture).holds, 2);
}

}  // namespace
}  // namespace pkslam
