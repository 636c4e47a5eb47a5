// Tests of vsd/core/value.hpp: the owning, type-erased Value.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <cstdint>
#include <functional>
#include <limits>
#include <string>
#include <utility>
#include <vector>
#include <vsd/vsd.hpp>

#include "test_util.hpp"

namespace vt {

struct alignas(32) VtAligned {
  double a = 0;
  double b = 0;
};
VSD_STRUCT(VtAligned, a, b)

struct VtCounted {  // counts live copies to check that Value constructs and destroys exactly once
  static inline int live = 0;
  std::int32_t n = 0;
  VtCounted() { ++live; }
  VtCounted(const VtCounted& o) : n(o.n) { ++live; }
  VtCounted& operator=(const VtCounted&) = default;
  ~VtCounted() { --live; }
};
VSD_STRUCT(VtCounted, n)

}  // namespace vt

namespace {

using testing::HasSubstr;
using vt::VtAligned;
using vt::VtCounted;

bool stored_inline(const vsd::Value& v) {
  const auto p = reinterpret_cast<std::uintptr_t>(v.data());
  const auto b = reinterpret_cast<std::uintptr_t>(&v);
  return p >= b && p < b + sizeof(vsd::Value);
}

using vsd_test::error_of;

Eigen::Isometry3d sample_frame() {
  Eigen::Isometry3d f = Eigen::Isometry3d::Identity();
  f.translation() = Eigen::Vector3d(1, 2, 3);
  f.linear() = Eigen::AngleAxisd(0.5, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  return f;
}

TEST(Value, EmptyValue) {
  vsd::Value v;
  EXPECT_TRUE(v.empty());
  EXPECT_EQ(v.type(), nullptr);
  EXPECT_EQ(v.data(), nullptr);
  EXPECT_FALSE(v.is<double>());
  EXPECT_EQ(v.try_as<double>(), nullptr);
  EXPECT_EQ(v.to_text(), "<empty>");
  v.reset();  // resetting an empty value is fine
  EXPECT_TRUE(v.empty());
}

TEST(Value, HoldsSmallValuesInline) {
  const vsd::Value d(2.5);
  EXPECT_EQ(d.type(), &vsd::meta_type<double>());
  EXPECT_TRUE(stored_inline(d));
  const vsd::Value s(std::string("hello"));
  EXPECT_EQ(s.type(), &vsd::meta_type<std::string>());
  EXPECT_TRUE(stored_inline(s)) << "a std::string (32 bytes) fits inline";
  const vsd::Value v3(Eigen::Vector3d(1, 2, 3));
  EXPECT_TRUE(stored_inline(v3));
  const vsd::Value vec(std::vector<double>{1, 2});
  EXPECT_TRUE(stored_inline(vec));
}

TEST(Value, HoldsLargeValuesOnTheHeap) {
  ASSERT_GT(sizeof(Eigen::Isometry3d), vsd::Value::inline_size);
  const Eigen::Isometry3d f = sample_frame();
  const vsd::Value v(f);
  EXPECT_EQ(v.type(), &vsd::meta_type<Eigen::Isometry3d>());
  EXPECT_FALSE(stored_inline(v));
  EXPECT_TRUE(v.as<Eigen::Isometry3d>().isApprox(f, 0));
  EXPECT_EQ(reinterpret_cast<std::uintptr_t>(v.data()) % alignof(Eigen::Isometry3d), 0u);
}

TEST(Value, OverAlignedValuesGoToTheHeapAligned) {
  ASSERT_GT(alignof(VtAligned), vsd::Value::inline_align);
  vsd::Value v(VtAligned{1, 2});
  EXPECT_FALSE(stored_inline(v));
  EXPECT_EQ(reinterpret_cast<std::uintptr_t>(v.data()) % 32, 0u);
  const vsd::Value c(v);
  EXPECT_EQ(reinterpret_cast<std::uintptr_t>(c.data()) % 32, 0u);
  EXPECT_EQ(c.as<VtAligned>().b, 2);
  vsd::Value d(vsd::meta_type<VtAligned>());
  EXPECT_EQ(reinterpret_cast<std::uintptr_t>(d.data()) % 32, 0u);
  d = std::move(v);
  EXPECT_EQ(d.as<VtAligned>().a, 1);
}

TEST(Value, DefaultValueOfAType) {
  EXPECT_EQ(vsd::Value(vsd::meta_type<std::int32_t>()).as<std::int32_t>(), 0);
  EXPECT_EQ(vsd::Value(vsd::meta_type<std::string>()).as<std::string>(), "");
  EXPECT_TRUE(vsd::Value(vsd::meta_type<Eigen::Isometry3d>())
                  .as<Eigen::Isometry3d>()
                  .isApprox(Eigen::Isometry3d::Identity(), 0));
}

TEST(Value, CopyFromRawMemory) {
  const double d = 4.25;
  const vsd::Value v(vsd::meta_type<double>(), &d);
  EXPECT_EQ(v.as<double>(), 4.25);
}

TEST(Value, StringLiteralsBecomeStrings) {
  const vsd::Value v("text");
  EXPECT_TRUE(v.is<std::string>());
  EXPECT_EQ(v.as<std::string>(), "text");
}

TEST(Value, IntegerLiteralsKeepTheirCppType) {
  EXPECT_TRUE(vsd::Value(3).is<std::int32_t>());
  EXPECT_TRUE(vsd::Value(3U).is<std::uint32_t>());
  EXPECT_TRUE(vsd::Value(std::int64_t{3}).is<std::int64_t>());
  EXPECT_TRUE(vsd::Value(3.0f).is<float>());
  EXPECT_TRUE(vsd::Value(true).is<bool>());
}

TEST(Value, CopyIsDeep) {
  vsd::Value a(std::vector<double>{1, 2, 3});
  vsd::Value b(a);
  b.as<std::vector<double>>().push_back(4);
  EXPECT_EQ(a.as<std::vector<double>>().size(), 3u);
  EXPECT_EQ(b.as<std::vector<double>>().size(), 4u);

  vsd::Value f(sample_frame());
  vsd::Value g(f);
  EXPECT_NE(f.data(), g.data());
  g.as<Eigen::Isometry3d>().translation().x() = 99;
  EXPECT_EQ(f.as<Eigen::Isometry3d>().translation().x(), 1);
  EXPECT_EQ(g.as<Eigen::Isometry3d>().translation().x(), 99);
}

TEST(Value, MoveOfInlineValue) {
  vsd::Value a(std::string("a string long enough to live on the heap of std::string itself"));
  const char* chars = a.as<std::string>().data();
  vsd::Value b(std::move(a));
  EXPECT_TRUE(a.empty());  // NOLINT(bugprone-use-after-move): a moved-from Value is empty
  EXPECT_EQ(b.as<std::string>().data(), chars) << "the string's buffer was moved, not copied";
}

TEST(Value, MoveOfHeapValueStealsThePointer) {
  vsd::Value a(sample_frame());
  const void* where = a.data();
  vsd::Value b(std::move(a));
  EXPECT_TRUE(a.empty());  // NOLINT(bugprone-use-after-move)
  EXPECT_EQ(b.data(), where);
  vsd::Value c;
  c = std::move(b);
  EXPECT_TRUE(b.empty());  // NOLINT(bugprone-use-after-move)
  EXPECT_EQ(c.data(), where);
  EXPECT_TRUE(c.as<Eigen::Isometry3d>().isApprox(sample_frame(), 0));
}

TEST(Value, AssignmentAcrossTypesAndStorage) {
  vsd::Value v(1.5);
  v = vsd::Value(std::string("now a string"));
  EXPECT_TRUE(v.is<std::string>());
  v = vsd::Value(sample_frame());  // inline -> heap
  EXPECT_TRUE(v.is<Eigen::Isometry3d>());
  v = vsd::Value(7);  // heap -> inline
  EXPECT_EQ(v.as<std::int32_t>(), 7);
  const vsd::Value frame(sample_frame());
  v = frame;  // copy-assign heap
  EXPECT_TRUE(v == frame);
  EXPECT_NE(v.data(), frame.data());
  v = vsd::Value();
  EXPECT_TRUE(v.empty());
}

TEST(Value, SelfAssignmentKeepsTheValue) {
  vsd::Value v(std::string("same"));
  const vsd::Value& alias = v;
  v = alias;
  EXPECT_EQ(v.as<std::string>(), "same");
  vsd::Value h(sample_frame());
  const vsd::Value& halias = h;
  h = halias;
  EXPECT_TRUE(h.as<Eigen::Isometry3d>().isApprox(sample_frame(), 0));
}

TEST(Value, ResetDestroysTheHeldValue) {
  const int before = VtCounted::live;
  {
    vsd::Value v(VtCounted{});
    EXPECT_EQ(VtCounted::live, before + 1);
    vsd::Value c(v);
    EXPECT_EQ(VtCounted::live, before + 2);
    v.reset();
    EXPECT_TRUE(v.empty());
    EXPECT_EQ(VtCounted::live, before + 1);
    vsd::Value m(std::move(c));
    EXPECT_EQ(VtCounted::live, before + 1);
    m = vsd::Value(1.0);
    EXPECT_EQ(VtCounted::live, before);
  }
  EXPECT_EQ(VtCounted::live, before);
}

TEST(Value, AsTryAsAndIs) {
  vsd::Value v(2.5);
  EXPECT_TRUE(v.is<double>());
  EXPECT_FALSE(v.is<float>());
  EXPECT_FALSE(v.is<std::int32_t>());
  ASSERT_NE(v.try_as<double>(), nullptr);
  EXPECT_EQ(*v.try_as<double>(), 2.5);
  EXPECT_EQ(v.try_as<std::string>(), nullptr);
  v.as<double>() = 3.5;  // the non-const as<T> gives write access
  EXPECT_EQ(v.as<double>(), 3.5);
  const vsd::Value& cv = v;
  EXPECT_EQ(cv.as<double>(), 3.5);
}

TEST(Value, AsWrongTypeThrowsNamingBothTypes) {
  const vsd::Value v(2.5);
  EXPECT_THROW((void)v.as<std::int32_t>(), vsd::Error);
  const std::string e = error_of([&] { (void)v.as<std::int32_t>(); });
  EXPECT_THAT(e, HasSubstr("double"));
  EXPECT_THAT(e, HasSubstr("int32"));

  vsd::Value s(std::string("x"));
  const std::string e2 = error_of([&] { (void)s.as<std::vector<double>>(); });
  EXPECT_THAT(e2, HasSubstr("string"));
  EXPECT_THAT(e2, HasSubstr("vector<double>"));

  const vsd::Value empty{};
  const std::string e3 = error_of([&] { (void)empty.as<double>(); });
  EXPECT_THAT(e3, HasSubstr("double"));
  EXPECT_THAT(e3, HasSubstr("nothing"));
}

TEST(Value, ConvertIntegerToDouble) {
  const vsd::Value d = vsd::Value(7).convert_to(vsd::meta_type<double>());
  EXPECT_EQ(d.as<double>(), 7.0);
  const vsd::Value f = vsd::Value(std::int64_t{-3}).convert_to(vsd::meta_type<float>());
  EXPECT_EQ(f.as<float>(), -3.0f);
  const vsd::Value u =
      vsd::Value(std::numeric_limits<std::uint32_t>::max()).convert_to(vsd::meta_type<double>());
  EXPECT_EQ(u.as<double>(), 4294967295.0);
}

TEST(Value, ConvertWholeDoubleToInteger) {
  EXPECT_EQ(vsd::Value(3.0).convert_to(vsd::meta_type<std::int32_t>()).as<std::int32_t>(), 3);
  EXPECT_EQ(vsd::Value(-128.0).convert_to(vsd::meta_type<std::int8_t>()).as<std::int8_t>(), -128);
  EXPECT_EQ(vsd::Value(255.0).convert_to(vsd::meta_type<std::uint8_t>()).as<std::uint8_t>(), 255);
  EXPECT_EQ(vsd::Value(-0.0).convert_to(vsd::meta_type<std::uint16_t>()).as<std::uint16_t>(), 0);
  EXPECT_EQ(vsd::Value(9007199254740992.0).convert_to(vsd::meta_type<std::int64_t>()).as<std::int64_t>(),
            9007199254740992LL);
}

TEST(Value, ConvertBetweenIntegers) {
  EXPECT_EQ(vsd::Value(100).convert_to(vsd::meta_type<std::int8_t>()).as<std::int8_t>(), 100);
  EXPECT_EQ(vsd::Value(std::uint8_t{200}).convert_to(vsd::meta_type<std::int64_t>()).as<std::int64_t>(), 200);
  EXPECT_EQ(vsd::Value(std::numeric_limits<std::uint64_t>::max())
                .convert_to(vsd::meta_type<std::uint64_t>())
                .as<std::uint64_t>(),
            std::numeric_limits<std::uint64_t>::max());
  EXPECT_EQ(vsd::Value(std::numeric_limits<std::int64_t>::min())
                .convert_to(vsd::meta_type<std::int64_t>())
                .as<std::int64_t>(),
            std::numeric_limits<std::int64_t>::min());
  EXPECT_EQ(vsd::Value(std::int64_t{std::numeric_limits<std::uint32_t>::max()})
                .convert_to(vsd::meta_type<std::uint32_t>())
                .as<std::uint32_t>(),
            std::numeric_limits<std::uint32_t>::max());
}

TEST(Value, ConvertFractionToIntegerThrows) {
  const std::string e = error_of([] { (void)vsd::Value(3.5).convert_to(vsd::meta_type<std::int32_t>()); });
  EXPECT_THAT(e, HasSubstr("int32"));
  EXPECT_THAT(e, HasSubstr("3.5"));
  EXPECT_THROW(
      (void)vsd::Value(std::numeric_limits<double>::quiet_NaN()).convert_to(vsd::meta_type<std::int32_t>()),
      vsd::Error);
  EXPECT_THROW(
      (void)vsd::Value(std::numeric_limits<double>::infinity()).convert_to(vsd::meta_type<std::int64_t>()),
      vsd::Error);
  EXPECT_THROW((void)vsd::Value(9223372036854775808.0).convert_to(vsd::meta_type<std::int64_t>()),
               vsd::Error);
}

TEST(Value, ConvertOutOfRangeIntegerThrows) {
  const std::string e = error_of([] { (void)vsd::Value(300).convert_to(vsd::meta_type<std::uint8_t>()); });
  EXPECT_THAT(e, HasSubstr("uint8"));
  EXPECT_THAT(e, HasSubstr("300"));
  EXPECT_THROW((void)vsd::Value(-1).convert_to(vsd::meta_type<std::uint32_t>()), vsd::Error);
  EXPECT_THROW((void)vsd::Value(128).convert_to(vsd::meta_type<std::int8_t>()), vsd::Error);
  EXPECT_THROW(
      (void)vsd::Value(std::numeric_limits<std::uint64_t>::max()).convert_to(vsd::meta_type<std::int64_t>()),
      vsd::Error);
  EXPECT_THROW(
      (void)vsd::Value(std::numeric_limits<std::int64_t>::min()).convert_to(vsd::meta_type<std::uint64_t>()),
      vsd::Error);
}

TEST(Value, ConvertInexactNumberThrows) {
  // "numbers convert when the number is representable": 2^53 + 1 has no double.
  const std::int64_t odd = (std::int64_t{1} << 53) + 1;
  EXPECT_THROW((void)vsd::Value(odd).convert_to(vsd::meta_type<double>()), vsd::Error);
  // 1e300 has no float (converting it is undefined behaviour in C++, and must not become inf).
  EXPECT_THROW((void)vsd::Value(1e300).convert_to(vsd::meta_type<float>()), vsd::Error);
}

TEST(Value, ConvertNonNumbersThrows) {
  const std::string e =
      error_of([] { (void)vsd::Value(std::string("1.5")).convert_to(vsd::meta_type<double>()); });
  EXPECT_THAT(e, HasSubstr("double"));
  EXPECT_THAT(e, HasSubstr("string"));
  EXPECT_THROW((void)vsd::Value(1.5).convert_to(vsd::meta_type<std::string>()), vsd::Error);
  EXPECT_THROW((void)vsd::Value(true).convert_to(vsd::meta_type<std::int32_t>()), vsd::Error);
  EXPECT_THROW((void)vsd::Value(std::vector<double>{1}).convert_to(vsd::meta_type<double>()), vsd::Error);
  const std::string empty = error_of([] { (void)vsd::Value().convert_to(vsd::meta_type<double>()); });
  EXPECT_THAT(empty, HasSubstr("double"));
}

TEST(Value, ConvertToTheSameTypeCopies) {
  const vsd::Value v(std::string("abc"));
  const vsd::Value c = v.convert_to(vsd::meta_type<std::string>());
  EXPECT_EQ(c.as<std::string>(), "abc");
  EXPECT_NE(c.data(), v.data());
}

TEST(Value, Equality) {
  EXPECT_TRUE(vsd::Value(1.5) == vsd::Value(1.5));
  EXPECT_FALSE(vsd::Value(1.5) == vsd::Value(2.5));
  EXPECT_FALSE(vsd::Value(1) == vsd::Value(1.0)) << "different types are never equal";
  EXPECT_FALSE(vsd::Value(std::int32_t{1}) == vsd::Value(std::int64_t{1}));
  EXPECT_TRUE(vsd::Value() == vsd::Value());
  EXPECT_FALSE(vsd::Value() == vsd::Value(0));
  EXPECT_FALSE(vsd::Value(0) == vsd::Value());
  EXPECT_TRUE(vsd::Value(std::string("a")) == vsd::Value("a"));
  EXPECT_TRUE(vsd::Value(std::vector<double>{1, 2}) == vsd::Value(std::vector<double>{1, 2}));
  EXPECT_FALSE(vsd::Value(std::vector<double>{1, 2}) == vsd::Value(std::vector<double>{1, 3}));
  EXPECT_TRUE(vsd::Value(sample_frame()) == vsd::Value(sample_frame()));
  EXPECT_TRUE(vsd::Value(std::numeric_limits<double>::quiet_NaN()) ==
              vsd::Value(std::numeric_limits<double>::quiet_NaN()));
  EXPECT_TRUE(vsd::Value(0.0) == vsd::Value(-0.0));
  EXPECT_TRUE(vsd::Value(1.5) != vsd::Value(2.5));
}

TEST(Value, ToText) {
  EXPECT_EQ(vsd::Value(2.5).to_text(), "2.5");
  EXPECT_EQ(vsd::Value(-7).to_text(), "-7");
  EXPECT_EQ(vsd::Value(true).to_text(), "true");
  EXPECT_EQ(vsd::Value("a\"b").to_text(), R"("a\"b")");
  EXPECT_EQ(vsd::Value(std::vector<std::int32_t>{1, 2}).to_text(), "[1, 2]");
  EXPECT_EQ(vsd::Value(Eigen::Vector3d(1, 2, 3)).to_text(), "[1, 2, 3]");
  EXPECT_EQ(vsd::Value(std::numeric_limits<double>::infinity()).to_text(), R"("inf")");
}

TEST(Value, FromText) {
  const vsd::Value d = vsd::Value::from_text(vsd::meta_type<double>(), " 2.5 ");
  EXPECT_EQ(d.as<double>(), 2.5);
  const vsd::Value v = vsd::Value::from_text(vsd::meta_type<std::vector<std::int32_t>>(), "[1, 2]");
  EXPECT_EQ(v.as<std::vector<std::int32_t>>(), (std::vector<std::int32_t>{1, 2}));
  const vsd::Value f =
      vsd::Value::from_text(vsd::meta_type<Eigen::Isometry3d>(), R"({"translation": [1, 2, 3]})");
  EXPECT_EQ(f.as<Eigen::Isometry3d>().translation(), Eigen::Vector3d(1, 2, 3));
  const vsd::Value old =
      vsd::Value::from_text(vsd::meta_type<Eigen::Isometry3d>(), "{translation: [1, 2, 3]}");
  EXPECT_TRUE(old == f) << "the older form with bare keys reads too";
  for (const vsd::Value& x : {vsd::Value(2.5), vsd::Value(std::string("q\"\n")), vsd::Value(sample_frame()),
                              vsd::Value(std::vector<std::string>{"a", "b"}), vsd::Value(std::int8_t{-5})}) {
    const vsd::Value back = vsd::Value::from_text(*x.type(), x.to_text());
    EXPECT_TRUE(back.type() == x.type());
    EXPECT_TRUE(back == x) << x.to_text();  // exactly, frames too
  }
}

TEST(Value, FromTextErrorNamesThePosition) {
  const std::string e =
      error_of([] { (void)vsd::Value::from_text(vsd::meta_type<std::vector<double>>(), "[1, 2, oops]"); });
  EXPECT_THAT(e, testing::StartsWith("<vector<double> value>:1:8: "));
  EXPECT_THAT(e, HasSubstr("oops"));
}

TEST(Value, FromTextErrorNamesTheOriginItIsGiven) {
  const std::string e = error_of(
      [] { (void)vsd::Value::from_text(vsd::meta_type<double>(), "\n 1.5x", nullptr, "cell.ini: speed"); });
  EXPECT_THAT(e, testing::StartsWith("cell.ini: speed:2:2: '1.5x' is not a number"));
  vsd::Value v(vsd::meta_type<double>());
  EXPECT_THAT(error_of([&] { vsd::meta_type<double>().from_text(v.data(), "true", nullptr, "arg 1"); }),
              testing::StartsWith("arg 1:1:1: "));
}

}  // namespace
