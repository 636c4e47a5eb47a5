// How a load changes the target state: the loader builds the state straight from its checked model
// (detail::StateBuilder) instead of applying a bundle, and must still do what applying that bundle did:
// the same signals, the same recording, every check before the first change, and no crash when a
// listener deletes what the load made.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "io_model.hpp"
#include "vsd/io/snapshot.hpp"

using testing::HasSubstr;
using vsd_test::build_model;
using vsd_test::bytes_of;
using vsd_test::diff_of;

namespace {

std::size_t child_links(const vsd::SimState& s) {
  std::size_t n = 0;
  for (const vsd::SimStateInstance* x : s.instances())
    if (const auto* node = x->as<vsd::Node>()) n += node->children().size();
  return n;
}

class LoadApply : public testing::TestWithParam<vsd::io::Format> {
 protected:
  static vsd::io::Format format() { return GetParam(); }
};

TEST_P(LoadApply, EveryCreationAndEveryChildIsSignalledWhileTheStateCountsAsApplying) {
  vsd::Environment env;
  build_model(env.main_state());
  const auto bytes = vsd::io::save_bytes(env.main_state(), format());
  auto& copy = env.create_state("copy");
  std::size_t created = 0, applying = 0, children = 0;
  auto c1 = copy.on_created().connect([&](vsd::SimStateInstance&) {
    ++created;
    applying += copy.applying() ? 1 : 0;
  });
  auto c2 = copy.on_child_added().connect([&](vsd::Node&, vsd::Node&) { ++children; });
  const auto report = vsd::io::load_bytes(copy, bytes);
  EXPECT_EQ(created, report.instances);
  EXPECT_EQ(applying, created) << "listeners hear a load as an applied change";
  EXPECT_EQ(children, child_links(env.main_state()));
  EXPECT_FALSE(copy.applying());
  EXPECT_EQ(diff_of(env.main_state(), copy), "");
}

// A load into a recording state records what it did: the recording rebuilds the same state elsewhere,
// as a whole state and under a node.
TEST_P(LoadApply, ARecordingStateRecordsTheLoad) {
  vsd::Environment env;
  build_model(env.main_state());
  const auto bytes = vsd::io::save_bytes(env.main_state(), format());

  auto& whole = env.create_state("whole");
  whole.start_recording();
  vsd::io::load_bytes(whole, bytes);
  const vsd::Transaction t = whole.stop_recording();
  auto& replica = env.create_state("replica");
  replica.apply(t);
  EXPECT_EQ(diff_of(whole, replica), "");
  EXPECT_EQ(diff_of(env.main_state(), replica), "");

  auto& under = env.create_state("under");
  auto& mount = under.create<vsd::Node>();
  mount.set_name("mount");
  under.database().add_child(mount);
  const vsd::Transaction before = under.snapshot();
  under.start_recording();
  const auto report = vsd::io::load_bytes(mount, bytes);
  const vsd::Transaction load = under.stop_recording();
  auto& replica2 = env.create_state("replica2");
  replica2.apply(before);
  replica2.apply(load);
  EXPECT_EQ(diff_of(under, replica2), "");
  ASSERT_EQ(report.roots.size(), 1u);
  EXPECT_EQ(report.roots[0]->parent(), &mount);
  EXPECT_EQ(vsd_test::check_reference_counts(replica2), "");
}

// A listener may delete what the load has made so far: the load stops with an error that says so, and
// nothing dangles (under ASan, a use of the deleted instance would be reported).
TEST_P(LoadApply, AListenerThatDeletesALoadedInstanceStopsTheLoadSafely) {
  vsd::Environment env;
  build_model(env.main_state());
  const auto bytes = vsd::io::save_bytes(env.main_state(), format());
  auto& copy = env.create_state("copy");
  auto c = copy.on_created().connect([&](vsd::SimStateInstance& x) {
    if (auto* n = x.as<vsd::Node>(); n != nullptr && n->name() == "goal") copy.destroy(x);
  });
  EXPECT_THAT([&] { vsd::io::load_bytes(copy, bytes, "m"); },
              testing::ThrowsMessage<vsd::Error>(
                  testing::AllOf(HasSubstr("m: instance #"), HasSubstr("was deleted by a listener"))));
  EXPECT_EQ(vsd_test::check_reference_counts(copy), "");
  EXPECT_FALSE(copy.applying());
  for (const vsd::SimStateInstance* x : copy.instances()) {
    if (const auto* n = x->as<vsd::Node>()) {
      EXPECT_NE(n->name(), "goal");
    }
  }
}

// A model with enough list elements (3 groups of 40) that a load makes its links in one block
// (detail::LinkBlock), which its links own: editing, deleting and moving them must free the block exactly
// once, after the last of them (AddressSanitizer and LeakSanitizer check the memory).
void build_groups(vsd::SimState& s) {
  for (int g = 0; g < 3; ++g) {
    auto& group = s.create<vsd::Node>();
    group.set_name("group" + std::to_string(g));
    s.database().add_child(group);
    for (int i = 0; i < 40; ++i) {
      auto& leaf = s.create<vsd::Node>();
      leaf.set_name("leaf" + std::to_string(i));
      group.add_child(leaf);
    }
  }
}

vsd::Node& child_of(const vsd::Node& n, std::size_t i) { return *n.children().at(i)->as<vsd::Node>(); }
vsd::Node& group_of(vsd::SimState& s, std::size_t g) { return child_of(s.database(), g); }

TEST_P(LoadApply, LinksOfALoadSurviveEditingAndGoWithTheirLists) {
  vsd::Environment env;
  build_groups(env.main_state());
  const auto bytes = vsd::io::save_bytes(env.main_state(), format());
  auto& copy = env.create_state("copy");
  vsd::io::load_bytes(copy, bytes);
  vsd::Node& g0 = group_of(copy, 0);
  vsd::Node& g1 = group_of(copy, 1);
  // Loaded links and new ones (from the heap) side by side; deleting frees loaded links one by one.
  auto& extra = copy.create<vsd::Node>();
  extra.set_name("extra");
  g0.add_child(extra);
  copy.destroy(child_of(g0, 3));
  g1.remove_child(child_of(g1, 0));
  EXPECT_EQ(g0.children().size(), 40U);
  EXPECT_EQ(g1.children().size(), 39U);
  EXPECT_EQ(child_of(g0, 3).name(), "leaf4");
  EXPECT_EQ(vsd_test::check_reference_counts(copy), "");
  copy.destroy(g1);  // a whole loaded list at once
  EXPECT_EQ(copy.database().children().size(), 2U);
  EXPECT_EQ(group_of(copy, 1).children().size(), 40U);
  EXPECT_EQ(vsd_test::check_reference_counts(copy), "");
}

// A list of loaded links moved out of its property into free storage outlives its SimState (and the
// Environment): the block stays until its last link is freed, not until the state dies.
TEST_P(LoadApply, LoadedLinksMovedOutOfTheirStateOutliveIt) {
  std::vector<std::uint8_t> bytes;
  {
    vsd::Environment env;
    build_groups(env.main_state());
    bytes = vsd::io::save_bytes(env.main_state(), format());
  }
  const vsd::MetaProperty& children = vsd::Node::vsd_prop_children();
  alignas(std::max_align_t) unsigned char taken[sizeof(std::vector<void*>) * 4];
  ASSERT_GE(sizeof(taken), children.type().size());
  {
    auto env = std::make_unique<vsd::Environment>();
    vsd::io::load_bytes(env->main_state(), bytes);
    vsd::Node& g2 = group_of(env->main_state(), 2);
    children.type().move_construct(taken, const_cast<void*>(children.address(g2)));
    EXPECT_EQ(g2.children().size(), 0U);
    EXPECT_EQ(static_cast<const vsd::RefListBase*>(static_cast<void*>(taken))->size(), 40U);
  }  // the Environment and its states go; the moved links stay, detached
  children.type().destroy(taken);
}

// A listener that stops a big load half way leaves the unused rest of the block behind, and the links
// already made keep working.
TEST_P(LoadApply, ALoadStoppedHalfWayFreesItsUnusedLinks) {
  vsd::Environment env;
  build_groups(env.main_state());
  const auto bytes = vsd::io::save_bytes(env.main_state(), format());
  auto& copy = env.create_state("copy");
  bool deleted = false;
  auto c = copy.on_child_added().connect([&](vsd::Node& parent, vsd::Node& child) {
    if (deleted || child.name() != "leaf20") return;
    deleted = true;  // a group that is still to get its children
    for (std::size_t g = 0; g < 3; ++g)
      if (&group_of(copy, g) != &parent && group_of(copy, g).children().empty()) {
        copy.destroy(group_of(copy, g));
        return;
      }
  });
  EXPECT_THROW(vsd::io::load_bytes(copy, bytes), vsd::Error);
  EXPECT_EQ(vsd_test::check_reference_counts(copy), "");
  c.disconnect();
  while (!copy.database().children().empty()) copy.destroy(child_of(copy.database(), 0));
  for (vsd::SimStateInstance* x : copy.instances())
    if (x != &copy.database()) copy.destroy(*x);
  EXPECT_EQ(copy.size(), 1U);
}

INSTANTIATE_TEST_SUITE_P(Formats, LoadApply, testing::Values(vsd::io::Format::Binary, vsd::io::Format::Text),
                         [](const auto& info) {
                           return info.param == vsd::io::Format::Text ? std::string("Text")
                                                                      : std::string("Binary");
                         });

// What a bundle's dry run used to find in the target state is found before the first change: an instance
// whose id is the Database's loads nothing, signals nothing, and leaves no class the file defined behind.
TEST(LoadApplyChecks, AnIdThatClashesWithTheDatabaseLoadsNothing) {
  const std::string text = R"({
  "format": "vsd-text", "version": 1, "kind": "subtree",
  "classes": [
    {"class": "LaClash", "base": "Node", "abstract": false,
     "properties": [{"name": "mass", "type": "double", "flags": "Savable", "default": 1}],
     "saved": {"name": "string", "mass": "double"}}
  ],
  "instances": [
    {"@id": 7, "@class": "Node", "name": "first"},
    {"@id": 1, "@class": "LaClash", "name": "clash", "mass": 2}
  ],
  "top": ["@7", "@1"]
})";
  vsd::Environment env;
  vsd::SimState& s = env.main_state();
  std::size_t signals = 0;
  auto c1 = s.on_created().connect([&](vsd::SimStateInstance&) { ++signals; });
  auto c2 = s.on_child_added().connect([&](vsd::Node&, vsd::Node&) { ++signals; });
  s.start_recording();
  EXPECT_THAT([&] { vsd::io::load_bytes(s, bytes_of(text), "clash.json"); },
              testing::ThrowsMessage<vsd::Error>(
                  testing::AllOf(HasSubstr("clash.json:10:"), HasSubstr("instance #1 already exists"))));
  EXPECT_EQ(s.size(), 1u);
  EXPECT_EQ(signals, 0u);
  EXPECT_TRUE(s.take_recording().empty());
  EXPECT_EQ(env.registry().find_class("LaClash"), nullptr) << "a failed load leaves no class behind";

  // Under a node the same file gets fresh ids and loads.
  auto& mount = s.create<vsd::Node>();
  s.database().add_child(mount);
  const auto report = vsd::io::load_bytes(mount, bytes_of(text), "clash.json");
  EXPECT_EQ(report.instances, 2u);
  EXPECT_EQ(mount.children().size(), 2u);
  EXPECT_EQ(report.defined_classes, std::vector<std::string>{"LaClash"});
}

}  // namespace
