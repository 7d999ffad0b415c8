// Tracking's cursor into a map's world-change log (tracking/world_change_cursor.h).
#include "tracking/world_change_cursor.h"

#include <gtest/gtest.h>

#include <cmath>

#include "map_model/atlas.h"
#include "map_model/map.h"
#include "map_model/map_editor.h"

namespace pkslam {
namespace {

WorldChange Transform(double yaw, double scale) {
  WorldChange change;
  change.kind = WorldChange::Kind::kTransform;
  change.rotation = SO3d::Exp(Eigen::Vector3d(0, 0, yaw));
  change.scale = scale;
  return change;
}

class WorldChangeCursorTest : public ::testing::Test {
 protected:
  void Record(const WorldChange& change) {
    auto lock = MapEditor(&atlas_).Write(MapEdit::kFixture);
    atlas_.current_map()->RecordWorldChange(lock, change);
  }
  Map& map() { return *atlas_.current_map(); }

  Atlas atlas_;
  WorldChangeCursor cursor_;
};

TEST_F(WorldChangeCursorTest, TheFirstLookAtAMapCarriesNothingAndTheNextSeesNoChange) {
  Record(Transform(0.3, 2.0));  // before tracking looked: already in the keyframes it sees
  const WorldChangesSeen first = cursor_.Follow(map());
  EXPECT_TRUE(first.new_map);
  EXPECT_FALSE(first.changed);
  EXPECT_FALSE(first.single_transform.has_value());
  EXPECT_FALSE(first.scale_ratio.has_value());
  const WorldChangesSeen again = cursor_.Follow(map());
  EXPECT_FALSE(again.ForgetsLastFrame());
}

TEST_F(WorldChangeCursorTest, OneTransformIsCarriedAcrossWithItsScale) {
  cursor_.Follow(map());
  WorldChange states;  // kInertialState: re-estimated in place, no transform
  Record(states);
  const WorldChangesSeen re_estimated = cursor_.Follow(map());
  EXPECT_TRUE(re_estimated.changed);
  EXPECT_EQ(re_estimated.transforms, 0);
  EXPECT_FALSE(re_estimated.scale_ratio.has_value());

  Record(Transform(0.3, 2.5));
  Record(states);
  const WorldChangesSeen moved = cursor_.Follow(map());
  EXPECT_TRUE(moved.changed);
  EXPECT_EQ(moved.transforms, 1);
  ASSERT_TRUE(moved.single_transform.has_value());
  EXPECT_NEAR(moved.single_transform->rotation.Log().z(), 0.3, 1e-12);
  ASSERT_TRUE(moved.scale_ratio.has_value());
  EXPECT_DOUBLE_EQ(*moved.scale_ratio, 2.5);
}

TEST_F(WorldChangeCursorTest, SeveralTransformsAreNotCarriedButTheirScalesMultiply) {
  cursor_.Follow(map());
  Record(Transform(0.1, 2.0));
  Record(Transform(-0.2, 1.5));
  const WorldChangesSeen seen = cursor_.Follow(map());
  EXPECT_EQ(seen.transforms, 2);
  EXPECT_FALSE(seen.single_transform.has_value());
  ASSERT_TRUE(seen.scale_ratio.has_value());
  EXPECT_DOUBLE_EQ(*seen.scale_ratio, 3.0);
  EXPECT_FALSE(cursor_.Follow(map()).ForgetsLastFrame()) << "each change is reported once";
}

TEST_F(WorldChangeCursorTest, ANewMapRestartsTheCursorAtItsEnd) {
  cursor_.Follow(map());
  {
    auto lock = MapEditor(&atlas_).Write(MapEdit::kFixture);
    atlas_.CreateNewMap(lock);
  }
  Record(Transform(0.2, 4.0));
  const WorldChangesSeen seen = cursor_.Follow(map());
  EXPECT_TRUE(seen.new_map);
  EXPECT_EQ(seen.transforms, 0) << "the new map's log is read from its end";
  Record(Transform(0.1, 0.5));
  const WorldChangesSeen next = cursor_.Follow(map());
  ASSERT_TRUE(next.scale_ratio.has_value());
  EXPECT_DOUBLE_EQ(*next.scale_ratio, 0.5) << "relative to the new map's scale when first seen";
}

}  // namespace
}  // namespace pkslam
