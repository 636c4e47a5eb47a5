#include "vsd/dist/wire.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <string_view>

#include "dist_test_util.hpp"

using testing::HasSubstr;
using vsd_dist_test::DArm;

namespace {

std::size_t occurrences(const std::vector<std::uint8_t>& bytes, std::string_view what) {
  std::size_t n = 0;
  const std::string_view all(reinterpret_cast<const char*>(bytes.data()), bytes.size());
  for (auto at = all.find(what); at != std::string_view::npos; at = all.find(what, at + 1)) ++n;
  return n;
}

struct WireTest : testing::Test {
  vsd::Environment env{1};
  vsd::SimState& source = env.main_state();
  vsd::SimState& replica = env.create_state("replica");
};

TEST_F(WireTest, NamesEachClassAndPropertyOncePerBundle) {
  source.start_recording();
  for (int i = 0; i < 50; ++i) {
    auto& a = source.create<DArm>();
    source.database().add_child(a);
    a.set_target(i * 0.5);
    a.set_position(i * 0.25);
  }
  const vsd::Transaction t = source.stop_recording();
  const auto wire = vsd::dist::encode_bundle(t, source);
  EXPECT_EQ(occurrences(wire.bytes, "DArm"), 1u);
  EXPECT_EQ(occurrences(wire.bytes, "target"), 1u);
  EXPECT_EQ(occurrences(wire.bytes, "position"), 1u);
  EXPECT_EQ(occurrences(wire.bytes, "children"), 1u);
  EXPECT_GT(occurrences(t.bytes(), "target"), 50u);  // the core's VSDT names it in every operation
  EXPECT_LT(wire.bytes.size() * 2, t.bytes().size());
  EXPECT_EQ(wire.ops, t.size());
  replica.apply(vsd::dist::decode_bundle(wire.bytes));
  std::string diff;
  EXPECT_TRUE(source.equals(replica, &diff)) << diff;
}

TEST_F(WireTest, OnlyDistributedPropertiesTravel) {
  auto& a = source.create<DArm>();
  source.database().add_child(a);
  replica.apply(source.snapshot());
  source.start_recording();
  a.set_note("local only");
  a.set_target(2.0);
  auto& b = source.create<DArm>();
  b.set_note("also local");
  const vsd::Transaction t = source.stop_recording();
  const auto wire = vsd::dist::encode_bundle(t, source);
  EXPECT_EQ(wire.dropped, 2u);  // the two sets of note (b's create carries no note either)
  EXPECT_EQ(occurrences(wire.bytes, "note"), 0u);
  replica.apply(vsd::dist::decode_bundle(wire.bytes));
  EXPECT_EQ(replica.find<DArm>(a.id())->target(), 2.0);
  EXPECT_EQ(replica.find<DArm>(a.id())->note(), "");
  ASSERT_NE(replica.find<DArm>(b.id()), nullptr);
  EXPECT_EQ(replica.find<DArm>(b.id())->note(), "");
}

TEST_F(WireTest, SetThenDeleteInOneBundleEncodes) {
  auto& a = source.create<DArm>();
  source.database().add_child(a);
  const vsd::Id id = a.id();
  replica.apply(source.snapshot());
  source.start_recording();
  a.set_target(1.0);
  source.destroy(a);  // gone from the state when the bundle is encoded
  const auto wire = vsd::dist::encode_bundle(source.stop_recording(), source);
  replica.apply(vsd::dist::decode_bundle(wire.bytes));
  EXPECT_EQ(replica.find(id), nullptr);
  EXPECT_TRUE(replica.database().children().empty());
}

TEST_F(WireTest, MalformedBytesAreErrorsWithTheirPosition) {
  source.start_recording();
  auto& a = source.create<DArm>();
  a.set_target(3.0);
  const auto good = vsd::dist::encode_bundle(source.stop_recording(), source).bytes;

  EXPECT_THAT(
      [&] {
        (void)vsd::dist::decode_bundle(std::vector<std::uint8_t>{'V', 'S', 'D', 'T', 1});
      },
      testing::ThrowsMessage<vsd::Error>(HasSubstr("wire bundle byte 0: not a vsd wire bundle")));
  auto bad_version = good;
  bad_version[4] = 9;
  EXPECT_THAT([&] { (void)vsd::dist::decode_bundle(bad_version); },
              testing::ThrowsMessage<vsd::Error>(HasSubstr("byte 4: wire bundle version 9")));
  for (std::size_t cut = 5; cut < good.size(); ++cut) {  // every truncation is an error, never a crash
    std::vector<std::uint8_t> part(good.begin(), good.begin() + static_cast<std::ptrdiff_t>(cut));
    EXPECT_THROW((void)vsd::dist::decode_bundle(part), vsd::Error) << "cut at " << cut;
  }
  auto trailing = good;
  trailing.push_back(0);
  EXPECT_THAT([&] { (void)vsd::dist::decode_bundle(trailing); },
              testing::ThrowsMessage<vsd::Error>(HasSubstr("1 unexpected bytes after the last operation")));
  // A name index past the table.
  const std::vector<std::uint8_t> bad_name{'V', 'S', 'D', 'W', 2, 1, 4, 'D', 'A', 'r', 'm', 1, 1, 5, 3};
  EXPECT_THAT([&] { (void)vsd::dist::decode_bundle(bad_name); },
              testing::ThrowsMessage<vsd::Error>(
                  HasSubstr("byte 14: name index 3 is past the name table (1 names)")));
  const std::vector<std::uint8_t> bad_code{'V', 'S', 'D', 'W', 2, 1, 4, 'D', 'A', 'r', 'm', 1, 9, 5, 0};
  EXPECT_THAT([&] { (void)vsd::dist::decode_bundle(bad_code); },
              testing::ThrowsMessage<vsd::Error>(HasSubstr("byte 12: unknown operation code 9")));
  const std::vector<std::uint8_t> huge_count{'V', 'S', 'D', 'W', 2, 0, 0x7f};
  EXPECT_THAT([&] { (void)vsd::dist::decode_bundle(huge_count); },
              testing::ThrowsMessage<vsd::Error>(HasSubstr("exceeds")));
}

TEST_F(WireTest, ABundleThatDoesNotFitChangesNothing) {
  auto& a = source.create<DArm>();
  source.database().add_child(a);
  const vsd::Id id = a.id();
  replica.apply(source.snapshot());
  source.start_recording();
  a.set_target(5.0);
  source.destroy(a);
  const auto wire = vsd::dist::encode_bundle(source.stop_recording(), source).bytes;
  replica.destroy(*replica.find(id));  // the replica has diverged: the set cannot apply
  const std::size_t before = replica.size();
  EXPECT_THAT([&] { replica.apply(vsd::dist::decode_bundle(wire)); },
              testing::ThrowsMessage<vsd::Error>(HasSubstr("no instance #" + std::to_string(id))));
  EXPECT_EQ(replica.size(), before);
}

// List edits in element form: the encoder names entries, the decoder's hook turns them back into indices;
// without a hook, and when cut anywhere, decoding is an error, never a crash.
TEST_F(WireTest, ElementFormListEditsRoundTripThroughTheHooks) {
  auto& a = source.create<DArm>();
  auto& n1 = source.create<vsd::Node>();
  auto& n2 = source.create<vsd::Node>();
  source.database().add_child(a);
  replica.apply(source.snapshot());
  source.start_recording();
  a.edit_tools().push_back(n1);
  a.edit_tools().insert(0, n2);
  a.edit_tools().erase(1);
  std::vector<vsd::dist::ElementEdit> seen;
  const auto wire = vsd::dist::encode_bundle(
      source.stop_recording(), source,
      [&](vsd::Transaction::Op op, vsd::Id holder, std::string_view prop, std::size_t index, vsd::Id target) {
        vsd::dist::ElementEdit e;
        e.op = op;
        e.holder = holder;
        e.property = prop;
        e.target = target;
        e.element = vsd::dist::ElementId{7, 9, index + 1};
        e.origin = vsd::dist::ElementId{0, 0, index};
        return e;
      });
  EXPECT_TRUE(wire.list_edits);
  EXPECT_THAT(
      [&] { (void)vsd::dist::decode_bundle(wire.bytes); },
      testing::ThrowsMessage<vsd::Error>(HasSubstr("an element-form list edit needs a list decoder")));
  vsd::dist::DecodeHooks hooks;
  hooks.list = [&](const vsd::dist::ElementEdit& e, std::vector<std::uint8_t>&, std::size_t&) {
    seen.push_back(e);
  };
  (void)vsd::dist::decode_bundle(wire.bytes, hooks);
  ASSERT_EQ(seen.size(), 3u);
  EXPECT_EQ(seen[0].op, vsd::Transaction::Op::Insert);
  EXPECT_EQ(seen[0].target, n1.id());
  EXPECT_EQ(seen[0].element.n, 1u);  // an insertion's clock and who are the stamp's
  EXPECT_EQ(seen[0].element.clock, 0u);
  EXPECT_EQ(seen[1].origin, (vsd::dist::ElementId{0, 0, 0}));  // inserted at the front
  EXPECT_EQ(seen[2].op, vsd::Transaction::Op::Erase);
  EXPECT_EQ(seen[2].element, (vsd::dist::ElementId{7, 9, 2}));  // erasures name the whole entry
  EXPECT_EQ(seen[2].target, n1.id());
  for (std::size_t cut = 5; cut < wire.bytes.size(); ++cut) {
    std::vector<std::uint8_t> part(wire.bytes.begin(), wire.bytes.begin() + static_cast<std::ptrdiff_t>(cut));
    EXPECT_THROW((void)vsd::dist::decode_bundle(part, hooks), vsd::Error) << "cut at " << cut;
  }
}

}  // namespace
