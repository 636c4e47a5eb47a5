// Tests of vsd/core/registry.hpp: finding classes and types by name.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>
#include <vsd/vsd.hpp>

#include "test_util.hpp"

namespace rg {

enum class RgMode { Idle, Busy };
VSD_ENUM(RgMode, Idle, Busy)

// Declared here and never added explicitly: static registration must find it.
class RgWidget : public vsd::Node {
  VSD_INSTANCE(RgWidget, vsd::Node)
  VSD_PROPERTY(RgMode, mode, RgMode::Idle)
  VSD_PROPERTY(std::vector<float>, weights, {})
};

class RgGizmo : public vsd::Extension {
  VSD_INSTANCE(RgGizmo, vsd::Extension)
  VSD_PROPERTY(double, level, 0.0)
};

// A property of type `long long`: the same size and sign as std::int64_t, but a distinct C++ type.
using RgTicks = long long;  // (a two-word type name does not work in VSD_PROPERTY, which writes Type(def))
class RgCounter : public vsd::Node {
  VSD_INSTANCE(RgCounter, vsd::Node)
  VSD_PROPERTY(RgTicks, ticks, 0)
};

// A user struct whose name is taken by a built-in type, and a class with a property of it.
struct Vector3d {
  double x = 0;
};
VSD_STRUCT(Vector3d, x)
class RgClash : public vsd::Node {
  VSD_INSTANCE(RgClash, vsd::Node)
  VSD_PROPERTY(rg::Vector3d, where, {})
};

}  // namespace rg

namespace {

using testing::HasSubstr;

using vsd_test::error_of;

vsd::Registry& global() { return vsd::Registry::global(); }

TEST(Registry, GlobalIsOneObject) { EXPECT_EQ(&vsd::Registry::global(), &vsd::Registry::global()); }

TEST(Registry, FindsCoreClasses) {
  EXPECT_EQ(global().find_class("Instance"), &vsd::Instance::static_meta());
  EXPECT_EQ(global().find_class("SimStateInstance"), &vsd::SimStateInstance::static_meta());
  EXPECT_EQ(global().find_class("NamedModelInstance"), &vsd::NamedModelInstance::static_meta());
  EXPECT_EQ(global().find_class("Node"), &vsd::Node::static_meta());
  EXPECT_EQ(global().find_class("Extension"), &vsd::Extension::static_meta());
  EXPECT_EQ(global().find_class("Database"), &vsd::Database::static_meta());
  EXPECT_EQ(global().find_class("SimState"), &vsd::SimState::static_meta());
  EXPECT_EQ(global().find_class("Environment"), &vsd::Environment::static_meta());
  EXPECT_EQ(&global().get_class("Node"), &vsd::Node::static_meta());
  EXPECT_EQ(&global().get_class("SimStateInstance"), &vsd::SimStateInstance::static_meta());
}

TEST(Registry, UnknownClass) {
  EXPECT_EQ(global().find_class("NoSuchClass"), nullptr);
  EXPECT_EQ(global().find_class(""), nullptr);
  EXPECT_EQ(global().find_class("node"), nullptr) << "names are case-sensitive";
  EXPECT_EQ(global().find_class("vsd::Node"), nullptr) << "class names are not qualified";
  const std::string e = error_of([] { (void)global().get_class("NoSuchClass"); });
  EXPECT_THAT(e, HasSubstr("'NoSuchClass'"));
  EXPECT_THAT(e, HasSubstr("class"));
}

TEST(Registry, FindsBuiltInTypes) {
  EXPECT_EQ(global().find_type("bool"), &vsd::meta_type<bool>());
  EXPECT_EQ(global().find_type("int8"), &vsd::meta_type<std::int8_t>());
  EXPECT_EQ(global().find_type("int32"), &vsd::meta_type<std::int32_t>());
  EXPECT_EQ(global().find_type("int64"), &vsd::meta_type<std::int64_t>());
  EXPECT_EQ(global().find_type("uint8"), &vsd::meta_type<std::uint8_t>());
  EXPECT_EQ(global().find_type("uint64"), &vsd::meta_type<std::uint64_t>());
  EXPECT_EQ(global().find_type("float"), &vsd::meta_type<float>());
  EXPECT_EQ(global().find_type("double"), &vsd::meta_type<double>());
  EXPECT_EQ(global().find_type("string"), &vsd::meta_type<std::string>());
  EXPECT_EQ(global().find_type("vector<double>"), &vsd::meta_type<std::vector<double>>());
  EXPECT_EQ(global().find_type("vector<string>"), &vsd::meta_type<std::vector<std::string>>());
  EXPECT_EQ(global().find_type("Vector3d"), &vsd::meta_type<Eigen::Vector3d>());
  EXPECT_EQ(global().find_type("Quaterniond"), &vsd::meta_type<Eigen::Quaterniond>());
  EXPECT_EQ(global().find_type("Isometry3d"), &vsd::meta_type<Eigen::Isometry3d>());
  EXPECT_EQ(&global().get_type("double"), &vsd::meta_type<double>());
  EXPECT_EQ(&global().get_type("vector<double>"), &vsd::meta_type<std::vector<double>>());
  EXPECT_EQ(&global().get_type("Isometry3d"), &vsd::meta_type<Eigen::Isometry3d>());
}

TEST(Registry, UnknownType) {
  EXPECT_EQ(global().find_type("no_such_type"), nullptr);
  EXPECT_EQ(global().find_type("Double"), nullptr);
  const std::string e = error_of([] { (void)global().get_type("no_such_type"); });
  EXPECT_THAT(e, HasSubstr("'no_such_type'"));
  EXPECT_THAT(error_of([] { (void)global().get_type("vector<no_such_type>"); }), HasSubstr("no_such_type"));
  EXPECT_THAT(error_of([] { (void)global().get_type("ref<"); }), HasSubstr("ref<"));
  EXPECT_THAT(error_of([] { (void)global().get_type("ref<>"); }), HasSubstr("ref<>"));
}

TEST(Registry, ReferenceTypesByName) {
  const vsd::MetaType& ref = global().get_type("ref<Node>");
  EXPECT_EQ(ref.name(), "ref<Node>");
  EXPECT_EQ(ref.kind(), vsd::TypeKind::Ref);
  EXPECT_EQ(ref.target(), &vsd::Node::static_meta());
  EXPECT_TRUE(ref.is_reference());
  EXPECT_TRUE(ref.is_composite());
  EXPECT_FALSE(ref.is_ref_list());

  const vsd::MetaType& shared = global().get_type("shared<Extension>");
  EXPECT_EQ(shared.kind(), vsd::TypeKind::SharedRef);
  EXPECT_EQ(shared.target(), &vsd::Extension::static_meta());
  EXPECT_FALSE(shared.is_composite());

  const vsd::MetaType& list = global().get_type("list<Node>");
  EXPECT_EQ(list.kind(), vsd::TypeKind::RefList);
  EXPECT_TRUE(list.is_ref_list());

  const vsd::MetaType& shared_list = global().get_type("shared_list<Node>");
  EXPECT_EQ(shared_list.name(), "shared_list<Node>");
  EXPECT_EQ(shared_list.kind(), vsd::TypeKind::SharedRefList);
  EXPECT_EQ(shared_list.target(), &vsd::Node::static_meta());
  EXPECT_TRUE(shared_list.is_ref_list());
  EXPECT_FALSE(shared_list.is_composite());

  const vsd::MetaType& widget = global().get_type("ref<RgWidget>");
  EXPECT_EQ(widget.target(), &rg::RgWidget::static_meta());
}

TEST(Registry, ReferenceTypesAreMadeOnce) {
  const vsd::MetaType& a = global().get_type("shared_list<Extension>");
  const vsd::MetaType& b = global().get_type("shared_list<Extension>");
  EXPECT_EQ(&a, &b);
  EXPECT_EQ(&global().reference_type(vsd::TypeKind::SharedRefList, vsd::Extension::static_meta()), &a);
  EXPECT_EQ(global().find_type("shared_list<Extension>"), &a);
  EXPECT_THROW((void)global().reference_type(vsd::TypeKind::Double, vsd::Node::static_meta()), vsd::Error);
}

TEST(Registry, ReferenceTypeNameMeansTheTypeOfDeclaredProperties) {
  // Node::children is a RefList<Node>, whose MetaType is named "list<Node>": looking that name up must give
  // the very type the property has, or Values of the two never match.
  const vsd::MetaType& children = vsd::Node::vsd_prop_children().type();
  EXPECT_EQ(children.name(), "list<Node>");
  EXPECT_EQ(&global().get_type("list<Node>"), &children);
  EXPECT_EQ(&global().reference_type(vsd::TypeKind::RefList, vsd::Node::static_meta()), &children);
  const vsd::MetaType& extensions = vsd::NamedModelInstance::vsd_prop_extensions().type();
  EXPECT_EQ(&global().get_type("list<Extension>"), &extensions);
}

TEST(Registry, UnknownClassInReferenceType) {
  const std::string e = error_of([] { (void)global().get_type("ref<NoSuchClass>"); });
  EXPECT_THAT(e, HasSubstr("NoSuchClass"));
  EXPECT_THAT(error_of([] { (void)global().get_type("shared_list<Nope>"); }), HasSubstr("Nope"));
}

TEST(Registry, ClassesDeclaredInThisFileAreRegisteredAutomatically) {
  EXPECT_EQ(global().find_class("RgWidget"), &rg::RgWidget::static_meta());
  EXPECT_EQ(global().find_class("RgGizmo"), &rg::RgGizmo::static_meta());
  EXPECT_EQ(&global().get_class("RgWidget"), &rg::RgWidget::static_meta());
  // The types of their properties come with them.
  EXPECT_EQ(global().find_type("RgMode"), &vsd::meta_type<rg::RgMode>());
  EXPECT_EQ(global().find_type("vector<float>"), &vsd::meta_type<std::vector<float>>());
  // And instances can be made by name.
  vsd::Environment env;
  vsd::SimStateInstance& w = env.main_state().create("RgWidget");
  EXPECT_EQ(&w.meta(), &rg::RgWidget::static_meta());
  EXPECT_EQ(w.get("mode").to_text(), "\"Idle\"");
}

TEST(Registry, ClassWithALongLongPropertyIsRegistered) {
  EXPECT_EQ(global().find_class("RgCounter"), &rg::RgCounter::static_meta())
      << "a property of type long long must not keep its class out of the registry";
  EXPECT_NO_THROW((void)global().add<rg::RgCounter>());
}

TEST(Registry, AddIsIdempotent) {
  const vsd::MetaInstance& a = global().add<rg::RgWidget>();
  const vsd::MetaInstance& b = global().add<rg::RgWidget>();
  EXPECT_EQ(&a, &rg::RgWidget::static_meta());
  EXPECT_EQ(&a, &b);
  EXPECT_EQ(&global().add<vsd::Node>(), &vsd::Node::static_meta());
  EXPECT_NO_THROW(global().add(vsd::Node::static_meta()));
  EXPECT_EQ(global().find_class("RgWidget"), &a);
  EXPECT_EQ(&global().add_type<double>(), &vsd::meta_type<double>());
  EXPECT_EQ(&global().add_type<rg::RgMode>(), &vsd::meta_type<rg::RgMode>());
  EXPECT_EQ(global().find_type("double"), &vsd::meta_type<double>());
}

TEST(Registry, LocalRegistryKnowsTheCoreAndWhatIsAdded) {
  vsd::Registry local;
  EXPECT_EQ(local.find_class("Node"), &vsd::Node::static_meta());
  EXPECT_EQ(local.find_type("Isometry3d"), &vsd::meta_type<Eigen::Isometry3d>());
  EXPECT_EQ(local.find_class("RgWidget"), nullptr) << "static registration goes to the global registry only";
  EXPECT_EQ(local.find_type("RgMode"), nullptr);
  local.add<rg::RgWidget>();
  EXPECT_EQ(local.find_class("RgWidget"), &rg::RgWidget::static_meta());
  EXPECT_EQ(local.find_type("RgMode"), &vsd::meta_type<rg::RgMode>());
  local.add<rg::RgWidget>();
  EXPECT_EQ(local.find_class("RgWidget"), &rg::RgWidget::static_meta());

  const auto classes = local.classes();
  EXPECT_TRUE(std::is_sorted(
      classes.begin(), classes.end(),
      [](const vsd::MetaInstance* a, const vsd::MetaInstance* b) { return a->name() < b->name(); }));
  EXPECT_NE(std::find(classes.begin(), classes.end(), &rg::RgWidget::static_meta()), classes.end());
  EXPECT_NE(std::find(classes.begin(), classes.end(), &vsd::Database::static_meta()), classes.end());
  const auto types = local.types();
  EXPECT_NE(std::find(types.begin(), types.end(), &vsd::meta_type<double>()), types.end());
  EXPECT_TRUE(std::is_sorted(types.begin(), types.end(), [](const vsd::MetaType* a, const vsd::MetaType* b) {
    return a->name() < b->name();
  }));
}

TEST(Registry, NameClashesAreErrors) {
  vsd::Registry local;
  // A different type under a registered name.
  static const vsd::MetaType impostor("double", vsd::TypeKind::Double, sizeof(double), alignof(double),
                                      vsd::detail::ValueOps<double>::table);
  const std::string t = error_of([&] { local.add(impostor); });
  EXPECT_THAT(t, HasSubstr("'double'"));
  EXPECT_EQ(local.find_type("double"), &vsd::meta_type<double>());
  // A different class under a registered name.
  const vsd::MetaInstance fake_node("Node", &vsd::Node::static_meta(), sizeof(vsd::Node), alignof(vsd::Node),
                                    nullptr, nullptr);
  const std::string c = error_of([&] { local.add(fake_node); });
  EXPECT_THAT(c, HasSubstr("'Node'"));
  EXPECT_EQ(local.find_class("Node"), &vsd::Node::static_meta());
}

TEST(Registry, AddIsAllOrNothing) {
  // RgClash has a property whose type name ("Vector3d") belongs to another type: adding the class fails,
  // and then the registry must not know the class either.
  vsd::Registry local;
  const std::string e = error_of([&] { (void)local.add<rg::RgClash>(); });
  EXPECT_THAT(e, HasSubstr("'Vector3d'"));
  EXPECT_EQ(local.find_class("RgClash"), nullptr);
  EXPECT_THROW((void)local.add<rg::RgClash>(), vsd::Error) << "adding it again reports the clash again";
}

}  // namespace

TEST(Registry, APrivateRegistryTearsDownRunTimeClassHierarchies) {
  // Run under AddressSanitizer: a subclass must unlink from its base before the base is freed, and the
  // classes' default values from their types before the types go.
  {
    vsd::Registry local;
    const vsd::MetaInstance& base = vsd::ClassBuilder("RgPrivBase", vsd::Node::static_meta())
                                        .property<double>("speed", 1.0)
                                        .define(local);
    const vsd::MetaInstance& mid = vsd::ClassBuilder("RgPrivMid", base)
                                       .property("next", local.reference_type(vsd::TypeKind::SharedRef, base))
                                       .define(local);
    const vsd::MetaInstance& leaf = vsd::ClassBuilder("RgPrivLeaf", mid).property<int>("n", 3).define(local);
    EXPECT_TRUE(leaf.is_a(base));
    vsd::Environment env(0, local);
    auto& x = env.main_state().create("RgPrivLeaf");
    EXPECT_EQ(x.get<int>("n"), 3);
  }
  EXPECT_EQ(vsd::Registry::global().find_class("RgPrivBase"), nullptr);
}

// undefine_all removes what nothing else uses and keeps the rest with what it uses, in one pass.
TEST(Registry, UndefineAllKeepsWhatIsUsedAndRemovesTheRest) {
  vsd::Registry r;
  const vsd::MetaType& color = vsd::EnumBuilder("RgColor").value("Red", 0).define(r);
  const vsd::MetaType& tag = vsd::StructBuilder("RgTag").field("color", color).define(r);
  const vsd::MetaType& spare = vsd::EnumBuilder("RgSpare").value("A", 0).define(r);
  const vsd::MetaType& spares = r.get_type("vector<vector<RgSpare>>");
  const vsd::MetaInstance& base = vsd::ClassBuilder("RgAllBase", vsd::Node::static_meta()).define(r);
  const vsd::MetaInstance& sub = vsd::ClassBuilder("RgAllSub", base).property("tag", tag).define(r);
  const vsd::MetaInstance& lone = vsd::ClassBuilder("RgAllLone", vsd::Node::static_meta())
                                      .property("spare", spares)
                                      .property("other", r.reference_type(vsd::TypeKind::SharedRef, base))
                                      .define(r);
  const vsd::MetaInstance& user = vsd::ClassBuilder("RgAllUser", vsd::Node::static_meta())
                                      .property("watched", r.reference_type(vsd::TypeKind::SharedRef, lone))
                                      .define(r);
  {
    vsd::Environment env(0, r);
    env.main_state().create(sub);  // a live instance keeps RgAllSub, its base and the types it uses
    const std::vector<const vsd::MetaInstance*> classes{&base, &sub, &lone};
    const std::vector<const vsd::MetaType*> types{&color, &tag, &spare};
    r.undefine_all(classes, types);
    EXPECT_NE(r.find_class("RgAllSub"), nullptr);
    EXPECT_NE(r.find_class("RgAllBase"), nullptr);
    EXPECT_NE(r.find_type("RgTag"), nullptr);
    EXPECT_NE(r.find_type("RgColor"), nullptr);
    EXPECT_NE(r.find_class("RgAllLone"), nullptr) << "RgAllUser, not in the lists, refers to it";
    EXPECT_NE(r.find_type("RgSpare"), nullptr) << "RgAllLone, kept, uses it";
  }
  r.undefine(user);
  const std::vector<const vsd::MetaInstance*> classes{&lone, &sub, &base};
  const std::vector<const vsd::MetaType*> types{&tag, &spare, &color};
  r.undefine_all(classes, types);  // the instance is gone: everything goes
  for (const char* name : {"RgAllBase", "RgAllSub", "RgAllLone"})
    EXPECT_EQ(r.find_class(name), nullptr) << name;
  for (const char* name : {"RgColor", "RgTag", "RgSpare", "vector<RgSpare>", "vector<vector<RgSpare>>",
                           "shared<RgAllBase>", "shared<RgAllLone>"})
    EXPECT_EQ(r.find_type(name), nullptr) << name;
  const auto derived = vsd::Node::static_meta().derived();
  EXPECT_EQ(std::count(derived.begin(), derived.end(), &base), 0) << "unlinked from its base";
}

TEST(Registry, ARunTimeBaseMustLiveInTheSameRegistry) {
  vsd::Registry one;
  vsd::Registry two;
  const vsd::MetaInstance& base = vsd::ClassBuilder("RgOneBase", vsd::Node::static_meta()).define(one);
  EXPECT_THAT([&] { (void)vsd::ClassBuilder("RgTwoSub", base).define(two); },
              testing::ThrowsMessage<vsd::Error>(testing::HasSubstr("another registry")));
  EXPECT_EQ(two.find_class("RgTwoSub"), nullptr);
  EXPECT_TRUE(base.derived().empty());
}
