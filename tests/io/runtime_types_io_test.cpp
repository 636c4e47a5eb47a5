// Files carry the run-time types (enums, flags, structs) their classes use, and qualified class names.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <random>

#include "io_model.hpp"
#include "vsd/io/file.hpp"
#include "vsd/io/snapshot.hpp"

using testing::ElementsAre;
using testing::HasSubstr;
using testing::MatchesRegex;
using vsd::io::Format;

namespace ion_scene {
VSD_CLASS_NAMESPACE("scene")
class Robot : public vsd::Node {
  VSD_INSTANCE(Robot, vsd::Node)
  VSD_PROPERTY(double, reach, 1.0)
};
class Hull : public vsd::Node {
  VSD_INSTANCE(Hull, vsd::Node)
  VSD_PROPERTY(vsd::SharedRef<Robot>, pilot, nullptr)
};
}  // namespace ion_scene

namespace ion_robotics {
VSD_CLASS_NAMESPACE("robotics")
class Robot : public vsd::Node {
  VSD_INSTANCE(Robot, vsd::Node)
  VSD_PROPERTY(int, axes, 6)
};
}  // namespace ion_robotics

using vsd_test::bytes_of;
using vsd_test::text_of;

namespace {

vsd::Registry& global() { return vsd::Registry::global(); }

class Files : public testing::TestWithParam<Format> {
 protected:
  static Format format() { return GetParam(); }
};

// ---- qualified class names ----

TEST_P(Files, ClassesOfOneShortNameInTwoNamespaces) {
  vsd::Environment env;
  vsd::SimState& s = env.main_state();
  auto& a = s.create<ion_scene::Robot>();
  auto& b = s.create<ion_robotics::Robot>();
  auto& h = s.create<ion_scene::Hull>();
  a.set_reach(3);
  b.set_axes(4);
  h.set_pilot(&a);
  for (vsd::Node* n : {static_cast<vsd::Node*>(&a), static_cast<vsd::Node*>(&b), static_cast<vsd::Node*>(&h)})
    s.database().add_child(*n);
  const auto bytes = vsd::io::save_bytes(s, format());
  if (format() == Format::Text) {
    EXPECT_THAT(text_of(bytes), HasSubstr("\"@class\": \"scene::Robot\""));
    EXPECT_THAT(text_of(bytes), HasSubstr("\"@class\": \"robotics::Robot\""));
    EXPECT_THAT(text_of(bytes), HasSubstr("\"pilot\": \"shared<scene::Robot>\""));
  }
  auto& copy = env.create_state("copy");
  vsd::io::load_bytes(copy, bytes);
  EXPECT_TRUE(s.equals(copy));
  EXPECT_EQ(copy.find<ion_robotics::Robot>(b.id())->axes(), 4);
  EXPECT_EQ(copy.find<ion_scene::Hull>(h.id())->pilot().get(), copy.find<ion_scene::Robot>(a.id()));
  EXPECT_EQ(vsd::io::save_bytes(copy, format()), bytes);
}

TEST(QualifiedNames, HandWrittenFilesMayUseUniqueShortNames) {
  global().add<ion_scene::Robot>();
  global().add<ion_robotics::Robot>();
  global().add<ion_scene::Hull>();
  const std::string head =
      "{\"format\": \"vsd-text\", \"version\": 1, \"kind\": \"subtree\",\n\"instances\": [\n";
  vsd::Environment env;
  const auto report = vsd::io::load_bytes(
      env.main_state(), bytes_of(head + "{\"@id\": 2, \"@class\": \"Hull\"}], \"top\": [\"@2\"]}"), "t.json");
  ASSERT_EQ(report.roots.size(), 1u);
  EXPECT_TRUE(report.roots[0]->is_a<ion_scene::Hull>());
  try {
    vsd::io::load_bytes(env.main_state(),
                        bytes_of(head + "{\"@id\": 3, \"@class\": \"Robot\"}], \"top\": [\"@3\"]}"),
                        "t.json");
    ADD_FAILURE() << "an ambiguous short name loaded";
  } catch (const vsd::Error& e) {
    EXPECT_STREQ(e.what(),
                 "t.json:3:22: class name 'Robot' is ambiguous: it may be 'robotics::Robot', "
                 "'scene::Robot' (use the full name)");
  }
}

// ---- run-time types ----

// The "writing program": run-time types and a run-time class using them, one instance, saved.
struct Written {
  std::vector<std::uint8_t> bytes;
  std::string values;  // the instance's values as text
};

const char* const type_names[] = {"IoRtColor", "IoRtTag", "IoRtAccess"};

void undefine_all() {
  if (const auto* c = global().find_class("IoRtMarker")) global().undefine(*c);
  for (const char* name : {"IoRtAccess", "IoRtTag", "IoRtColor"})
    if (const auto* t = global().find_type(name)) global().undefine(*t);
}

std::string values_of(const vsd::SimStateInstance& x) {
  std::string out;
  for (const vsd::MetaProperty* p : x.meta().properties()) {
    out += p->name() + "=";
    if (!p->type().is_reference()) p->type().write_text(p->address(x), out);
    out += ";";
  }
  return out;
}

Written write_with_types(Format format) {
  const vsd::MetaType& color = vsd::EnumBuilder("IoRtColor")
                                   .underlying(vsd::meta_type<std::int16_t>())
                                   .value("Red", -1)
                                   .value("Blue", 9)
                                   .define();
  const vsd::MetaType& tag = vsd::StructBuilder("IoRtTag")
                                 .field<std::string>("label")
                                 .field("color", color)
                                 .field<Eigen::Vector3d>("at")
                                 .define();
  const vsd::MetaType& access = vsd::EnumBuilder("IoRtAccess", vsd::TypeKind::Flags)
                                    .underlying(vsd::meta_type<std::uint8_t>())
                                    .value("Read", 1)
                                    .value("Write", 2)
                                    .define();
  const vsd::MetaInstance& marker =
      vsd::ClassBuilder("IoRtMarker", vsd::Node::static_meta())
          .property("main", tag, vsd::Value::from_text(tag, "{\"label\": \"default\", \"color\": \"Blue\"}"))
          .property("tags", global().get_type("vector<IoRtTag>"))
          .property("access", access)
          .property("colors", global().get_type("vector<IoRtColor>"))
          .define();
  Written w;
  {
    vsd::Environment env;
    auto& m = static_cast<vsd::Node&>(env.main_state().create(marker));
    m.set_name("m");
    m.set("main",
          vsd::Value::from_text(tag, "{\"label\": \"first\", \"color\": \"Red\", \"at\": [1, 2, 3]}"));
    m.set("tags", vsd::Value::from_text(global().get_type("vector<IoRtTag>"),
                                        "[{\"label\": \"a\"}, {\"label\": \"b\", \"color\": 5}]"));
    m.set("access", vsd::Value::from_text(access, "\"Read|Write\""));
    m.set("colors", vsd::Value::from_text(global().get_type("vector<IoRtColor>"), "[\"Blue\", \"Red\"]"));
    env.main_state().database().add_child(m);
    w.bytes = vsd::io::save_bytes(env.main_state(), format);
    w.values = values_of(m);
  }
  undefine_all();  // the reading program never defined them
  return w;
}

TEST_P(Files, RunTimeTypesTravelWithTheFile) {
  const Written w = write_with_types(format());
  if (format() == Format::Text) {
    EXPECT_THAT(text_of(w.bytes), HasSubstr("\"version\": 2,"));
    EXPECT_THAT(
        text_of(w.bytes),
        HasSubstr("  \"types\": [\n"
                  "    {\"type\": \"IoRtColor\", \"kind\": \"enum\", \"underlying\": \"int16\", "
                  "\"values\": [[\"Red\", -1], [\"Blue\", 9]]},\n"
                  "    {\"type\": \"IoRtTag\", \"kind\": \"struct\", \"fields\": [[\"label\", \"string\"], "
                  "[\"color\", \"IoRtColor\"], [\"at\", \"Vector3d\"]]},\n"
                  "    {\"type\": \"IoRtAccess\", \"kind\": \"flags\", \"underlying\": \"uint8\", "
                  "\"values\": [[\"Read\", 1], [\"Write\", 2]]}\n"
                  "  ],\n"));
  } else {
    EXPECT_EQ(w.bytes[4], 2u) << "version 2: with a type table";
  }
  EXPECT_EQ(vsd::io::check_bytes(w.bytes).defined_types,
            std::vector<std::string>({"IoRtColor", "IoRtTag", "IoRtAccess"}));
  EXPECT_EQ(global().find_type("IoRtTag"), nullptr) << "a check leaves nothing behind";
  {
    vsd::Environment env;
    const auto report = vsd::io::load_bytes(env.main_state(), w.bytes);
    EXPECT_THAT(report.defined_types, ElementsAre("IoRtColor", "IoRtTag", "IoRtAccess"));
    EXPECT_THAT(report.defined_classes, ElementsAre("IoRtMarker"));
    EXPECT_EQ(report.version, 2);
    ASSERT_EQ(report.roots.size(), 1u);
    EXPECT_EQ(values_of(*report.roots[0]), w.values);
    EXPECT_EQ(vsd::io::save_bytes(env.main_state(), format()), w.bytes)
        << "loaded and saved again: unchanged";
    // The other format carries them too.
    const Format other = format() == Format::Text ? Format::Binary : Format::Text;
    const auto converted = vsd::io::save_bytes(env.main_state(), other);
    vsd::Environment env2;
    vsd::io::load_bytes(env2.main_state(), converted);
    EXPECT_TRUE(env.main_state().equals(env2.main_state()));
    EXPECT_EQ(vsd::io::save_bytes(env2.main_state(), format()), w.bytes);
  }
  // A program that has the same types uses its own.
  {
    vsd::Environment env;
    const auto report = vsd::io::load_bytes(env.main_state(), w.bytes);
    EXPECT_TRUE(report.defined_types.empty());
    EXPECT_TRUE(report.defined_classes.empty());
  }
  undefine_all();
}

TEST_P(Files, FilesWithoutRunTimeTypesStayVersion1) {
  vsd::Environment env;
  const vsd::MetaInstance& belt =
      vsd::ClassBuilder("IoRtPlainBelt", vsd::Node::static_meta()).property<double>("speed", 1.0).define();
  auto& b = static_cast<vsd::Node&>(env.main_state().create(belt));
  env.main_state().database().add_child(b);
  const auto bytes = vsd::io::save_bytes(env.main_state(), format());
  if (format() == Format::Text) {
    EXPECT_THAT(text_of(bytes), HasSubstr("\"version\": 1,"));
    EXPECT_THAT(text_of(bytes), testing::Not(HasSubstr("\"types\"")));
  } else {
    EXPECT_EQ(bytes[4], 1u);
  }
  env.main_state().destroy(b);
  global().undefine(belt);
}

TEST_P(Files, TypesThatClashAreErrorsAndFailedLoadsLeaveNoType) {
  const Written w = write_with_types(format());
  // This program's IoRtColor has other values: the file's definition clashes.
  const vsd::MetaType& mine = vsd::EnumBuilder("IoRtColor").value("Red", 0).define();
  vsd::Environment env;
  std::string error;
  try {
    vsd::io::load_bytes(env.main_state(), w.bytes, "f");
  } catch (const vsd::Error& e) {
    error = e.what();
  }
  EXPECT_THAT(error, MatchesRegex(format() == Format::Text ? "f:6:5: .*" : "f: byte 7: .*"));
  EXPECT_THAT(error, HasSubstr("type 'IoRtColor' of the file clashes with this program's type 'IoRtColor'"));
  global().undefine(mine);
  // A file that defines its types and then fails leaves none of them behind.
  auto bad = w.bytes;
  bad.resize(bad.size() - 2);
  EXPECT_THROW(vsd::io::load_bytes(env.main_state(), bad, "f"), vsd::Error);
  for (const char* name : type_names) EXPECT_EQ(global().find_type(name), nullptr) << name;
  EXPECT_EQ(global().find_type("vector<IoRtTag>"), nullptr);
  EXPECT_EQ(global().find_class("IoRtMarker"), nullptr);
  EXPECT_EQ(env.main_state().size(), 1u);
}

TEST_P(Files, TruncatedAndCorruptDefinitionsAreRejected) {
  const Written w = write_with_types(format());
  // Every cut of the file is rejected with a position; nothing is left defined.
  for (std::size_t n = 0; n + 1 < w.bytes.size(); n += format() == Format::Text ? 7 : 1) {
    std::vector<std::uint8_t> part(w.bytes.begin(), w.bytes.begin() + static_cast<std::ptrdiff_t>(n));
    vsd::Environment env;
    try {
      vsd::io::load_bytes(env.main_state(), part, "f");
      ADD_FAILURE() << "a cut at " << n << " loaded";
    } catch (const vsd::Error& e) {
      EXPECT_THAT(e.what(), MatchesRegex("f(:[0-9]+:[0-9]+|: byte [0-9]+): .*")) << n;
    }
    ASSERT_EQ(global().find_type("IoRtColor"), nullptr) << n;
  }
  // Random corruption: loaded or rejected, never a crash; a rejection leaves no type behind.
  std::mt19937 rng(11);
  for (int round = 0; round < 1500; ++round) {
    auto bad = w.bytes;
    const int flips = 1 + static_cast<int>(rng() % 3);
    for (int k = 0; k < flips; ++k) bad[rng() % bad.size()] = static_cast<std::uint8_t>(rng());
    vsd::io::LoadReport report;
    {
      vsd::Environment env;
      try {
        report = vsd::io::load_bytes(env.main_state(), bad, "f");
      } catch (const vsd::Error&) {
        EXPECT_EQ(env.main_state().size(), 1u);
        EXPECT_EQ(global().find_class("IoRtMarker"), nullptr);
        EXPECT_EQ(global().find_type("IoRtTag"), nullptr);
        continue;
      }
    }
    // Loaded (a corrupt name is still a name): once its instances are gone, remove what it defined.
    for (auto it = report.defined_classes.rbegin(); it != report.defined_classes.rend(); ++it)
      global().undefine(global().get_class(*it));
    for (auto it = report.defined_types.rbegin(); it != report.defined_types.rend(); ++it)
      global().undefine(*global().find_type(*it));
  }
}

TEST(RunTimeTypeText, BadDefinitionsSayWhereAndWhat) {
  auto load_error = [](const std::string& types) {
    const std::string file =
        "{\"format\": \"vsd-text\", \"version\": 2, \"kind\": \"state\",\n\"types\": [\n" + types + "\n]}";
    vsd::Environment env;
    try {
      vsd::io::load_bytes(env.main_state(), bytes_of(file), "t.json");
    } catch (const vsd::Error& e) {
      EXPECT_EQ(global().find_type("IoRtBad"), nullptr);
      EXPECT_EQ(global().find_type("IoRtGood"), nullptr);
      return std::string(e.what());
    }
    return std::string("<loaded>");
  };
  EXPECT_EQ(load_error("{\"type\": \"IoRtBad\", \"kind\": \"blob\"}"),
            "t.json:3:29: unknown kind of type 'blob' (enum, flags or struct)");
  EXPECT_EQ(load_error("{\"type\": \"IoRtBad\"}"), "t.json:3:1: a type needs a \"type\" name and a \"kind\"");
  EXPECT_EQ(load_error("{\"type\": \"IoRtBad\", \"kind\": \"enum\", \"values\": [[\"A\", 1], [\"A\", 2]]}"),
            "t.json:3:1: cannot define type 'IoRtBad': enum 'IoRtBad': value 'A' is given twice");
  EXPECT_THAT(load_error("{\"type\": \"IoRtBad\", \"kind\": \"enum\", \"values\": [[\"A\", 1.5]]}"),
              HasSubstr("t.json:3:54: '1.5' is not an integer"));
  EXPECT_EQ(load_error("{\"type\": \"IoRtBad\", \"kind\": \"enum\", \"underlying\": \"double\"}"),
            "t.json:3:1: cannot define type 'IoRtBad': enum 'IoRtBad': its underlying type must be an "
            "integer type, "
            "not double");
  EXPECT_EQ(load_error("{\"type\": \"IoRtGood\", \"kind\": \"enum\", \"values\": [[\"A\", 1]]},\n"
                       "{\"type\": \"IoRtBad\", \"kind\": \"struct\", \"fields\": [[\"a\", \"IoRtNope\"]]}"),
            "t.json:4:56: unknown type 'IoRtNope'");
  EXPECT_EQ(load_error("{\"type\": \"IoRtBad\", \"kind\": \"struct\", \"fields\": []}"),
            "t.json:3:1: cannot define type 'IoRtBad': struct 'IoRtBad' has no fields");
  EXPECT_EQ(
      load_error("{\"type\": \"double\", \"kind\": \"struct\", \"fields\": [[\"a\", \"int32\"]]}"),
      "t.json:3:1: type 'double' of the file clashes with this program's type 'double', which is defined "
      "differently");
  EXPECT_EQ(
      load_error(
          "{\"type\": \"IoRtBad\", \"kind\": \"struct\", \"fields\": [[\"a\", \"int32\"]], \"values\": []}"),
      "t.json:3:77: struct 'IoRtBad' has fields, not values");
}

INSTANTIATE_TEST_SUITE_P(Formats, Files, testing::Values(Format::Binary, Format::Text),
                         [](const auto& info) { return info.param == Format::Text ? "Text" : "Binary"; });

}  // namespace
