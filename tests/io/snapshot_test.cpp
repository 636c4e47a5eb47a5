#include "vsd/io/snapshot.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <random>
#include <string_view>

#include "../core/memory_cap.hpp"
#include "../core/random_model.hpp"
#include "io_model.hpp"
#include "vsd/core/bytes.hpp"
#include "vsd/io/file.hpp"

using testing::HasSubstr;
using vsd_test::TRobot;
using vsd_test::TSensor;
using vsd_test::TTool;

using vsd_test::build_model;
using vsd_test::IoPlain;

using vsd_test::diff_of;

namespace {

std::string format_name(vsd::io::Format f) { return f == vsd::io::Format::Text ? "Text" : "Binary"; }

// What both formats must do alike.
class Snapshot : public testing::TestWithParam<vsd::io::Format> {
 protected:
  static vsd::io::Format format() { return GetParam(); }
};

TEST_P(Snapshot, WholeStateRoundTripKeepsIdsAndEverything) {
  vsd::Environment env;
  build_model(env.main_state());
  const auto bytes = vsd::io::save_bytes(env.main_state(), format());
  auto& copy = env.create_state("copy");
  const vsd::io::LoadReport report = vsd::io::load_bytes(copy, bytes);
  EXPECT_EQ(diff_of(env.main_state(), copy), "");
  EXPECT_EQ(report.instances, env.main_state().size() - 1);
  ASSERT_EQ(report.roots.size(), 1u);
  EXPECT_EQ(report.roots[0]->name(), "cell");
  EXPECT_TRUE(report.warnings.empty());
  EXPECT_EQ(vsd_test::check_reference_counts(copy), "");
  EXPECT_EQ(vsd::io::save_bytes(copy, format()), bytes) << "saving what was loaded gives the same bytes";
}

// A chain of 100,000 nodes saves, loads (whole, and under the bottom of another deep chain) and goes in
// about linear time: a load used to check every link against all the levels above it.
TEST_P(Snapshot, DeepChainsLoadAndGo) {
  constexpr std::size_t deep = 100'000;
  vsd::Environment env;
  vsd::Node* at = &env.main_state().database();
  for (std::size_t i = 0; i < deep; ++i) at = &at->add_child(env.main_state().create<vsd::Node>());
  const auto bytes = vsd::io::save_bytes(env.main_state(), format());
  auto& copy = env.create_state("copy");
  vsd::io::load_bytes(copy, bytes);
  EXPECT_EQ(copy.size(), deep + 1);
  const vsd::Node* bottom = copy.find(at->id())->as<vsd::Node>();
  ASSERT_NE(bottom, nullptr);
  std::size_t depth = 0;
  for (const vsd::Node* n = bottom; n != &copy.database(); n = n->parent()) ++depth;
  EXPECT_EQ(depth, deep);
  const auto report = vsd::io::load_bytes(*at, bytes);  // under the bottom of the original chain
  ASSERT_EQ(report.roots.size(), 1u);
  EXPECT_EQ(env.main_state().size(), 2 * deep + 1);
  copy.destroy(*copy.database().children()[0]);
  EXPECT_EQ(copy.size(), 1u);
  env.remove_state(copy);
}

// A load keeps no value for a reference without targets (an empty list, a null reference): the property
// keeps what a new instance has. Whole state and under a node, the result is the saved state.
TEST_P(Snapshot, EmptyListsAndNullReferencesLoadAsDefaults) {
  vsd::Environment env;
  vsd::SimState& s = env.main_state();
  auto& bare = s.create<TRobot>();  // no tool, no target, no children, extensions or watched
  bare.set_name("bare");
  s.database().add_child(bare);
  auto& held = s.create<TRobot>();
  held.set_name("held");
  bare.add_child(held);
  const auto bytes = vsd::io::save_bytes(s, format());

  auto& copy = env.create_state("copy");
  vsd::io::load_bytes(copy, bytes);
  EXPECT_EQ(diff_of(s, copy), "");
  EXPECT_EQ(vsd_test::check_reference_counts(copy), "");
  EXPECT_EQ(vsd::io::save_bytes(copy, format()), bytes);

  auto& under = env.create_state("under");
  auto& parent = under.create<vsd::Node>();
  under.database().add_child(parent);
  const vsd::io::LoadReport report = vsd::io::load_bytes(parent, bytes);
  ASSERT_EQ(report.roots.size(), 1u);
  auto* loaded = dynamic_cast<TRobot*>(report.roots[0]);
  ASSERT_NE(loaded, nullptr);
  EXPECT_EQ(loaded->tool().get(), nullptr);
  EXPECT_EQ(loaded->target().get(), nullptr);
  EXPECT_TRUE(loaded->extensions().empty());
  ASSERT_EQ(loaded->children().size(), 1u);
  EXPECT_EQ(loaded->children()[0]->name(), "held");
  EXPECT_TRUE(loaded->children()[0]->children().empty());
  EXPECT_EQ(vsd_test::check_reference_counts(under), "");
}

// A frame's rotation is stored as its exact matrix: an arbitrary rotation comes back bit for bit.
TEST_P(Snapshot, FramesRoundTripExactly) {
  vsd::Environment env;
  auto& r = env.main_state().create<TRobot>();
  Eigen::Isometry3d f = Eigen::Isometry3d::Identity();
  f.rotate(Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized()));
  f.translation() << 0.1, -0.2, 1e-300;
  r.set_frame(f);
  auto& copy = env.create_state("copy");
  vsd::io::load_bytes(copy, vsd::io::save_bytes(env.main_state(), format()));
  const Eigen::Isometry3d& g = copy.find<TRobot>(r.id())->frame();
  for (int i = 0; i < 16; ++i) EXPECT_EQ(f.matrix().data()[i], g.matrix().data()[i]) << i;
}

TEST_P(Snapshot, LoadedIdsAreNeverHandedOutAgain) {
  vsd::Environment source;
  build_model(source.main_state());
  for (int i = 0; i < 50; ++i) source.main_state().create<vsd::Node>();
  const auto bytes = vsd::io::save_bytes(source.main_state(), format());
  vsd::Environment target;  // a fresh environment whose counter starts low
  vsd::io::load_bytes(target.main_state(), bytes);
  for (int i = 0; i < 100; ++i) target.main_state().create<vsd::Node>();  // must not clash
  EXPECT_EQ(target.main_state().size(), source.main_state().size() + 100);
}

TEST_P(Snapshot, LoadingUnderANodeGivesFreshIds) {
  vsd::Environment env;
  build_model(env.main_state());
  const auto bytes = vsd::io::save_bytes(env.main_state(), format());
  vsd::SimState& s = env.main_state();
  auto& holder = s.create<vsd::Node>();
  holder.set_name("imports");
  s.database().add_child(holder);
  const auto first = vsd::io::load_bytes(holder, bytes);
  const auto second = vsd::io::load_bytes(holder, bytes);
  ASSERT_EQ(holder.children().size(), 2u);
  EXPECT_NE(first.roots[0]->id(), second.roots[0]->id());
  auto* arm = static_cast<TRobot*>(second.roots[0]->find_child("arm"));
  ASSERT_NE(arm, nullptr);
  EXPECT_EQ(arm->target().get(), second.roots[0]->find_child("goal")) << "references follow the new ids";
  EXPECT_EQ(arm->tool()->length(), 0.25);
  EXPECT_EQ(s.database().name(), "world") << "a load under a node leaves the Database's values alone";
  EXPECT_EQ(vsd_test::check_reference_counts(s), "");
}

TEST_P(Snapshot, SubtreesCutOutsideReferences) {
  vsd::Environment env;
  build_model(env.main_state());
  vsd::SimState& s = env.main_state();
  auto* arm = static_cast<TRobot*>(s.database().find_child("cell")->find_child("arm"));
  vsd::io::SaveReport saved;
  const auto bytes = vsd::io::save_bytes(*arm, format(), &saved);
  EXPECT_EQ(saved.instances, 3u);       // arm, its tool, its sensor
  EXPECT_EQ(saved.cut_references, 3u);  // target and two watched nodes lie outside
  auto& other = env.create_state("other");
  const auto report = vsd::io::load_bytes(other, bytes);
  ASSERT_EQ(report.roots.size(), 1u);
  auto& loaded = static_cast<TRobot&>(*report.roots[0]);
  EXPECT_EQ(loaded.parent(), &other.database());
  EXPECT_EQ(loaded.target().get(), nullptr);
  EXPECT_TRUE(loaded.watched().empty());
  ASSERT_NE(loaded.tool().get(), nullptr);
  EXPECT_NE(loaded.find_extension<TSensor>(), nullptr);
}

TEST_P(Snapshot, OnlySavablePropertiesAreWritten) {
  vsd::Environment env;
  auto& p = env.main_state().create<IoPlain>();
  p.set_saved(5);
  p.set_not_saved(6);
  env.main_state().database().add_child(p);
  auto& copy = env.create_state("copy");
  vsd::io::load_bytes(copy, vsd::io::save_bytes(env.main_state(), format()));
  auto* q = copy.find<IoPlain>(p.id());
  ASSERT_NE(q, nullptr);
  EXPECT_EQ(q->saved(), 5);
  EXPECT_EQ(q->not_saved(), 2) << "not Savable: the default";
}

TEST_P(Snapshot, RunTimeClassesTravelWithTheFile) {
  std::vector<std::uint8_t> bytes;
  {
    const vsd::MetaInstance& belt = vsd::ClassBuilder("IoBelt", vsd::Node::static_meta())
                                        .property<double>("speed", 0.5)
                                        .property<std::string>("label", std::string("none"))
                                        .define();
    const vsd::MetaInstance& fast = vsd::ClassBuilder("IoFastBelt", belt).property<int>("lanes", 2).define();
    vsd::Environment env;
    auto& b = static_cast<vsd::Node&>(env.main_state().create(fast));
    b.set("speed", vsd::Value(3.0));
    b.set("label", vsd::Value("express"));
    env.main_state().database().add_child(b);
    bytes = vsd::io::save_bytes(env.main_state(), format());
  }
  vsd::Registry::global().undefine(vsd::Registry::global().get_class("IoFastBelt"));
  vsd::Registry::global().undefine(vsd::Registry::global().get_class("IoBelt"));
  // This "program" does not know IoBelt: the file defines it.
  vsd::Environment env;
  const auto report = vsd::io::load_bytes(env.main_state(), bytes);
  EXPECT_THAT(report.defined_classes, testing::ElementsAre("IoBelt", "IoFastBelt"));
  ASSERT_EQ(report.roots.size(), 1u);
  EXPECT_EQ(report.roots[0]->get<double>("speed"), 3.0);
  EXPECT_EQ(report.roots[0]->get<std::string>("label"), "express");
  EXPECT_EQ(report.roots[0]->get<int>("lanes"), 2);
  EXPECT_EQ(vsd::io::save_bytes(env.main_state(), format()), bytes) << "loaded and saved again: unchanged";
  env.main_state().destroy(*report.roots[0]);
  vsd::Registry::global().undefine(vsd::Registry::global().get_class("IoFastBelt"));
  vsd::Registry::global().undefine(vsd::Registry::global().get_class("IoBelt"));
}

TEST_P(Snapshot, SchemaEvolution) {
  std::vector<std::uint8_t> bytes;
  {
    const vsd::MetaInstance& v1 = vsd::ClassBuilder("IoEvolving", vsd::Node::static_meta())
                                      .property<int>("speed", 0)
                                      .property<double>("gone", 0.0)
                                      .property<std::string>("colour", std::string())
                                      .define();
    vsd::Environment env;
    auto& x = env.main_state().create(v1);
    x.set("speed", vsd::Value(4));
    x.set("gone", vsd::Value(1.5));
    x.set("colour", vsd::Value("red"));
    env.main_state().database().add_child(static_cast<vsd::Node&>(x));
    bytes = vsd::io::save_bytes(env.main_state(), format());
    env.main_state().destroy(x);
    vsd::Registry::global().undefine(v1);
  }
  // Version 2: speed renamed to velocity and now a double, gone removed, colour became a number, added new.
  const vsd::MetaInstance& v2 = vsd::ClassBuilder("IoEvolving", vsd::Node::static_meta())
                                    .property<double>("velocity", 0.0)
                                    .alias("speed")
                                    .property<double>("colour", 0.0)
                                    .property<double>("added", 7.0)
                                    .define();
  {
    vsd::Environment env;
    const auto report = vsd::io::load_bytes(env.main_state(), bytes);
    ASSERT_EQ(report.roots.size(), 1u);
    vsd::Node& x = *report.roots[0];
    EXPECT_EQ(x.get<double>("velocity"), 4.0);
    EXPECT_EQ(x.get<double>("added"), 7.0);
    EXPECT_EQ(x.get<double>("colour"), 0.0);
    EXPECT_THAT(report.warnings, testing::UnorderedElementsAre(
                                     HasSubstr("changed from int32 to double: values are converted"),
                                     HasSubstr("no property 'gone'"),
                                     HasSubstr("changed from string to double: saved values are dropped")));
    env.main_state().destroy(x);
  }
  vsd::Registry::global().undefine(v2);
}

INSTANTIATE_TEST_SUITE_P(Formats, Snapshot, testing::Values(vsd::io::Format::Binary, vsd::io::Format::Text),
                         [](const auto& info) { return format_name(info.param); });

class HostileSnapshot : public testing::Test {
 protected:
  void SetUp() override {
    build_model(source.main_state());
    bytes = vsd::io::save_bytes(source.main_state());
  }
  // Loads @p bad into a fresh state; returns the error, checking that the state was left untouched.
  std::string load_error(const std::vector<std::uint8_t>& bad) {
    vsd::Environment env;
    try {
      vsd::io::load_bytes(env.main_state(), bad, "model.vsds");
    } catch (const vsd::Error& e) {
      EXPECT_EQ(env.main_state().size(), 1u) << "a rejected file must change nothing";
      return e.what();
    }
    return "<loaded>";
  }
  vsd::Environment source;
  std::vector<std::uint8_t> bytes;
};

TEST_F(HostileSnapshot, EveryTruncationIsRejectedWithAPosition) {
  for (std::size_t n = 0; n < bytes.size(); ++n) {
    const std::string e =
        load_error(std::vector<std::uint8_t>(bytes.begin(), bytes.begin() + static_cast<std::ptrdiff_t>(n)));
    EXPECT_THAT(e, HasSubstr("model.vsds: ")) << n;
    EXPECT_THAT(e, HasSubstr("byte ")) << n;
  }
}

TEST_F(HostileSnapshot, CorruptionNeverCrashesOrHalfLoads) {
  std::mt19937 rng(99);
  int loaded = 0;
  for (int round = 0; round < 3000; ++round) {
    auto bad = bytes;
    const int flips = 1 + static_cast<int>(rng() % 4);
    for (int k = 0; k < flips; ++k) bad[rng() % bad.size()] = static_cast<std::uint8_t>(rng());
    if (load_error(bad) == "<loaded>") ++loaded;  // a flip inside a number may still be a valid file
  }
  EXPECT_LT(loaded, 3000);
}

TEST_F(HostileSnapshot, HeaderAndVersion) {
  auto bad = bytes;
  bad[0] = 'X';
  EXPECT_THAT(load_error(bad), HasSubstr("byte 0: not a vsd file"));
  bad = bytes;
  bad[4] = 9;
  EXPECT_THAT(load_error(bad), HasSubstr("byte 4: snapshot format version 9"));
}

TEST_F(HostileSnapshot, AbsurdSizesDoNotAllocate) {
  std::vector<std::uint8_t> bad(bytes.begin(), bytes.begin() + 6);  // header, then a huge class count
  for (int i = 0; i < 9; ++i) bad.push_back(0xFF);
  bad.push_back(0x01);
  EXPECT_THAT(load_error(bad), HasSubstr("exceeds"));
}

TEST_F(HostileSnapshot, UnknownClassesAndDanglingReferences) {
  auto bad = bytes;
  auto at = std::search(bad.begin(), bad.end(), std::begin("TRobot"), std::end("TRobot") - 1);
  ASSERT_NE(at, bad.end());
  *at = 'Q';
  EXPECT_THAT(load_error(bad), HasSubstr("unknown class 'QRobot'"));
}

TEST(SnapshotState, WholeStateLoadNeedsAnEmptyState) {
  vsd::Environment env;
  build_model(env.main_state());
  const auto bytes = vsd::io::save_bytes(env.main_state());
  EXPECT_THAT([&] { vsd::io::load_bytes(env.main_state(), bytes); },
              testing::ThrowsMessage<vsd::Error>(HasSubstr("needs an empty SimState")));
}

TEST(SnapshotFiles, SaveAndLoadThroughFiles) {
  vsd::Environment env;
  build_model(env.main_state());
  const auto path =
      std::filesystem::temp_directory_path() / ("vsd_snapshot_test_" + std::to_string(::getpid()));
  vsd::io::save(env.main_state(), path);
  auto& copy = env.create_state("copy");
  vsd::io::load(copy, path);
  EXPECT_EQ(diff_of(env.main_state(), copy), "");
  std::filesystem::remove(path);
  EXPECT_THAT([&] { vsd::io::load(copy, path); },
              testing::ThrowsMessage<vsd::Error>(HasSubstr("cannot open")));
  // A directory is said to be one (it was "a file of 9223372036854775807 bytes").
  const auto dir = std::filesystem::temp_directory_path();
  EXPECT_THAT([&] { vsd::io::load(copy, dir); },
              testing::ThrowsMessage<vsd::Error>(HasSubstr(dir.string() + ": is a directory, not a file")));
}

// A file whose model does not fit the memory left is a vsd::Error naming the file, like any bad file:
// std::bad_alloc never leaves a load or a check.
TEST_P(Snapshot, RunningOutOfMemoryIsAnError) {
  VSD_TEST_RUN_CAPPED();
  // 300,000 nodes, written directly (a state built first would leave its freed memory to the load).
  constexpr vsd::Id count = 300'000;
  std::vector<std::uint8_t> bytes;
  if (format() == vsd::io::Format::Binary) {
    vsd::ByteWriter w(bytes);
    for (const char c : std::string_view("VSDS\x01\x00", 6)) w.u8(static_cast<std::uint8_t>(c));
    w.varint(1);  // one class: Node, C++, no saved property
    w.string("Node");
    w.u8(0);
    w.varint(0);
    w.varint(count);
    for (vsd::Id id = 2; id < count + 2; ++id) {
      w.varint(id);
      w.varint(0);
    }
    w.varint(0);  // no top-level node
  } else {
    std::string text = "{\"format\": \"vsd-text\", \"version\": 1, \"instances\": [";
    for (vsd::Id id = 2; id < count + 2; ++id)
      text +=
          (id == 2 ? "" : ",\n") + std::string("{\"@id\": ") + std::to_string(id) + ", \"@class\": \"Node\"}";
    text += "]}\n";
    bytes.assign(text.begin(), text.end());
  }
  vsd_test::cap_memory(std::size_t{16} << 20);
  for (const bool load : {false, true}) {
    vsd::Environment env;
    EXPECT_THAT(
        [&] {
          if (load)
            vsd::io::load_bytes(env.main_state(), bytes, "big.vsd");
          else
            (void)vsd::io::check_bytes(bytes, "big.vsd");
        },
        testing::ThrowsMessage<vsd::Error>(testing::StartsWith("big.vsd: out of memory while")))
        << (load ? "load" : "check");
  }
}

}  // namespace

namespace {

// Round trips of randomly grown models: every kind of value and reference, floating instances,
// deletions and moves behind them.
class SnapshotRandomModels : public testing::TestWithParam<std::tuple<std::uint32_t, vsd::io::Format>> {};

TEST_P(SnapshotRandomModels, RoundTripToEqualStates) {
  vsd::Environment env;
  vsd::SimState& state = env.main_state();
  const auto [seed, format] = GetParam();
  vsd_test::RandomModel model(state, seed);
  for (int round = 0; round < 5; ++round) {
    for (int i = 0; i < 300; ++i) model.step();
    const auto bytes = vsd::io::save_bytes(state, format);
    auto& copy = env.create_state("copy");
    vsd::io::load_bytes(copy, bytes);
    std::string diff;
    ASSERT_TRUE(copy.equals(state, &diff)) << "round " << round << ": " << diff;
    ASSERT_EQ(vsd_test::check_reference_counts(copy), "");
    ASSERT_EQ(vsd::io::save_bytes(copy, format), bytes) << "round " << round;
    // The same file under a node of another state: fresh ids, same shape.
    auto& other = env.create_state("other");
    auto& holder = other.create<vsd::Node>();
    other.database().add_child(holder);
    const auto report = vsd::io::load_bytes(holder, bytes);
    EXPECT_EQ(report.roots.size(), state.database().children().size());
    EXPECT_EQ(other.size(), state.size() + 1);  // its Database and holder; the file's Database is not copied
    EXPECT_EQ(vsd_test::check_reference_counts(other), "");
    env.remove_state(copy);
    env.remove_state(other);
  }
}

INSTANTIATE_TEST_SUITE_P(Seeds, SnapshotRandomModels,
                         testing::Combine(testing::Values(11u, 12u, 13u),
                                          testing::Values(vsd::io::Format::Binary, vsd::io::Format::Text)),
                         [](const auto& info) {
                           return format_name(std::get<1>(info.param)) + std::to_string(std::get<0>(info.param));
                         });

}  // namespace
