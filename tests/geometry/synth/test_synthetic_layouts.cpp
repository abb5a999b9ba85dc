// The camera layouts of the synthetic scenes: counts, splits, cameras inside rooms and clear
// of objects, the spacing each layout promises, walls and doors.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <utility>
#include <vector>

#include "geometry/synth/synthetic_scene.h"
#include "tests/geometry/synth/synth_test_support.h"

using namespace saresgs;
using namespace saresgs::synth_test;

TEST(SyntheticLayouts, ObjectLayoutCountsAndHemisphere) {
  const SyntheticScene& s = scene("object");
  ASSERT_EQ(s.cameras.size(), 150u);
  ASSERT_EQ(s.names.size(), 150u);
  EXPECT_EQ(s.names[0], "0000.png");
  EXPECT_EQ(s.names[149], "0149.png");
  ASSERT_EQ(s.train.size(), 100u);
  ASSERT_EQ(s.test.size(), 50u);
  for (int i = 0; i < 100; ++i) EXPECT_EQ(s.train[i], i);
  for (int i = 0; i < 50; ++i) EXPECT_EQ(s.test[i], 100 + i);
  for (const Camera& c : s.cameras) {
    const Eigen::Vector3d p = c.center();
    EXPECT_NEAR(p.norm(), 4.0, 1e-9);
    const double el = std::asin(p.z() / p.norm()) * 180 / std::numbers::pi;
    EXPECT_GE(el, 10.0 - 1e-9);
    EXPECT_LE(el, 80.0 + 1e-9);
    EXPECT_GT(c.viewDirection().dot(-p.normalized()), 1 - 1e-9);  // looks at the origin
    EXPECT_TRUE(s.intersect(p.cast<float>(), c.viewDirection().cast<float>()).hit);
  }
  // Test views are at positions of their own.
  for (int t : s.test)
    for (int r : s.train) EXPECT_GT((s.cameras[t].center() - s.cameras[r].center()).norm(), 1e-3);
  EXPECT_EQ(s.background, Eigen::Vector3f(1, 1, 1));
}

TEST(SyntheticLayouts, RoomLayoutsKeepCamerasInsideTheRoomAndOutsideObjects) {
  for (const char* layout : {"room360", "unbalanced", "tworooms", "corridor"}) {
    const SyntheticScene& s = scene(layout);
    const auto n = s.cameras.size();
    EXPECT_GE(n, 140u) << layout;
    EXPECT_LE(n, 160u) << layout;
    ASSERT_EQ(s.train.size() + s.test.size(), n);
    for (int i : s.test) EXPECT_EQ(i % 8, 0);
    for (int i : s.train) EXPECT_NE(i % 8, 0);
    ASSERT_TRUE(s.manifest.contains("room")) << layout;
    const Eigen::AlignedBox3f room(vec3(s.manifest["room"]["min"]), vec3(s.manifest["room"]["max"]));
    std::vector<Eigen::AlignedBox3f> boxes;
    for (const auto& o : s.manifest["objects"])
      if (o["name"].get<std::string>().rfind("room_", 0) != 0)
        boxes.emplace_back(vec3(o["bbox_min"]), vec3(o["bbox_max"]));
    EXPECT_GE(boxes.size(), 4u);
    for (std::size_t i = 0; i < n; ++i) {
      const Eigen::Vector3f c = s.cameras[i].center().cast<float>();
      EXPECT_TRUE(room.contains(c)) << layout << " camera " << i;
      // At least 20 cm from every wall.
      EXPECT_GT((c - room.min()).minCoeff(), 0.2f) << layout << " camera " << i;
      EXPECT_GT((room.max() - c).minCoeff(), 0.2f) << layout << " camera " << i;
      for (const auto& b : boxes) EXPECT_FALSE(b.contains(c)) << layout << " camera " << i;
      const SurfaceHit h = s.intersect(c, s.cameras[i].viewDirection().cast<float>());
      EXPECT_TRUE(h.hit) << layout << " camera " << i;
      EXPECT_GT(h.distance, 0.3f) << layout << " camera " << i << " faces a surface too close";
    }
  }
}

TEST(SyntheticLayouts, ContentObjectsDoNotIntersect) {
  for (const char* layout : {"room360", "unbalanced", "tworooms", "corridor"}) {
    const SyntheticScene& s = scene(layout);
    std::vector<Eigen::AlignedBox3f> boxes;
    for (const auto& o : s.manifest["objects"])
      if (o["name"].get<std::string>().rfind("room_", 0) != 0)
        boxes.emplace_back(vec3(o["bbox_min"]), vec3(o["bbox_max"]));
    for (std::size_t i = 0; i < boxes.size(); ++i)
      for (std::size_t j = i + 1; j < boxes.size(); ++j)
        EXPECT_FALSE(boxes[i].intersects(boxes[j])) << layout << " " << i << " " << j;
    // Everything stands on the floor (z = room min) and stays inside the room.
    const Eigen::AlignedBox3f room(vec3(s.manifest["room"]["min"]), vec3(s.manifest["room"]["max"]));
    for (const auto& b : boxes) {
      EXPECT_NEAR(b.min().z(), room.min().z(), 1e-4f);
      EXPECT_TRUE(room.contains(b)) << layout;
    }
  }
}

TEST(SyntheticLayouts, UnbalancedSpacingIsUnevenRoom360IsEven) {
  const auto unb = nearestNeighbourDistances(scene("unbalanced").cameras);
  const auto orbit = nearestNeighbourDistances(scene("room360").cameras);
  const double r_unb = *std::max_element(unb.begin(), unb.end()) / median(unb);
  const double r_orbit = *std::max_element(orbit.begin(), orbit.end()) / median(orbit);
  EXPECT_GT(r_unb, 3.0);
  EXPECT_LT(r_orbit, 2.5);
}

TEST(SyntheticLayouts, SomeObjectsAreHiddenFromSomeUnbalancedViews) {
  // The pillars and the partition occlude: for some camera and content object, the
  // segment from the camera to the object's centre top is blocked by an occluder.
  const SyntheticScene& s = scene("unbalanced");
  const auto names = s.objectNames();
  int blocked_by_occluder = 0;
  for (const auto& o : s.manifest["objects"]) {
    const std::string name = o["name"];
    if (name.rfind("room_", 0) == 0 || name.rfind("pillar", 0) == 0 || name == "partition") continue;
    const Eigen::Vector3f top = 0.5f * (vec3(o["bbox_min"]) + vec3(o["bbox_max"]));
    for (const Camera& c : s.cameras) {
      const Eigen::Vector3f cc = c.center().cast<float>();
      const SurfaceHit h = s.intersect(cc, top - cc, 0.0f, 1.0f);
      if (h.hit) {
        const std::string& by = names[h.object];
        if (by.rfind("pillar", 0) == 0 || by == "partition") ++blocked_by_occluder;
      }
    }
  }
  EXPECT_GT(blocked_by_occluder, 10);
}

// A room layout's manifest split into its dividing walls (room_divider_*) and its content
// objects (everything not named room_*), by bounding box.
struct RoomParts {
  std::vector<Eigen::AlignedBox3f> dividers;
  std::vector<std::pair<std::string, Eigen::AlignedBox3f>> content;  // name, box
};
RoomParts roomParts(const SyntheticScene& s) {
  RoomParts p;
  for (const auto& o : s.manifest["objects"]) {
    const std::string name = o["name"];
    const Eigen::AlignedBox3f box(vec3(o["bbox_min"]), vec3(o["bbox_max"]));
    if (name.rfind("room_divider", 0) == 0)
      p.dividers.push_back(box);
    else if (name.rfind("room_", 0) != 0)
      p.content.emplace_back(name, box);
  }
  return p;
}

TEST(SyntheticLayouts, TwoRoomsIsRealMeshesBehindAWallWithADoor) {
  const SyntheticScene& s = scene("tworooms");
  const auto names = s.objectNames();
  // The content is CGAL's meshes, three per room; the divider has a doorway.
  std::vector<Eigen::AlignedBox3f> dividers;
  std::vector<Eigen::Vector3f> first_room;  // centres of the content objects at x < 0
  int content = 0;
  for (const auto& o : s.manifest["objects"]) {
    const std::string name = o["name"];
    const Eigen::AlignedBox3f box(vec3(o["bbox_min"]), vec3(o["bbox_max"]));
    if (name.rfind("room_divider", 0) == 0) {
      dividers.push_back(box);
    } else if (name.rfind("room_", 0) != 0) {
      ++content;
      EXPECT_EQ(o["mesh"].get<std::string>().rfind("cgal:", 0), 0u) << name;
      if (box.center().x() < 0) first_room.push_back(box.center());
    }
  }
  EXPECT_EQ(content, 6);
  EXPECT_EQ(first_room.size(), 3u);
  ASSERT_EQ(dividers.size(), 3u);
  // The walk passes the wall's plane through the door only: no camera inside the wall.
  int in_first = 0, in_second = 0;
  for (const Camera& c : s.cameras) {
    const Eigen::Vector3f p = c.center().cast<float>();
    for (const auto& b : dividers) EXPECT_FALSE(b.contains(p));
    (p.x() < 0 ? in_first : in_second) += 1;
  }
  EXPECT_GT(in_first, 50);
  EXPECT_GT(in_second, 50);
  // From the second room the wall hides the first room's objects from most cameras, and
  // the doorway shows them to some.
  int hidden_by_wall = 0, through_door = 0;
  for (const Camera& c : s.cameras) {
    const Eigen::Vector3f cc = c.center().cast<float>();
    if (cc.x() < 0.1f) continue;
    for (const Eigen::Vector3f& target : first_room) {
      const SurfaceHit h = s.intersect(cc, target - cc, 0.0f, 1.0f);
      const bool by_wall = h.hit && names[h.object].rfind("room_divider", 0) == 0;
      hidden_by_wall += by_wall;
      // Where the segment crosses x = 0: clear inside the doorway (|y| < 0.55, z < 2.1),
      // stopped by the wall, or by something before it, outside (10 cm margins: the
      // wall is 16 cm thick).
      const float t0 = cc.x() / (cc.x() - target.x());
      const Eigen::Vector3f at = cc + t0 * (target - cc);
      const bool in_door = std::abs(at.y()) < 0.45f && at.z() < 2.0f;
      const bool outside = std::abs(at.y()) > 0.65f || at.z() > 2.2f;
      if (in_door) {
        EXPECT_FALSE(by_wall) << "segment through the door at (" << at.y() << ", " << at.z() << ")";
      }
      if (outside) {
        EXPECT_TRUE(by_wall || (h.hit && h.distance < t0 * (target - cc).norm()))
            << "segment through the wall at (" << at.y() << ", " << at.z() << ")";
      }
      through_door += in_door;
    }
  }
  EXPECT_GT(hidden_by_wall, 100);
  EXPECT_GT(through_door, 5);
}

TEST(SyntheticLayouts, CorridorIsThreeRoomsWithDoorsOnOppositeSidesAndAnUnevenWalk) {
  const SyntheticScene& s = scene("corridor");
  const auto names = s.objectNames();
  const RoomParts parts = roomParts(s);
  const std::vector<Eigen::AlignedBox3f>& dividers = parts.dividers;
  std::vector<Eigen::Vector3f> first_room;  // centres of the content objects at x < -3
  for (const auto& [name, box] : parts.content)
    if (box.center().x() < -3) first_room.push_back(box.center());
  EXPECT_EQ(parts.content.size(), 7u);
  EXPECT_EQ(first_room.size(), 2u);
  ASSERT_EQ(dividers.size(), 6u);
  // The walk visits the three rooms in order and never stands inside a wall.
  int per_room[3] = {0, 0, 0};
  int last_room = 0;
  for (const Camera& c : s.cameras) {
    const Eigen::Vector3f p = c.center().cast<float>();
    for (const auto& b : dividers) EXPECT_FALSE(b.contains(p));
    const int room = p.x() < -3 ? 0 : (p.x() < 3 ? 1 : 2);
    EXPECT_GE(room, last_room) << "the walk goes back a room";
    last_room = room;
    ++per_room[room];
  }
  EXPECT_GT(per_room[0], 40);
  EXPECT_GT(per_room[1], 10);
  EXPECT_GT(per_room[2], 60);
  // Uneven: the densest views are far closer together than the sparsest.
  const auto nn = nearestNeighbourDistances(s.cameras);
  EXPECT_GT(*std::max_element(nn.begin(), nn.end()) / median(nn), 3.0);
  // The doors are on opposite sides: from the third room the first room's objects are
  // hidden from every camera, by a wall or by what stands before it.
  int third_room_segments = 0, by_wall = 0;
  for (const Camera& c : s.cameras) {
    const Eigen::Vector3f cc = c.center().cast<float>();
    if (cc.x() < 3.2f) continue;
    for (const Eigen::Vector3f& target : first_room) {
      ++third_room_segments;
      const SurfaceHit h = s.intersect(cc, target - cc, 0.0f, 1.0f);
      ASSERT_TRUE(h.hit);
      // The segment stops at the first room's wall or before it.
      EXPECT_GT(h.point.x(), -3.1f) << "the third room sees " << names[h.object] << " in the first";
      by_wall += names[h.object].rfind("room_divider", 0) == 0;
    }
  }
  EXPECT_GT(third_room_segments, 100);
  EXPECT_GT(by_wall, third_room_segments / 2);
}

TEST(SyntheticLayouts, NumViewsOverridesTheCountAndSeedsChangeLayouts) {
  for (const char* layout : {"object", "room360", "unbalanced", "tworooms", "corridor"}) {
    SyntheticOptions o;
    o.layout = layout;
    o.width = 64;
    o.height = 48;
    o.num_views = 40;
    const SyntheticScene s = makeSyntheticScene(o);
    EXPECT_EQ(s.cameras.size(), 40u) << layout;
    EXPECT_EQ(s.train.size() + s.test.size(), 40u) << layout;
    EXPECT_FALSE(s.test.empty());
    EXPECT_EQ(s.manifest["num_views"], 40);
    EXPECT_EQ(s.cameras[0].K.width, 64);
    o.seed = 1;
    const SyntheticScene t = makeSyntheticScene(o);
    EXPECT_GT((t.cameras[5].center() - s.cameras[5].center()).norm(), 1e-3) << layout;
  }
}

TEST(SyntheticLayouts, ManifestDescribesTheScene) {
  const SyntheticScene& s = scene("room360");
  const auto& m = s.manifest;
  EXPECT_EQ(m["layout"], "room360");
  EXPECT_EQ(m["seed"], 3);
  EXPECT_EQ(m["width"], 128);
  EXPECT_EQ(m["height"], 96);
  EXPECT_EQ(m["num_views"], 150);
  ASSERT_EQ(m["objects"].size(), s.objectNames().size());
  EXPECT_NEAR(vec3(m["light"]["direction"]).norm(), 1.0f, 1e-5f);
  EXPECT_GE(m["light"]["ambient"].get<double>(), 0.3);
  std::set<std::string> textures;
  int procedural_objects = 0;
  for (const auto& o : m["objects"]) {
    EXPECT_EQ(o["mesh"].get<std::string>().rfind("procedural:", 0), 0u);
    EXPECT_EQ(o["transform"].size(), 4u);
    textures.insert(o["texture"]);
    if (o["name"].get<std::string>().rfind("room_", 0) != 0) ++procedural_objects;
  }
  EXPECT_GE(procedural_objects, 4);
  EXPECT_LE(procedural_objects, 6);
  // The six room faces are told apart by their textures.
  std::set<std::string> room_textures;
  for (const auto& o : m["objects"])
    if (o["name"].get<std::string>().rfind("room_", 0) == 0) room_textures.insert(o["texture"]);
  EXPECT_EQ(room_textures.size(), 6u);
}

// ------------------------------------------------------------------ surface samples
