// Tests of run-time classes (vsd::ClassBuilder in vsd/core/meta_instance.hpp): classes defined while the
// program runs behave like C++ classes on every generic path. Class names are global in
// Registry::global(), so every test uses its own prefix and undefines its classes at the end.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cstdint>
#include <functional>
#include <span>
#include <string>
#include <vector>
#include <vsd/vsd.hpp>

#include "test_util.hpp"

namespace rc {

// A C++ class that run-time classes derive from.
class RcMotor : public vsd::Node {
  VSD_INSTANCE(RcMotor, vsd::Node)
  VSD_PROPERTY(double, torque, 1.0)

 public:
  [[nodiscard]] double doubled() const { return 2 * torque(); }
  VSD_METHOD(doubled)
};

}  // namespace rc

namespace {

using rc::RcMotor;
using testing::ElementsAre;
using testing::HasSubstr;

using vsd_test::error_of;

using vsd_test::names_of;

/// Undefines a run-time class when the test ends (also when it fails early). Declare guards before the
/// Environment whose instances they outlive, and a subclass's guard after its base's.
class Defined {
 public:
  explicit Defined(const vsd::MetaInstance& cls) : cls_(&cls), name_(cls.name()) {}
  Defined(const Defined&) = delete;
  Defined& operator=(const Defined&) = delete;
  ~Defined() {
    if (cls_ == nullptr || vsd::Registry::global().find_class(name_) != cls_) return;
    try {
      vsd::Registry::global().undefine(*cls_);
    } catch (const vsd::Error& e) {
      ADD_FAILURE() << "could not undefine " << name_ << ": " << e.what();
    }
  }
  const vsd::MetaInstance& operator*() const { return *cls_; }
  const vsd::MetaInstance* operator->() const { return cls_; }
  /// The test undefines the class itself.
  void dismiss() { cls_ = nullptr; }

 private:
  const vsd::MetaInstance* cls_;
  std::string name_;
};

Eigen::Isometry3d frame(double x, double y, double z) {
  Eigen::Isometry3d f = Eigen::Isometry3d::Identity();
  f.translation() = Eigen::Vector3d(x, y, z);
  return f;
}

const vsd::MetaType& shared_node_type() {
  return vsd::Registry::global().reference_type(vsd::TypeKind::SharedRef, vsd::Node::static_meta());
}

// A run-time class deriving Node with properties of several types and a method bound to a lambda.
const vsd::MetaInstance& define_robot(const std::string& name) {
  return vsd::ClassBuilder(name, vsd::Node::static_meta())
      .property<double>("speed", 2.5)
      .property<std::string>("label", std::string("r2"))
      .property<std::vector<double>>("samples", std::vector<double>{1.0, 2.0})
      .property<Eigen::Isometry3d>("pose", frame(1, 2, 3))
      .property("target", shared_node_type())
      .property<std::int32_t>("count", 0, vsd::Editable | vsd::Transient)
      .method("scaled_speed", {&vsd::meta_type<double>()}, &vsd::meta_type<double>(),
              [](vsd::SimStateInstance& self, std::span<const vsd::Value> args) -> vsd::Value {
                return vsd::Value(self.get<double>("speed") * args[0].as<double>());
              })
      .method("reset_speed", {}, nullptr,
              [](vsd::SimStateInstance& self, std::span<const vsd::Value>) -> vsd::Value {
                self.set("speed", vsd::Value(0.0));
                return {};
              })
      .define();
}

vsd::Node& as_node(vsd::SimStateInstance& x) { return static_cast<vsd::Node&>(x); }

const vsd::SimStateInstance* target_of(const vsd::SimStateInstance& x) {
  const vsd::Value v = x.get("target");
  return static_cast<const vsd::RefBase*>(v.data())->get();
}

// ---- defining ---------------------------------------------------------------------------------------------

TEST(RuntimeClass, DefineDescribesTheClass) {
  Defined cls(define_robot("RcDescribe_Robot"));
  EXPECT_EQ(cls->name(), "RcDescribe_Robot");
  EXPECT_EQ(cls->base(), &vsd::Node::static_meta());
  EXPECT_TRUE(cls->is_runtime());
  EXPECT_FALSE(cls->is_abstract());
  EXPECT_EQ(cls->depth(), vsd::Node::static_meta().depth() + 1);
  EXPECT_TRUE(cls->is_a(vsd::Node::static_meta()));
  EXPECT_TRUE(cls->is_a(*cls));
  EXPECT_FALSE(vsd::Node::static_meta().is_a(*cls));
  EXPECT_FALSE(cls->is_a(RcMotor::static_meta()));
  EXPECT_EQ(vsd::Registry::global().find_class("RcDescribe_Robot"), &*cls);
  const auto derived = vsd::Node::static_meta().derived();
  EXPECT_NE(std::find(derived.begin(), derived.end(), &*cls), derived.end());
  EXPECT_GT(cls->size(), sizeof(vsd::Node));
  EXPECT_GE(cls->alignment(), alignof(Eigen::Isometry3d));
  EXPECT_EQ(cls->size() % cls->alignment(), 0u);

  EXPECT_THAT(names_of(cls->properties()), ElementsAre("name", "extensions", "children", "speed", "label",
                                                       "samples", "pose", "target", "count"));
  EXPECT_THAT(names_of(cls->own_properties()),
              ElementsAre("speed", "label", "samples", "pose", "target", "count"));
  EXPECT_THAT(names_of(cls->reference_properties()), ElementsAre("extensions", "children", "target"));

  const vsd::MetaProperty& speed = cls->property("speed");
  EXPECT_EQ(&speed.type(), &vsd::meta_type<double>());
  EXPECT_EQ(&speed.owner(), &*cls);
  EXPECT_EQ(speed.flags(), vsd::DefaultFlags);
  EXPECT_EQ(speed.default_value().as<double>(), 2.5);
  EXPECT_EQ(cls->property("label").default_value().as<std::string>(), "r2");
  EXPECT_EQ(cls->property("samples").default_value().as<std::vector<double>>(),
            (std::vector<double>{1.0, 2.0}));
  EXPECT_EQ(cls->property("pose").default_value().as<Eigen::Isometry3d>().translation(),
            Eigen::Vector3d(1, 2, 3));
  EXPECT_EQ(&cls->property("target").type(), &shared_node_type());
  EXPECT_EQ(cls->property("count").flags(), vsd::Editable | vsd::Transient);
  EXPECT_EQ(cls->find_property("nope"), nullptr);
  EXPECT_THAT(error_of([&] { (void)cls->property("nope"); }), HasSubstr("RcDescribe_Robot"));

  EXPECT_EQ(cls->method("scaled_speed").signature(), "scaled_speed(double) -> double");
  EXPECT_EQ(cls->method("reset_speed").result(), nullptr);
}

TEST(RuntimeClass, PropertyWithoutDefaultStartsAtTheTypeDefault) {
  Defined cls(vsd::ClassBuilder("RcNoDefault_Class", vsd::Node::static_meta())
                  .property("plain", vsd::meta_type<std::string>())
                  .property("number", vsd::meta_type<double>(), vsd::Value(3))  // an exact number converts
                  .define());
  EXPECT_EQ(cls->property("plain").default_value().as<std::string>(), "");
  EXPECT_EQ(cls->property("number").default_value().as<double>(), 3.0);
  vsd::Environment env;
  auto& x = env.main_state().create(*cls);
  EXPECT_EQ(x.get<std::string>("plain"), "");
  EXPECT_EQ(x.get<double>("number"), 3.0);
}

// ---- instances --------------------------------------------------------------------------------------------

TEST(RuntimeClass, CreateByClassAndByName) {
  Defined cls(define_robot("RcCreate_Robot"));
  vsd::Environment env;
  auto& state = env.main_state();
  vsd::SimStateInstance& a = state.create(*cls);
  vsd::SimStateInstance& b = state.create("RcCreate_Robot");
  EXPECT_EQ(&a.meta(), &*cls);
  EXPECT_EQ(&b.meta(), &*cls);
  EXPECT_NE(a.id(), b.id());
  EXPECT_EQ(cls->live_instances(), 2u);
  EXPECT_EQ(state.find(a.id()), &a);
  for (vsd::SimStateInstance* x : {&a, &b}) {
    EXPECT_EQ(x->get<double>("speed"), 2.5);
    EXPECT_EQ(x->get<std::string>("label"), "r2");
    EXPECT_EQ(x->get<std::vector<double>>("samples"), (std::vector<double>{1.0, 2.0}));
    EXPECT_EQ(x->get<Eigen::Isometry3d>("pose").translation(), Eigen::Vector3d(1, 2, 3));
    EXPECT_EQ(target_of(*x), nullptr);
    EXPECT_EQ(x->get<std::int32_t>("count"), 0);
  }
  const auto& pose = cls->property("pose");
  EXPECT_EQ(reinterpret_cast<std::uintptr_t>(pose.address(a)) % alignof(Eigen::Isometry3d), 0u);
  EXPECT_THAT(error_of([&] { (void)state.create("RcCreate_NoSuchClass"); }),
              HasSubstr("RcCreate_NoSuchClass"));
}

TEST(RuntimeClass, InstanceWorksAsANode) {
  Defined cls(define_robot("RcNode_Robot"));
  vsd::Environment env;
  auto& state = env.main_state();
  vsd::SimStateInstance& x = state.create(*cls);
  EXPECT_TRUE(x.is_a<vsd::Node>());
  EXPECT_TRUE(x.is_a<vsd::NamedModelInstance>());
  EXPECT_FALSE(x.is_a<vsd::Extension>());
  vsd::Node* node = x.as<vsd::Node>();
  ASSERT_NE(node, nullptr);
  node->set_name("rt");
  EXPECT_EQ(x.get<std::string>("name"), "rt");
  state.database().add_child(*node);
  EXPECT_EQ(node->parent(), &state.database());
  EXPECT_EQ(node->path(), "/rt");
  EXPECT_EQ(state.database().find_child("rt"), node);
  auto& child = state.create<vsd::Node>();
  child.set_name("kid");
  node->add_child(child);
  EXPECT_EQ(child.path(), "/rt/kid");
  EXPECT_EQ(x.get("children").to_text(), "[\"@" + std::to_string(child.id()) + "\"]");
  // Removing the run-time node from the tree deletes it with its subtree.
  const vsd::Id id = x.id();
  state.database().remove_child(*node);
  EXPECT_EQ(state.find(id), nullptr);
  EXPECT_EQ(cls->live_instances(), 0u);
}

TEST(RuntimeClass, GenericGetAndSet) {
  Defined cls(define_robot("RcGeneric_Robot"));
  vsd::Environment env;
  vsd::SimStateInstance& x = env.main_state().create(*cls);
  x.set("speed", vsd::Value(3.0));
  EXPECT_EQ(x.get("speed").as<double>(), 3.0);
  x.set("speed", vsd::Value(4));  // int -> double
  EXPECT_EQ(x.get<double>("speed"), 4.0);
  x.set("label", vsd::Value("hello"));
  EXPECT_EQ(x.get<std::string>("label"), "hello");
  x.set("samples", vsd::Value(std::vector<double>{5, 6, 7}));
  EXPECT_EQ(x.get<std::vector<double>>("samples"), (std::vector<double>{5, 6, 7}));
  x.set("pose", vsd::Value(frame(7, 8, 9)));
  EXPECT_EQ(x.get<Eigen::Isometry3d>("pose").translation(), Eigen::Vector3d(7, 8, 9));
  x.set<std::int32_t>("count", 12);
  EXPECT_EQ(x.get<std::int32_t>("count"), 12);

  const vsd::MetaProperty& speed = cls->property("speed");
  speed.set<double>(x, 6.5);
  EXPECT_EQ(speed.get<double>(x), 6.5);
  EXPECT_EQ(speed.get_value(x).as<double>(), 6.5);

  EXPECT_THAT(error_of([&] { x.set("speed", vsd::Value("fast")); }), HasSubstr("string"));
  EXPECT_THAT(error_of([&] { (void)speed.get<float>(x); }), HasSubstr("RcGeneric_Robot::speed"));
  EXPECT_THAT(error_of([&] { x.set("altitude", vsd::Value(1.0)); }), HasSubstr("altitude"));
  EXPECT_EQ(x.get<double>("speed"), 6.5);

  // A property of the run-time class on an instance of another class is rejected.
  auto& plain = env.main_state().create<vsd::Node>();
  EXPECT_THAT(error_of([&] { (void)speed.get<double>(plain); }), HasSubstr("RcGeneric_Robot::speed"));
  EXPECT_THROW(speed.set_value(plain, vsd::Value(1.0)), vsd::Error);
}

TEST(RuntimeClass, SharedReferenceProperty) {
  Defined cls(define_robot("RcShared_Robot"));
  vsd::Environment env;
  auto& state = env.main_state();
  vsd::SimStateInstance& x = state.create(*cls);
  auto& target = state.create<vsd::Node>();
  x.set("target", vsd::Value(vsd::SharedRef<vsd::Node>(&target)));
  EXPECT_EQ(target_of(x), &target);
  EXPECT_EQ(x.get("target").to_text(), "\"@" + std::to_string(target.id()) + "\"");
  EXPECT_EQ(target.composite_count(), 0u) << "a shared reference does not count";

  int changes = 0;
  auto c = x.on_changed().connect([&](vsd::SimStateInstance&, const vsd::MetaProperty& p) {
    if (p.name() == "target") ++changes;
  });
  state.destroy(target);
  EXPECT_EQ(target_of(x), nullptr) << "deleting the target nulls the shared reference";
  EXPECT_EQ(changes, 1) << "and the holder is told";

  auto& ext = state.create<vsd::Extension>();
  EXPECT_THROW(x.set("target", vsd::Value(vsd::SharedRef<vsd::Extension>(&ext))), vsd::Error)
      << "an Extension is not a Node";
  EXPECT_EQ(target_of(x), nullptr);
}

TEST(RuntimeClass, SharedListPropertyAcceptsTheCppListType) {
  // The property's type comes from the registry by name; a C++ SharedRefList<Node> is "shared_list<Node>"
  // too.
  Defined cls(vsd::ClassBuilder("RcList_Class", vsd::Node::static_meta())
                  .property("friends", vsd::Registry::global().get_type("shared_list<Node>"))
                  .define());
  vsd::Environment env;
  auto& state = env.main_state();
  vsd::SimStateInstance& x = state.create(*cls);
  auto& a = state.create<vsd::Node>();
  auto& b = state.create<vsd::Node>();
  vsd::SharedRefList<vsd::Node> list;
  list.push_back(&a);
  list.push_back(&b);
  EXPECT_NO_THROW(x.set("friends", vsd::Value(list)));
  EXPECT_EQ(x.get("friends").to_text(),
            "[\"@" + std::to_string(a.id()) + "\", \"@" + std::to_string(b.id()) + "\"]");
  EXPECT_NO_THROW((void)x.get<vsd::SharedRefList<vsd::Node>>("friends"));
}

TEST(RuntimeClass, MethodBoundToALambda) {
  Defined cls(define_robot("RcMethod_Robot"));
  vsd::Environment env;
  vsd::SimStateInstance& x = env.main_state().create(*cls);
  EXPECT_EQ(x.call("scaled_speed", {vsd::Value(2.0)}).as<double>(), 5.0);
  EXPECT_EQ(x.call("scaled_speed", {vsd::Value(3)}).as<double>(), 7.5) << "exact numbers convert";
  const std::vector<vsd::Value> args{vsd::Value(4.0)};
  EXPECT_EQ(cls->call(x, "scaled_speed", args).as<double>(), 10.0);
  EXPECT_TRUE(x.call("reset_speed").empty());
  EXPECT_EQ(x.get<double>("speed"), 0.0);

  const std::string arity = error_of([&] { (void)x.call("scaled_speed"); });
  EXPECT_THAT(arity, HasSubstr("RcMethod_Robot::scaled_speed"));
  EXPECT_THAT(arity, HasSubstr("takes 1"));
  const std::string type = error_of([&] { (void)x.call("scaled_speed", {vsd::Value("x")}); });
  EXPECT_THAT(type, HasSubstr("argument 1"));
  EXPECT_THAT(type, HasSubstr("double"));
  EXPECT_THAT(error_of([&] { (void)x.call("fly"); }), HasSubstr("'fly'"));
}

TEST(RuntimeClass, PropertyNamesAreIdentifiers) {
  for (const char* bad : {"", "@class", "1st", "a b", "x-y", "caf\xC3\xA9"}) {
    EXPECT_THAT(
        [&] { (void)vsd::ClassBuilder("RcBadName_Class", vsd::Node::static_meta()).property<int>(bad, 1); },
        testing::ThrowsMessage<vsd::Error>(testing::HasSubstr("is not a property name")))
        << bad;
  }
  EXPECT_THAT(
      [&] {
        (void)vsd::ClassBuilder("RcBadName_Class", vsd::Node::static_meta())
            .property<int>("ok_1", 1)
            .alias("@id");
      },
      testing::ThrowsMessage<vsd::Error>(testing::HasSubstr("is not a property name")));
  EXPECT_EQ(vsd::Registry::global().find_class("RcBadName_Class"), nullptr);
}

TEST(RuntimeClass, MethodWithoutBodyIsRejected) {
  EXPECT_THROW((void)vsd::ClassBuilder("RcNoBody_Class", vsd::Node::static_meta())
                   .method("nothing", {}, nullptr, vsd::MetaMethod::Invoker{}),
               vsd::Error);
  EXPECT_EQ(vsd::Registry::global().find_class("RcNoBody_Class"), nullptr);
}

// ---- run-time subclasses ----------------------------------------------------------------------------------

TEST(RuntimeClass, SubclassOfACppClassKeepsItsCppBehaviour) {
  Defined sub(vsd::ClassBuilder("RcCppSub_Motor", RcMotor::static_meta())
                  .property<std::int32_t>("gear", 3)
                  .property<std::string>("brand", std::string("acme"))
                  .define());
  EXPECT_THAT(names_of(sub->properties()),
              ElementsAre("name", "extensions", "children", "torque", "gear", "brand"));
  EXPECT_GE(sub->size(), sizeof(RcMotor) + sizeof(std::int32_t) + sizeof(std::string));
  vsd::Environment env;
  auto& state = env.main_state();
  vsd::SimStateInstance& x = state.create(*sub);
  EXPECT_TRUE(x.is_a<RcMotor>());
  ASSERT_NE(x.as<RcMotor>(), nullptr);
  auto& motor = static_cast<RcMotor&>(x);
  EXPECT_EQ(motor.torque(), 1.0) << "the C++ part is constructed with its defaults";
  motor.set_torque(2.0);
  EXPECT_EQ(motor.torque(), 2.0);
  EXPECT_EQ(motor.doubled(), 4.0);
  EXPECT_EQ(x.get<double>("torque"), 2.0);
  EXPECT_EQ(RcMotor::vsd_prop_torque().get<double>(x), 2.0);
  x.set("torque", vsd::Value(5.0));
  EXPECT_EQ(motor.torque(), 5.0);
  EXPECT_EQ(x.call("doubled").as<double>(), 10.0) << "the C++ method is inherited";
  EXPECT_EQ(x.get<std::int32_t>("gear"), 3);
  EXPECT_EQ(x.get<std::string>("brand"), "acme");
  x.set("gear", vsd::Value(4));
  EXPECT_EQ(x.get<std::int32_t>("gear"), 4);
  EXPECT_EQ(motor.torque(), 5.0) << "run-time storage does not overlap the C++ members";

  const auto motors = state.index().all<RcMotor>();
  EXPECT_NE(std::find(motors.begin(), motors.end(), &motor), motors.end());
}

TEST(RuntimeClass, TypedSetterOfTheCppBaseSignalsAndRecords) {
  Defined sub(
      vsd::ClassBuilder("RcCppSignal_Motor", RcMotor::static_meta()).property<double>("ratio", 1.0).define());
  vsd::Environment env;
  auto& state = env.main_state();
  auto& motor = static_cast<RcMotor&>(state.create(*sub));
  std::vector<std::string> changed;
  auto c = state.on_property_changed().connect(
      [&](vsd::SimStateInstance&, const vsd::MetaProperty& p) { changed.push_back(p.name()); });
  motor.set_torque(3.0);
  motor.set("ratio", vsd::Value(0.5));
  EXPECT_THAT(changed, ElementsAre("torque", "ratio"));
}

TEST(RuntimeClass, RuntimeMethodHidesTheCppMethod) {
  Defined sub(vsd::ClassBuilder("RcHide_Motor", RcMotor::static_meta())
                  .method("doubled", {}, &vsd::meta_type<double>(),
                          [](vsd::Instance&, std::span<const vsd::Value>) { return vsd::Value(99.0); })
                  .define());
  vsd::Environment env;
  auto& x = env.main_state().create(*sub);
  EXPECT_EQ(x.call("doubled").as<double>(), 99.0);
  EXPECT_EQ(static_cast<RcMotor&>(x).doubled(), 2.0) << "C++ calls are not redirected";
  EXPECT_EQ(&sub->method("doubled").owner(), &*sub);
  auto& plain = env.main_state().create<RcMotor>();
  EXPECT_EQ(plain.call("doubled").as<double>(), 2.0);
}

TEST(RuntimeClass, SubclassOfARuntimeClass) {
  Defined parent(define_robot("RcChain_Robot"));
  Defined child(vsd::ClassBuilder("RcChain_Child", *parent)
                    .property<double>("extra", 0.5)
                    .property<std::vector<std::string>>("tags", std::vector<std::string>{"t"})
                    .method("scaled_speed", {&vsd::meta_type<double>()}, &vsd::meta_type<double>(),
                            [](vsd::Instance&, std::span<const vsd::Value> a) {
                              return vsd::Value(-a[0].as<double>());
                            })
                    .define());
  EXPECT_EQ(child->base(), &*parent);
  EXPECT_EQ(child->depth(), parent->depth() + 1);
  EXPECT_TRUE(child->is_a(*parent));
  EXPECT_TRUE(child->is_a(vsd::Node::static_meta()));
  EXPECT_FALSE(parent->is_a(*child));
  EXPECT_THAT(names_of(child->properties()),
              ElementsAre("name", "extensions", "children", "speed", "label", "samples", "pose", "target",
                          "count", "extra", "tags"));
  EXPECT_THAT(names_of(child->own_properties()), ElementsAre("extra", "tags"));
  const auto derived = parent->derived();
  EXPECT_NE(std::find(derived.begin(), derived.end(), &*child), derived.end());

  vsd::Environment env;
  auto& state = env.main_state();
  vsd::SimStateInstance& x = state.create(*child);
  EXPECT_TRUE(x.is_a(*parent));
  EXPECT_EQ(x.get<double>("speed"), 2.5);
  EXPECT_EQ(x.get<double>("extra"), 0.5);
  EXPECT_EQ(x.get<std::vector<std::string>>("tags"), std::vector<std::string>{"t"});
  parent->property("speed").set<double>(x, 1.25);  // the parent's handle works on the child
  EXPECT_EQ(x.get<double>("speed"), 1.25);
  x.set("extra", vsd::Value(9.0));
  EXPECT_EQ(x.get<double>("extra"), 9.0);
  EXPECT_EQ(x.get<std::string>("label"), "r2");
  EXPECT_EQ(x.call("scaled_speed", {vsd::Value(2.0)}).as<double>(), -2.0)
      << "the child's method hides the parent's";
  EXPECT_EQ(x.call("reset_speed").empty(), true);
  EXPECT_EQ(x.get<double>("speed"), 0.0);
  EXPECT_THROW((void)child->property("extra").get<double>(state.create(*parent)), vsd::Error);
}

// A class defined without methods (from a file's schema) is given them later: the class and its
// subclasses see them; one it declares already with the same signature stays; another signature is refused.
TEST(RuntimeClass, AddMethodsToADefinedClassAndItsSubclasses) {
  auto twice = [](vsd::SimStateInstance& self, std::span<const vsd::Value> a) {
    return vsd::Value(2.0 * a[0].as<double>() + self.get<double>("v"));
  };
  Defined parent(vsd::ClassBuilder("RcAdd_Parent", vsd::Node::static_meta()).property("v", 0.5).define());
  Defined child(vsd::ClassBuilder("RcAdd_Child", *parent).define());
  vsd::Environment env;
  vsd::SimStateInstance& x = env.main_state().create(*child);
  EXPECT_THAT(error_of([&] { (void)x.call("twice", {vsd::Value(1.0)}); }), HasSubstr("'twice'"));
  vsd::Registry::global().add_methods(
      *parent,
      std::move(vsd::ClassBuilder("RcAdd_Parent", vsd::Node::static_meta())
                    .method("twice", {&vsd::meta_type<double>()}, &vsd::meta_type<double>(), twice)));
  EXPECT_EQ(x.call("twice", {vsd::Value(1.0)}).as<double>(), 2.5) << "the subclass sees the new method";
  EXPECT_EQ(parent->method("twice").owner().name(), "RcAdd_Parent");
  EXPECT_EQ(child->properties().size(), parent->properties().size());
  EXPECT_EQ(child->find_property("v"), &parent->property("v"));
  // The same signature again: kept (no duplicate); another signature: refused, nothing changed.
  const vsd::MetaMethod* kept = parent->find_method("twice");
  vsd::Registry::global().add_methods(
      *parent,
      std::move(vsd::ClassBuilder("RcAdd_Parent", vsd::Node::static_meta())
                    .method("twice", {&vsd::meta_type<double>()}, &vsd::meta_type<double>(), twice)));
  EXPECT_EQ(parent->find_method("twice"), kept);
  EXPECT_EQ(parent->methods().size(), child->methods().size());
  const std::string e = error_of([&] {
    vsd::Registry::global().add_methods(
        *parent, std::move(vsd::ClassBuilder("RcAdd_Parent", vsd::Node::static_meta())
                               .method("other", {}, nullptr, twice)
                               .method("twice", {&vsd::meta_type<std::string>()}, nullptr, twice)));
  });
  EXPECT_THAT(e, HasSubstr("class 'RcAdd_Parent' has method twice(double) -> double, not twice(string)"));
  EXPECT_EQ(parent->find_method("other"), nullptr);
  EXPECT_THAT(error_of([&] {
                vsd::Registry::global().add_methods(vsd::Node::static_meta(),
                                                    vsd::ClassBuilder("RcAdd_X", vsd::Node::static_meta()));
              }),
              HasSubstr("built-in class 'Node' cannot be given methods"));
  env.main_state().destroy(x);
}

TEST(RuntimeClass, BaseCannotBeUndefinedBeforeItsSubclass) {
  Defined parent(define_robot("RcOrder_Robot"));
  Defined child(vsd::ClassBuilder("RcOrder_Child", *parent).define());
  const std::string e = error_of([&] { vsd::Registry::global().undefine(*parent); });
  EXPECT_THAT(e, HasSubstr("RcOrder_Robot"));
  EXPECT_THAT(e, HasSubstr("subclass"));
  EXPECT_EQ(vsd::Registry::global().find_class("RcOrder_Robot"), &*parent);
}

TEST(RuntimeClass, AbstractRuntimeClass) {
  Defined base(vsd::ClassBuilder("RcAbstract_Base", vsd::Node::static_meta())
                   .property<double>("mass", 1.0)
                   .set_abstract()
                   .define());
  Defined concrete(vsd::ClassBuilder("RcAbstract_Concrete", *base).define());
  EXPECT_TRUE(base->is_abstract());
  EXPECT_FALSE(concrete->is_abstract());
  vsd::Environment env;
  const std::string e = error_of([&] { (void)env.main_state().create(*base); });
  EXPECT_THAT(e, HasSubstr("RcAbstract_Base"));
  EXPECT_THAT(e, HasSubstr("abstract"));
  auto& x = env.main_state().create(*concrete);
  EXPECT_EQ(x.get<double>("mass"), 1.0);
}

TEST(RuntimeClass, BaseMustBeASimStateInstance) {
  EXPECT_THROW(vsd::ClassBuilder("RcBadBase_Env", vsd::Environment::static_meta()), vsd::Error);
  const std::string e =
      error_of([] { vsd::ClassBuilder("RcBadBase_Instance", vsd::Instance::static_meta()); });
  EXPECT_THAT(e, HasSubstr("RcBadBase_Instance"));
  EXPECT_EQ(vsd::Registry::global().find_class("RcBadBase_Env"), nullptr);
}

// Each class keeps all its ancestors and their properties: a chain of classes costs the square of its length
// in memory. A chain a file or a script could make without end (100,000 classes: tens of GB) stops at
// MetaInstance::max_depth.
TEST(RuntimeClass, ClassChainsAreBounded) {
  vsd::Registry registry;
  const vsd::MetaInstance* base = &vsd::Node::static_meta();
  while (base->depth() < vsd::MetaInstance::max_depth)
    base = &vsd::ClassBuilder("Deep" + std::to_string(base->depth()), *base)
                .property<int>("p" + std::to_string(base->depth()), 1)
                .define(registry);
  EXPECT_EQ(base->properties().size(), vsd::Node::static_meta().properties().size() +
                                           vsd::MetaInstance::max_depth - vsd::Node::static_meta().depth());
  const std::string e = error_of([&] { vsd::ClassBuilder("TooDeep", *base); });
  EXPECT_EQ(e, "run-time class 'TooDeep' would derive from more than 256 classes (its base '" + base->name() +
                   "' is 256 deep)");
  vsd::Environment env(0, registry);
  EXPECT_EQ(env.main_state().create(*base).get<int>("p200"), 1);
}

// ---- the element index and signals ------------------------------------------------------------------------

TEST(RuntimeClass, ElementIndexFindsInstances) {
  Defined parent(define_robot("RcIndex_Robot"));
  Defined child(vsd::ClassBuilder("RcIndex_Child", *parent).define());
  vsd::Environment env;
  auto& state = env.main_state();
  const std::size_t nodes_before = state.index().count(vsd::Node::static_meta());
  auto& a = state.create(*parent);
  auto& b = state.create(*parent);
  auto& c = state.create(*child);
  EXPECT_EQ(state.index().exact(*parent).size(), 2u);
  EXPECT_EQ(state.index().exact(*child).size(), 1u);
  EXPECT_EQ(state.index().exact(*child)[0], &c);
  EXPECT_EQ(state.index().count(*parent), 3u) << "subclasses included";
  EXPECT_EQ(state.index().count(*parent, false), 2u);
  EXPECT_EQ(state.index().count(vsd::Node::static_meta()), nodes_before + 3);
  const auto nodes = state.index().all<vsd::Node>();
  for (vsd::SimStateInstance* x : {&a, &b, &c})
    EXPECT_NE(std::find(nodes.begin(), nodes.end(), static_cast<vsd::Node*>(x)), nodes.end());

  int created = 0;
  auto on_created = state.index().on_created(*parent).connect([&](vsd::SimStateInstance&) { ++created; });
  (void)state.create(*child);
  EXPECT_EQ(created, 1) << "creation signals reach the base class's listeners";

  state.destroy(a);
  EXPECT_EQ(state.index().exact(*parent).size(), 1u);
  EXPECT_EQ(state.index().count(vsd::Node::static_meta()), nodes_before + 3);
}

TEST(RuntimeClass, PropertyChangedSignalsFireForRuntimeProperties) {
  Defined parent(define_robot("RcSignal_Robot"));
  Defined child(vsd::ClassBuilder("RcSignal_Child", *parent).property<double>("extra", 0.0).define());
  vsd::Environment env;
  auto& state = env.main_state();
  vsd::SimStateInstance& x = state.create(*parent);
  vsd::SimStateInstance& y = state.create(*child);

  std::vector<std::string> all;
  auto c1 = state.on_property_changed().connect([&](vsd::SimStateInstance& i, const vsd::MetaProperty& p) {
    all.push_back((&i == &x ? "x." : "y.") + p.name());
  });
  std::vector<std::string> by_type;
  auto c2 = state.on_property_changed(*parent).connect(
      [&](vsd::SimStateInstance&, const vsd::MetaProperty& p) { by_type.push_back(p.name()); });
  std::vector<std::string> exact;
  auto c3 =
      state.on_property_changed(*parent, false)
          .connect([&](vsd::SimStateInstance&, const vsd::MetaProperty& p) { exact.push_back(p.name()); });
  std::vector<std::string> own;
  auto c4 = x.on_changed().connect(
      [&](vsd::SimStateInstance&, const vsd::MetaProperty& p) { own.push_back(p.name()); });

  x.set("speed", vsd::Value(7.0));
  x.set("speed", vsd::Value(7.0));  // unchanged: no signal
  x.set("label", vsd::Value("new"));
  x.set("samples", vsd::Value(std::vector<double>{}));
  x.set("count", vsd::Value(1));  // transient properties signal too
  y.set("extra", vsd::Value(1.0));
  y.set("speed", vsd::Value(3.0));
  as_node(x).set_name("x");

  EXPECT_THAT(all, ElementsAre("x.speed", "x.label", "x.samples", "x.count", "y.extra", "y.speed", "x.name"));
  EXPECT_THAT(by_type, ElementsAre("speed", "label", "samples", "count", "extra", "speed", "name"));
  EXPECT_THAT(exact, ElementsAre("speed", "label", "samples", "count", "name"));
  EXPECT_THAT(own, ElementsAre("speed", "label", "samples", "count", "name"));
}

// ---- transactions -----------------------------------------------------------------------------------------

TEST(RuntimeClass, TransactionsRecordAndReplayRuntimeInstances) {
  Defined robot(define_robot("RcTx_Robot"));
  Defined child(
      vsd::ClassBuilder("RcTx_Child", *robot).property<std::string>("note", std::string("n")).define());
  Defined motor(
      vsd::ClassBuilder("RcTx_Motor", RcMotor::static_meta()).property<std::int32_t>("gear", 1).define());
  vsd::Environment env;
  auto& state = env.main_state();

  state.start_recording();
  vsd::SimStateInstance& a = state.create(*robot);
  a.set("speed", vsd::Value(9.5));
  a.set("label", vsd::Value("alpha"));
  a.set("samples", vsd::Value(std::vector<double>{3, 4, 5}));
  a.set("pose", vsd::Value(frame(4, 5, 6)));
  as_node(a).set_name("a");
  state.database().add_child(as_node(a));
  vsd::SimStateInstance& b = state.create("RcTx_Child");
  b.set("target", vsd::Value(vsd::SharedRef<vsd::Node>(&as_node(a))));
  b.set("note", vsd::Value("hello"));
  as_node(a).add_child(as_node(b));
  a.set("count", vsd::Value(5));  // transient: not recorded
  auto& m = static_cast<RcMotor&>(state.create(*motor));
  m.set_torque(3.5);
  m.set("gear", vsd::Value(7));
  state.database().add_child(m);
  const vsd::Transaction t = state.stop_recording();

  ASSERT_FALSE(t.empty());
  EXPECT_THAT(t.describe(), HasSubstr("create #" + std::to_string(a.id()) + " RcTx_Robot"));
  EXPECT_THAT(t.describe(), HasSubstr("create #" + std::to_string(b.id()) + " RcTx_Child"));
  EXPECT_THAT(t.describe(), HasSubstr("set #" + std::to_string(m.id()) + ".torque"));
  EXPECT_THAT(t.describe(), testing::Not(HasSubstr(".count")));

  auto& replica = env.create_state("replica");
  replica.apply(t);
  std::string diff;
  EXPECT_TRUE(replica.equals(state, &diff)) << diff;
  vsd::SimStateInstance* ra = replica.find(a.id());
  vsd::SimStateInstance* rb = replica.find(b.id());
  ASSERT_NE(ra, nullptr);
  ASSERT_NE(rb, nullptr);
  EXPECT_EQ(&ra->meta(), &*robot);
  EXPECT_EQ(&rb->meta(), &*child);
  EXPECT_EQ(ra->get<double>("speed"), 9.5);
  EXPECT_EQ(ra->get<std::string>("label"), "alpha");
  EXPECT_EQ(ra->get<std::vector<double>>("samples"), (std::vector<double>{3, 4, 5}));
  EXPECT_EQ(ra->get<Eigen::Isometry3d>("pose").translation(), Eigen::Vector3d(4, 5, 6));
  EXPECT_EQ(ra->get<std::int32_t>("count"), 0) << "transient values stay local";
  EXPECT_EQ(rb->get<std::string>("note"), "hello");
  EXPECT_EQ(target_of(*rb), ra) << "references are replayed by id";
  EXPECT_EQ(as_node(*rb).parent(), ra);
  EXPECT_EQ(as_node(*ra).parent(), &replica.database());
  auto* rm = replica.find<RcMotor>(m.id());
  ASSERT_NE(rm, nullptr);
  EXPECT_EQ(rm->torque(), 3.5);
  EXPECT_EQ(rm->get<std::int32_t>("gear"), 7);

  // The same bundle through its bytes, as another thread or machine would receive it.
  auto& remote = env.create_state("remote");
  remote.apply(vsd::Transaction::from_bytes(t.bytes()));
  EXPECT_TRUE(remote.equals(state, &diff)) << diff;

  // Undo: the inverted bundle removes everything again.
  state.apply(t.inverted());
  EXPECT_EQ(state.size(), 1u);
  EXPECT_TRUE(state.database().children().empty());
  EXPECT_EQ(robot->live_instances(), 2u) << "the replicas still hold theirs";
}

TEST(RuntimeClass, CopyFromCopiesRuntimeInstances) {
  Defined robot(define_robot("RcCopy_Robot"));
  vsd::Environment env;
  auto& state = env.main_state();
  auto& a = state.create(*robot);
  a.set("speed", vsd::Value(1.75));
  a.set("label", vsd::Value("copied"));
  as_node(a).set_name("a");
  state.database().add_child(as_node(a));
  auto& other = state.create(*robot);
  other.set("target", vsd::Value(vsd::SharedRef<vsd::Node>(&as_node(a))));
  as_node(a).add_child(as_node(other));

  auto& copy = env.create_state("copy");
  copy.copy_from(state);
  std::string diff;
  EXPECT_TRUE(copy.equals(state, &diff)) << diff;
  ASSERT_NE(copy.find(a.id()), nullptr);
  EXPECT_EQ(copy.find(a.id())->get<std::string>("label"), "copied");
  EXPECT_EQ(target_of(*copy.find(other.id())), copy.find(a.id()));
}

// ---- undefine and errors ----------------------------------------------------------------------------------

TEST(RuntimeClass, UndefineOnlyWithoutInstances) {
  auto& reg = vsd::Registry::global();
  Defined cls(
      vsd::ClassBuilder("RcUndef_Class", vsd::Node::static_meta()).property<double>("v", 1.0).define());
  {
    vsd::Environment env;
    auto& state = env.main_state();
    auto& x = state.create(*cls);
    const std::string e = error_of([&] { reg.undefine(*cls); });
    EXPECT_THAT(e, HasSubstr("RcUndef_Class"));
    EXPECT_THAT(e, HasSubstr("1 instance"));
    EXPECT_EQ(reg.find_class("RcUndef_Class"), &*cls);
    state.destroy(x);
    EXPECT_EQ(cls->live_instances(), 0u);
    const vsd::MetaInstance& doomed = *cls;
    cls.dismiss();
    EXPECT_NO_THROW(reg.undefine(doomed));
  }
  EXPECT_EQ(reg.find_class("RcUndef_Class"), nullptr);
  // The name is free again.
  Defined again(vsd::ClassBuilder("RcUndef_Class", vsd::Node::static_meta())
                    .property<std::string>("v", std::string())
                    .define());
  EXPECT_EQ(&again->property("v").type(), &vsd::meta_type<std::string>());
}

TEST(RuntimeClass, UndefineAfterTheEnvironmentIsGone) {
  auto& reg = vsd::Registry::global();
  const vsd::MetaInstance* cls = &define_robot("RcUndefEnv_Robot");
  {
    vsd::Environment env;
    auto& x = env.main_state().create(*cls);
    env.main_state().database().add_child(as_node(x));
    (void)env.main_state().create(*cls);  // floating
    EXPECT_THROW(reg.undefine(*cls), vsd::Error);
  }
  EXPECT_EQ(cls->live_instances(), 0u);
  EXPECT_NO_THROW(reg.undefine(*cls));
  EXPECT_EQ(reg.find_class("RcUndefEnv_Robot"), nullptr);
}

TEST(RuntimeClass, UndefineRejectsAClassStillReferencedByAnotherClass) {
  auto& reg = vsd::Registry::global();
  const vsd::MetaInstance* target = &vsd::ClassBuilder("RcRefd_Target", vsd::Node::static_meta()).define();
  const vsd::MetaInstance* holder =
      &vsd::ClassBuilder("RcRefd_Holder", vsd::Node::static_meta())
           .property("link", reg.reference_type(vsd::TypeKind::SharedRef, *target))
           .define();
  EXPECT_EQ(reg.find_type("shared<RcRefd_Target>"), &holder->property("link").type());
  const std::string e = error_of([&] { reg.undefine(*target); });
  EXPECT_THAT(e, HasSubstr("RcRefd_Target"));
  EXPECT_THAT(e, HasSubstr("RcRefd_Holder::link"));
  EXPECT_NO_THROW(reg.undefine(*holder));
  EXPECT_NO_THROW(reg.undefine(*target));
  EXPECT_EQ(reg.find_class("RcRefd_Target"), nullptr);
  EXPECT_EQ(reg.find_type("shared<RcRefd_Target>"), nullptr)
      << "reference types to an undefined class go with it";
  EXPECT_THROW((void)reg.get_type("shared<RcRefd_Target>"), vsd::Error);
}

TEST(RuntimeClass, UndefineRejectsBuiltInAndForeignClasses) {
  auto& reg = vsd::Registry::global();
  EXPECT_THAT(error_of([&] { reg.undefine(vsd::Node::static_meta()); }), HasSubstr("Node"));
  EXPECT_THROW(reg.undefine(RcMotor::static_meta()), vsd::Error);
  Defined cls(vsd::ClassBuilder("RcForeign_Class", vsd::Node::static_meta()).define());
  vsd::Registry other;
  EXPECT_THAT(error_of([&] { other.undefine(*cls); }), HasSubstr("RcForeign_Class"));
  EXPECT_EQ(reg.find_class("RcForeign_Class"), &*cls);
}

TEST(RuntimeClass, DuplicateClassName) {
  Defined first(
      vsd::ClassBuilder("RcDup_Class", vsd::Node::static_meta()).property<double>("v", 1.0).define());
  const std::string e = error_of([] {
    (void)vsd::ClassBuilder("RcDup_Class", vsd::Node::static_meta()).property<double>("w", 2.0).define();
  });
  EXPECT_THAT(e, HasSubstr("RcDup_Class"));
  EXPECT_EQ(vsd::Registry::global().find_class("RcDup_Class"), &*first);
  EXPECT_EQ(first->find_property("w"), nullptr);
  EXPECT_THAT(error_of([] { (void)vsd::ClassBuilder("Node", vsd::Node::static_meta()).define(); }),
              HasSubstr("Node"));
  EXPECT_THAT(error_of([] { (void)vsd::ClassBuilder("RcMotor", vsd::Node::static_meta()).define(); }),
              HasSubstr("RcMotor"));
  EXPECT_EQ(vsd::Registry::global().find_class("Node"), &vsd::Node::static_meta());
  EXPECT_EQ(vsd::Registry::global().find_class("RcMotor"), &RcMotor::static_meta());
}

TEST(RuntimeClass, DuplicatePropertyName) {
  const std::string twice = error_of([] {
    (void)vsd::ClassBuilder("RcDupProp_Class", vsd::Node::static_meta())
        .property<double>("x", 1.0)
        .property<double>("x", 2.0);
  });
  EXPECT_THAT(twice, HasSubstr("RcDupProp_Class"));
  EXPECT_THAT(twice, HasSubstr("'x'"));
  const std::string inherited = error_of([] {
    (void)vsd::ClassBuilder("RcDupProp_Named", vsd::Node::static_meta())
        .property<std::string>("name", std::string());
  });
  EXPECT_THAT(inherited, HasSubstr("'name'"));
  const std::string cpp = error_of([] {
    (void)vsd::ClassBuilder("RcDupProp_Motor", RcMotor::static_meta()).property<double>("torque", 1.0);
  });
  EXPECT_THAT(cpp, HasSubstr("'torque'"));
  Defined parent(define_robot("RcDupProp_Robot"));
  const std::string runtime_base =
      error_of([&] { (void)vsd::ClassBuilder("RcDupProp_Child", *parent).property<double>("speed", 1.0); });
  EXPECT_THAT(runtime_base, HasSubstr("'speed'"));
  EXPECT_EQ(vsd::Registry::global().find_class("RcDupProp_Class"), nullptr);
  EXPECT_EQ(vsd::Registry::global().find_class("RcDupProp_Child"), nullptr);
}

TEST(RuntimeClass, DefaultValueOfTheWrongType) {
  const std::string e = error_of([] {
    (void)vsd::ClassBuilder("RcBadDefault_Class", vsd::Node::static_meta())
        .property("speed", vsd::meta_type<double>(), vsd::Value(std::string("fast")));
  });
  EXPECT_THAT(e, HasSubstr("double"));
  EXPECT_THAT(e, HasSubstr("string"));
  EXPECT_THROW((void)vsd::ClassBuilder("RcBadDefault_Int", vsd::Node::static_meta())
                   .property("n", vsd::meta_type<std::int32_t>(), vsd::Value(2.5)),
               vsd::Error);
  EXPECT_THROW((void)vsd::ClassBuilder("RcBadDefault_U8", vsd::Node::static_meta())
                   .property("n", vsd::meta_type<std::uint8_t>(), vsd::Value(300)),
               vsd::Error);
  EXPECT_EQ(vsd::Registry::global().find_class("RcBadDefault_Class"), nullptr);
}

TEST(RuntimeClass, FailedDefineLeavesNoTrace) {
  // A property type whose name clashes with a registered type makes define() fail; the registry must then
  // not remember the class at all. (A local registry: a dangling entry must not reach the global one.)
  static const vsd::MetaType impostor("double", vsd::TypeKind::Double, sizeof(double), alignof(double),
                                      vsd::detail::ValueOps<double>::table);
  vsd::Registry local;
  const std::string e = error_of([&] {
    (void)vsd::ClassBuilder("RcFailed_Class", vsd::Node::static_meta()).property("v", impostor).define(local);
  });
  EXPECT_THAT(e, HasSubstr("'double'"));
  EXPECT_EQ(local.find_class("RcFailed_Class"), nullptr)
      << "the failed class must not stay registered (dangling)";
  for (const vsd::MetaInstance* d : vsd::Node::static_meta().derived())
    EXPECT_NE(d->name(), "RcFailed_Class");
  // The name can be used by a correct definition.
  EXPECT_NO_THROW((void)vsd::ClassBuilder("RcFailed_Class", vsd::Node::static_meta())
                      .property<double>("v", 1.0)
                      .define(local));
}

TEST(RuntimeClass, DefineTwiceFromOneBuilder) {
  vsd::ClassBuilder builder("RcTwice_Class", vsd::Node::static_meta());
  Defined cls(builder.property<double>("v", 1.0).define());
  EXPECT_THROW((void)builder.define(), vsd::Error);
}

}  // namespace

// A property change reaches the exact listener of the instance's class first, then the subtree listeners
// of the class and of every base, most derived first — also past the eight that a class's list keeps,
// and when listeners are added after the list was made.
TEST(RuntimeClass, SubtreeSignalsOfADeepChainFireInChainOrder) {
  std::vector<std::unique_ptr<Defined>> chain;
  const vsd::MetaInstance* base = &vsd::Node::static_meta();
  for (int k = 0; k < 12; ++k) {
    auto b = vsd::ClassBuilder("RcDeep" + std::to_string(k), *base);
    if (k == 0) b.property<double>("v", 0.0);
    chain.push_back(std::make_unique<Defined>(b.define()));
    base = &**chain.back();
  }
  {
  vsd::Environment env;
  auto& state = env.main_state();
  vsd::SimStateInstance& x = state.create(*base);
  std::vector<int> heard;
  std::vector<vsd::Connection> keep;
  auto listen = [&](int k) {
    keep.emplace_back(state.on_property_changed(**chain[static_cast<std::size_t>(k)], true)
                          .connect([&heard, k](vsd::SimStateInstance&, const vsd::MetaProperty&) { heard.push_back(k); }));
  };
  for (int k = 0; k < 12; k += 2) listen(k);
  x.set("v", vsd::Value(1.0));
  EXPECT_EQ(heard, (std::vector<int>{10, 8, 6, 4, 2, 0}));
  heard.clear();
  for (int k = 1; k < 12; k += 2) listen(k);  // the class's list is made again
  keep.emplace_back(state.on_property_changed(*base, false).connect(
      [&heard](vsd::SimStateInstance&, const vsd::MetaProperty&) { heard.push_back(-1); }));
  x.set("v", vsd::Value(2.0));
  EXPECT_EQ(heard, (std::vector<int>{-1, 11, 10, 9, 8, 7, 6, 5, 4, 3, 2, 1, 0}));
  heard.clear();
  keep.clear();  // nobody listens: the instance is back on the fast path after its next set
  x.set("v", vsd::Value(3.0));
  EXPECT_TRUE(heard.empty());
  EXPECT_FALSE(x.observed());
  }
  while (!chain.empty()) chain.pop_back();  // subclasses first
}
