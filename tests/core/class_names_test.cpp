// Qualified class names: VSD_CLASS_NAMESPACE, full and short names in the Registry, bundles.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <vsd/vsd.hpp>

using testing::HasSubstr;

namespace cn_scene {
VSD_CLASS_NAMESPACE("scene")

class Hull : public vsd::Node {
  VSD_INSTANCE(Hull, vsd::Node)
  VSD_PROPERTY(double, volume, 1.0)
};

class Robot : public vsd::Node {
  VSD_INSTANCE(Robot, vsd::Node)
  VSD_PROPERTY(double, reach, 1.0)
  VSD_PROPERTY(vsd::SharedRef<Robot>, buddy, nullptr)
};
}  // namespace cn_scene

namespace cn_robotics {
VSD_CLASS_NAMESPACE("robotics")

class Robot : public vsd::Node {
  VSD_INSTANCE(Robot, vsd::Node)
  VSD_PROPERTY(int, axes, 6)
  VSD_PROPERTY(vsd::Ref<cn_scene::Hull>, hull, nullptr)
};
}  // namespace cn_robotics

// A user's class in a namespace that declares none keeps its plain name, though its base has one.
namespace cn_app {
class Welder : public cn_scene::Robot {
  VSD_INSTANCE(Welder, cn_scene::Robot)
};
}  // namespace cn_app

// A using-directive does not carry a namespace's declaration over to the global namespace's classes.
using namespace cn_scene;  // NOLINT(google-build-using-namespace): that is what is tested
class CnGlobalBot : public cn_scene::Robot {
  VSD_INSTANCE(CnGlobalBot, cn_scene::Robot)
};

namespace {

TEST(ClassNames, NamespacesQualifyClassNames) {
  EXPECT_EQ(cn_scene::Robot::static_meta().name(), "scene::Robot");
  EXPECT_EQ(cn_robotics::Robot::static_meta().name(), "robotics::Robot");
  EXPECT_EQ(cn_app::Welder::static_meta().name(), "Welder");
  EXPECT_EQ(CnGlobalBot::static_meta().name(), "CnGlobalBot");
  EXPECT_EQ(vsd::Node::static_meta().name(), "Node") << "core classes keep their names";
  EXPECT_EQ(cn_scene::Robot::vsd_prop_buddy().type().name(), "shared<scene::Robot>");
  EXPECT_EQ(cn_robotics::Robot::vsd_prop_hull().type().name(), "ref<scene::Hull>");
}

TEST(ClassNames, FullAndShortLookups) {
  vsd::Registry& r = vsd::Registry::global();
  r.add<cn_scene::Robot>();
  r.add<cn_robotics::Robot>();
  r.add<cn_scene::Hull>();
  EXPECT_EQ(r.find_class("scene::Robot"), &cn_scene::Robot::static_meta());
  EXPECT_EQ(r.find_class("robotics::Robot"), &cn_robotics::Robot::static_meta());
  EXPECT_EQ(r.find_class("Hull"), &cn_scene::Hull::static_meta()) << "a unique short name";
  EXPECT_EQ(r.find_class_exact("Hull"), nullptr);
  EXPECT_EQ(r.find_class("robotics::Hull"), nullptr);
  EXPECT_THAT([&] { (void)r.find_class("Robot"); },
              testing::ThrowsMessage<vsd::Error>("class name 'Robot' is ambiguous: it may be "
                                                 "'robotics::Robot', 'scene::Robot' (use the full name)"));
  EXPECT_THAT([&] { (void)r.get_type("ref<Robot>"); },
              testing::ThrowsMessage<vsd::Error>(HasSubstr("ambiguous")));
  EXPECT_EQ(&r.get_type("ref<scene::Hull>"), &cn_robotics::Robot::vsd_prop_hull().type());
  EXPECT_EQ(&r.get_type("ref<Hull>"), &cn_robotics::Robot::vsd_prop_hull().type());
  EXPECT_EQ(r.get_type("list<scene::Robot>").target(), &cn_scene::Robot::static_meta());
}

TEST(ClassNames, BothClassesAreUsableAndTravelInBundles) {
  vsd::Environment env;
  vsd::SimState& s = env.main_state();
  s.start_recording();
  auto& a = static_cast<vsd::Node&>(s.create("scene::Robot"));
  auto& b = static_cast<vsd::Node&>(s.create("robotics::Robot"));
  auto& h = static_cast<vsd::Node&>(s.create("Hull"));
  s.database().add_child(a);
  s.database().add_child(b);
  b.set("hull", vsd::Value(vsd::Ref<cn_scene::Hull>(static_cast<cn_scene::Hull*>(&h))));
  a.set("reach", vsd::Value(2.5));
  b.set("axes", vsd::Value(7));
  const vsd::Transaction t = s.stop_recording();
  vsd::SimState& replica = env.create_state("replica");
  replica.apply(vsd::Transaction::from_bytes(t.bytes()));
  EXPECT_TRUE(s.equals(replica));
  auto* ra = replica.find<cn_scene::Robot>(a.id());
  auto* rb = replica.find<cn_robotics::Robot>(b.id());
  ASSERT_NE(ra, nullptr);
  ASSERT_NE(rb, nullptr);
  EXPECT_EQ(ra->reach(), 2.5);
  EXPECT_EQ(rb->axes(), 7);
  EXPECT_EQ(rb->hull()->id(), h.id());
  EXPECT_THAT([&] { (void)s.create("Robot"); }, testing::ThrowsMessage<vsd::Error>(HasSubstr("ambiguous")));
}

TEST(ClassNames, RunTimeClassesMayBeQualified) {
  vsd::Registry registry;
  const vsd::MetaInstance& crate =
      vsd::ClassBuilder("yard::Crate", vsd::Node::static_meta()).define(registry);
  EXPECT_EQ(registry.find_class("Crate"), &crate);
  const vsd::MetaInstance& other = vsd::ClassBuilder("lab::Crate", vsd::Node::static_meta()).define(registry);
  EXPECT_THAT([&] { (void)registry.get_class("Crate"); },
              testing::ThrowsMessage<vsd::Error>(HasSubstr("'lab::Crate', 'yard::Crate'")));
  // A class whose full name is the short name wins over the qualified ones.
  const vsd::MetaInstance& plain = vsd::ClassBuilder("Crate", vsd::Node::static_meta()).define(registry);
  EXPECT_EQ(&registry.get_class("Crate"), &plain);
  registry.undefine(plain);
  registry.undefine(other);
  EXPECT_EQ(&registry.get_class("Crate"), &crate) << "unique again";
  for (const char* bad : {"::Crate", "yard::", "a::::b", ""})
    EXPECT_THAT([&] { vsd::ClassBuilder(bad, vsd::Node::static_meta()).define(registry); },
                testing::ThrowsMessage<vsd::Error>(HasSubstr("is not a class name")))
        << bad;
  registry.undefine(crate);
  EXPECT_EQ(registry.find_class("Crate"), nullptr);
}

}  // namespace
