// LoadOptions::unknown_classes: a file of classes neither the program nor the file defines (a user's C++
// classes, read by a program that does not link them) is refused by default, and with Placeholder loads
// through stand-ins that keep the saved values.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <string>

#include "io_model.hpp"
#include "vsd/io/snapshot.hpp"

namespace {

using testing::HasSubstr;
using vsd::io::Format;
using vsd::io::LoadOptions;
using vsd::io::UnknownClasses;

LoadOptions placeholders() {
  LoadOptions o;
  o.unknown_classes = UnknownClasses::Placeholder;
  return o;
}

// The io model saved, with its test classes renamed to names no program has (same length, so the binary
// form stays valid): TRobot -> XRobot, TTool -> XTool, TSensor -> XSensor.
std::vector<std::uint8_t> unknown_model(Format format) {
  vsd::Environment env;
  vsd_test::build_model(env.main_state());
  auto bytes = vsd::io::save_bytes(env.main_state(), format);
  for (const std::string from : {"TRobot", "TTool", "TSensor"}) {
    auto it = bytes.begin();
    while ((it = std::search(it, bytes.end(), from.begin(), from.end())) != bytes.end()) *it++ = 'X';
  }
  return bytes;
}

class UnknownClassesTest : public testing::TestWithParam<Format> {
 protected:
  void TearDown() override {  // stand-ins live in the registry of the state that loaded them
    for (const char* name : {"XSensor", "XRobot", "XTool"})
      if (const auto* c = vsd::Registry::global().find_class_exact(name)) vsd::Registry::global().undefine(*c);
  }
};

TEST_P(UnknownClassesTest, AreRefusedByDefault) {
  vsd::Environment env;
  try {
    vsd::io::load_bytes(env.main_state(), unknown_model(GetParam()), "user.file");
    FAIL() << "loaded";
  } catch (const vsd::Error& e) {
    EXPECT_THAT(e.what(), HasSubstr("unknown class 'X"));
  }
  EXPECT_EQ(env.main_state().size(), 1u);
}

TEST_P(UnknownClassesTest, PlaceholdersKeepTheSavedValues) {
  vsd::Environment env;
  vsd::SimState& s = env.main_state();
  const auto report = vsd::io::load_bytes(s, unknown_model(GetParam()), "user.file", placeholders());
  EXPECT_THAT(report.placeholder_classes, testing::UnorderedElementsAre("XRobot", "XTool", "XSensor"));
  EXPECT_TRUE(report.defined_classes.empty());
  std::string warnings;
  for (const auto& w : report.warnings) warnings += w + "\n";
  EXPECT_THAT(warnings, HasSubstr("class 'XRobot' is not known to this program: its instances are shown "
                                  "through a stand-in derived from Node"));
  // (This program has TSensor, of XSensor's very shape: its stand-in may derive from that; an Extension
  // either way.)
  EXPECT_TRUE(env.registry().get_class("XSensor").is_a(vsd::Extension::static_meta()));

  const vsd::MetaInstance& robot_class = env.registry().get_class("XRobot");
  EXPECT_TRUE(robot_class.is_runtime());
  EXPECT_TRUE(robot_class.is_a(vsd::Node::static_meta()));
  const auto robots = s.index().exact(robot_class);
  ASSERT_EQ(robots.size(), 1u);
  vsd::SimStateInstance& arm = *robots[0];
  EXPECT_EQ(arm.as<vsd::Node>()->name(), "arm");
  EXPECT_EQ(arm.get("speed").to_text(), "2.5");
  EXPECT_EQ(arm.get("joints").to_text(), "[0.1, -0.2, 0.3]");
  // References keep their targets: to a known class typed as before, to an unknown one as any instance.
  const vsd::Value target = arm.get("target");
  EXPECT_EQ(robot_class.find_property("target")->type().name(), "shared<Node>");
  EXPECT_EQ(robot_class.find_property("tool")->type().name(), "ref<SimStateInstance>");
  const auto* tool = static_cast<const vsd::RefBase*>(robot_class.find_property("tool")->address(arm))->get();
  ASSERT_NE(tool, nullptr);
  EXPECT_EQ(tool->meta().name(), "XTool");
  EXPECT_EQ(tool->get("length").to_text(), "0.25");
  const auto* extension = arm.as<vsd::Node>()->extensions()[0];
  EXPECT_EQ(extension->meta().name(), "XSensor");
  EXPECT_EQ(extension->get("range").to_text(), "9");
}

TEST_P(UnknownClassesTest, CheckReportsThemAndLeavesNothingDefined) {
  const auto report =
      vsd::io::check_bytes(unknown_model(GetParam()), "user.file", vsd::Registry::global(), placeholders());
  EXPECT_EQ(report.placeholder_classes.size(), 3u);
  EXPECT_EQ(vsd::Registry::global().find_class_exact("XRobot"), nullptr);
}

TEST_P(UnknownClassesTest, AFailedLoadRemovesTheStandIns) {
  auto bytes = unknown_model(GetParam());
  bytes.resize(bytes.size() - 3);  // truncated: the load fails after the classes were read
  vsd::Environment env;
  EXPECT_THROW(vsd::io::load_bytes(env.main_state(), bytes, "cut.file", placeholders()), vsd::Error);
  EXPECT_EQ(env.registry().find_class_exact("XRobot"), nullptr);
  EXPECT_EQ(env.main_state().size(), 1u);
}

INSTANTIATE_TEST_SUITE_P(Formats, UnknownClassesTest, testing::Values(Format::Binary, Format::Text),
                         [](const auto& info) { return info.param == Format::Text ? "Text" : "Binary"; });

TEST(UnknownClassesText, NeedTheClassTable) {
  // Without "classes" the file does not say what the properties are: no stand-in can be made.
  const std::string text = R"({"format": "vsd-text", "version": 1, "kind": "state",
  "instances": [{"@id": 1, "@class": "Database", "name": "w", "extensions": [], "children": ["@2"]},
                {"@id": 2, "@class": "UserThing", "name": "t", "extensions": [], "children": []}]})";
  vsd::Environment env;
  try {
    vsd::io::load_bytes(env.main_state(), vsd_test::bytes_of(text), "hand.json", placeholders());
    FAIL() << "loaded";
  } catch (const vsd::Error& e) {
    EXPECT_THAT(e.what(), HasSubstr("unknown class 'UserThing'"));
  }
}

TEST(UnknownClassesText, PropertiesOfUnknownTypesAreLeftOutWithAWarning) {
  const std::string text = R"({"format": "vsd-text", "version": 1, "kind": "state",
  "classes": [{"class": "UserThing", "saved": {"name": "string", "extensions": "list<Extension>",
               "children": "list<Node>", "pose": "UserPose", "count": "int32"}}],
  "instances": [{"@id": 1, "@class": "Database", "name": "w", "extensions": [], "children": ["@2"]},
                {"@id": 2, "@class": "UserThing", "name": "t", "extensions": [], "children": [],
                 "pose": {"x": 1}, "count": 7}]})";
  vsd::Environment env;
  const auto report =
      vsd::io::load_bytes(env.main_state(), vsd_test::bytes_of(text), "hand.json", placeholders());
  ASSERT_EQ(report.roots.size(), 1u);
  EXPECT_EQ(report.roots[0]->get("count").to_text(), "7");
  EXPECT_EQ(report.roots[0]->meta().find_property("pose"), nullptr);
  std::string warnings;
  for (const auto& w : report.warnings) warnings += w + "\n";
  EXPECT_THAT(warnings, HasSubstr("left out: pose (of unknown type UserPose)"));
}

}  // namespace
