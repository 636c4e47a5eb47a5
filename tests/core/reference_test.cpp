#include "vsd/core/reference.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <random>
#include <set>
#include <string>
#include <string_view>
#include <vector>

#include "test_classes.hpp"
#include "test_util.hpp"

using testing::HasSubstr;
using testing::StartsWith;
using vsd_test::TRobot;
using vsd_test::TTool;

namespace {

struct ReferenceTest : testing::Test {
  vsd::Environment env;
  vsd::SimState& state = env.main_state();
  vsd::Database& root = state.database();
};

TEST_F(ReferenceTest, ChildrenAreCompositeAndCounted) {
  auto& n = state.create<vsd::Node>();
  EXPECT_EQ(n.composite_count(), 0u);  // floating until attached
  root.add_child(n);
  EXPECT_EQ(n.composite_count(), 1u);
  EXPECT_EQ(n.parent(), &root);
}

TEST_F(ReferenceTest, ReleasingTheLastCompositeReferenceDeletes) {
  auto& r = state.create<TRobot>();
  root.add_child(r);
  auto& tool = state.create<TTool>();
  r.set_tool(&tool);
  r.add_child(tool);  // two composite holders now
  EXPECT_EQ(tool.composite_count(), 2u);
  const vsd::Id id = tool.id();
  r.remove_child(tool);
  ASSERT_NE(state.find(id), nullptr) << "still held by the tool property";
  r.set_tool(nullptr);
  EXPECT_EQ(state.find(id), nullptr);
}

TEST_F(ReferenceTest, DeletingANodeDeletesItsCompositeSubtree) {
  auto& a = state.create<vsd::Node>();
  auto& b = state.create<vsd::Node>();
  auto& c = state.create<vsd::Node>();
  auto& keep = state.create<TRobot>();
  root.add_child(a);
  a.add_child(b);
  b.add_child(c);
  root.add_child(keep);
  auto& shared_child = state.create<TTool>();
  b.add_child(shared_child);
  keep.set_tool(&shared_child);  // held by another composite holder: survives
  const vsd::Id ia = a.id(), ib = b.id(), ic = c.id(), is = shared_child.id();
  state.destroy(a);
  EXPECT_EQ(state.find(ia), nullptr);
  EXPECT_EQ(state.find(ib), nullptr);
  EXPECT_EQ(state.find(ic), nullptr);
  ASSERT_NE(state.find(is), nullptr);
  EXPECT_EQ(shared_child.composite_count(), 1u);
  EXPECT_EQ(shared_child.parent(), nullptr);
  EXPECT_EQ(vsd_test::check_reference_counts(state), "");
}

TEST_F(ReferenceTest, DeletingTargetNullsSharedRefsAndNotifiesHolders) {
  auto& r = state.create<TRobot>();
  auto& goal = state.create<vsd::Node>();
  root.add_child(r);
  root.add_child(goal);
  r.set_target(&goal);
  r.set_watched([&] {
    vsd::SharedRefList<vsd::Node> l;
    l.push_back(&goal);
    l.push_back(&root);
    return l;
  }());
  std::vector<std::string> changes;
  auto c = r.on_changed().connect(
      [&](vsd::SimStateInstance&, const vsd::MetaProperty& p) { changes.push_back(p.name()); });
  state.destroy(goal);
  EXPECT_EQ(r.target().get(), nullptr);
  ASSERT_EQ(r.watched().size(), 1u);
  EXPECT_EQ(r.watched()[0], &root);
  EXPECT_THAT(changes, testing::UnorderedElementsAre("target", "watched"));
}

TEST_F(ReferenceTest, SharedReferencesDoNotCount) {
  auto& r = state.create<TRobot>();
  auto& goal = state.create<vsd::Node>();
  r.set_target(&goal);
  EXPECT_EQ(goal.composite_count(), 0u);
}

TEST_F(ReferenceTest, FreeSharedRefIsAWeakHandle) {
  auto& n = state.create<vsd::Node>();
  vsd::SharedRef<vsd::Node> handle(&n);
  EXPECT_EQ(handle.get(), &n);
  EXPECT_EQ(handle.holder(), nullptr);
  state.destroy(n);
  EXPECT_EQ(handle.get(), nullptr);
  EXPECT_FALSE(handle);
}

TEST_F(ReferenceTest, FreeRefOwnsLikeASharedPointer) {
  auto& n = state.create<vsd::Node>();
  root.add_child(n);
  const vsd::Id id = n.id();
  {
    vsd::Ref<vsd::Node> keep(&n);
    root.remove_child(n);
    EXPECT_NE(state.find(id), nullptr);
  }
  EXPECT_EQ(state.find(id), nullptr);
}

TEST_F(ReferenceTest, AFreeRefDoesNotAdoptAFloatingInstance) {
  auto& n = state.create<vsd::Node>();
  EXPECT_TRUE(n.is_floating());
  const vsd::Id id = n.id();
  {
    vsd::Ref<vsd::Node> hold(&n);
    EXPECT_EQ(n.composite_count(), 1u);
    vsd::Value as_value(hold);
    EXPECT_EQ(n.composite_count(), 2u);
  }
  ASSERT_EQ(state.find(id), &n) << "dropping free references leaves a floating instance floating";
  EXPECT_TRUE(n.is_floating());
  EXPECT_EQ(n.composite_count(), 0u);
  root.add_child(n);  // a property adopts it
  EXPECT_FALSE(n.is_floating());
  root.remove_child(n);
  EXPECT_EQ(state.find(id), nullptr) << "an adopted instance goes with its last composite reference";
}

// Records everything the state announces, to prove that a rejected change announces nothing.
struct Announcements {
  std::vector<std::string> log;
  std::vector<vsd::Connection> c;
  explicit Announcements(vsd::SimState& s) {
    c.push_back(s.on_created().connect(
        [this](vsd::SimStateInstance& i) { log.push_back("create #" + std::to_string(i.id())); }));
    c.push_back(s.on_deleted().connect(
        [this](vsd::SimStateInstance& i) { log.push_back("delete #" + std::to_string(i.id())); }));
    c.push_back(s.on_property_changed().connect([this](vsd::SimStateInstance& i, const vsd::MetaProperty& p) {
      log.push_back("set #" + std::to_string(i.id()) + "." + p.name());
    }));
  }
};

TEST_F(ReferenceTest, ARejectedCompositeSetDeletesNothing) {
  // x floats (never attached) and holds h as its child; h.tool = x would make x its own ancestor.
  auto& x = state.create<TTool>();
  auto& h = state.create<TRobot>();
  x.add_child(h);
  const vsd::Id xid = x.id(), hid = h.id();
  Announcements seen(state);
  state.start_recording();
  EXPECT_THAT([&] { h.set_tool(&x); }, testing::ThrowsMessage<vsd::Error>(HasSubstr("its own ancestor")));
  EXPECT_THAT([&] { h.set("tool", vsd::Value(vsd::Ref<TTool>(&x))); },
              testing::ThrowsMessage<vsd::Error>(HasSubstr("its own ancestor")));
  EXPECT_THAT(
      [&] {
        vsd::MetaProperty const& p = TRobot::vsd_prop_tool();
        p.set(h, vsd::Ref<TTool>(x));
      },
      testing::ThrowsMessage<vsd::Error>(HasSubstr("its own ancestor")));
  EXPECT_TRUE(state.stop_recording().empty());
  EXPECT_TRUE(seen.log.empty());
  ASSERT_EQ(state.find(xid), &x);
  ASSERT_EQ(state.find(hid), &h);
  EXPECT_TRUE(x.is_floating());
  EXPECT_EQ(x.composite_count(), 0u);
  EXPECT_EQ(h.composite_count(), 1u);
  EXPECT_EQ(h.tool().get(), nullptr);
  EXPECT_EQ(h.parent(), &x);
  EXPECT_EQ(vsd_test::check_reference_counts(state), "");
}

TEST_F(ReferenceTest, ARejectedSetToAnotherSimStateDeletesNothing) {
  auto& other = env.create_state("other");
  auto& far = other.create<TTool>();  // floating over there
  auto& far_node = other.create<vsd::Node>();
  auto& h = state.create<TRobot>();
  root.add_child(h);
  EXPECT_THAT([&] { h.set_tool(&far); },
              testing::ThrowsMessage<vsd::Error>(HasSubstr("different SimStates")));
  EXPECT_THAT([&] { h.edit_watched().push_back(far_node); },
              testing::ThrowsMessage<vsd::Error>(HasSubstr("different SimStates")));
  EXPECT_THAT([&] { root.add_child(far_node); },
              testing::ThrowsMessage<vsd::Error>(HasSubstr("different SimStates")));
  EXPECT_EQ(other.find(far.id()), &far);
  EXPECT_EQ(other.find(far_node.id()), &far_node);
  EXPECT_TRUE(far.is_floating());
  EXPECT_EQ(far.composite_count(), 0u);
  EXPECT_EQ(far_node.composite_count(), 0u);
  EXPECT_EQ(other.size(), 3u);
}

TEST_F(ReferenceTest, AListAssignmentThatFailsHalfWayDeletesNothing) {
  // children = [a, far]: a is linked (and adopted) first, then far is refused; the rollback must give a
  // back its floating state instead of releasing it.
  auto& other = env.create_state("other");
  auto& a = state.create<vsd::Node>();
  auto& far = other.create<vsd::Node>();
  auto& holder = state.create<vsd::Node>();
  root.add_child(holder);
  vsd::RefList<vsd::Node> list;
  list.push_back(&a);
  list.push_back(&far);
  Announcements seen(state);
  EXPECT_THAT([&] { holder.set_children(list); },
              testing::ThrowsMessage<vsd::Error>(HasSubstr("different SimStates")));
  EXPECT_THAT([&] { holder.set("children", vsd::Value(list)); }, testing::Throws<vsd::Error>());
  list.clear();
  EXPECT_TRUE(seen.log.empty());
  EXPECT_EQ(state.find(a.id()), &a);
  EXPECT_TRUE(a.is_floating());
  EXPECT_EQ(a.composite_count(), 0u);
  EXPECT_TRUE(holder.children().empty());
  EXPECT_EQ(vsd_test::check_reference_counts(state), "");
}

TEST_F(ReferenceTest, ARejectedListInsertDeletesNothing) {
  auto& x = state.create<vsd::Node>();
  auto& h = state.create<vsd::Node>();
  x.add_child(h);  // x floats, h is its child
  Announcements seen(state);
  EXPECT_THAT([&] { h.add_child(x); }, testing::ThrowsMessage<vsd::Error>(HasSubstr("its own ancestor")));
  EXPECT_THAT([&] { h.edit_children().insert(0, x); },
              testing::ThrowsMessage<vsd::Error>(HasSubstr("its own ancestor")));
  EXPECT_THAT([&] { h.list_insert(vsd::Node::vsd_prop_children(), 0, x); },
              testing::ThrowsMessage<vsd::Error>(HasSubstr("its own ancestor")));
  EXPECT_TRUE(seen.log.empty());
  EXPECT_EQ(state.find(x.id()), &x);
  EXPECT_EQ(state.find(h.id()), &h);
  EXPECT_TRUE(x.is_floating());
  EXPECT_EQ(h.parent(), &x);
  EXPECT_EQ(vsd_test::check_reference_counts(state), "");
}

TEST_F(ReferenceTest, FreeReferencesOutlivingTheEnvironmentBecomeNull) {
  vsd::SharedRef<vsd::Node> weak;
  vsd::Ref<vsd::Node> strong;
  {
    vsd::Environment other;
    auto& n = other.main_state().create<vsd::Node>();
    weak = &n;
    strong = &n;
  }
  EXPECT_EQ(weak.get(), nullptr);
  EXPECT_EQ(strong.get(), nullptr);
}

TEST_F(ReferenceTest, CompositeCyclesAreRejected) {
  auto& a = state.create<vsd::Node>();
  auto& b = state.create<vsd::Node>();
  root.add_child(a);
  a.add_child(b);
  EXPECT_THAT([&] { b.add_child(a); }, testing::ThrowsMessage<vsd::Error>(HasSubstr("its own ancestor")));
  EXPECT_THAT([&] { a.add_child(a); }, testing::ThrowsMessage<vsd::Error>(HasSubstr("its own ancestor")));
  EXPECT_EQ(a.parent(), &root);
  EXPECT_EQ(vsd_test::check_reference_counts(state), "");
}

// The cycle check searches up from the holder and down from the target at once: a chain of 100,000 is
// built from either end and edited in the middle in about linear time (it used to rescan the chain
// above the holder for every insert: 3,000 levels took 0.65 s), and deleting it recurses no deeper.
constexpr int deep = 100'000;

TEST_F(ReferenceTest, DeepChainsBuildFromEitherEndAndStillRefuseCycles) {
  std::vector<vsd::Node*> down{&state.create<vsd::Node>()};
  root.add_child(*down[0]);
  for (int i = 1; i < deep; ++i) down.push_back(&down.back()->add_child(state.create<vsd::Node>()));
  // From the bottom up: each new node takes the chain so far as its child.
  std::vector<vsd::Node*> up{&state.create<vsd::Node>()};
  for (int i = 1; i < deep; ++i) {
    auto& n = state.create<vsd::Node>();
    n.add_child(*up.back());
    up.push_back(&n);
  }
  root.add_child(*up.back());
  EXPECT_EQ(down.back()->parent(), down[deep - 2]);
  EXPECT_EQ(up.front()->parent(), up[1]);

  // Cycles at any distance, either way round, are still refused, and change nothing.
  EXPECT_THAT([&] { down.back()->add_child(*down.front()); },
              testing::ThrowsMessage<vsd::Error>(HasSubstr("would make an instance its own ancestor")));
  EXPECT_THAT([&] { down[deep / 2]->add_child(*down[deep / 2 - 1]); },
              testing::ThrowsMessage<vsd::Error>(HasSubstr("its own ancestor")));
  EXPECT_THAT([&] { up.front()->add_child(*up.back()); },
              testing::ThrowsMessage<vsd::Error>(HasSubstr("its own ancestor")));
  EXPECT_EQ(down.front()->parent(), &root);
  EXPECT_EQ(up.back()->parent(), &root);

  // Moves: a deep subtree under the bottom of the other chain, then back under the root.
  down.back()->add_child(*up.back());
  EXPECT_EQ(up.back()->parent(), down.back());
  EXPECT_THAT([&] { up.front()->add_child(*down.front()); },
              testing::ThrowsMessage<vsd::Error>(HasSubstr("its own ancestor")));
  root.add_child(*up.back());
  EXPECT_EQ(vsd_test::check_reference_counts(state), "");
  EXPECT_EQ(state.size(), 2u * deep + 1);

  // Deleting the top of a chain deletes all of it without recursing once per level.
  const vsd::Id last = down.back()->id();
  state.destroy(*down.front());
  EXPECT_EQ(state.find(last), nullptr);
  root.remove_child(*up.back());  // the release cascade
  EXPECT_EQ(state.size(), 1u);
}

TEST_F(ReferenceTest, ADeepChainGoesWithItsSimState) {
  auto& other = env.create_state("deep");
  vsd::Node* at = &other.database();
  for (int i = 0; i < deep; ++i) at = &at->add_child(other.create<vsd::Node>());
  env.remove_state(other);  // no recursion per level either
}

// The cycle check against the definition: random composite references (children lists and a Ref
// property, instances with several holders) are refused exactly when the target already reaches the
// holder.
TEST_F(ReferenceTest, TheCycleCheckAgreesWithReachability) {
  std::mt19937 rng(11);
  std::vector<vsd::Node*> xs;
  for (int i = 0; i < 40; ++i) {
    xs.push_back(i % 4 == 0 ? static_cast<vsd::Node*>(&state.create<TTool>()) : &state.create<TRobot>());
    root.add_child(*xs.back());
  }
  auto reaches = [&](const vsd::Node* from, const vsd::Node* goal) {
    std::vector<const vsd::Node*> todo{from};
    std::set<const vsd::Node*> seen;
    while (!todo.empty()) {
      const vsd::Node* x = todo.back();
      todo.pop_back();
      if (x == goal) return true;
      if (!seen.insert(x).second) continue;
      for (vsd::Node* c : x->children()) todo.push_back(c);
      if (const auto* r = x->as<TRobot>(); r != nullptr && r->tool()) todo.push_back(r->tool().get());
    }
    return false;
  };
  int refused = 0;
  for (int round = 0; round < 3000; ++round) {
    vsd::Node& h = *xs[rng() % xs.size()];
    vsd::Node& t = *xs[rng() % xs.size()];
    const bool cycle = reaches(&t, &h);
    const unsigned what = rng() % 8;
    const std::string error = vsd_test::error_of([&] {
      if (what < 4) {
        h.list_insert(vsd::Node::vsd_prop_children(), 0, t);  // maybe a second holder: a DAG
      } else if (what < 6 && h.is_a<TRobot>() && t.is_a<TTool>()) {
        static_cast<TRobot&>(h).set_tool(&static_cast<TTool&>(t));
      } else if (!h.children().empty()) {  // every x stays held by root: nothing is deleted
        h.list_erase(vsd::Node::vsd_prop_children(), rng() % h.children().size());
      }
    });
    if (error != "<no error>") {
      EXPECT_TRUE(cycle) << error;
      EXPECT_THAT(error, HasSubstr("its own ancestor"));
      ++refused;
    } else if (what < 4) {
      EXPECT_FALSE(cycle) << "#" << h.id() << " took #" << t.id();
    }
  }
  EXPECT_GT(refused, 100);
  EXPECT_EQ(vsd_test::check_reference_counts(state), "");
}

TEST_F(ReferenceTest, ReferencesCannotCrossSimStates) {
  auto& other = env.create_state("other");
  auto& r = state.create<TRobot>();
  auto& far = other.create<vsd::Node>();
  EXPECT_THAT([&] { r.set_target(&far); },
              testing::ThrowsMessage<vsd::Error>(HasSubstr("different SimStates")));
  EXPECT_THAT([&] { root.add_child(far); },
              testing::ThrowsMessage<vsd::Error>(HasSubstr("different SimStates")));
}

TEST_F(ReferenceTest, GenericSetChecksTheTargetClass) {
  auto& r = state.create<TRobot>();
  auto& plain = state.create<vsd::Node>();
  // tool is a ref<TTool>: a plain Node does not fit.
  vsd::Ref<vsd::Node> wrong(&plain);
  EXPECT_THROW(r.set("tool", vsd::Value(wrong)), vsd::Error);
  auto& tool = state.create<TTool>();
  r.set("tool", vsd::Value(vsd::Ref<TTool>(&tool)));
  EXPECT_EQ(r.tool().get(), &tool);
  const vsd::MetaProperty& children = vsd::Node::vsd_prop_children();
  auto& ext = state.create<vsd::Extension>();
  EXPECT_THAT([&] { r.list_insert(children, 0, ext); },
              testing::ThrowsMessage<vsd::Error>(HasSubstr("holds Node")));
  EXPECT_THAT([&] { r.list_insert(children, 5, plain); },
              testing::ThrowsMessage<vsd::Error>(HasSubstr("past the end")));
  EXPECT_THAT([&] { r.list_erase(children, 0); }, testing::ThrowsMessage<vsd::Error>(HasSubstr("out of")));
  EXPECT_THAT([&] { r.list_insert(TRobot::vsd_prop_speed(), 0, plain); },
              testing::ThrowsMessage<vsd::Error>(HasSubstr("not a reference list")));
}

TEST_F(ReferenceTest, ValuesHoldingReferencesCount) {
  auto& n = state.create<vsd::Node>();
  root.add_child(n);
  {
    vsd::Value v{vsd::Ref<vsd::Node>(&n)};
    EXPECT_EQ(n.composite_count(), 2u);
    vsd::Value copy = v;
    EXPECT_EQ(n.composite_count(), 3u);
    EXPECT_EQ(copy.to_text(), "\"@" + std::to_string(n.id()) + "\"");
  }
  EXPECT_EQ(n.composite_count(), 1u);
}

TEST_F(ReferenceTest, ReferenceTextNeedsAResolver) {
  const auto& t = vsd::meta_type<vsd::SharedRef<vsd::Node>>();
  EXPECT_EQ(t.name(), "shared<Node>");
  EXPECT_EQ(t.target(), &vsd::Node::static_meta());
  vsd::Value null = vsd::Value::from_text(t, "null");
  EXPECT_EQ(static_cast<const vsd::RefBase*>(null.data())->get(), nullptr);
  EXPECT_THAT([&] { (void)vsd::Value::from_text(t, "@12"); },
              testing::ThrowsMessage<vsd::Error>(HasSubstr("1:")));
  EXPECT_THAT([&] { (void)vsd::Value::from_text(t, R"("@12")"); },
              testing::ThrowsMessage<vsd::Error>(HasSubstr("1:1: cannot resolve reference @12")));
}

struct StateResolver final : vsd::RefResolver {
  explicit StateResolver(vsd::SimState& s) : state(s) {}
  vsd::SimStateInstance* resolve(vsd::Id id) const override { return state.find(id); }
  vsd::SimState& state;
};

// The error parsing @p text throws, after the origin it starts with ("<TYPE value>:", checked and stripped).
std::string text_error(const vsd::MetaType& type, std::string_view text, const vsd::RefResolver* refs) {
  try {
    (void)vsd::Value::from_text(type, text, refs);
  } catch (const vsd::Error& e) {
    const std::string msg = e.what(), origin = "<" + type.name() + " value>:";
    return msg.rfind(origin, 0) == 0 ? msg.substr(origin.size()) : "no origin in: " + msg;
  }
  return "<no error>";
}

TEST_F(ReferenceTest, ReferenceTextIsJsonAndTheOlderFormReads) {
  auto& a = state.create<vsd::Node>();
  auto& b = state.create<vsd::Node>();
  root.add_child(a);
  root.add_child(b);
  const StateResolver refs(state);
  const std::string a_id = std::to_string(a.id());
  const std::string b_id = std::to_string(b.id());

  // A reference is the JSON string "@id" or null; the older bare @id reads too.
  const auto& t = vsd::meta_type<vsd::SharedRef<vsd::Node>>();
  EXPECT_EQ(vsd::Value(vsd::SharedRef<vsd::Node>(&a)).to_text(), "\"@" + a_id + "\"");
  EXPECT_EQ(vsd::Value(vsd::SharedRef<vsd::Node>()).to_text(), "null");
  for (const std::string& text : {"\"@" + a_id + "\"", "@" + a_id, " \"@" + a_id + "\" "}) {
    const vsd::Value v = vsd::Value::from_text(t, text, &refs);
    EXPECT_EQ(static_cast<const vsd::RefBase*>(v.data())->get(), &a) << text;
  }
  EXPECT_EQ(static_cast<const vsd::RefBase*>(vsd::Value::from_text(t, "null", &refs).data())->get(), nullptr);

  // A reference list is a JSON array of them.
  vsd::SharedRefList<vsd::Node> list;
  list.push_back(&a);
  list.push_back(&b);
  const std::string list_text = "[\"@" + a_id + "\", \"@" + b_id + "\"]";
  EXPECT_EQ(vsd::Value(list).to_text(), list_text);
  EXPECT_EQ(vsd::Value(vsd::SharedRefList<vsd::Node>()).to_text(), "[]");
  const auto& lt = vsd::meta_type<vsd::SharedRefList<vsd::Node>>();
  for (const std::string& text :
       {list_text, "[@" + a_id + ", @" + b_id + "]", "[@" + a_id + ", \"@" + b_id + "\"]"}) {
    EXPECT_TRUE(vsd::Value::from_text(lt, text, &refs) == vsd::Value(list)) << text;
  }

  // Errors name the line and column of the offending reference.
  EXPECT_THAT(text_error(t, R"("@x")", &refs), StartsWith("1:3: 'x' is not an unsigned integer"));
  EXPECT_THAT(text_error(t, R"("42")", &refs), StartsWith("1:1: expected a reference"));
  EXPECT_THAT(text_error(t, "\"@" + a_id, &refs), HasSubstr("ended"));
  EXPECT_THAT(text_error(t, "nil", &refs),
              StartsWith("1:1: expected a reference (\"@id\" or null), found 'nil'"));
  EXPECT_THAT(text_error(t, "5", &refs), StartsWith("1:1: expected a reference"));
  EXPECT_THAT(text_error(t, R"( "@999999999")", &refs), StartsWith("1:2: dangling reference"));
  EXPECT_THAT(text_error(lt, "[\"@" + a_id + "\",\n null]", &refs),
              StartsWith("2:2: a reference list cannot hold null"));
  EXPECT_THAT(text_error(lt, "[\"@" + a_id + "\", \"@999999999\"]", &refs), HasSubstr("dangling reference"));
}

}  // namespace
