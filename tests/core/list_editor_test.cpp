#include "vsd/core/list_editor.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "test_classes.hpp"

using testing::ElementsAre;
using testing::HasSubstr;
using vsd_test::TRobot;
using vsd_test::TTool;

namespace {

struct ListEditorTest : testing::Test {
  vsd::Environment env;
  vsd::SimState& state = env.main_state();
  vsd::Database& root = state.database();

  vsd::Node& node(const std::string& name) {
    auto& n = state.create<vsd::Node>();
    n.set_name(name);
    root.add_child(n);
    return n;
  }
  static std::vector<std::string> names(const vsd::ListEditor<vsd::Node>& l) {
    std::vector<std::string> out;
    for (vsd::Node* n : l) out.push_back(n->name());
    return out;
  }
};

TEST_F(ListEditorTest, EditsASharedListTypedRecordedAndSignalled) {
  auto& r = state.create<TRobot>();
  auto& a = node("a");
  auto& b = node("b");
  auto& c = node("c");
  int signals = 0;
  auto conn = r.on_changed().connect([&](vsd::SimStateInstance&, const vsd::MetaProperty& p) {
    EXPECT_EQ(&p, &TRobot::vsd_prop_watched());
    ++signals;
  });
  state.start_recording();
  auto watched = r.edit_watched();
  watched.push_back(a);
  watched.push_back(c);
  watched.insert(1, b);
  EXPECT_THAT(names(watched), ElementsAre("a", "b", "c"));
  EXPECT_EQ(watched.size(), 3u);
  EXPECT_EQ(watched[2], &c);
  EXPECT_EQ(watched.index_of(b), 1u);
  EXPECT_TRUE(r.watched().contains(&b)) << "the property itself sees the edits";
  EXPECT_TRUE(watched.remove(a));
  EXPECT_FALSE(watched.remove(a));
  watched.erase(0);
  EXPECT_THAT(names(watched), ElementsAre("c"));
  const vsd::Transaction t = state.stop_recording();
  EXPECT_EQ(signals, 5);
  EXPECT_EQ(t.size(), 5u) << t.describe();
  EXPECT_THAT(t.describe(), HasSubstr("insert #" + std::to_string(b.id()) + " into #" +
                                      std::to_string(r.id()) + ".watched[1]"));
  state.apply(t.inverted());  // undo, operation by operation
  EXPECT_TRUE(r.watched().empty());
  EXPECT_EQ(a.composite_count(), 1u) << "a shared list does not count";
}

TEST_F(ListEditorTest, ErasingFromACompositeListReleasesTheElement) {
  auto& parent = node("parent");
  auto& child = state.create<vsd::Node>();
  parent.edit_children().push_back(child);
  EXPECT_EQ(child.parent(), &parent);
  EXPECT_FALSE(child.is_floating());
  const vsd::Id id = child.id();
  parent.edit_children().clear();
  EXPECT_EQ(state.find(id), nullptr);
}

TEST_F(ListEditorTest, BadEditsAreErrorsThatChangeNothing) {
  auto& r = state.create<TRobot>();
  auto& a = node("a");
  auto watched = r.edit_watched();
  EXPECT_THAT([&] { watched.insert(2, a); }, testing::ThrowsMessage<vsd::Error>(HasSubstr("past the end")));
  EXPECT_THAT([&] { watched.erase(0); }, testing::ThrowsMessage<vsd::Error>(HasSubstr("out of")));
  auto& other = env.create_state("other");
  auto& far = other.create<vsd::Node>();
  EXPECT_THAT([&] { watched.push_back(far); },
              testing::ThrowsMessage<vsd::Error>(HasSubstr("different SimStates")));
  EXPECT_TRUE(watched.empty());
  auto& tool = state.create<TTool>();
  root.add_child(tool);
  auto kids = tool.edit_children();
  EXPECT_THAT([&] { kids.push_back(tool); },
              testing::ThrowsMessage<vsd::Error>(HasSubstr("its own ancestor")));
  EXPECT_EQ(tool.parent(), &root);
}

TEST_F(ListEditorTest, OnlyReferenceListsHaveAnEditor) {
  static_assert(vsd::detail::IsRefList<vsd::RefList<vsd::Node>>);
  static_assert(vsd::detail::IsRefList<vsd::SharedRefList<TTool>>);
  static_assert(!vsd::detail::IsRefList<vsd::Ref<vsd::Node>>);
  static_assert(!vsd::detail::IsRefList<std::vector<double>>);
  auto& r = state.create<TRobot>();
  auto editor = r.edit_children();
  static_assert(std::is_same_v<decltype(editor), vsd::ListEditor<vsd::Node>>);
  EXPECT_TRUE(editor.empty());
}

}  // namespace
