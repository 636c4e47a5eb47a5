// The instance life cycle's fast paths: a SimState reuses the memory of deleted instances (per class),
// takes its ids in blocks, frees lone instances without a dispatch and reserves room for big bundles.
// None of it may show: ids stay unique, signals and the graveyard rule hold, run-time classes keep their
// trailing storage, and every SimState keeps its own memory.
#include "vsd/core/detail/instance_pool.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cstdint>
#include <set>
#include <string>
#include <vector>

#include "test_classes.hpp"
#include "vsd/core/detail/huge_pages.hpp"
#include "vsd/core/environment.hpp"
#include "vsd/core/registry.hpp"
#include "vsd/core/sim_state.hpp"

using testing::HasSubstr;
using vsd_test::TGripper;
using vsd_test::TRobot;
using vsd_test::TTool;

namespace {

/// Undefines a run-time class when the test ends; declare it before the Environment.
class DefinedClass {
 public:
  explicit DefinedClass(const vsd::MetaInstance& cls) : cls_(&cls) {}
  DefinedClass(const DefinedClass&) = delete;
  DefinedClass& operator=(const DefinedClass&) = delete;
  ~DefinedClass() {
    try {
      vsd::Registry::global().undefine(*cls_);
    } catch (const vsd::Error& e) {
      ADD_FAILURE() << "could not undefine " << cls_->name() << ": " << e.what();
    }
  }
  const vsd::MetaInstance& operator*() const { return *cls_; }
  const vsd::MetaInstance* operator->() const { return cls_; }

 private:
  const vsd::MetaInstance* cls_;
};

std::uintptr_t address(const void* p) { return reinterpret_cast<std::uintptr_t>(p); }

struct InstancePoolTest : testing::Test {
  vsd::Environment env;
  vsd::SimState& state = env.main_state();
};

TEST_F(InstancePoolTest, ReusedMemoryGetsANewIdAndFreshValues) {
  auto& a = state.create<TRobot>();
  a.set_speed(7.5);
  a.set_axes(3);
  a.set_joints({1.0, 2.0});
  const vsd::Id old_id = a.id();
  const void* old_memory = &a;
  state.destroy(a);
  EXPECT_EQ(state.find(old_id), nullptr);

  auto& b = state.create<TRobot>();
  EXPECT_EQ(static_cast<const void*>(&b), old_memory) << "the block of the deleted robot is reused";
  EXPECT_NE(b.id(), old_id);
  EXPECT_EQ(state.find(b.id()), &b);
  EXPECT_EQ(state.find(old_id), nullptr) << "the old id does not come back with the memory";
  EXPECT_EQ(b.speed(), 1.0);
  EXPECT_EQ(b.axes(), 6);
  EXPECT_TRUE(b.joints().empty());
  EXPECT_EQ(b.composite_count(), 0u);
  EXPECT_FALSE(b.is_being_deleted());
  EXPECT_EQ(state.index().exact(TRobot::static_meta()).size(), 1u);
}

TEST_F(InstancePoolTest, ClassesDoNotShareBlocks) {
  auto& robot = state.create<TRobot>();
  const void* robot_memory = &robot;
  state.destroy(robot);
  auto& tool = state.create<TTool>();
  EXPECT_NE(static_cast<const void*>(&tool), robot_memory) << "a TTool never lands in a TRobot's block";
  auto& gripper = state.create<TGripper>();  // a subclass is a class of its own, and bigger
  EXPECT_NE(static_cast<const void*>(&gripper), robot_memory);
  auto& again = state.create<TRobot>();
  EXPECT_EQ(static_cast<const void*>(&again), robot_memory);
}

TEST_F(InstancePoolTest, ManyInstancesKeepUniqueIdsAndAddresses) {
  std::vector<TRobot*> robots;
  for (int i = 0; i < 1000; ++i) robots.push_back(&state.create<TRobot>());
  for (std::size_t i = 0; i < robots.size(); i += 2) state.destroy(*robots[i]);
  for (int i = 0; i < 700; ++i) robots.push_back(&state.create<TRobot>());
  std::set<vsd::Id> ids;
  std::set<std::uintptr_t> addresses;
  for (vsd::SimStateInstance* x : state.index().exact(TRobot::static_meta())) {
    EXPECT_TRUE(ids.insert(x->id()).second) << "id #" << x->id() << " twice";
    EXPECT_TRUE(addresses.insert(address(x)).second) << "two live robots share memory";
    EXPECT_EQ(state.find(x->id()), x);
    EXPECT_EQ(address(x) % TRobot::static_meta().alignment(), 0u);
  }
  EXPECT_EQ(ids.size(), 1200u);
  EXPECT_EQ(state.size(), 1201u);
}

TEST_F(InstancePoolTest, SignalsOfTheOldInstanceDoNotFollowItsMemory) {
  auto& a = state.create<TRobot>();
  int a_changes = 0;
  auto c = a.on_changed().connect([&](vsd::SimStateInstance&, const vsd::MetaProperty&) { ++a_changes; });
  a.set_speed(2.0);
  EXPECT_EQ(a_changes, 1);
  state.destroy(a);
  auto& b = state.create<TRobot>();
  ASSERT_EQ(static_cast<void*>(&b), static_cast<void*>(&a));
  b.set_speed(3.0);
  EXPECT_EQ(a_changes, 1) << "the listener of the deleted robot is not told about its successor";
  int b_changes = 0;
  auto d = b.on_changed().connect([&](vsd::SimStateInstance&, const vsd::MetaProperty&) { ++b_changes; });
  b.set_speed(4.0);
  EXPECT_EQ(b_changes, 1);
}

TEST_F(InstancePoolTest, CreateAndDeleteSignalsStillFire) {
  std::vector<vsd::Id> created, deleted, typed;
  auto c1 = state.on_created().connect([&](vsd::SimStateInstance& x) { created.push_back(x.id()); });
  auto c2 = state.on_deleted().connect([&](vsd::SimStateInstance& x) { deleted.push_back(x.id()); });
  auto c3 = state.index().on_deleted(TRobot::static_meta()).connect([&](vsd::SimStateInstance& x) {
    typed.push_back(x.id());
  });
  auto& a = state.create<TRobot>();
  const vsd::Id id = a.id();
  state.destroy(a);
  auto& b = state.create<TRobot>();
  EXPECT_EQ(created, (std::vector<vsd::Id>{id, b.id()}));
  EXPECT_EQ(deleted, std::vector<vsd::Id>{id});
  EXPECT_EQ(typed, std::vector<vsd::Id>{id});
}

TEST_F(InstancePoolTest, InstancesDeletedDuringADispatchKeepTheirMemoryUntilItEnds) {
  auto& trigger = state.create<TTool>();
  auto& victim = state.create<TRobot>();
  const void* victim_memory = &victim;
  const vsd::Id victim_id = victim.id();
  bool victim_readable = false;
  const void* made_inside = nullptr;
  auto c = state.on_deleted().connect([&](vsd::SimStateInstance& x) {
    if (&x != &trigger) return;
    state.destroy(victim);
    // Still allocated (the graveyard rule): its memory is neither freed nor handed to a new robot.
    victim_readable = victim.is_being_deleted() && victim.id() == victim_id && victim.speed() == 1.0;
    made_inside = &state.create<TRobot>();
  });
  state.destroy(trigger);
  EXPECT_TRUE(victim_readable);
  EXPECT_NE(made_inside, victim_memory);
  EXPECT_EQ(state.find(victim_id), nullptr);
  // The dispatch is over: the victim's block is free again.
  c.disconnect();
  auto& after = state.create<TRobot>();
  EXPECT_EQ(static_cast<const void*>(&after), victim_memory);
}

TEST_F(InstancePoolTest, DeletingASubtreeStillCascades) {
  auto& parent = state.create<vsd::Node>();
  state.database().add_child(parent);
  std::vector<vsd::Id> kids;
  for (int i = 0; i < 10; ++i) {
    auto& k = state.create<TRobot>();
    parent.add_child(k);
    kids.push_back(k.id());
  }
  state.database().remove_child(parent);
  for (vsd::Id id : kids) EXPECT_EQ(state.find(id), nullptr);
  EXPECT_EQ(state.size(), 1u);
  for (int i = 0; i < 10; ++i) (void)state.create<TRobot>();
  EXPECT_EQ(state.index().exact(TRobot::static_meta()).size(), 10u);
}

TEST_F(InstancePoolTest, RecordingSeesEveryCreateAndDeleteOfReusedMemory) {
  auto& replica = env.create_state("replica");
  state.start_recording();
  auto& a = state.create<TRobot>();
  const vsd::Id a_id = a.id();
  a.set_speed(5.0);
  state.destroy(a);
  auto& b = state.create<TRobot>();
  b.set_speed(6.0);
  state.database().add_child(b);
  replica.apply(state.stop_recording());
  std::string diff;
  EXPECT_TRUE(replica.equals(state, &diff)) << diff;
  EXPECT_EQ(replica.find(a_id), nullptr);
  ASSERT_NE(replica.find(b.id()), nullptr);
  EXPECT_EQ(replica.find(b.id())->get<double>("speed"), 6.0);
}

TEST_F(InstancePoolTest, RuntimeClassesGetBlocksOfTheirOwnSizeAndAlignment) {
  DefinedClass small(vsd::ClassBuilder("IpSmall", vsd::Node::static_meta()).property<int>("n", 1).define());
  DefinedClass big(vsd::ClassBuilder("IpBig", *small)
                       .property<std::string>("label", std::string("a label longer than any small string"))
                       .property<std::vector<double>>("samples", std::vector<double>{1.0, 2.0, 3.0})
                       .property<Eigen::Isometry3d>("pose", Eigen::Isometry3d::Identity())
                       .define());
  ASSERT_GT(big->size(), small->size());
  vsd::Environment e;
  auto& s = e.main_state();
  std::vector<vsd::SimStateInstance*> made;
  for (int round = 0; round < 3; ++round) {
    for (int i = 0; i < 50; ++i) {
      auto& x = s.create(*big);
      EXPECT_EQ(address(&x) % big->alignment(), 0u);
      EXPECT_EQ(address(big->property("pose").address(x)) % alignof(Eigen::Isometry3d), 0u);
      EXPECT_EQ(x.get<std::string>("label"), "a label longer than any small string");
      EXPECT_EQ(x.get<std::vector<double>>("samples"), (std::vector<double>{1.0, 2.0, 3.0}));
      EXPECT_EQ(x.get<int>("n"), 1);
      x.set("label", vsd::Value(std::string(200, 'x')));  // heap storage that must be freed
      x.set("n", vsd::Value(round * 100 + i));
      made.push_back(&x);
      made.push_back(&s.create(*small));
    }
    EXPECT_EQ(big->live_instances(), 50u);
    EXPECT_EQ(small->live_instances(), 50u);
    for (vsd::SimStateInstance* x : made) s.destroy(*x);
    made.clear();
    EXPECT_EQ(big->live_instances(), 0u);
    EXPECT_EQ(small->live_instances(), 0u);
  }
}

TEST(InstancePool, ARuntimeClassMayGoWhileItsBlocksWaitInThePool) {
  vsd::Environment env;
  auto& s = env.main_state();
  const auto& cls = vsd::ClassBuilder("IpGone", vsd::Node::static_meta()).property<double>("v", 2.0).define();
  s.destroy(s.create(cls));
  EXPECT_NO_THROW(vsd::Registry::global().undefine(cls));
  // The state still holds the block; new classes and instances go on as usual.
  DefinedClass next(
      vsd::ClassBuilder("IpNext", vsd::Node::static_meta()).property<double>("w", 3.0).define());
  EXPECT_EQ(s.create(*next).get<double>("w"), 3.0);
  s.destroy(*s.index().exact(*next)[0]);
}

TEST(InstancePool, EveryStateHasItsOwnMemoryAndIdsStayUnique) {
  vsd::Environment env;
  std::vector<vsd::SimState*> states{&env.main_state(), &env.create_state("b"), &env.create_state("c")};
  std::set<vsd::Id> ids;
  std::vector<std::vector<TRobot*>> robots(states.size());
  for (int i = 0; i < 300; ++i)
    for (std::size_t k = 0; k < states.size(); ++k) {
      auto& r = states[k]->create<TRobot>();
      r.set_axes(static_cast<int>(k));
      EXPECT_TRUE(ids.insert(r.id()).second) << "id #" << r.id() << " handed out twice";
      robots[k].push_back(&r);
    }
  // Free memory in one state; the others never get it.
  const void* freed = robots[1].back();
  states[1]->destroy(*robots[1].back());
  robots[1].pop_back();
  EXPECT_NE(static_cast<const void*>(&states[0]->create<TRobot>()), freed);
  EXPECT_NE(static_cast<const void*>(&states[2]->create<TRobot>()), freed);
  EXPECT_EQ(static_cast<const void*>(&states[1]->create<TRobot>()), freed);
  for (std::size_t k = 0; k < states.size(); ++k)
    for (TRobot* r : robots[k]) EXPECT_EQ(r->axes(), static_cast<int>(k));
  // A state that goes takes its memory with it; the others are untouched.
  env.remove_state(*states[2]);
  for (TRobot* r : robots[0]) EXPECT_EQ(states[0]->find(r->id()), r);
  EXPECT_EQ(states[0]->size(), 302u);
}

TEST(InstancePool, IdsReservedFromOutsideAreNeverHandedOut) {
  vsd::Environment env;
  auto& a = env.main_state();
  auto& b = env.create_state("b");
  const vsd::Id first = a.create<TRobot>().id();  // a now holds a block of ids after `first`
  env.reserve_ids_through(first + 500);           // e.g. a file brought ids up to first + 500
  const vsd::Id next_a = a.create<TRobot>().id();
  const vsd::Id next_b = b.create<TRobot>().id();
  EXPECT_GT(next_a, first + 500);
  EXPECT_GT(next_b, first + 500);
  EXPECT_NE(next_a, next_b);
  EXPECT_GT(env.next_id(), first + 500);
}

TEST(InstancePool, ABigBundleFillsAStateEqualToItsSource) {
  vsd::Environment env;
  auto& source = env.main_state();
  for (int g = 0; g < 5; ++g) {
    auto& group = source.create<vsd::Node>();
    group.set_name("g" + std::to_string(g));
    source.database().add_child(group);
    for (int i = 0; i < 100; ++i) {
      auto& r = source.create<TRobot>();
      r.set_speed(i * 0.5);
      group.add_child(r);
    }
  }
  auto& copy = env.create_state("copy");
  copy.copy_from(source);  // 505 creates: the bundle reserves room for them at once
  std::string diff;
  EXPECT_TRUE(copy.equals(source, &diff)) << diff;
  EXPECT_EQ(copy.index().exact(TRobot::static_meta()).size(), 500u);
  // The reserved room serves later creates too, and deleting a group frees its robots.
  copy.database().remove_child(*copy.database().children()[0]);
  EXPECT_EQ(copy.size(), source.size() - 101);
  for (int i = 0; i < 200; ++i) (void)copy.create<TRobot>();
  EXPECT_EQ(copy.index().exact(TRobot::static_meta()).size(), 600u);
}

TEST(InstancePool, ADuplicateIdIsRejectedAndLeavesNothingBehind) {
  vsd::Environment env;
  auto& source = env.main_state();
  auto& r = source.create<TRobot>();
  auto& replica = env.create_state("replica");
  replica.copy_from(source);
  ASSERT_NE(replica.find(r.id()), nullptr);
  // The same create again: the dry run refuses it, the replica is unchanged.
  source.start_recording();
  source.destroy(r);
  auto t = source.stop_recording().inverted();  // re-creates #r in the replica, which already has it
  EXPECT_THAT([&] { replica.apply(t); }, testing::ThrowsMessage<vsd::Error>(HasSubstr("already exists")));
  EXPECT_EQ(replica.size(), 2u);
}

// A reservation of more than huge_block_bytes is one chunk, aligned to a huge page (so that the system
// can back it with huge pages): the reserved instances lie back to back, and blocks given back are
// reused before the rest of the chunk.
TEST(InstancePool, ABigReservationIsOneHugePageAlignedChunk) {
  const vsd::MetaInstance& cls = TRobot::static_meta();
  const std::size_t count = vsd::detail::huge_block_bytes / cls.size() + 10;
  vsd::detail::InstancePool pool;
  pool.reserve(cls, count);
  std::vector<void*> blocks;
  blocks.reserve(count);
  for (std::size_t i = 0; i < count; ++i) blocks.push_back(pool.allocate(cls));
  EXPECT_EQ(address(blocks.front()) % vsd::detail::huge_page_bytes, 0U);
  const std::size_t stride = address(blocks[1]) - address(blocks[0]);
  EXPECT_GE(stride, cls.size());
  for (std::size_t i = 1; i < count; ++i) ASSERT_EQ(address(blocks[i]) - address(blocks[i - 1]), stride) << i;
  pool.deallocate(cls, blocks[5]);
  EXPECT_EQ(pool.allocate(cls), blocks[5]);
  // Past the reservation, chunks are the usual small ones again.
  const void* more = pool.allocate(cls);
  EXPECT_TRUE(address(more) < address(blocks.front()) || address(more) >= address(blocks.back()) + stride);
}

// Reserving after deletes uses up the free blocks first (no huge chunk for a state that has room).
TEST(InstancePool, ABigReservationWithFreeBlocksAddsNoHugeChunk) {
  const vsd::MetaInstance& cls = TRobot::static_meta();
  vsd::detail::InstancePool pool;
  void* a = pool.allocate(cls);
  pool.deallocate(cls, a);
  pool.reserve(cls, vsd::detail::huge_block_bytes / cls.size() + 10);
  EXPECT_EQ(pool.allocate(cls), a);
}

// HugeAllocator: a vector that grows past huge_block_bytes keeps its elements and gets a block aligned
// to a huge page; a small one is plain memory.
TEST(HugePages, AVectorGrowsThroughTheThreshold) {
  std::vector<std::uint64_t, vsd::detail::HugeAllocator<std::uint64_t>> v;
  const std::size_t n = vsd::detail::huge_block_bytes / sizeof(std::uint64_t) * 2;
  for (std::size_t i = 0; i < n; ++i) v.push_back(i * 3);
  for (std::size_t i = 0; i < n; i += 4097) ASSERT_EQ(v[i], i * 3);
  EXPECT_EQ(address(v.data()) % vsd::detail::huge_page_bytes, 0U);
  v.resize(10);
  v.shrink_to_fit();
  EXPECT_EQ(v.back(), 27U);
  vsd::detail::advise_huge_pages(v.data(), 0);  // advice on nothing: a no-op
}

}  // namespace
