#include "vsd/core/node.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "test_classes.hpp"

using testing::ElementsAre;
using testing::HasSubstr;

namespace {

struct NodeTest : testing::Test {
  vsd::Environment env;
  vsd::SimState& state = env.main_state();
  vsd::Database& root = state.database();

  vsd::Node& node(const std::string& name) {
    auto& n = state.create<vsd::Node>();
    n.set_name(name);
    return n;
  }
  static std::vector<std::string> names(const vsd::Node& n) {
    std::vector<std::string> out;
    for (vsd::Node* c : n.children()) out.push_back(c->name());
    return out;
  }
};

TEST_F(NodeTest, AddInsertAndFindChildren) {
  auto& a = node("a");
  auto& b = node("b");
  auto& c = node("c");
  root.add_child(a);
  root.add_child(c);
  root.insert_child(1, b);
  EXPECT_THAT(names(root), ElementsAre("a", "b", "c"));
  EXPECT_EQ(root.find_child("b"), &b);
  EXPECT_EQ(root.find_child("zz"), nullptr);
  EXPECT_EQ(b.parent(), &root);
  EXPECT_EQ(root.parent(), nullptr);
}

TEST_F(NodeTest, PathJoinsNamesFromTheRoot) {
  auto& robot = node("robot");
  auto& arm = node("arm");
  root.add_child(robot);
  robot.add_child(arm);
  EXPECT_EQ(arm.path(), "/robot/arm");
  EXPECT_EQ(root.path(), "/");
}

TEST_F(NodeTest, MovingAChildKeepsItAlive) {
  auto& from = node("from");
  auto& to = node("to");
  auto& child = node("child");
  root.add_child(from);
  root.add_child(to);
  from.add_child(child);
  const vsd::Id id = child.id();
  to.add_child(child);
  ASSERT_NE(state.find(id), nullptr);
  EXPECT_EQ(child.parent(), &to);
  EXPECT_TRUE(from.children().empty());
  EXPECT_EQ(child.composite_count(), 1u);
}

TEST_F(NodeTest, MovingWithinTheSameParentReorders) {
  auto& a = node("a");
  auto& b = node("b");
  auto& c = node("c");
  root.add_child(a);
  root.add_child(b);
  root.add_child(c);
  root.insert_child(0, c);
  EXPECT_THAT(names(root), ElementsAre("c", "a", "b"));
  root.add_child(c);
  EXPECT_THAT(names(root), ElementsAre("a", "b", "c"));
  EXPECT_EQ(c.composite_count(), 1u);
}

TEST_F(NodeTest, RemovingAChildDeletesIt) {
  auto& a = node("a");
  root.add_child(a);
  const vsd::Id id = a.id();
  root.remove_child(a);
  EXPECT_EQ(state.find(id), nullptr);
}

TEST_F(NodeTest, RemovingANonChildIsAnError) {
  auto& a = node("a");
  EXPECT_THAT([&] { root.remove_child(a); }, testing::ThrowsMessage<vsd::Error>(HasSubstr("not a child")));
}

TEST_F(NodeTest, VisitGoesDepthFirstParentsFirst) {
  auto& a = node("a");
  auto& b = node("b");
  auto& c = node("c");
  root.add_child(a);
  a.add_child(b);
  root.add_child(c);
  std::vector<std::string> seen;
  root.visit([&](vsd::Node& n) { seen.push_back(n.name()); });
  EXPECT_THAT(seen, ElementsAre("", "a", "b", "c"));
}

TEST_F(NodeTest, VisitAndPathReachAnyDepth) {
  vsd::Node* at = &root;
  for (int i = 0; i < 100'000; ++i) at = &at->add_child(node(i % 2 == 0 ? "x" : "y"));
  std::size_t count = 0;
  root.visit([&](vsd::Node&) { ++count; });  // a recursion per level overflowed the stack here
  EXPECT_EQ(count, 100'001u);
  EXPECT_EQ(at->path().size(), 200'000u);
  EXPECT_TRUE(root.contains(*at));
  EXPECT_EQ(root.size(), 100'001u);
}

TEST_F(NodeTest, ExtensionsAttachToNodesAndToExtensions) {
  auto& n = node("n");
  auto& sensor = state.create<vsd_test::TSensor>();
  auto& sub = state.create<vsd::Extension>();
  n.add_extension(sensor);
  sensor.add_extension(sub);
  EXPECT_EQ(sensor.owner(), &n);
  EXPECT_EQ(sub.owner(), &sensor);
  EXPECT_EQ(n.find_extension<vsd_test::TSensor>(), &sensor);
  EXPECT_EQ(n.find_extension<vsd::Extension>(), &sensor);
  EXPECT_EQ(sensor.find_extension<vsd_test::TSensor>(), nullptr);
  // Deleting the node deletes its extensions and theirs.
  root.add_child(n);
  const vsd::Id is = sensor.id(), iu = sub.id();
  root.remove_child(n);
  EXPECT_EQ(state.find(is), nullptr);
  EXPECT_EQ(state.find(iu), nullptr);
}

TEST_F(NodeTest, ExtensionsMoveBetweenOwners) {
  auto& a = node("a");
  auto& b = node("b");
  auto& e = state.create<vsd::Extension>();
  a.add_extension(e);
  b.add_extension(e);
  EXPECT_EQ(e.owner(), &b);
  EXPECT_TRUE(a.extensions().empty());
  const vsd::Id id = e.id();
  b.remove_extension(e);  // its last composite holder: e is deleted
  EXPECT_EQ(state.find(id), nullptr);
  auto& loose = state.create<vsd::Extension>();
  EXPECT_THAT([&] { b.remove_extension(loose); },
              testing::ThrowsMessage<vsd::Error>(HasSubstr("not attached")));
}

TEST_F(NodeTest, DatabaseIsTheContainerOfTheTree) {
  auto& a = node("a");
  auto& b = node("b");
  auto& loose = node("loose");
  root.add_child(a);
  a.add_child(b);
  EXPECT_EQ(root.size(), 3u);
  EXPECT_TRUE(root.contains(b));
  EXPECT_FALSE(root.contains(loose));
  std::vector<std::string> order;
  root.for_each([&](vsd::Node& n) { order.push_back(n.name()); });
  EXPECT_THAT(order, ElementsAre("", "a", "b"));
  EXPECT_EQ(root.id(), 1u);
  EXPECT_THAT([&] { state.destroy(root); },
              testing::ThrowsMessage<vsd::Error>(HasSubstr("cannot be deleted")));
}

TEST_F(NodeTest, DatabaseSignalsAttachAndDetach) {
  std::vector<std::string> log;
  auto c1 = root.on_added().connect([&](vsd::Node& n) { log.push_back("+" + n.name()); });
  auto c2 = root.on_removed().connect([&](vsd::Node& n) { log.push_back("-" + n.name()); });
  auto& a = node("a");
  auto& b = node("b");
  auto& loose = node("loose");
  auto& inner = node("inner");
  loose.add_child(inner);  // not in the tree: no signal
  root.add_child(a);
  a.add_child(b);
  a.remove_child(b);
  EXPECT_THAT(log, ElementsAre("+a", "+b", "-b"));
}

}  // namespace
