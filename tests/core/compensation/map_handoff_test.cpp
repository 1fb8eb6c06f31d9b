// The publication protocol between publishing threads and the servo thread, alone: what the
// servo side takes, when the publishing side may release a map, and that the servo side
// allocates nothing.

#include "core/compensation/map_handoff.h"

#include <memory>

#include <gtest/gtest.h>

#include "allocation_counter.h"
#include "autograv/map/gravity_map.h"
#include "field_map.h"

namespace autograv {
namespace {

std::shared_ptr<const GravityMap> smallMap(double gravity_z_n) {
  return testing::uniformFieldMap(WorkspaceGrid(Eigen::Vector3d::Zero(), 0.1, 2),
                                  Eigen::Vector3d(0.0, 0.0, gravity_z_n), "fake:handoff");
}

TEST(MapHandoffTest, TheServoSideTakesEachPublicationOnce) {
  MapHandoff handoff;
  const GravityMap* taken = nullptr;
  EXPECT_FALSE(handoff.hasNewPublication());
  EXPECT_FALSE(handoff.take(taken));

  const auto map = smallMap(1.0);
  handoff.publish(map);
  EXPECT_TRUE(handoff.hasNewPublication());
  EXPECT_TRUE(handoff.take(taken));
  EXPECT_EQ(taken, map.get());
  EXPECT_FALSE(handoff.hasNewPublication());
  EXPECT_FALSE(handoff.take(taken));
  EXPECT_EQ(handoff.latest(), map);
}

TEST(MapHandoffTest, OnlyTheLatestOfSeveralPublicationsIsTaken) {
  MapHandoff handoff;
  const auto first = smallMap(1.0);
  const auto second = smallMap(2.0);
  handoff.publish(first);
  handoff.publish(second);
  const GravityMap* taken = nullptr;
  EXPECT_TRUE(handoff.take(taken));
  EXPECT_EQ(taken, second.get());
  handoff.publish(nullptr);
  EXPECT_TRUE(handoff.take(taken));
  EXPECT_EQ(taken, nullptr);
  EXPECT_EQ(handoff.latest(), nullptr);
}

TEST(MapHandoffTest, MapsAreReleasedOnlyOnceTheServoSideAcknowledgedANewerOne) {
  MapHandoff handoff;
  std::weak_ptr<const GravityMap> first_alive;
  {
    auto first = smallMap(1.0);
    first_alive = first;
    handoff.publish(std::move(first));
  }
  const GravityMap* taken = nullptr;
  ASSERT_TRUE(handoff.take(taken));
  handoff.acknowledgeTaken();
  EXPECT_TRUE(handoff.latestAcknowledged());

  handoff.publish(smallMap(2.0));
  EXPECT_FALSE(handoff.latestAcknowledged());
  EXPECT_EQ(handoff.reclaimRetired(), 0u);  // the servo side may still read the first
  EXPECT_EQ(handoff.retainedCount(), 2u);
  EXPECT_FALSE(first_alive.expired());

  ASSERT_TRUE(handoff.take(taken));
  EXPECT_FALSE(handoff.latestAcknowledged());
  handoff.acknowledgeTaken();
  EXPECT_TRUE(handoff.latestAcknowledged());
  EXPECT_EQ(handoff.reclaimRetired(), 1u);
  EXPECT_EQ(handoff.retainedCount(), 1u);
  EXPECT_TRUE(first_alive.expired());
}

TEST(MapHandoffTest, TheServoSideAllocatesNothing) {
  MapHandoff handoff;
  const auto map = smallMap(1.0);
  handoff.publish(map);
  const GravityMap* taken = nullptr;
  testing::AllocationCounter counter;
  for (int k = 0; k < 1000; ++k) {
    if (handoff.hasNewPublication()) handoff.take(taken);
    handoff.acknowledgeTaken();
  }
  EXPECT_EQ(counter.count(), 0u);
  EXPECT_EQ(taken, map.get());
}

}  // namespace
}  // namespace autograv
