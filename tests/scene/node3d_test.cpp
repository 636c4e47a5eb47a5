// World frames of Node3D: correct after any change, recomputed only below what moved.
#include "vsd/scene/node3d.hpp"

#include <gtest/gtest.h>

#include <vector>

#include "vsd/core.hpp"
#include "vsd/io.hpp"
#include "vsd/scene.hpp"

namespace vsd::scene {
namespace {

Eigen::Isometry3d step(double x, double angle) {
  Eigen::Isometry3d f = Eigen::Isometry3d::Identity();
  f.translate(Eigen::Vector3d(x, 0.5, 0));
  f.rotate(Eigen::AngleAxisd(angle, Eigen::Vector3d::UnitZ()));
  return f;
}

// The world frame recomputed from scratch, by the definition (product of frames up the Node3D ancestors).
Eigen::Isometry3d expected_world(const Node3D& n) {
  Eigen::Isometry3d w = n.frame();
  for (const Node3D* p = n.frame_parent(); p != nullptr; p = p->frame_parent()) w = p->frame() * w;
  return w;
}

struct Chain {
  explicit Chain(SimState& s, int depth) {
    for (int i = 0; i < depth; ++i) {
      Node3D& n = s.create<Node3D>();
      n.set_name("n" + std::to_string(i));
      n.set_frame(step(1.0, 0.1 * (i + 1)));
      if (i == 0) {
        s.database().add_child(n);
      } else {
        nodes.back()->add_child(n);
      }
      nodes.push_back(&n);
      // A sibling at every level: it must never be recomputed by changes on the chain.
      Node3D& side = s.create<Node3D>();
      side.set_frame(step(-1.0, -0.2));
      if (i == 0) {
        s.database().add_child(side);
      } else {
        nodes[nodes.size() - 2]->add_child(side);
      }
      siblings.push_back(&side);
    }
  }
  std::vector<Node3D*> nodes;
  std::vector<Node3D*> siblings;
};

class Node3DTest : public ::testing::Test {
 protected:
  void SetUp() override { env.use<Module>(); }
  void expect_all_correct(const Chain& c) {
    for (const Node3D* n : c.nodes)
      EXPECT_TRUE(n->world_frame().isApprox(expected_world(*n), 1e-12)) << n->name();
    for (const Node3D* n : c.siblings) EXPECT_TRUE(n->world_frame().isApprox(expected_world(*n), 1e-12));
  }
  Environment env;
  SimState& s = env.main_state();
};

TEST_F(Node3DTest, WorldFrameIsProductOfFramesInDeepTree) {
  Chain c(s, 40);
  expect_all_correct(c);
  // Reading again is a load: nothing is recomputed.
  std::vector<std::uint64_t> before;
  for (const Node3D* n : c.nodes) before.push_back(n->world_frame_updates());
  expect_all_correct(c);
  for (std::size_t i = 0; i < c.nodes.size(); ++i) EXPECT_EQ(c.nodes[i]->world_frame_updates(), before[i]);
  for (const Node3D* n : c.nodes) EXPECT_EQ(n->world_frame_updates(), 1u);
}

TEST_F(Node3DTest, MovedRootUpdatesEveryDescendantOnce) {
  Chain c(s, 30);
  expect_all_correct(c);
  c.nodes[0]->set_frame(step(5.0, 1.0));
  for (const Node3D* n : c.nodes) EXPECT_FALSE(n->world_frame_clean());
  expect_all_correct(c);
  for (const Node3D* n : c.nodes) EXPECT_EQ(n->world_frame_updates(), 2u);
  // Siblings of the root are beside it; siblings below it are part of its subtree.
  EXPECT_EQ(c.siblings[0]->world_frame_updates(), 1u);
  for (std::size_t i = 1; i < c.siblings.size(); ++i) EXPECT_EQ(c.siblings[i]->world_frame_updates(), 2u);
}

TEST_F(Node3DTest, MovedLeafTouchesNothingAboveOrBeside) {
  Chain c(s, 30);
  expect_all_correct(c);
  Node3D* leaf = c.nodes.back();
  leaf->set_frame(step(0.25, -0.5));
  EXPECT_FALSE(leaf->world_frame_clean());
  for (std::size_t i = 0; i + 1 < c.nodes.size(); ++i) EXPECT_TRUE(c.nodes[i]->world_frame_clean());
  expect_all_correct(c);
  EXPECT_EQ(leaf->world_frame_updates(), 2u);
  for (std::size_t i = 0; i + 1 < c.nodes.size(); ++i) EXPECT_EQ(c.nodes[i]->world_frame_updates(), 1u);
  for (const Node3D* n : c.siblings) EXPECT_EQ(n->world_frame_updates(), 1u);
}

TEST_F(Node3DTest, MovedMiddleRecomputesOnlyItsSubtree) {
  Chain c(s, 20);
  expect_all_correct(c);
  c.nodes[10]->set_frame(step(2.0, 0.7));
  expect_all_correct(c);
  for (int i = 0; i < 20; ++i) EXPECT_EQ(c.nodes[i]->world_frame_updates(), i < 10 ? 1u : 2u) << i;
  // Siblings at levels 0..10 hang off nodes above the moved one (or beside it).
  for (int i = 0; i < 20; ++i) EXPECT_EQ(c.siblings[i]->world_frame_updates(), i <= 10 ? 1u : 2u) << i;
}

TEST_F(Node3DTest, ReadingALeafComputesOnlyItsChain) {
  Chain c(s, 10);
  EXPECT_TRUE(c.nodes[5]->world_frame().isApprox(expected_world(*c.nodes[5])));
  for (int i = 0; i < 10; ++i) EXPECT_EQ(c.nodes[i]->world_frame_clean(), i <= 5) << i;
  for (const Node3D* n : c.siblings) EXPECT_FALSE(n->world_frame_clean());
}

TEST_F(Node3DTest, GenericSetsAndBurstsAreSeen) {
  Chain c(s, 10);
  expect_all_correct(c);
  // Through the meta-information, not the setter.
  c.nodes[3]->set("frame", step(-3.0, 2.0));
  expect_all_correct(c);
  Node3D::vsd_prop_frame().set(*c.nodes[7], step(0.0, 0.3));
  expect_all_correct(c);
  // A burst of changes costs one recomputation per node read.
  for (int k = 0; k < 50; ++k) c.nodes[0]->set_frame(step(0.01 * k, 0.02 * k));
  expect_all_correct(c);
  EXPECT_EQ(c.nodes[9]->world_frame_updates(), 4u);
}

TEST_F(Node3DTest, ReparentingMovesTheWorldFrame) {
  Chain a(s, 8);
  Chain b(s, 8);
  expect_all_correct(a);
  expect_all_correct(b);
  b.nodes[0]->set_frame(step(100.0, 0.0));
  (void)b.nodes[0]->world_frame();
  // Move a's tail (nodes 4..7) under b's node 2; b's node 2 stays clean, the moved subtree gets dirty.
  const Ref<Node3D> keep(a.nodes[3]);     // a free Ref keeps the removed child alive
  a.nodes[2]->remove_child(*a.nodes[3]);  // detached: world = own frame
  EXPECT_EQ(a.nodes[3]->frame_parent(), nullptr);
  EXPECT_TRUE(a.nodes[3]->world_frame().isApprox(a.nodes[3]->frame()));
  EXPECT_TRUE(a.nodes[7]->world_frame().isApprox(expected_world(*a.nodes[7])));
  b.nodes[2]->add_child(*a.nodes[3]);
  EXPECT_EQ(a.nodes[3]->frame_parent(), b.nodes[2]);
  EXPECT_FALSE(a.nodes[7]->world_frame_clean());
  expect_all_correct(a);
  expect_all_correct(b);
  EXPECT_GT(a.nodes[7]->world_frame().translation().x(), 90.0);
}

TEST_F(Node3DTest, DeletingNodesWithCleanCachesIsSafe) {
  Chain c(s, 12);
  expect_all_correct(c);
  // Deleting a middle node deletes its subtree (nothing else holds it); the rest stays correct and clean.
  const Id leaf_id = c.nodes.back()->id();
  s.destroy(*c.nodes[6]);
  EXPECT_EQ(s.find(leaf_id), nullptr);
  c.nodes.resize(6);
  c.siblings.resize(7);  // sibling 6 hung off node 5, which survives
  for (const Node3D* n : c.nodes) EXPECT_TRUE(n->world_frame_clean());
  expect_all_correct(c);
  c.nodes[0]->set_frame(step(4, 4));
  expect_all_correct(c);
  s.destroy(*c.nodes[0]);
  EXPECT_EQ(s.size(), 2u);  // the Database and the top-level sibling
}

TEST_F(Node3DTest, UndoAndLoadingUnderANodeKeepWorldFramesCurrent) {
  Chain c(s, 6);
  expect_all_correct(c);
  const Eigen::Isometry3d before = c.nodes[5]->world_frame();
  s.start_recording();
  c.nodes[2]->set_frame(step(8, 0.9));
  c.nodes[4]->set_frame(step(-2, 0.1));
  const Transaction t = s.stop_recording();
  EXPECT_FALSE(c.nodes[5]->world_frame().isApprox(before));
  s.apply(t.inverted());  // undo
  EXPECT_TRUE(c.nodes[5]->world_frame().isApprox(before, 1e-12));
  expect_all_correct(c);
  // A subtree saved and loaded under a moved Node3D of the same state hangs below it.
  const auto bytes = io::save_bytes(*c.nodes[3], io::Format::Binary);
  Node3D& anchor = s.create<Node3D>();
  anchor.set_frame(step(50, 0));
  s.database().add_child(anchor);
  (void)anchor.world_frame();
  const io::LoadReport r = io::load_bytes(anchor, bytes);
  ASSERT_EQ(r.roots.size(), 1u);
  auto* loaded = r.roots[0]->as<Node3D>();
  ASSERT_NE(loaded, nullptr);
  EXPECT_TRUE(loaded->world_frame().isApprox(anchor.frame() * c.nodes[3]->frame(), 1e-12));
  loaded->visit([&](Node& n) {
    if (auto* n3 = n.as<Node3D>()) {
      EXPECT_TRUE(n3->world_frame().isApprox(expected_world(*n3), 1e-12));
    }
  });
}

TEST_F(Node3DTest, DeletedGeometryNullsTheHullsThatShareIt) {
  Hull& a = s.create<Hull>();
  Hull& b = s.create<Hull>();
  s.database().add_child(a);
  s.database().add_child(b);
  Geometry& g = s.create<Geometry>();
  g.set_kind(GeometryKind::Capsule);
  a.set_geometry(&g);
  b.set_geometry(&g);
  int changes = 0;
  Connection watch = b.on_changed().connect([&](SimStateInstance&, const MetaProperty& p) {
    if (p.name() == "geometry") ++changes;
  });
  s.destroy(g);
  EXPECT_EQ(a.geometry().get(), nullptr);
  EXPECT_EQ(b.geometry().get(), nullptr);
  EXPECT_EQ(changes, 1);  // a collision module following the hull hears of it
}

TEST_F(Node3DTest, PlainNodesInBetweenAreTransparent) {
  Node3D& top = s.create<Node3D>();
  s.database().add_child(top);
  Node& group = s.create<Node>();
  top.add_child(group);
  Node3D& leaf = s.create<Node3D>();
  group.add_child(leaf);
  top.set_frame(step(1, 0.5));
  leaf.set_frame(step(2, 0.25));
  EXPECT_EQ(leaf.frame_parent(), &top);
  EXPECT_TRUE(leaf.world_frame().isApprox(top.frame() * leaf.frame()));
  // Moving the plain group to another Node3D moves the leaf.
  Node3D& other = s.create<Node3D>();
  other.set_frame(step(-7, 0));
  s.database().add_child(other);
  other.add_child(group);
  EXPECT_TRUE(leaf.world_frame().isApprox(other.frame() * leaf.frame()));
}

TEST_F(Node3DTest, SetWorldFrameSolvesForTheRelativeFrame) {
  Chain c(s, 5);
  const Eigen::Isometry3d target = step(3, 1.2);
  c.nodes[4]->set_world_frame(target);
  EXPECT_TRUE(c.nodes[4]->world_frame().isApprox(target, 1e-12));
  expect_all_correct(c);
}

TEST_F(Node3DTest, ReplicaKeepsItsWorldFramesCurrent) {
  Chain c(s, 6);
  SimState& replica = env.create_state("replica");
  replica.copy_from(s);
  auto* r5 = replica.find(c.nodes[5]->id())->as<Node3D>();
  ASSERT_NE(r5, nullptr);
  EXPECT_TRUE(r5->world_frame().isApprox(c.nodes[5]->world_frame(), 1e-12));
  s.start_recording();
  c.nodes[1]->set_frame(step(9, -1));
  replica.apply(s.stop_recording());
  EXPECT_TRUE(r5->world_frame().isApprox(c.nodes[5]->world_frame(), 1e-12));
  EXPECT_TRUE(r5->world_frame().isApprox(expected_world(*r5), 1e-12));
}

// Every state of the environment keeps its world frames, whenever and however it was made, and states
// come and go in any order (run under ASan in CI).
TEST_F(Node3DTest, StatesMadeCopiedAndRemovedInAnyOrderKeepTheirWorldFrames) {
  Chain c(s, 4);
  SimState& a = env.create_state("a");
  a.copy_from(s);
  SimState& b = env.create_state("b");
  b.copy_from(a);
  auto* b3 = b.find(c.nodes[3]->id())->as<Node3D>();
  EXPECT_TRUE(b3->world_frame().isApprox(c.nodes[3]->world_frame(), 1e-12));  // clean caches in b
  s.start_recording();
  c.nodes[0]->set_frame(step(2, 0.3));
  const Transaction t = s.stop_recording();
  env.remove_state(a);  // the older copy goes first, while b has clean caches
  b.apply(t);
  EXPECT_FALSE(b3->world_frame_clean()) << "b's own watch heard the applied bundle";
  EXPECT_TRUE(b3->world_frame().isApprox(c.nodes[3]->world_frame(), 1e-12));
  SimState& late = env.create_state("late");
  late.copy_from(b);
  env.remove_state(b);
  auto* l3 = late.find(c.nodes[3]->id())->as<Node3D>();
  EXPECT_TRUE(l3->world_frame().isApprox(c.nodes[3]->world_frame(), 1e-12));
  late.find(c.nodes[1]->id())->as<Node3D>()->set_frame(step(-3, 1.0));
  EXPECT_TRUE(l3->world_frame().isApprox(expected_world(*l3), 1e-12));
}

TEST_F(Node3DTest, WithoutTheModulesServiceCachesAreForgottenAndRebuiltOnRead) {
  Chain c(s, 3);
  Node3D& leaf = *c.nodes[2];
  (void)leaf.world_frame();
  EXPECT_TRUE(leaf.world_frame_clean());
  env.set_service<Module>(s, Service::none);
  EXPECT_FALSE(leaf.world_frame_clean()) << "no watch: no cache can be trusted";
  c.nodes[0]->set_frame(step(4, 0.2));
  EXPECT_TRUE(leaf.world_frame().isApprox(expected_world(leaf), 1e-12)) << "a read makes the watch again";
  c.nodes[0]->set_frame(step(5, 0.1));
  EXPECT_TRUE(leaf.world_frame().isApprox(expected_world(leaf), 1e-12));
}

}  // namespace
}  // namespace vsd::scene
