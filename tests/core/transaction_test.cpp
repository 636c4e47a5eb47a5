#include "vsd/core/transaction.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <future>
#include <thread>

#include "test_classes.hpp"
#include "vsd/core/bytes.hpp"
#include "vsd/core/detail/tx_codec.hpp"

using testing::HasSubstr;
using vsd_test::TRobot;
using vsd_test::TTool;

namespace {

struct TransactionTest : testing::Test {
  vsd::Environment env;
  vsd::SimState& source = env.main_state();
  vsd::SimState& replica = env.create_state("replica");

  void expect_equal(const vsd::SimState& a, const vsd::SimState& b) {
    std::string diff;
    EXPECT_TRUE(a.equals(b, &diff)) << diff;
  }
};

TEST_F(TransactionTest, RecordsEveryKindOfChange) {
  source.start_recording();
  auto& r = source.create<TRobot>();
  source.database().add_child(r);
  r.set_speed(2.0);
  auto& child = source.create<vsd::Node>();
  const std::string ir = std::to_string(r.id()), ic = std::to_string(child.id());
  r.add_child(child);
  r.remove_child(child);  // its last composite holder: deleted
  const vsd::Transaction t = source.stop_recording();
  EXPECT_EQ(t.describe(), "create #" + ir + " TRobot\ninsert #" + ir + " into #1.children[0]\nset #" + ir +
                              ".speed\ncreate #" + ic + " Node\ninsert #" + ic + " into #" + ir +
                              ".children[0]\nerase #" + ic + " from #" + ir + ".children[0]\ndelete #" + ic +
                              " Node\n");
  EXPECT_EQ(t.size(), 7u);
}

// A set of a fixed-size value (numbers, frames) is framed by a fast path; its bytes must be those of the
// general encoding, which the variable-size values (strings, vectors) still take.
TEST_F(TransactionTest, RecordedSetsHaveTheGeneralEncodingOnEveryPath) {
  auto& r = source.create<TRobot>();
  Eigen::Isometry3d f = Eigen::Isometry3d::Identity();
  f.linear() = Eigen::AngleAxisd(0.7, Eigen::Vector3d(0, 1, 1).normalized()).toRotationMatrix();
  f.translation() = Eigen::Vector3d(1, -2, 3);
  source.start_recording();
  r.set_frame(f);
  r.set_speed(-0.0);
  r.set_axes(7);
  r.set_joints({1, 2});
  const vsd::Transaction t = source.stop_recording();

  const auto bytes = [](const auto& v) {
    std::vector<std::uint8_t> out;
    vsd::ByteWriter w(out);
    vsd::meta_type<std::decay_t<decltype(v)>>().write_bytes(&v, w);
    return out;
  };
  std::vector<std::uint8_t> expected;
  vsd::detail::write_tx_header(expected);
  vsd::detail::write_set(expected, r.id(), "frame", bytes(Eigen::Isometry3d(Eigen::Isometry3d::Identity())),
                         bytes(f));
  vsd::detail::write_set(expected, r.id(), "speed", bytes(1.0), bytes(-0.0));
  vsd::detail::write_set(expected, r.id(), "axes", bytes(6), bytes(7));
  vsd::detail::write_set(expected, r.id(), "joints", bytes(std::vector<double>{}), bytes(std::vector<double>{1, 2}));
  EXPECT_EQ(t.bytes(), expected);

  // And the frame comes back exactly, both ways.
  replica.copy_from(source);
  replica.apply(t.inverted());
  auto& twin = static_cast<TRobot&>(*replica.find(r.id()));
  EXPECT_TRUE(twin.frame().isApprox(Eigen::Isometry3d::Identity(), 0.0));
  replica.apply(t);
  EXPECT_EQ(twin.frame().matrix(), f.matrix());
}

// A stepped state takes a bundle a step: the buffer keeps room for the next one, and bundles of any size in
// any order come out whole.
TEST_F(TransactionTest, BundlesOfChangingSizeComeOutWhole) {
  auto& r = source.create<TRobot>();
  replica.copy_from(source);
  source.start_recording();
  for (const int n : {1, 1000, 3, 0, 5000, 2}) {
    for (int i = 0; i < n; ++i) {
      r.set_speed(static_cast<double>(n + i) + 0.5);  // never the value it has
      if (i % 7 == 0) r.set_joints({static_cast<double>(n), static_cast<double>(i)});  // always new
    }
    const vsd::Transaction t = source.take_recording();
    EXPECT_EQ(t.size(), static_cast<std::size_t>(n + (n + 6) / 7));
    replica.apply(t);
    expect_equal(source, replica);
  }
  EXPECT_TRUE(source.stop_recording().empty());
}

// take_recording(into): the same bundles as take_recording(), heard by the listeners the same way, and the
// state records on into the buffer it was handed back (so two buffers take turns, both warm).
TEST_F(TransactionTest, TakingIntoABundleRecordsIntoItsOldBuffer) {
  auto& r = source.create<TRobot>();
  replica.copy_from(source);
  std::vector<std::size_t> heard;
  const vsd::Connection c = source.on_bundle().connect([&](const vsd::Transaction& t) { heard.push_back(t.size()); });

  vsd::Transaction into;
  source.take_recording(into);  // not recording: an empty bundle, nothing heard
  EXPECT_TRUE(into.empty());
  EXPECT_EQ(into.bytes(), vsd::Transaction().bytes());

  source.start_recording();
  const std::uint8_t* buffers[2] = {nullptr, nullptr};
  for (int step = 0; step < 8; ++step) {
    for (int i = 0; i < 100; ++i) r.set_speed(step * 1000.0 + i + 0.5);
    source.take_recording(into);
    ASSERT_EQ(into.size(), 100u);
    replica.apply(into);
    expect_equal(source, replica);
    // Once both buffers have grown to a step's size, neither is new again: the state records into the
    // one handed back.
    if (step >= 3) {
      EXPECT_EQ(into.bytes().data(), buffers[step % 2]) << "step " << step;
    }
    buffers[step % 2] = into.bytes().data();
  }
  EXPECT_EQ(heard, std::vector<std::size_t>(8, 100));

  // Nothing since the last cut: an empty bundle, and the state stops cleanly with the buffer taken back.
  source.take_recording(into);
  EXPECT_TRUE(into.empty());
  EXPECT_EQ(into.bytes(), vsd::Transaction().bytes());
  EXPECT_TRUE(source.stop_recording().empty());
  EXPECT_EQ(heard.size(), 8u);
}

TEST_F(TransactionTest, ReplicaAppliesToEquality) {
  source.start_recording();
  auto& r = source.create<TRobot>();
  r.set_name("arm");
  source.database().add_child(r);
  auto& tool = source.create<TTool>();
  r.set_tool(&tool);
  r.set_target(&source.database());
  r.set_joints({0.1, 0.2, 0.3});
  Eigen::Isometry3d f = Eigen::Isometry3d::Identity();
  f.translate(Eigen::Vector3d(1, 2, 3));
  r.set_frame(f);
  replica.apply(source.take_recording());
  expect_equal(source, replica);
  // Recording goes on after take_recording; deletions replicate too.
  source.destroy(r);
  replica.apply(source.take_recording());
  expect_equal(source, replica);
  EXPECT_EQ(replica.size(), 1u);
}

TEST_F(TransactionTest, TransientPropertiesAreNotRecorded) {
  auto& r = source.create<TRobot>();
  source.start_recording();
  r.set_cache("scratch");
  EXPECT_TRUE(source.stop_recording().empty());
}

TEST_F(TransactionTest, BundlesTravelAsBytes) {
  source.start_recording();
  auto& r = source.create<TRobot>();
  source.database().add_child(r);
  r.set_speed(0.25);
  const std::vector<std::uint8_t> wire = source.stop_recording().bytes();
  const vsd::Transaction received = vsd::Transaction::from_bytes(wire);
  replica.apply(received);
  expect_equal(source, replica);
}

// The paper's streaming example: a loader thread fills its own SimState and hands the result over.
TEST_F(TransactionTest, LoaderThreadHandsASubtreeToTheMainState) {
  vsd::SimState& loader_state = env.create_state("loader");
  std::promise<std::vector<std::uint8_t>> handover;
  std::thread loader([&] {
    loader_state.start_recording();
    auto& site = loader_state.create<vsd::Node>();
    site.set_name("site");
    loader_state.database().add_child(site);
    for (int i = 0; i < 100; ++i) {
      auto& r = loader_state.create<TRobot>();
      r.set_name("robot" + std::to_string(i));
      r.set_speed(i);
      site.add_child(r);
    }
    handover.set_value(loader_state.stop_recording().bytes());
  });
  const auto bytes = handover.get_future().get();
  loader.join();
  source.apply(vsd::Transaction::from_bytes(bytes));
  vsd::Node* site = source.database().find_child("site");
  ASSERT_NE(site, nullptr);
  EXPECT_EQ(site->children().size(), 100u);
  EXPECT_EQ(static_cast<TRobot*>(site->children()[42])->speed(), 42.0);
  expect_equal(loader_state, source);
}

TEST_F(TransactionTest, InvertedBundleUndoes) {
  auto& keep = source.create<TRobot>();
  source.database().add_child(keep);
  auto& gone = source.create<vsd::Node>();
  keep.add_child(gone);
  keep.set_target(&gone);
  replica.copy_from(source);  // the state before

  source.start_recording();
  keep.set_speed(3.0);
  auto& added = source.create<TTool>();
  keep.set_tool(&added);
  source.destroy(gone);  // detaches, nulls the shared target, deletes
  auto& other = source.create<vsd::Node>();
  source.database().add_child(other);
  const vsd::Transaction t = source.stop_recording();

  source.apply(t.inverted());
  expect_equal(source, replica);
  // And redo.
  source.apply(t);
  replica.apply(t);
  expect_equal(source, replica);
}

TEST_F(TransactionTest, ApplyingToAStateThatLacksTheInstancesChangesNothing) {
  auto& r = source.create<TRobot>();
  source.database().add_child(r);
  source.start_recording();
  r.set_speed(7.0);
  auto& n = source.create<vsd::Node>();
  r.add_child(n);
  const vsd::Transaction t = source.stop_recording();

  auto& unrelated = replica.create<vsd::Node>();
  replica.database().add_child(unrelated);
  auto& before = env.create_state("before");
  before.copy_from(replica);
  EXPECT_THAT([&] { replica.apply(t); },
              testing::ThrowsMessage<vsd::Error>(testing::AllOf(
                  HasSubstr("no instance #" + std::to_string(r.id())), HasSubstr("nothing was applied"))));
  expect_equal(replica, before);
}

// A replica that diverged from the source can receive a bundle whose composite insert would close a
// cycle there. The dry run must catch it before anything changes.
TEST_F(TransactionTest, CompositeCyclesAreRejectedBeforeAnythingChanges) {
  auto& a = source.create<vsd::Node>();
  auto& b = source.create<vsd::Node>();
  auto& r = source.create<TRobot>();
  auto& t = source.create<TTool>();
  source.database().add_child(a);
  source.database().add_child(b);
  source.database().add_child(r);
  source.database().add_child(t);
  replica.copy_from(source);
  // The replica moves a under b, and r under the tool t.
  replica.find<vsd::Node>(b.id())->add_child(*replica.find<vsd::Node>(a.id()));
  replica.find<TTool>(t.id())->add_child(*replica.find<vsd::Node>(r.id()));
  auto& before = env.create_state("before");
  before.copy_from(replica);

  source.start_recording();
  a.add_child(b);  // in the replica, b is a's parent: a cycle
  const vsd::Transaction list_cycle = source.stop_recording();
  EXPECT_THAT([&] { replica.apply(list_cycle); },
              testing::ThrowsMessage<vsd::Error>(
                  testing::AllOf(HasSubstr("its own ancestor"), HasSubstr("nothing was applied"))));
  source.start_recording();
  r.set_tool(&t);  // in the replica, t holds r: a cycle through a single composite reference
  const vsd::Transaction ref_cycle = source.stop_recording();
  EXPECT_THAT([&] { replica.apply(ref_cycle); },
              testing::ThrowsMessage<vsd::Error>(HasSubstr("its own ancestor")));
  std::string diff;
  EXPECT_TRUE(replica.equals(before, &diff)) << diff;
  // Where the graph allows it, the same bundles apply.
  auto& fresh = env.create_state("fresh");
  auto& was = env.create_state("was");
  was.copy_from(source);
  fresh.copy_from(source);
  fresh.apply(list_cycle.inverted());  // undo the move of b ...
  fresh.apply(list_cycle);             // ... and redo it: no cycle in an undiverged copy
  EXPECT_TRUE(fresh.equals(was, &diff)) << diff;
}

TEST_F(TransactionTest, MovesWithinABundleAreNotMistakenForCycles) {
  auto& a = source.create<vsd::Node>();
  auto& b = source.create<vsd::Node>();
  source.database().add_child(a);
  a.add_child(b);
  replica.copy_from(source);
  source.start_recording();
  source.database().add_child(b);  // b leaves a ...
  b.add_child(a);                  // ... so a may go under b
  replica.apply(source.stop_recording());
  std::string diff;
  EXPECT_TRUE(source.equals(replica, &diff)) << diff;
  EXPECT_EQ(replica.find<vsd::Node>(a.id())->parent()->id(), b.id());
}

// A node has one parent: a bundle that would leave one in two children lists (a replica whose node moved
// meanwhile, or a hand-made bundle) is refused before anything changes; a move (insert, then erase from
// the old parent) is not.
TEST_F(TransactionTest, ABundleThatGivesANodeTwoParentsIsRefused) {
  auto& b = source.create<vsd::Node>();
  auto& c = source.create<vsd::Node>();
  auto& x = source.create<vsd::Node>();  // floating
  source.database().add_child(b);
  source.database().add_child(c);
  replica.copy_from(source);
  replica.find<vsd::Node>(c.id())->add_child(*replica.find<vsd::Node>(x.id()));  // the replica placed x
  auto& before = env.create_state("before");
  before.copy_from(replica);

  source.start_recording();
  b.add_child(x);  // an insert, no erase: in the replica c holds x already
  const vsd::Transaction move = source.stop_recording();
  const std::string expected = "node #" + std::to_string(x.id()) + " would be a child of #" +
                               std::to_string(b.id()) + " and #" + std::to_string(c.id()) +
                               ": a node has one parent (a move erases it from the old one)";
  EXPECT_THAT([&] { replica.apply(move); },
              testing::ThrowsMessage<vsd::Error>(testing::AllOf(
                  HasSubstr("operation 1 (insert into #" + std::to_string(b.id()) + ".children)"),
                  HasSubstr(expected), HasSubstr("nothing was applied"))));
  std::string diff;
  EXPECT_TRUE(replica.equals(before, &diff)) << diff;
  // Where the graph allows it, the move applies; twice in one list is refused too.
  auto& fresh = env.create_state("fresh");
  fresh.copy_from(source);
  fresh.apply(move.inverted());
  fresh.apply(move);
  EXPECT_TRUE(fresh.equals(source, &diff)) << diff;
  source.start_recording();
  b.list_insert(vsd::Node::vsd_prop_children(), 0, x);  // the core's generic insert does not stop this
  const vsd::Transaction twice = source.stop_recording();
  EXPECT_THAT(
      [&] { fresh.apply(twice); },
      testing::ThrowsMessage<vsd::Error>(HasSubstr("node #" + std::to_string(x.id()) +
                                                   " would be listed twice by #" + std::to_string(b.id()))));
}

// Bundles of deep trees: a snapshot of a chain of 100,000 applies and is undone in about linear time.
TEST_F(TransactionTest, ASnapshotOfADeepChainApplies) {
  vsd::Node* at = &source.database();
  for (int i = 0; i < 100'000; ++i) at = &at->add_child(source.create<vsd::Node>());
  const vsd::Transaction copy = source.snapshot();
  replica.apply(copy);
  EXPECT_EQ(replica.size(), source.size());
  replica.apply(copy.inverted());
  EXPECT_EQ(replica.size(), 1u);
}

TEST_F(TransactionTest, ApplyingTwiceIsRejectedAsAWhole) {
  source.start_recording();
  auto& r = source.create<TRobot>();
  source.database().add_child(r);
  const vsd::Transaction t = source.stop_recording();
  replica.apply(t);
  EXPECT_THAT([&] { replica.apply(t); }, testing::ThrowsMessage<vsd::Error>(HasSubstr("already exists")));
  EXPECT_EQ(replica.size(), 2u);
}

TEST_F(TransactionTest, AnEmptyBundleIsItsHeader) {
  const vsd::Transaction empty;
  EXPECT_TRUE(empty.empty());
  ASSERT_EQ(empty.bytes().size(), 5u);
  EXPECT_EQ(std::string(empty.bytes().begin(), empty.bytes().begin() + 4), "VSDT");
  EXPECT_EQ(empty.bytes()[4], vsd::Transaction::format_version);
  EXPECT_TRUE(vsd::Transaction::from_bytes(empty.bytes()).empty());
  EXPECT_EQ(empty.inverted().bytes(), empty.bytes());
  source.start_recording();
  EXPECT_EQ(source.stop_recording().bytes(), empty.bytes());
  EXPECT_EQ(replica.snapshot().bytes(), empty.bytes()) << "an empty state snapshots to the empty bundle";
  replica.apply(empty);
  replica.apply(vsd::Transaction::from_bytes(empty.bytes()));
}

TEST_F(TransactionTest, AListenerDeletingWhatTheBundleNeedsIsAnErrorNotACrash) {
  auto& r = source.create<TRobot>();
  source.database().add_child(r);
  replica.copy_from(source);
  source.start_recording();
  r.set_speed(3.0);
  auto& tool = source.create<TTool>();
  r.add_child(tool);
  const vsd::Transaction t = source.stop_recording();
  // On the replica, a listener deletes the robot as soon as its speed changes.
  auto c = replica.on_property_changed().connect([&](vsd::SimStateInstance& i, const vsd::MetaProperty& p) {
    if (p.name() == "speed" && !i.is_being_deleted()) replica.destroy(i);
  });
  EXPECT_THAT([&] { replica.apply(t); }, testing::ThrowsMessage<vsd::Error>(HasSubstr(
                                             "was deleted by a listener while the bundle was applied")));
}

TEST_F(TransactionTest, HeaderAndVersionAreChecked) {
  EXPECT_THAT(
      [] {
        (void)vsd::Transaction::from_bytes({'X', 'Y', 'Z', 'W', 1});
      },
      testing::ThrowsMessage<vsd::Error>(HasSubstr("byte 0")));
  EXPECT_THAT(
      [] {
        (void)vsd::Transaction::from_bytes({'V', 'S', 'D', 'T', 99});
      },
      testing::ThrowsMessage<vsd::Error>(HasSubstr("version 99")));
  EXPECT_TRUE(vsd::Transaction::from_bytes({}).empty());
}

TEST_F(TransactionTest, EveryTruncationIsAClearErrorAndChangesNothing) {
  source.start_recording();
  auto& r = source.create<TRobot>();
  r.set_name("truncated");
  source.database().add_child(r);
  r.set_joints({1, 2, 3});
  const auto bytes = source.stop_recording().bytes();
  int rejected = 0;
  for (std::size_t n = 5; n < bytes.size(); ++n) {
    std::vector<std::uint8_t> cut(bytes.begin(), bytes.begin() + static_cast<std::ptrdiff_t>(n));
    auto& target = env.create_state("cut");
    try {
      target.apply(vsd::Transaction::from_bytes(cut));
      // A cut exactly between operations is a valid, shorter bundle.
    } catch (const vsd::Error& e) {
      ++rejected;
      EXPECT_THAT(e.what(), HasSubstr("byte ")) << "cut at " << n;
      EXPECT_EQ(target.size(), 1u) << "cut at " << n;
    }
    env.remove_state(target);
  }
  EXPECT_GT(rejected, static_cast<int>(bytes.size()) / 2);
}

TEST_F(TransactionTest, CorruptedBytesNeverCrash) {
  source.start_recording();
  auto& r = source.create<TRobot>();
  source.database().add_child(r);
  r.set_joints({1, 2, 3});
  r.set_target(&source.database());
  const auto bytes = source.stop_recording().bytes();
  std::uint32_t seed = 12345;
  for (int round = 0; round < 2000; ++round) {
    auto bad = bytes;
    for (int k = 0; k < 3; ++k) {
      seed = seed * 1664525u + 1013904223u;
      bad[5 + seed % (bad.size() - 5)] = static_cast<std::uint8_t>(seed >> 24);
    }
    auto& target = env.create_state("fuzz");
    try {
      target.apply(vsd::Transaction::from_bytes(bad));
    } catch (const vsd::Error&) {
      EXPECT_EQ(target.size(), 1u) << "a rejected bundle must change nothing";
    }
    env.remove_state(target);
  }
}

TEST_F(TransactionTest, UnknownClassesAndPropertiesAreReported) {
  source.start_recording();
  auto& r = source.create<TRobot>();
  r.set_speed(5);
  auto bytes = source.stop_recording().bytes();
  // Rename the class in the bundle: "TRobot" -> "XRobot".
  auto at = std::search(bytes.begin(), bytes.end(), std::begin("TRobot"), std::end("TRobot") - 1);
  ASSERT_NE(at, bytes.end());
  *at = 'X';
  EXPECT_THAT([&] { replica.apply(vsd::Transaction::from_bytes(bytes)); },
              testing::ThrowsMessage<vsd::Error>(HasSubstr("unknown class 'XRobot'")));
  *at = 'T';
  auto sp = std::search(bytes.begin(), bytes.end(), std::begin("speed"), std::end("speed") - 1);
  *sp = 'z';
  EXPECT_THAT([&] { replica.apply(vsd::Transaction::from_bytes(bytes)); },
              testing::ThrowsMessage<vsd::Error>(HasSubstr("no property 'zpeed'")));
  EXPECT_EQ(replica.size(), 1u);
}

}  // namespace

namespace {

// Savepoints (SimState::savepoint, roll_back, release): what SOML++ uses to make a net firing all or
// nothing.
TEST_F(TransactionTest, RollBackUndoesEveryChangeSinceTheSavepointAndRecordsNothing) {
  auto& r = source.create<TRobot>();
  source.database().add_child(r);
  auto& kept = source.create<vsd::Node>();
  r.add_child(kept);
  r.edit_watched().push_back(kept);
  auto& gone = source.create<vsd::Node>();
  gone.set_name("gone");
  source.database().add_child(gone);
  const vsd::Id gone_id = gone.id();
  replica.copy_from(source);
  EXPECT_FALSE(source.recording());
  const vsd::SimState::Savepoint sp = source.savepoint();
  EXPECT_TRUE(source.recording());
  r.set_speed(5.0);
  auto& made = source.create<TTool>();
  r.set_tool(vsd::Ref<TTool>(&made));
  r.edit_watched().erase(0);
  source.destroy(gone);  // deleted: comes back with its id and values
  int heard = 0;
  auto c = source.on_property_changed().connect(
      [&](vsd::SimStateInstance&, const vsd::MetaProperty&) { ++heard; });
  source.roll_back(sp);
  EXPECT_GT(heard, 0);  // the undo signals like any change
  EXPECT_FALSE(source.recording());
  expect_equal(source, replica);
  ASSERT_NE(source.find(gone_id), nullptr);
  EXPECT_EQ(source.find<vsd::Node>(gone_id)->name(), "gone");
  EXPECT_EQ(r.speed(), 1.0);
  EXPECT_EQ(r.tool().get(), nullptr);
  EXPECT_EQ(r.watched().size(), 1u);
  // Nothing of it is left in a later recording.
  source.start_recording();
  EXPECT_TRUE(source.stop_recording().empty());
}

TEST_F(TransactionTest, SavepointsNestInsideARecordingThatKeepsOnlyWhatStood) {
  auto& r = source.create<TRobot>();
  source.database().add_child(r);
  replica.copy_from(source);
  source.start_recording();
  r.set_speed(2.0);
  const auto outer = source.savepoint();
  r.set_axes(7);
  const auto inner = source.savepoint();
  r.set_speed(3.0);
  source.roll_back(inner);  // speed back to 2
  EXPECT_TRUE(source.recording());
  source.release(outer);  // axes = 7 stays
  EXPECT_TRUE(source.recording());
  const vsd::Transaction t = source.stop_recording();
  const std::string ir = std::to_string(r.id());
  EXPECT_EQ(t.describe(), "set #" + ir + ".speed\nset #" + ir + ".axes\n");
  replica.apply(t);
  expect_equal(source, replica);
  EXPECT_EQ(r.speed(), 2.0);
  EXPECT_EQ(r.axes(), 7);
}

TEST_F(TransactionTest, ReleasingASavepointOfAStateThatDidNotRecordStopsRecording) {
  auto& r = source.create<TRobot>();
  const auto sp = source.savepoint();
  r.set_speed(4.0);
  source.release(sp);
  EXPECT_FALSE(source.recording());
  EXPECT_EQ(r.speed(), 4.0);
  source.start_recording();
  r.set_axes(3);
  EXPECT_EQ(source.stop_recording().size(), 1u);  // only what came after start_recording
}

}  // namespace
