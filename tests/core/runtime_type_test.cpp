// Tests of vsd/core/type_builder.hpp: run-time enums, flags, structs and vectors of them.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <vsd/vsd.hpp>

using testing::HasSubstr;
using testing::ThrowsMessage;

namespace rt {

enum class Shade : std::uint8_t { Dark, Light = 7 };
enum class Access : std::uint16_t { Read = 1, Write = 2 };
struct Tag {
  std::string label;
  double weight = 0;
  Shade shade = Shade::Dark;
};
VSD_ENUM(Shade, Dark, Light)
VSD_FLAGS(Access, Read, Write)
VSD_STRUCT(Tag, label, weight, shade)

}  // namespace rt

namespace {

std::vector<std::uint8_t> bytes_of(const vsd::Value& v) {
  std::vector<std::uint8_t> out;
  vsd::ByteWriter w(out);
  v.type()->write_bytes(v.data(), w);
  return out;
}

vsd::Value from_bytes(const vsd::MetaType& t, const std::vector<std::uint8_t>& bytes) {
  vsd::Value v(t);
  vsd::ByteReader r(bytes.data(), bytes.size());
  t.read_bytes(v.data(), r);
  EXPECT_TRUE(r.at_end());
  return v;
}

// The run-time twins of the C++ types above, in a registry of their own (same names).
struct Twins {
  vsd::Registry registry;
  const vsd::MetaType& shade = vsd::EnumBuilder("Shade")
                                   .underlying(vsd::meta_type<std::uint8_t>())
                                   .value("Dark", 0)
                                   .value("Light", 7)
                                   .define(registry);
  const vsd::MetaType& access = vsd::EnumBuilder("Access", vsd::TypeKind::Flags)
                                    .underlying(vsd::meta_type<std::uint16_t>())
                                    .value("Read", 1)
                                    .value("Write", 2)
                                    .define(registry);
  const vsd::MetaType& tag = vsd::StructBuilder("Tag")
                                 .field<std::string>("label")
                                 .field<double>("weight")
                                 .field("shade", shade)
                                 .define(registry);
};

TEST(RuntimeTypes, EnumsAndFlagsHaveTheFormsOfDeclaredOnes) {
  Twins t;
  EXPECT_EQ(t.shade.kind(), vsd::TypeKind::Enum);
  EXPECT_EQ(t.shade.size(), 1u);
  EXPECT_TRUE(vsd::detail::same_definition(t.shade, vsd::meta_type<rt::Shade>()));
  EXPECT_TRUE(vsd::detail::same_definition(t.access, vsd::meta_type<rt::Access>()));
  vsd::Value light = vsd::Value::from_text(t.shade, "\"Light\"");
  EXPECT_EQ(t.shade.load_integer(light.data()), 7);
  EXPECT_EQ(light.type()->to_text(light.data()), "\"Light\"");
  EXPECT_EQ(bytes_of(light), bytes_of(vsd::Value(rt::Shade::Light)));
  EXPECT_EQ(from_bytes(t.shade, bytes_of(light)), light);
  vsd::Value both = vsd::Value::from_text(t.access, "\"Read|Write\"");
  EXPECT_EQ(
      both.type()->to_text(both.data()),
      vsd::Value(static_cast<rt::Access>(3)).type()->to_text(vsd::Value(static_cast<rt::Access>(3)).data()));
  EXPECT_EQ(bytes_of(both), bytes_of(vsd::Value(static_cast<rt::Access>(3))));
  EXPECT_THAT([&] { (void)vsd::Value::from_text(t.shade, "\"Dim\""); },
              ThrowsMessage<vsd::Error>(HasSubstr("'Dim' is not a value of Shade")));
  EXPECT_THAT([&] { (void)vsd::Value::from_text(t.shade, "300"); },
              ThrowsMessage<vsd::Error>(HasSubstr("out of range for Shade")));
  EXPECT_EQ(vsd::Value(t.shade).type()->to_text(vsd::Value(t.shade).data()), "\"Dark\"") << "defaults to 0";
}

TEST(RuntimeTypes, StructsHaveTheFormsOfDeclaredOnes) {
  Twins t;
  EXPECT_TRUE(vsd::detail::same_definition(t.tag, vsd::meta_type<rt::Tag>()));
  const rt::Tag cpp{"first \"one\"", 2.5, rt::Shade::Light};
  const vsd::Value cpp_value(cpp);
  const std::string text = cpp_value.type()->to_text(cpp_value.data());
  const vsd::Value v = vsd::Value::from_text(t.tag, text);
  EXPECT_EQ(v.type()->to_text(v.data()), text);
  EXPECT_EQ(bytes_of(v), bytes_of(cpp_value));
  EXPECT_EQ(from_bytes(t.tag, bytes_of(v)), v);
  vsd::Value copy = v;
  EXPECT_EQ(copy, v);
  EXPECT_EQ(copy.type()->hash(copy.data()), v.type()->hash(v.data()));
  vsd::Value other = vsd::Value::from_text(t.tag, "{\"weight\": 3}");
  EXPECT_NE(other, v);
  other = v;
  EXPECT_EQ(other, v);
  // A struct of numbers only is written as an array, as a declared one is.
  const vsd::MetaType& point =
      vsd::StructBuilder("Point").field<float>("x").field<std::int16_t>("y").define(t.registry);
  EXPECT_EQ(point.size(), 8u);
  EXPECT_EQ(point.fields()[1].offset, 4u);
  vsd::Value p = vsd::Value::from_text(point, "[1.5, -2]");
  EXPECT_EQ(p.type()->to_text(p.data()), "[1.5, -2]");
  EXPECT_THAT([&] { (void)vsd::Value::from_text(t.tag, "{\"colour\": 1}"); },
              ThrowsMessage<vsd::Error>(HasSubstr("Tag has no field 'colour'")));
}

TEST(RuntimeTypes, VectorsOfRunTimeTypesAreMadeOnDemand) {
  Twins t;
  const vsd::MetaType& tags = t.registry.get_type("vector<Tag>");
  EXPECT_EQ(&t.registry.vector_type(t.tag), &tags);
  EXPECT_EQ(tags.element(), &t.tag);
  const vsd::MetaType& nested = t.registry.get_type("vector<vector<Shade>>");
  EXPECT_EQ(nested.element()->element(), &t.shade);
  const std::string text =
      "[{\"label\": \"a\", \"weight\": 1, \"shade\": \"Light\"}, "
      "{\"label\": \"b\", \"weight\": 2, \"shade\": \"Dark\"}, "
      "{\"label\": \"c\", \"weight\": 3, \"shade\": \"Dark\"}, "
      "{\"label\": \"d\", \"weight\": 4, \"shade\": \"Dark\"}, "
      "{\"label\": \"a long label that is not stored inline\", \"weight\": 5, \"shade\": \"Light\"}]";
  const vsd::Value v = vsd::Value::from_text(tags, text);
  EXPECT_EQ(v.type()->to_text(v.data()), text);
  std::vector<rt::Tag> cpp{{"a", 1, rt::Shade::Light},
                           {"b", 2, rt::Shade::Dark},
                           {"c", 3, rt::Shade::Dark},
                           {"d", 4, rt::Shade::Dark},
                           {"a long label that is not stored inline", 5, rt::Shade::Light}};
  const auto bytes = bytes_of(v);
  EXPECT_EQ(bytes, bytes_of(vsd::Value(cpp)));
  const vsd::Value back = from_bytes(tags, bytes);
  EXPECT_EQ(back, v);
  vsd::Value n = vsd::Value::from_text(nested, "[[\"Dark\"], [], [\"Light\", 7]]");
  EXPECT_EQ(n.type()->to_text(n.data()), "[[\"Dark\"], [], [\"Light\", \"Light\"]]");
  // Hostile bytes: a count larger than the bytes, a truncated element, bad text half way.
  for (std::size_t cut = 0; cut < bytes.size(); ++cut) {
    std::vector<std::uint8_t> part(bytes.begin(), bytes.begin() + static_cast<std::ptrdiff_t>(cut));
    vsd::Value x(tags);
    vsd::ByteReader r(part.data(), part.size());
    EXPECT_THROW(tags.read_bytes(x.data(), r), vsd::Error) << cut;
    EXPECT_EQ(x, vsd::Value(tags)) << "unchanged";
  }
  const std::vector<std::uint8_t> huge{0xff, 0xff, 0xff, 0xff, 0x0f, 1, 2};
  vsd::Value x(tags);
  vsd::ByteReader r(huge.data(), huge.size());
  EXPECT_THROW(tags.read_bytes(x.data(), r), vsd::Error);
  vsd::Value kept = v;
  EXPECT_THROW(kept.type()->from_text(kept.data(), "[{\"label\": \"z\"}, {\"weight\": \"x\"}]"), vsd::Error);
  EXPECT_EQ(kept, v) << "a failed read leaves the value as it was";
  EXPECT_THAT([&] { (void)t.registry.get_type("vector<Nope>"); },
              ThrowsMessage<vsd::Error>("unknown type 'vector<Nope>'"));
}

TEST(RuntimeTypes, RunTimeClassesUseThem) {
  Twins t;
  vsd::Environment env(0, t.registry);
  const vsd::MetaInstance& marker =
      vsd::ClassBuilder("Marker", vsd::Node::static_meta())
          .property("main", t.tag, vsd::Value::from_text(t.tag, "{\"label\": \"x\"}"))
          .property("tags", t.registry.get_type("vector<Tag>"))
          .property("access", t.access)
          .define(t.registry);
  vsd::SimState& s = env.main_state();
  auto& m = s.create(marker);
  EXPECT_EQ(m.get("main").type()->to_text(m.get("main").data()),
            "{\"label\": \"x\", \"weight\": 0, \"shade\": \"Dark\"}");
  m.set("tags",
        vsd::Value::from_text(t.registry.get_type("vector<Tag>"), "[{\"label\": \"y\", \"shade\": 7}]"));
  m.set("access", vsd::Value::from_text(t.access, "\"Write\""));
  auto& copy = env.create_state("copy");
  copy.apply(s.snapshot());
  EXPECT_TRUE(s.equals(copy));
  EXPECT_EQ(copy.find(m.id())->get("tags"), m.get("tags"));
  // In use: neither the class's types nor the types they hold can go.
  EXPECT_THAT([&] { t.registry.undefine(t.tag); },
              ThrowsMessage<vsd::Error>("type 'Tag' is still used by property 'Marker::main'"));
  env.remove_state(copy);
  s.destroy(m);
  t.registry.undefine(marker);
  EXPECT_THAT([&] { t.registry.undefine(t.shade); },
              ThrowsMessage<vsd::Error>("type 'Shade' is still used by type 'Tag'"));
  t.registry.undefine(t.tag);
  EXPECT_EQ(t.registry.find_type("Tag"), nullptr);
  EXPECT_EQ(t.registry.find_type("vector<Tag>"), nullptr) << "its vectors go with it";
  EXPECT_THAT([&] { t.registry.undefine(vsd::meta_type<double>()); },
              ThrowsMessage<vsd::Error>(HasSubstr("not a run-time type")));
}

// A registry that goes away takes its run-time classes first, then the types their defaults use.
TEST(RuntimeTypes, ARegistryOwnsItsTypes) {
  auto r = std::make_unique<vsd::Registry>();
  const vsd::MetaType& tag = vsd::StructBuilder("Tag").field<std::string>("s").define(*r);
  vsd::ClassBuilder("Holder", vsd::Node::static_meta())
      .property("tag", tag, vsd::Value::from_text(tag, "{\"s\": \"a text too long to be stored inline\"}"))
      .property("tags", r->get_type("vector<Tag>"),
                vsd::Value::from_text(r->get_type("vector<Tag>"), "[{\"s\": \"x\"}]"))
      .define(*r);
  EXPECT_TRUE(r->owns(tag));
  EXPECT_FALSE(r->owns(vsd::meta_type<double>()));
  r.reset();  // (the sanitizers check that nothing is used after it is freed)
}

TEST(RuntimeTypes, BuildersCheckWhatTheyAreGiven) {
  vsd::Registry r;
  auto error = [](auto&& build) {
    try {
      build();
    } catch (const vsd::Error& e) {
      return std::string(e.what());
    }
    return std::string("<defined>");
  };
  EXPECT_EQ(error([&] { vsd::EnumBuilder("E").value("A", 0).value("A", 1).define(r); }),
            "enum 'E': value 'A' is given twice");
  EXPECT_EQ(error([&] { vsd::EnumBuilder("E").value("a b", 0).define(r); }),
            "enum 'E': value name 'a b' is not an identifier");
  EXPECT_EQ(error([&] {
              vsd::EnumBuilder("E").underlying(vsd::meta_type<std::int8_t>()).value("A", 200).define(r);
            }),
            "enum 'E': value A = 200 does not fit int8");
  EXPECT_EQ(error([&] { vsd::EnumBuilder("E").underlying(vsd::meta_type<double>()); }),
            "enum 'E': its underlying type must be an integer type, not double");
  EXPECT_EQ(error([&] { vsd::EnumBuilder("E", vsd::TypeKind::Struct); }),
            "EnumBuilder 'E': the kind is Enum or Flags");
  EXPECT_EQ(error([&] { vsd::EnumBuilder("double").define(r); }),
            "type name 'double' is already registered for another type");
  EXPECT_EQ(error([&] { vsd::StructBuilder("S").define(r); }), "struct 'S' has no fields");
  EXPECT_EQ(error([&] { vsd::StructBuilder("S").field<int>("a").field<double>("a").define(r); }),
            "struct 'S': field 'a' is given twice");
  EXPECT_EQ(error([&] { vsd::StructBuilder("S").field<vsd::SharedRef<vsd::Node>>("n").define(r); }),
            "struct 'S': field 'n' cannot be a reference (shared<Node>)");
  EXPECT_EQ(r.find_type("E"), nullptr);
  EXPECT_EQ(r.find_type("S"), nullptr);
}

// Values of run-time types are copied, compared, read and written by recursion over their parts: how deep
// a type may nest is bounded (MetaType::max_depth), so that a file or a script defining a struct of a
// struct of ... (or naming vector<vector<...>>) a hundred thousand levels deep gets an error, not a crash.
TEST(RuntimeTypes, NestingIsBounded) {
  vsd::Registry r;
  const vsd::MetaType* t = &vsd::meta_type<double>();
  EXPECT_EQ(t->depth(), 1u);
  for (std::size_t depth = 2; depth <= vsd::MetaType::max_depth; ++depth) {
    t = depth % 2 == 0 ? &vsd::StructBuilder("S" + std::to_string(depth)).field("inner", *t).define(r)
                       : &r.vector_type(*t);
    ASSERT_EQ(t->depth(), depth);
  }
  EXPECT_THAT([&] { vsd::StructBuilder("Deeper").field("inner", *t).define(r); },
              ThrowsMessage<vsd::Error>("struct 'Deeper': values would nest deeper than 64 levels"));
  EXPECT_THAT([&] { (void)r.vector_type(*t); },
              ThrowsMessage<vsd::Error>(HasSubstr(">: values would nest deeper than 64 levels")));
  EXPECT_EQ(r.find_type("Deeper"), nullptr);
  // A value of the deepest type goes through text and bytes.
  vsd::Value v(*t);
  EXPECT_EQ(vsd::Value::from_text(*t, v.type()->to_text(v.data())), v);
  // Names: each "vector<" is a level; a name deeper than any type may be is refused before it is parsed.
  std::string name = "S64";
  for (int i = 0; i < 100'000; ++i) name = "vector<" + name + ">";
  EXPECT_THAT([&] { (void)r.get_type(name); },
              ThrowsMessage<vsd::Error>(HasSubstr("vectors nest deeper than 64 levels")));
  EXPECT_THAT([&] { (void)r.get_type("vector<S64>"); },
              ThrowsMessage<vsd::Error>(HasSubstr("values would nest deeper than 64 levels")));
  EXPECT_EQ(r.get_type("vector<S62>").depth(), 63u);
}

}  // namespace
