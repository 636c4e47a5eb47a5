// What a file's top level means (LoadReport::roots, "top" checked against the Database), and unknown
// members of class entries (warnings, not errors).
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "io_model.hpp"
#include "vsd/io/snapshot.hpp"

using testing::ElementsAre;
using testing::HasSubstr;
using vsd::io::Format;

using vsd_test::bytes_of;

namespace {


std::string load_error(vsd::SimState& state, const std::vector<std::uint8_t>& bytes, const char* origin) {
  const std::size_t before = state.size();
  try {
    vsd::io::load_bytes(state, bytes, origin);
  } catch (const vsd::Error& e) {
    EXPECT_EQ(state.size(), before) << "a rejected file changes nothing";
    return e.what();
  }
  return "<loaded>";
}

template <class Nodes>
std::vector<vsd::Id> ids_of(const Nodes& nodes) {
  std::vector<vsd::Id> out;
  for (const vsd::Node* n : nodes) out.push_back(n->id());
  return out;
}

const std::string head =
    "{\"format\": \"vsd-text\", \"version\": 1, \"kind\": \"state\",\n\"instances\": [\n";

TEST(TopLevel, RootsAreTheDatabasesChildrenInBothFormats) {
  vsd::Environment env;
  vsd_test::build_model(env.main_state());
  auto& second = env.main_state().create<vsd::Node>();
  env.main_state().database().add_child(second);
  for (const Format f : {Format::Binary, Format::Text}) {
    auto& copy = env.create_state(f == Format::Text ? "text" : "binary");
    const auto report = vsd::io::load_bytes(copy, vsd::io::save_bytes(env.main_state(), f));
    EXPECT_EQ(ids_of(report.roots), ids_of(copy.database().children()));
    ASSERT_EQ(report.roots.size(), 2u);
    for (const vsd::Node* n : report.roots) EXPECT_EQ(n->parent(), &copy.database()) << "attached";
    // Under a node the same nodes (with fresh ids) are the node's new children.
    auto& holder = env.main_state().create<vsd::Node>();
    const auto under = vsd::io::load_bytes(holder, vsd::io::save_bytes(env.main_state(), f));
    EXPECT_EQ(ids_of(under.roots), ids_of(holder.children()));
    env.main_state().destroy(holder);
  }
}

// A node has one parent and an extension one owner: a file that lists one twice is refused where the
// second listing is. The core lets a program make such a state (SimStateInstance::list_insert), so both
// formats can carry it.
TEST(TopLevel, ANodeHasOneParentInEveryFile) {
  vsd::Environment env;
  const std::string twice = head +
                            "{\"@id\": 2, \"@class\": \"Node\", \"children\": [\"@4\"]},\n"
                            "{\"@id\": 3, \"@class\": \"Node\", \"children\": [\"@5\", \"@4\"]},\n"
                            "{\"@id\": 4, \"@class\": \"Node\"}, {\"@id\": 5, \"@class\": \"Node\"}],\n"
                            "\"top\": [\"@2\", \"@3\"]}";
  EXPECT_EQ(
      load_error(env.main_state(), bytes_of(twice), "two.json"),
      "two.json:4:49: node #4 is already a child of #2: #3.children lists it too (a node has one parent)");
  const std::string same = head +
                           "{\"@id\": 2, \"@class\": \"Node\", \"children\": [\"@4\", \"@4\"]},\n"
                           "{\"@id\": 4, \"@class\": \"Node\"}], \"top\": [\"@2\"]}";
  EXPECT_EQ(load_error(env.main_state(), bytes_of(same), "same.json"),
            "same.json:3:49: node #4 is listed twice in #2.children (a node has one parent)");
  const std::string owners = head +
                             "{\"@id\": 2, \"@class\": \"Node\", \"extensions\": [\"@4\"]},\n"
                             "{\"@id\": 3, \"@class\": \"Node\", \"extensions\": [\"@4\"]},\n"
                             "{\"@id\": 4, \"@class\": \"Extension\"}], \"top\": [\"@2\", \"@3\"]}";
  EXPECT_THAT(
      load_error(env.main_state(), bytes_of(owners), "owners.json"),
      HasSubstr("owners.json:4:45: extension #4 is already attached to #2: #3.extensions lists it too"));

  // Written by a program, in both formats.
  vsd::SimState& s = env.main_state();
  auto& a = s.create<vsd::Node>();
  auto& b = s.create<vsd::Node>();
  auto& c = s.create<vsd::Node>();
  s.database().add_child(a);
  s.database().add_child(b);
  a.add_child(c);
  b.list_insert(vsd::Node::vsd_prop_children(), 0, c);
  for (const Format f : {Format::Binary, Format::Text}) {
    auto& copy = env.create_state(f == Format::Text ? "text" : "binary");
    const std::string e = load_error(copy, vsd::io::save_bytes(s, f), "file");
    EXPECT_THAT(
        e, HasSubstr("node #" + std::to_string(c.id()) + " is already a child of #" + std::to_string(a.id()) +
                     ": #" + std::to_string(b.id()) + ".children lists it too"));
    EXPECT_THAT(e, testing::StartsWith(f == Format::Text ? "file:" : "file: byte "));
  }
}

TEST(TopLevel, TextTopMustAgreeWithTheDatabase) {
  // #3 is a node of the file but not a child of the Database: "top" that names it is an error where it says
  // so.
  const std::string body =
      "{\"@id\": 1, \"@class\": \"Database\", \"children\": [\"@2\"]},\n"
      "{\"@id\": 2, \"@class\": \"Node\"},\n"
      "{\"@id\": 3, \"@class\": \"Node\"}\n],\n";
  vsd::Environment env;
  EXPECT_EQ(load_error(env.main_state(), bytes_of(head + body + "\"top\": [\"@3\"]}"), "t.json"),
            "t.json:7:9: \"top\" [#3] is not what the Database #1 holds as its children [#2]");
  EXPECT_THAT(load_error(env.main_state(), bytes_of(head + body + "\"top\": []}"), "t.json"),
              HasSubstr("t.json:7:8: \"top\" [] is not what the Database #1 holds as its children [#2]"));
  EXPECT_THAT(load_error(env.main_state(), bytes_of(head + body + "\"top\": [\"@2\", \"@3\"]}"), "t.json"),
              HasSubstr("t.json:7:15: \"top\" [#2, #3] is not"));
  // Without "top" the roots are derived; with the right one they agree.
  for (const std::string tail : {"\"top\": [\"@2\"]}", "\"unused\": 0}"}) {
    vsd::Environment fresh;
    const auto report = vsd::io::load_bytes(fresh.main_state(), bytes_of(head + body + tail), "t.json");
    ASSERT_EQ(report.roots.size(), 1u) << tail;
    EXPECT_EQ(report.roots[0]->id(), 2u);
    EXPECT_EQ(report.roots[0]->parent(), &fresh.main_state().database());
  }
}

TEST(TopLevel, BinaryTopMustAgreeWithTheDatabase) {
  vsd::Environment env;
  auto& a = env.main_state().create<vsd::Node>();
  auto& b = env.main_state().create<vsd::Node>();
  env.main_state().database().add_child(a);
  a.add_child(b);
  auto bytes = vsd::io::save_bytes(env.main_state(), Format::Binary);
  ASSERT_LT(b.id(), 128u);
  ASSERT_EQ(bytes.back(), a.id()) << "the file ends with the top ids (one-byte varints here)";
  bytes.back() = static_cast<std::uint8_t>(b.id());
  auto& copy = env.create_state("copy");
  EXPECT_EQ(load_error(copy, bytes, "s.vsds"),
            "s.vsds: byte " + std::to_string(bytes.size() - 1) + ": \"top\" [#" + std::to_string(b.id()) +
                "] is not what the Database #" + std::to_string(env.main_state().database().id()) +
                " holds as its children [#" + std::to_string(a.id()) + "]");
  bytes.pop_back();
  bytes.back() = 0;  // no top-level node at all
  EXPECT_THAT(load_error(copy, bytes, "s.vsds"),
              HasSubstr("s.vsds: byte " + std::to_string(bytes.size() - 1) + ": \"top\" [] is not what"));
}

// A state file without a Database (hand-written): "top" names the nodes that become the Database's
// children, and they are attached, never left floating.
TEST(TopLevel, StateFileWithoutDatabaseAttachesTop) {
  const std::string file = head +
                           "{\"@id\": 4, \"@class\": \"Node\", \"children\": [\"@5\"]},\n"
                           "{\"@id\": 5, \"@class\": \"Node\"}],\n\"top\": [\"@4\"]}";
  vsd::Environment env;
  const auto report = vsd::io::load_bytes(env.main_state(), bytes_of(file), "t.json");
  ASSERT_EQ(report.roots.size(), 1u);
  EXPECT_EQ(report.roots[0]->id(), 4u);
  EXPECT_THAT(ids_of(env.main_state().database().children()), ElementsAre(4u));
  // A top-level node that another instance holds would have two parents.
  vsd::Environment other;
  const std::string held = head +
                           "{\"@id\": 4, \"@class\": \"Node\", \"children\": [\"@5\"]},\n"
                           "{\"@id\": 5, \"@class\": \"Node\"}],\n\"top\": [\"@4\", \"@5\"]}";
  EXPECT_EQ(
      load_error(other.main_state(), bytes_of(held), "t.json"),
      "t.json:3:42: top-level node #5 is held by #4.children: a load attaches it, so nothing in the file "
      "may hold it");
}

TEST(TopLevel, SubtreeFilesNameTheirRoot) {
  const std::string sub =
      "{\"format\": \"vsd-text\", \"version\": 1, \"kind\": \"subtree\",\n"
      "\"instances\": [{\"@id\": 4, \"@class\": \"Node\"}]";
  vsd::Environment env;
  EXPECT_EQ(load_error(env.main_state(), bytes_of(sub + ", \"top\": []}"), "t.json"),
            "t.json:2:53: a subtree file names its root in \"top\"");
  EXPECT_EQ(load_error(env.main_state(), bytes_of(sub + "}"), "t.json"),
            "t.json:1:1: a subtree file names its root in \"top\"");
  EXPECT_EQ(load_error(env.main_state(), bytes_of(sub + ", \"top\": [\"@4\", \"@4\"]}"), "t.json"),
            "t.json:2:60: top-level node #4 is listed twice");
}

TEST(TopLevel, UnknownMembersOfClassesAreWarnings) {
  const std::string file =
      "{\"format\": \"vsd-text\", \"version\": 1, \"kind\": \"subtree\",\n"
      "\"classes\": [{\"class\": \"IoTopLevelBelt\", \"base\": \"Node\", \"color\": \"red\",\n"
      "  \"properties\": [{\"name\": \"speed\", \"type\": \"double\", \"unit\": \"m/s\", \"default\": 2}]},\n"
      "  {\"class\": \"Node\", \"since\": 3}],\n"
      "\"instances\": [{\"@id\": 4, \"@class\": \"IoTopLevelBelt\"}], \"top\": [\"@4\"]}";
  vsd::Environment env;
  const auto report = vsd::io::load_bytes(env.main_state(), bytes_of(file), "t.json");
  EXPECT_THAT(report.warnings,
              ElementsAre("t.json:2:57: unknown member 'color' in a class is ignored",
                          "t.json:3:54: unknown member 'unit' in a property definition is ignored",
                          "t.json:4:21: unknown member 'since' in a class is ignored"));
  ASSERT_EQ(report.roots.size(), 1u);
  EXPECT_EQ(report.roots[0]->get<double>("speed"), 2.0);
  env.main_state().destroy(*report.roots[0]);
  vsd::Registry::global().undefine(vsd::Registry::global().get_class("IoTopLevelBelt"));
}

}  // namespace
