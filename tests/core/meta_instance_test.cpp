// Tests of vsd/core/meta_instance.hpp, meta_property.hpp, meta_method.hpp and declare.hpp: the class
// descriptors of C++ classes declared with VSD_INSTANCE / VSD_PROPERTY / VSD_METHOD.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>
#include <vsd/vsd.hpp>

#include "test_util.hpp"

namespace mi {

class MiVehicle : public vsd::Node {
  VSD_INSTANCE(MiVehicle, vsd::Node)
  VSD_PROPERTY(double, speed, 1.5)
  VSD_PROPERTY(std::int32_t, wheels, 4, vsd::Editable | vsd::Savable)
  VSD_PROPERTY(std::string, label, "car")
  VSD_PROPERTY(std::int64_t, serial, 7, vsd::ReadOnly)
  VSD_PROPERTY(std::vector<double>, samples, (std::vector<double>{1.0, 2.0}))

 public:
  void honk() { ++honks_; }
  VSD_METHOD(honk)
  [[nodiscard]] std::int32_t honk_count() const { return honks_; }
  VSD_METHOD(honk_count)
  void rename(const std::string& s) { set_label(s); }
  VSD_METHOD(rename)
  [[nodiscard]] double add(double a, std::int32_t b) const { return a + b; }
  VSD_METHOD(add)
  [[nodiscard]] std::string describe() const { return "vehicle " + label(); }
  VSD_METHOD(describe)

 private:
  std::int32_t honks_ = 0;
};

class MiTruck : public MiVehicle {
  VSD_INSTANCE(MiTruck, mi::MiVehicle)
  VSD_PROPERTY(double, load, 0.0)

 public:
  [[nodiscard]] std::string describe() const {
    return "truck carrying " + std::to_string(static_cast<int>(load()));
  }
  VSD_METHOD(describe)
};

// Unrelated to MiVehicle; starts with doubles so that a MiVehicle offset read from it stays in bounds.
class MiGadget : public vsd::Node {
  VSD_INSTANCE(MiGadget, vsd::Node)
  VSD_PROPERTY(double, a, 0.25)
  VSD_PROPERTY(double, b, 0.5)
  VSD_PROPERTY(double, c, 0.75)
  VSD_PROPERTY(double, d, 1.0)
  VSD_PROPERTY(double, e, 1.25)
  VSD_PROPERTY(double, f, 1.5)
  VSD_PROPERTY(double, g, 1.75)
  VSD_PROPERTY(double, h, 2.0)
  VSD_PROPERTY(double, i, 2.25)
  VSD_PROPERTY(double, j, 2.5)
  VSD_PROPERTY(double, k, 2.75)
  VSD_PROPERTY(double, l, 3.0)
};

class MiShape : public vsd::Node {
  VSD_ABSTRACT_INSTANCE(MiShape, vsd::Node)
  VSD_PROPERTY(double, area, 0.0)
};

}  // namespace mi

namespace {

using mi::MiGadget;
using mi::MiShape;
using mi::MiTruck;
using mi::MiVehicle;
using testing::ElementsAre;
using testing::HasSubstr;

using vsd_test::error_of;

using vsd_test::names_of;

std::vector<std::string> method_names(const vsd::MetaInstance& m) {
  std::vector<std::string> out;
  for (const vsd::MetaMethod* x : m.methods()) out.push_back(x->name());
  return out;
}

class MetaInstanceTest : public testing::Test {
 protected:
  vsd::Environment env;
  vsd::SimState& state = env.main_state();
};

// ---- class descriptors ------------------------------------------------------------------------------------

TEST(MetaInstance, NameBaseAndDepth) {
  const vsd::MetaInstance& m = MiVehicle::static_meta();
  EXPECT_EQ(m.name(), "MiVehicle");
  EXPECT_EQ(m.base(), &vsd::Node::static_meta());
  EXPECT_EQ(vsd::Instance::static_meta().depth(), 0u);
  EXPECT_EQ(vsd::Instance::static_meta().base(), nullptr);
  EXPECT_EQ(vsd::SimStateInstance::static_meta().depth(), 1u);
  EXPECT_EQ(vsd::NamedModelInstance::static_meta().depth(), 2u);
  EXPECT_EQ(vsd::Node::static_meta().depth(), 3u);
  EXPECT_EQ(m.depth(), 4u);
  EXPECT_EQ(MiTruck::static_meta().depth(), 5u);
  EXPECT_EQ(MiTruck::static_meta().base(), &m);
  EXPECT_FALSE(m.is_runtime());
  EXPECT_FALSE(m.is_abstract());
  EXPECT_TRUE(MiShape::static_meta().is_abstract());
  EXPECT_EQ(m.size(), sizeof(MiVehicle));
  EXPECT_EQ(m.alignment(), alignof(MiVehicle));
  EXPECT_NE(m.index(), MiTruck::static_meta().index());
}

TEST(MetaInstance, IsA) {
  const vsd::MetaInstance& vehicle = MiVehicle::static_meta();
  const vsd::MetaInstance& truck = MiTruck::static_meta();
  EXPECT_TRUE(vehicle.is_a(vehicle));
  EXPECT_TRUE(vehicle.is_a(vsd::Node::static_meta()));
  EXPECT_TRUE(vehicle.is_a(vsd::NamedModelInstance::static_meta()));
  EXPECT_TRUE(vehicle.is_a(vsd::SimStateInstance::static_meta()));
  EXPECT_TRUE(vehicle.is_a(vsd::Instance::static_meta()));
  EXPECT_TRUE(truck.is_a(vehicle));
  EXPECT_FALSE(vehicle.is_a(truck)) << "a base is not its subclass";
  EXPECT_FALSE(vehicle.is_a(MiGadget::static_meta()));
  EXPECT_FALSE(vehicle.is_a(vsd::Extension::static_meta()));
  EXPECT_FALSE(vehicle.is_a(vsd::Database::static_meta()));
  EXPECT_FALSE(vsd::Node::static_meta().is_a(vehicle));
}

TEST(MetaInstance, DerivedListsSubclasses) {
  const auto derived = MiVehicle::static_meta().derived();
  EXPECT_NE(std::find(derived.begin(), derived.end(), &MiTruck::static_meta()), derived.end());
  const auto nodes = vsd::Node::static_meta().derived();
  EXPECT_NE(std::find(nodes.begin(), nodes.end(), &MiVehicle::static_meta()), nodes.end());
  EXPECT_NE(std::find(nodes.begin(), nodes.end(), &MiGadget::static_meta()), nodes.end());
  EXPECT_EQ(std::find(nodes.begin(), nodes.end(), &MiTruck::static_meta()), nodes.end())
      << "only direct subclasses";
}

TEST(MetaInstance, PropertiesInheritedFirst) {
  EXPECT_THAT(names_of(MiVehicle::static_meta().properties()),
              ElementsAre("name", "extensions", "children", "speed", "wheels", "label", "serial", "samples"));
  EXPECT_THAT(names_of(MiVehicle::static_meta().own_properties()),
              ElementsAre("speed", "wheels", "label", "serial", "samples"));
  EXPECT_THAT(
      names_of(MiTruck::static_meta().properties()),
      ElementsAre("name", "extensions", "children", "speed", "wheels", "label", "serial", "samples", "load"));
  EXPECT_THAT(names_of(MiTruck::static_meta().own_properties()), ElementsAre("load"));
  EXPECT_THAT(names_of(vsd::Node::static_meta().own_properties()), ElementsAre("children"));
}

TEST(MetaInstance, ReferencePropertiesAreListed) {
  EXPECT_THAT(names_of(MiVehicle::static_meta().reference_properties()),
              ElementsAre("extensions", "children"));
}

TEST(MetaInstance, FindProperty) {
  const vsd::MetaInstance& m = MiVehicle::static_meta();
  const vsd::MetaProperty* speed = m.find_property("speed");
  ASSERT_NE(speed, nullptr);
  EXPECT_EQ(speed->name(), "speed");
  EXPECT_EQ(&speed->type(), &vsd::meta_type<double>());
  EXPECT_EQ(&speed->owner(), &m);
  EXPECT_EQ(speed, &MiVehicle::vsd_prop_speed());
  const vsd::MetaProperty* name = m.find_property("name");
  ASSERT_NE(name, nullptr);
  EXPECT_EQ(&name->owner(), &vsd::NamedModelInstance::static_meta());
  EXPECT_EQ(m.find_property("nope"), nullptr);
  EXPECT_EQ(m.find_property(""), nullptr);
  EXPECT_EQ(m.find_property("Speed"), nullptr) << "names are case-sensitive";
  EXPECT_EQ(vsd::Node::static_meta().find_property("speed"), nullptr)
      << "a base does not see subclass properties";
  EXPECT_EQ(MiTruck::static_meta().find_property("speed"), speed)
      << "inherited properties are the same object";
  EXPECT_EQ(&m.property("label"), &MiVehicle::vsd_prop_label());
}

TEST(MetaInstance, PropertyThrowsNamingClassAndProperty) {
  const std::string e = error_of([] { (void)MiVehicle::static_meta().property("altitude"); });
  EXPECT_THAT(e, HasSubstr("MiVehicle"));
  EXPECT_THAT(e, HasSubstr("altitude"));
}

TEST(MetaInstance, PropertyFlags) {
  const vsd::MetaProperty& speed = MiVehicle::vsd_prop_speed();
  EXPECT_EQ(speed.flags(), vsd::DefaultFlags);
  EXPECT_EQ(vsd::DefaultFlags, vsd::Editable | vsd::Savable | vsd::Distributed);
  EXPECT_TRUE(speed.has(vsd::Editable));
  EXPECT_TRUE(speed.has(vsd::Savable | vsd::Distributed));
  EXPECT_FALSE(speed.has(vsd::ReadOnly));

  const vsd::MetaProperty& wheels = MiVehicle::vsd_prop_wheels();
  EXPECT_EQ(wheels.flags(), vsd::Editable | vsd::Savable);
  EXPECT_FALSE(wheels.has(vsd::Distributed));

  const vsd::MetaProperty& serial = MiVehicle::vsd_prop_serial();
  EXPECT_EQ(serial.flags(), vsd::ReadOnly) << "explicit flags replace the defaults";
  EXPECT_TRUE(serial.has(vsd::ReadOnly));

  EXPECT_EQ(vsd::Node::vsd_prop_children().flags(), vsd::Savable | vsd::Distributed);
  EXPECT_TRUE(vsd::NamedModelInstance::vsd_prop_name().has(vsd::Editable));
}

TEST(MetaInstance, DefaultValues) {
  EXPECT_EQ(MiVehicle::vsd_prop_speed().default_value().as<double>(), 1.5);
  EXPECT_EQ(MiVehicle::vsd_prop_wheels().default_value().as<std::int32_t>(), 4);
  EXPECT_EQ(MiVehicle::vsd_prop_label().default_value().as<std::string>(), "car");
  EXPECT_EQ(MiVehicle::vsd_prop_serial().default_value().as<std::int64_t>(), 7);
  EXPECT_EQ(MiVehicle::vsd_prop_samples().default_value().as<std::vector<double>>(),
            (std::vector<double>{1.0, 2.0}));
  EXPECT_EQ(vsd::NamedModelInstance::vsd_prop_name().default_value().as<std::string>(), "");
}

// ---- instances: typed and generic access ------------------------------------------------------------------

TEST_F(MetaInstanceTest, NewInstanceHasTheDefaults) {
  auto& v = state.create<MiVehicle>();
  EXPECT_EQ(&v.meta(), &MiVehicle::static_meta());
  EXPECT_EQ(v.speed(), 1.5);
  EXPECT_EQ(v.wheels(), 4);
  EXPECT_EQ(v.label(), "car");
  EXPECT_EQ(v.serial(), 7);
  EXPECT_EQ(v.samples(), (std::vector<double>{1.0, 2.0}));
  EXPECT_EQ(v.name(), "");
  for (const vsd::MetaProperty* p : v.meta().properties()) {
    if (p->type().is_reference()) continue;
    EXPECT_TRUE(v.get(p->name()) == p->default_value()) << p->name();
  }
}

TEST_F(MetaInstanceTest, InstanceIsA) {
  auto& t = state.create<MiTruck>();
  EXPECT_TRUE(t.is_a<MiTruck>());
  EXPECT_TRUE(t.is_a<MiVehicle>());
  EXPECT_TRUE(t.is_a<vsd::Node>());
  EXPECT_FALSE(t.is_a<MiGadget>());
  EXPECT_NE(t.as<MiVehicle>(), nullptr);
  EXPECT_EQ(t.as<MiGadget>(), nullptr);
}

TEST_F(MetaInstanceTest, TypedGettersAndSetters) {
  auto& v = state.create<MiVehicle>();
  v.set_speed(3.25);
  v.set_label("van");
  v.set_samples({4.0});
  v.set_name("v1");
  EXPECT_EQ(v.speed(), 3.25);
  EXPECT_EQ(v.label(), "van");
  EXPECT_EQ(v.samples(), std::vector<double>{4.0});
  EXPECT_EQ(v.name(), "v1");
  EXPECT_EQ(v.get("speed").as<double>(), 3.25);
  EXPECT_EQ(v.get<std::string>("label"), "van");
}

TEST_F(MetaInstanceTest, GenericAccessByHandle) {
  auto& v = state.create<MiVehicle>();
  const vsd::MetaProperty& speed = MiVehicle::static_meta().property("speed");
  EXPECT_EQ(speed.get<double>(v), 1.5);
  speed.set<double>(v, 4.0);
  EXPECT_EQ(v.speed(), 4.0);
  EXPECT_EQ(speed.get<double>(v), 4.0);
  EXPECT_EQ(speed.get_value(v).as<double>(), 4.0);
  speed.set_value(v, vsd::Value(5.0));
  EXPECT_EQ(v.speed(), 5.0);
  const vsd::MetaProperty& samples = MiVehicle::vsd_prop_samples();
  samples.set<std::vector<double>>(v, {7, 8, 9});
  EXPECT_EQ(v.samples(), (std::vector<double>{7, 8, 9}));
  EXPECT_EQ(speed.address(v), static_cast<const void*>(&v.speed()));
}

TEST_F(MetaInstanceTest, GenericAccessByName) {
  auto& v = state.create<MiVehicle>();
  const vsd::Value got = v.get("speed");
  EXPECT_TRUE(got.is<double>());
  EXPECT_EQ(got.as<double>(), 1.5);
  v.set("speed", vsd::Value(2.0));
  EXPECT_EQ(v.speed(), 2.0);
  v.set("speed", vsd::Value(3));  // int converts to double
  EXPECT_EQ(v.speed(), 3.0);
  v.set("wheels", vsd::Value(6.0));  // a whole double converts to int32
  EXPECT_EQ(v.wheels(), 6);
  v.set("label", vsd::Value("bus"));
  EXPECT_EQ(v.label(), "bus");
  v.set("name", vsd::Value("named"));
  EXPECT_EQ(v.name(), "named");
  v.set<double>("speed", 8.5);
  EXPECT_EQ(v.get<double>("speed"), 8.5);
}

TEST_F(MetaInstanceTest, GenericSetRejectsValuesThatDoNotConvert) {
  auto& v = state.create<MiVehicle>();
  const std::string fraction = error_of([&] { v.set("wheels", vsd::Value(2.5)); });
  EXPECT_THAT(fraction, HasSubstr("int32"));
  EXPECT_EQ(v.wheels(), 4) << "a rejected set changes nothing";
  const std::string text = error_of([&] { v.set("speed", vsd::Value("fast")); });
  EXPECT_THAT(text, HasSubstr("double"));
  EXPECT_THAT(text, HasSubstr("string"));
  EXPECT_EQ(v.speed(), 1.5);
  const std::string unknown = error_of([&] { v.set("altitude", vsd::Value(1.0)); });
  EXPECT_THAT(unknown, HasSubstr("MiVehicle"));
  EXPECT_THAT(unknown, HasSubstr("altitude"));
  const std::string unknown_get = error_of([&] { (void)v.get("altitude"); });
  EXPECT_THAT(unknown_get, HasSubstr("altitude"));
}

TEST_F(MetaInstanceTest, WrongTypeByHandleThrows) {
  auto& v = state.create<MiVehicle>();
  const vsd::MetaProperty& speed = MiVehicle::vsd_prop_speed();
  const std::string get = error_of([&] { (void)speed.get<std::int32_t>(v); });
  EXPECT_THAT(get, HasSubstr("MiVehicle::speed"));
  EXPECT_THAT(get, HasSubstr("double"));
  EXPECT_THAT(get, HasSubstr("int32"));
  const std::string set = error_of([&] { speed.set<float>(v, 1.0f); });
  EXPECT_THAT(set, HasSubstr("double"));
  EXPECT_THAT(set, HasSubstr("float"));
  EXPECT_EQ(v.speed(), 1.5);
  EXPECT_THROW((void)v.get<std::string>("speed"), vsd::Error);
  EXPECT_THROW(v.set<std::int32_t>("speed", 3), vsd::Error) << "the typed path does not convert";
}

TEST_F(MetaInstanceTest, ReadOnlyPropertyRejectsGenericSetButNotTheTypedSetter) {
  auto& v = state.create<MiVehicle>();
  const vsd::MetaProperty& serial = MiVehicle::vsd_prop_serial();
  const std::string by_name = error_of([&] { v.set("serial", vsd::Value(std::int64_t{9})); });
  EXPECT_THAT(by_name, HasSubstr("MiVehicle::serial"));
  EXPECT_THAT(by_name, HasSubstr("read-only"));
  EXPECT_THAT(error_of([&] { serial.set<std::int64_t>(v, 9); }), HasSubstr("read-only"));
  EXPECT_THAT(error_of([&] { serial.set_value(v, vsd::Value(std::int64_t{9})); }), HasSubstr("read-only"));
  EXPECT_EQ(v.serial(), 7);
  v.set_serial(9);  // the C++ API may change it
  EXPECT_EQ(v.serial(), 9);
  EXPECT_EQ(serial.get<std::int64_t>(v), 9) << "reading a read-only property is fine";
  EXPECT_EQ(v.get("serial").as<std::int64_t>(), 9);
}

TEST_F(MetaInstanceTest, PropertyOfAnotherClassIsRejected) {
  auto& g = state.create<MiGadget>();
  const vsd::MetaProperty& speed = MiVehicle::vsd_prop_speed();
  const std::string get = error_of([&] { (void)speed.get<double>(g); });
  EXPECT_THAT(get, HasSubstr("MiVehicle::speed"));
  EXPECT_THAT(get, HasSubstr("MiGadget"));
  EXPECT_THAT(error_of([&] { speed.set<double>(g, 1.0); }), HasSubstr("MiGadget"));
  EXPECT_THAT(error_of([&] { speed.set_value(g, vsd::Value(1.0)); }), HasSubstr("MiGadget"));
  EXPECT_EQ(g.a(), 0.25) << "nothing was written into the gadget";
  // Reading through get_value must check the class just like get<T>.
  EXPECT_THAT(error_of([&] { (void)speed.get_value(g); }), HasSubstr("MiGadget"));
}

TEST_F(MetaInstanceTest, BasePropertyWorksOnSubclassInstances) {
  auto& t = state.create<MiTruck>();
  const vsd::MetaProperty& speed = MiVehicle::vsd_prop_speed();
  speed.set<double>(t, 9.0);
  EXPECT_EQ(t.speed(), 9.0);
  EXPECT_EQ(speed.get<double>(t), 9.0);
  const vsd::MetaProperty& name = vsd::NamedModelInstance::vsd_prop_name();
  name.set<std::string>(t, "big");
  EXPECT_EQ(t.name(), "big");
  // A subclass property on a base-class instance is rejected.
  auto& v = state.create<MiVehicle>();
  EXPECT_THROW((void)MiTruck::vsd_prop_load().get<double>(v), vsd::Error);
}

TEST_F(MetaInstanceTest, AbstractClassCannotBeCreated) {
  const std::string e = error_of([&] { (void)state.create(MiShape::static_meta()); });
  EXPECT_THAT(e, HasSubstr("MiShape"));
  EXPECT_THAT(e, HasSubstr("abstract"));
}

TEST_F(MetaInstanceTest, CreateByName) {
  vsd::SimStateInstance& x = state.create("MiVehicle");
  EXPECT_EQ(&x.meta(), &MiVehicle::static_meta());
  EXPECT_EQ(static_cast<MiVehicle&>(x).speed(), 1.5);
  EXPECT_THAT(error_of([&] { (void)state.create("MiSpaceship"); }), HasSubstr("MiSpaceship"));
}

// ---- methods ----------------------------------------------------------------------------------------------

TEST(MetaMethod, SignaturesOfDeclaredMethods) {
  const vsd::MetaInstance& m = MiVehicle::static_meta();
  EXPECT_THAT(method_names(m), ElementsAre("honk", "honk_count", "rename", "add", "describe"));
  const vsd::MetaMethod& add = m.method("add");
  EXPECT_EQ(add.name(), "add");
  EXPECT_EQ(&add.owner(), &m);
  EXPECT_EQ(add.result(), &vsd::meta_type<double>());
  ASSERT_EQ(add.arguments().size(), 2u);
  EXPECT_EQ(add.arguments()[0], &vsd::meta_type<double>());
  EXPECT_EQ(add.arguments()[1], &vsd::meta_type<std::int32_t>());
  EXPECT_EQ(add.signature(), "add(double, int32) -> double");
  EXPECT_EQ(m.method("honk").result(), nullptr);
  EXPECT_EQ(m.method("honk").signature(), "honk()");
  EXPECT_EQ(m.method("rename").signature(), "rename(string)");
  EXPECT_EQ(m.find_method("fly"), nullptr);
  EXPECT_THAT(error_of([&] { (void)m.method("fly"); }), HasSubstr("fly"));
}

TEST_F(MetaInstanceTest, CallWithZeroOneAndTwoArguments) {
  auto& v = state.create<MiVehicle>();
  const vsd::Value none = v.call("honk");
  EXPECT_TRUE(none.empty()) << "a void method returns an empty Value";
  v.call("honk", {});
  EXPECT_EQ(v.call("honk_count").as<std::int32_t>(), 2);

  v.call("rename", {vsd::Value("lorry")});
  EXPECT_EQ(v.label(), "lorry");
  EXPECT_EQ(v.call("describe").as<std::string>(), "vehicle lorry");

  const vsd::Value sum = v.call("add", {vsd::Value(1.5), vsd::Value(2)});
  EXPECT_EQ(sum.as<double>(), 3.5);
}

TEST_F(MetaInstanceTest, CallConvertsExactNumbers) {
  auto& v = state.create<MiVehicle>();
  EXPECT_EQ(v.call("add", {vsd::Value(1), vsd::Value(2.0)}).as<double>(), 3.0);
  EXPECT_EQ(v.call("add", {vsd::Value(1.0f), vsd::Value(std::int64_t{-4})}).as<double>(), -3.0);
}

TEST_F(MetaInstanceTest, CallThroughTheClassDescriptor) {
  auto& v = state.create<MiVehicle>();
  const std::vector<vsd::Value> args{vsd::Value(0.5), vsd::Value(1)};
  EXPECT_EQ(MiVehicle::static_meta().call(v, "add", args).as<double>(), 1.5);
  EXPECT_EQ(v.meta().call(v, "describe", {}).as<std::string>(), "vehicle car");
  const std::vector<vsd::Value> one{vsd::Value("renamed")};
  MiVehicle::static_meta().method("rename").invoke(v, one);
  EXPECT_EQ(v.label(), "renamed");
}

TEST_F(MetaInstanceTest, CallUnknownMethod) {
  auto& v = state.create<MiVehicle>();
  const std::string e = error_of([&] { (void)v.call("fly", {vsd::Value(1)}); });
  EXPECT_THAT(e, HasSubstr("MiVehicle"));
  EXPECT_THAT(e, HasSubstr("'fly'"));
}

TEST_F(MetaInstanceTest, CallWithWrongArity) {
  auto& v = state.create<MiVehicle>();
  const std::string few = error_of([&] { (void)v.call("add", {vsd::Value(1.0)}); });
  EXPECT_THAT(few, HasSubstr("MiVehicle::add"));
  EXPECT_THAT(few, HasSubstr("takes 2"));
  EXPECT_THAT(few, HasSubstr("got 1"));
  const std::string many = error_of([&] { (void)v.call("honk", {vsd::Value(1)}); });
  EXPECT_THAT(many, HasSubstr("takes 0"));
  EXPECT_THAT(many, HasSubstr("got 1"));
  EXPECT_EQ(v.call("honk_count").as<std::int32_t>(), 0) << "a rejected call does not run";
}

TEST_F(MetaInstanceTest, CallWithWrongArgumentType) {
  auto& v = state.create<MiVehicle>();
  const std::string text = error_of([&] { (void)v.call("add", {vsd::Value(1.0), vsd::Value("two")}); });
  EXPECT_THAT(text, HasSubstr("MiVehicle::add"));
  EXPECT_THAT(text, HasSubstr("argument 2"));
  EXPECT_THAT(text, HasSubstr("int32"));
  EXPECT_THAT(text, HasSubstr("string"));
  const std::string fraction = error_of([&] { (void)v.call("add", {vsd::Value(1.0), vsd::Value(2.5)}); });
  EXPECT_THAT(fraction, HasSubstr("argument 2"));
  const std::string first = error_of([&] { (void)v.call("rename", {vsd::Value(3)}); });
  EXPECT_THAT(first, HasSubstr("argument 1"));
  EXPECT_THAT(first, HasSubstr("string"));
  EXPECT_EQ(v.label(), "car");
  const std::string empty = error_of([&] { (void)v.call("rename", {vsd::Value()}); });
  EXPECT_THAT(empty, HasSubstr("argument 1"));
}

TEST_F(MetaInstanceTest, CallOnAnInstanceOfAnotherClass) {
  auto& g = state.create<MiGadget>();
  const std::string e = error_of([&] { (void)MiVehicle::static_meta().call(g, "honk", {}); });
  EXPECT_THAT(e, HasSubstr("MiVehicle"));
  EXPECT_THAT(e, HasSubstr("MiGadget"));
}

TEST_F(MetaInstanceTest, SubclassMethodHidesTheBaseMethod) {
  auto& t = state.create<MiTruck>();
  t.set_load(12);
  EXPECT_EQ(t.call("describe").as<std::string>(), "truck carrying 12");
  auto& v = state.create<MiVehicle>();
  EXPECT_EQ(v.call("describe").as<std::string>(), "vehicle car");
  // The subclass sees one "describe", its own, and inherits the others.
  const auto names = method_names(MiTruck::static_meta());
  EXPECT_EQ(std::count(names.begin(), names.end(), "describe"), 1);
  EXPECT_EQ(names.size(), 5u);
  EXPECT_EQ(&MiTruck::static_meta().method("describe").owner(), &MiTruck::static_meta());
  EXPECT_EQ(&MiTruck::static_meta().method("honk").owner(), &MiVehicle::static_meta());
  t.call("honk");
  EXPECT_EQ(t.call("honk_count").as<std::int32_t>(), 1);
  // Calling through the base class's descriptor dispatches by name on the base's table.
  const std::vector<vsd::Value> args{vsd::Value(1.0), vsd::Value(1)};
  EXPECT_EQ(MiVehicle::static_meta().call(t, "add", args).as<double>(), 2.0);
}

}  // namespace
