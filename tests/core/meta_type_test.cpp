// Tests of vsd/core/meta_type.hpp, meta_type_eigen.hpp, text.hpp and bytes.hpp: the MetaTypes of built-in
// and user types, their text and binary forms, equality and hashing, and the errors on bad input.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <string>
#include <string_view>
#include <vector>
#include <vsd/vsd.hpp>

#include "memory_cap.hpp"

namespace mt {

enum class MtColor { Red, Green = 5, Blue = -3 };
VSD_ENUM(MtColor, Red, Green, Blue)

enum class MtLevel : std::uint8_t { Low = 1, High = 200 };
VSD_ENUM(MtLevel, Low, High)

enum class MtAccess : std::uint32_t { Read = 1, Write = 2, Exec = 4 };
VSD_FLAGS(MtAccess, Read, Write, Exec)
constexpr MtAccess operator|(MtAccess a, MtAccess b) {
  return static_cast<MtAccess>(static_cast<std::uint32_t>(a) | static_cast<std::uint32_t>(b));
}

enum class MtWide : std::uint64_t { Low = 1 };  // flags of 64 bits
VSD_FLAGS(MtWide, Low)

struct MtPose {
  double x = 0;
  double y = 0;
  double theta = 0;
};
VSD_STRUCT(MtPose, x, y, theta)

struct MtPart {
  std::string name;
  MtPose pose;
  std::vector<Eigen::Vector3d> points;
  MtColor color = MtColor::Red;
  bool active = false;
  std::vector<MtPose> waypoints;
};
VSD_STRUCT(MtPart, name, pose, points, color, active, waypoints)

}  // namespace mt

namespace {

using mt::MtAccess;
using mt::MtColor;
using mt::MtLevel;
using mt::MtPart;
using mt::MtPose;
using mt::MtWide;
using testing::HasSubstr;
using testing::MatchesRegex;
using testing::StartsWith;

// ---- helpers ----------------------------------------------------------------------------------------------

template <class T>
std::string text_of(const T& v) {
  return vsd::meta_type<T>().to_text(&v);
}

template <class T>
T parse(std::string_view text) {
  return vsd::Value::from_text(vsd::meta_type<T>(), text).template as<T>();
}

template <class T>
std::vector<std::uint8_t> bytes_of(const T& v) {
  std::vector<std::uint8_t> out;
  vsd::ByteWriter w(out);
  vsd::meta_type<T>().write_bytes(&v, w);
  return out;
}

template <class T>
T read_back(const std::vector<std::uint8_t>& bytes) {
  vsd::Value v(vsd::meta_type<T>());
  vsd::ByteReader r(bytes.data(), bytes.size());
  vsd::meta_type<T>().read_bytes(v.data(), r);
  EXPECT_TRUE(r.at_end()) << r.remaining() << " bytes left unread";
  return v.as<T>();
}

template <class T>
T binary_round_trip(const T& v) {
  return read_back<T>(bytes_of(v));
}

// The message of the vsd::Error that parsing @p text as @p type throws ("<no error>" when none is thrown),
// after the origin every such message starts with ("<TYPE value>:"), which it checks and strips.
std::string text_error(const vsd::MetaType& type, std::string_view text) {
  try {
    (void)vsd::Value::from_text(type, text);
  } catch (const vsd::Error& e) {
    const std::string msg = e.what(), origin = "<" + type.name() + " value>:";
    return msg.rfind(origin, 0) == 0 ? msg.substr(origin.size()) : "no origin in: " + msg;
  }
  return "<no error>";
}

template <class T>
std::string bytes_error(const std::vector<std::uint8_t>& bytes) {
  try {
    vsd::Value v(vsd::meta_type<T>());
    vsd::ByteReader r(bytes.data(), bytes.size());
    vsd::meta_type<T>().read_bytes(v.data(), r);
  } catch (const vsd::Error& e) {
    return e.what();
  }
  return "<no error>";
}

template <class T>
std::size_t hash_of(const T& v) {
  return vsd::meta_type<T>().hash(&v);
}
template <class T>
bool equal(const T& a, const T& b) {
  return vsd::meta_type<T>().equal(&a, &b);
}

Eigen::Isometry3d make_frame(const Eigen::Vector3d& t, double angle, const Eigen::Vector3d& axis) {
  Eigen::Isometry3d f = Eigen::Isometry3d::Identity();
  f.translation() = t;
  f.linear() = Eigen::AngleAxisd(angle, axis.normalized()).toRotationMatrix();
  return f;
}

constexpr double nan = std::numeric_limits<double>::quiet_NaN();
constexpr double inf = std::numeric_limits<double>::infinity();

// ---- names and kinds --------------------------------------------------------------------------------------

TEST(MetaType, NamesAndKindsOfBuiltInTypes) {
  struct Expect {
    const vsd::MetaType* type;
    const char* name;
    vsd::TypeKind kind;
    std::size_t size;
  };
  const Expect cases[] = {
      {&vsd::meta_type<bool>(), "bool", vsd::TypeKind::Bool, 1},
      {&vsd::meta_type<std::int8_t>(), "int8", vsd::TypeKind::Int, 1},
      {&vsd::meta_type<std::int16_t>(), "int16", vsd::TypeKind::Int, 2},
      {&vsd::meta_type<std::int32_t>(), "int32", vsd::TypeKind::Int, 4},
      {&vsd::meta_type<std::int64_t>(), "int64", vsd::TypeKind::Int, 8},
      {&vsd::meta_type<std::uint8_t>(), "uint8", vsd::TypeKind::UInt, 1},
      {&vsd::meta_type<std::uint16_t>(), "uint16", vsd::TypeKind::UInt, 2},
      {&vsd::meta_type<std::uint32_t>(), "uint32", vsd::TypeKind::UInt, 4},
      {&vsd::meta_type<std::uint64_t>(), "uint64", vsd::TypeKind::UInt, 8},
      {&vsd::meta_type<float>(), "float", vsd::TypeKind::Float, sizeof(float)},
      {&vsd::meta_type<double>(), "double", vsd::TypeKind::Double, sizeof(double)},
      {&vsd::meta_type<std::string>(), "string", vsd::TypeKind::String, sizeof(std::string)},
      {&vsd::meta_type<Eigen::Vector2d>(), "Vector2d", vsd::TypeKind::Struct, sizeof(Eigen::Vector2d)},
      {&vsd::meta_type<Eigen::Vector3d>(), "Vector3d", vsd::TypeKind::Struct, sizeof(Eigen::Vector3d)},
      {&vsd::meta_type<Eigen::Vector4d>(), "Vector4d", vsd::TypeKind::Struct, sizeof(Eigen::Vector4d)},
      {&vsd::meta_type<Eigen::Quaterniond>(), "Quaterniond", vsd::TypeKind::Struct,
       sizeof(Eigen::Quaterniond)},
      {&vsd::meta_type<Eigen::Isometry3d>(), "Isometry3d", vsd::TypeKind::Struct, sizeof(Eigen::Isometry3d)},
      {&vsd::meta_type<std::vector<double>>(), "vector<double>", vsd::TypeKind::Vector,
       sizeof(std::vector<double>)},
      {&vsd::meta_type<std::vector<std::string>>(), "vector<string>", vsd::TypeKind::Vector,
       sizeof(std::vector<std::string>)},
      {&vsd::meta_type<std::vector<std::vector<std::int32_t>>>(), "vector<vector<int32>>",
       vsd::TypeKind::Vector, sizeof(std::vector<std::vector<std::int32_t>>)},
      {&vsd::meta_type<std::vector<Eigen::Vector3d>>(), "vector<Vector3d>", vsd::TypeKind::Vector,
       sizeof(std::vector<Eigen::Vector3d>)},
  };
  for (const auto& c : cases) {
    SCOPED_TRACE(c.name);
    EXPECT_EQ(c.type->name(), c.name);
    EXPECT_EQ(c.type->kind(), c.kind);
    EXPECT_EQ(c.type->size(), c.size);
    EXPECT_FALSE(c.type->is_reference());
  }
}

TEST(MetaType, OneMetaTypePerCppType) {
  EXPECT_EQ(&vsd::meta_type<double>(), &vsd::meta_type<double>());
  EXPECT_NE(&vsd::meta_type<double>(), &vsd::meta_type<float>());
  EXPECT_EQ(vsd::meta_type<std::vector<double>>().element(), &vsd::meta_type<double>());
  EXPECT_EQ(vsd::meta_type<std::vector<std::vector<double>>>().element(),
            &vsd::meta_type<std::vector<double>>());
}

TEST(MetaType, ArithmeticClassification) {
  EXPECT_FALSE(vsd::meta_type<bool>().is_arithmetic());
  EXPECT_TRUE(vsd::meta_type<std::int8_t>().is_arithmetic());
  EXPECT_TRUE(vsd::meta_type<std::uint64_t>().is_arithmetic());
  EXPECT_TRUE(vsd::meta_type<float>().is_arithmetic());
  EXPECT_TRUE(vsd::meta_type<double>().is_arithmetic());
  EXPECT_FALSE(vsd::meta_type<std::string>().is_arithmetic());
  EXPECT_FALSE(vsd::meta_type<MtColor>().is_arithmetic());
  EXPECT_FALSE(vsd::meta_type<Eigen::Vector3d>().is_arithmetic());
}

TEST(MetaType, EigenTypesDescribeTheirFields) {
  const auto& v3 = vsd::meta_type<Eigen::Vector3d>();
  ASSERT_EQ(v3.fields().size(), 3u);
  EXPECT_EQ(v3.fields()[0].name, "x");
  EXPECT_EQ(v3.fields()[2].name, "z");
  const auto& q = vsd::meta_type<Eigen::Quaterniond>();
  ASSERT_EQ(q.fields().size(), 4u);
  EXPECT_EQ(q.fields()[0].name, "w");
  const auto& f = vsd::meta_type<Eigen::Isometry3d>();
  ASSERT_EQ(f.fields().size(), 2u);
  EXPECT_EQ(f.fields()[0].name, "translation");
  EXPECT_EQ(f.fields()[0].type, &v3);
  EXPECT_EQ(f.fields()[1].name, "rotation");
  EXPECT_EQ(f.fields()[1].type, &q);
}

TEST(MetaType, DefaultValues) {
  EXPECT_EQ(vsd::Value(vsd::meta_type<double>()).as<double>(), 0.0);
  EXPECT_EQ(vsd::Value(vsd::meta_type<std::string>()).as<std::string>(), "");
  EXPECT_TRUE(vsd::Value(vsd::meta_type<Eigen::Vector3d>()).as<Eigen::Vector3d>().isZero(0));
  EXPECT_TRUE(vsd::Value(vsd::meta_type<Eigen::Quaterniond>())
                  .as<Eigen::Quaterniond>()
                  .coeffs()
                  .isApprox(Eigen::Quaterniond::Identity().coeffs(), 0));
  EXPECT_TRUE(vsd::Value(vsd::meta_type<Eigen::Isometry3d>())
                  .as<Eigen::Isometry3d>()
                  .isApprox(Eigen::Isometry3d::Identity(), 0));
}

// ---- text round trips -------------------------------------------------------------------------------------

TEST(MetaTypeText, Bool) {
  EXPECT_EQ(text_of(true), "true");
  EXPECT_EQ(text_of(false), "false");
  EXPECT_TRUE(parse<bool>("true"));
  EXPECT_FALSE(parse<bool>("  false  "));
}

TEST(MetaTypeText, IntegersAtTheirLimits) {
  EXPECT_EQ(text_of(std::int8_t{-128}), "-128");
  EXPECT_EQ(text_of(std::int8_t{127}), "127");
  EXPECT_EQ(text_of(std::uint8_t{255}), "255");
  EXPECT_EQ(text_of(std::numeric_limits<std::int64_t>::min()), "-9223372036854775808");
  EXPECT_EQ(text_of(std::numeric_limits<std::uint64_t>::max()), "18446744073709551615");

  EXPECT_EQ(parse<std::int8_t>("-128"), -128);
  EXPECT_EQ(parse<std::int8_t>("127"), 127);
  EXPECT_EQ(parse<std::uint8_t>("255"), 255);
  EXPECT_EQ(parse<std::int16_t>("-32768"), -32768);
  EXPECT_EQ(parse<std::uint16_t>("65535"), 65535);
  EXPECT_EQ(parse<std::int32_t>("+42"), 42);
  EXPECT_EQ(parse<std::uint32_t>("4294967295"), 4294967295U);
  EXPECT_EQ(parse<std::int64_t>("-9223372036854775808"), std::numeric_limits<std::int64_t>::min());
  EXPECT_EQ(parse<std::uint64_t>("18446744073709551615"), std::numeric_limits<std::uint64_t>::max());
}

TEST(MetaTypeText, DoublesUseTheShortestRoundTrip) {
  EXPECT_EQ(text_of(0.1), "0.1");
  EXPECT_EQ(text_of(1.0), "1");
  EXPECT_EQ(text_of(-2.5), "-2.5");
  EXPECT_EQ(text_of(1e300), "1e+300");
  EXPECT_EQ(parse<double>("0.1"), 0.1);
  EXPECT_EQ(parse<double>("3"), 3.0);
  EXPECT_EQ(parse<double>("-1.5e-3"), -1.5e-3);
  for (const double v : {0.1, 1.0 / 3.0, 2.0 / 3.0, 1e-300, 5e-324, 1.7976931348623157e308, -123456.789,
                         std::nextafter(1.0, 2.0), 6.02214076e23}) {
    SCOPED_TRACE(v);
    const std::string t = text_of(v);
    EXPECT_EQ(parse<double>(t), v) << t;
    EXPECT_LE(t.size(), 24u) << "shortest form expected, got " << t;
  }
}

TEST(MetaTypeText, DoubleSpecialValues) {
  // JSON has no NaN or infinity: they are written as strings.
  EXPECT_EQ(text_of(nan), R"("nan")");
  EXPECT_EQ(text_of(inf), R"("inf")");
  EXPECT_EQ(text_of(-inf), R"("-inf")");
  EXPECT_EQ(text_of(-nan), R"("nan")");
  EXPECT_TRUE(std::isnan(parse<double>(R"("nan")")));
  EXPECT_EQ(parse<double>(R"("inf")"), inf);
  EXPECT_EQ(parse<double>(R"("-inf")"), -inf);
  // The older bare forms.
  EXPECT_TRUE(std::isnan(parse<double>("nan")));
  EXPECT_EQ(parse<double>("inf"), inf);
  EXPECT_EQ(parse<double>("+inf"), inf);
  EXPECT_EQ(parse<double>("-inf"), -inf);

  const double neg_zero = parse<double>(text_of(-0.0));
  EXPECT_EQ(neg_zero, 0.0);
  EXPECT_TRUE(std::signbit(neg_zero)) << "-0.0 keeps its sign through text: " << text_of(-0.0);
  EXPECT_FALSE(std::signbit(parse<double>(text_of(0.0))));
}

TEST(MetaTypeText, FloatRoundTrip) {
  for (const float v : {0.1f, 1.0f / 3.0f, -2.5f, 3.4028235e38f, 1e-45f}) {
    SCOPED_TRACE(v);
    EXPECT_EQ(parse<float>(text_of(v)), v);
  }
}

TEST(MetaTypeText, SpecialValuesRoundTrip) {
  constexpr float finf = std::numeric_limits<float>::infinity();
  EXPECT_EQ(text_of(std::numeric_limits<float>::quiet_NaN()), R"("nan")");
  EXPECT_EQ(text_of(-finf), R"("-inf")");
  for (const float v : {finf, -finf}) EXPECT_EQ(parse<float>(text_of(v)), v);
  EXPECT_TRUE(std::isnan(parse<float>(text_of(std::numeric_limits<float>::quiet_NaN()))));
  EXPECT_TRUE(std::isnan(parse<float>("nan")));
  for (const double v : {inf, -inf}) EXPECT_EQ(parse<double>(text_of(v)), v);
  EXPECT_TRUE(std::isnan(parse<double>(text_of(nan))));

  // In containers and structs too: the text stays JSON and reads back.
  const std::vector<double> specials{nan, inf, -inf, 1.5};
  EXPECT_EQ(text_of(specials), R"(["nan", "inf", "-inf", 1.5])");
  EXPECT_TRUE(equal(parse<std::vector<double>>(text_of(specials)), specials));
  EXPECT_TRUE(equal(parse<std::vector<double>>("[nan, inf, -inf, 1.5]"), specials));
  const MtPose pose{nan, -inf, 0};
  EXPECT_EQ(text_of(pose), R"(["nan", "-inf", 0])");
  EXPECT_TRUE(equal(parse<MtPose>(text_of(pose)), pose));

  // A string that is not one of the specials is no number; the error points at the string.
  EXPECT_THAT(text_error(vsd::meta_type<double>(), R"("infinite")"), StartsWith("1:1: "));
  const std::string e = text_error(vsd::meta_type<std::vector<double>>(), R"([1, "infinite"])");
  EXPECT_THAT(e, StartsWith("1:5: expected a number"));
  EXPECT_THAT(e, HasSubstr("\"infinite\""));
  EXPECT_THAT(text_error(vsd::meta_type<std::int32_t>(), R"("inf")"), StartsWith("1:1: expected a number"));
}

TEST(MetaTypeText, FloatTextIsShortestForTheFloat) {
  // 0.1f is 0.100000001490116119384765625: the shortest text that reads back as that float is "0.1".
  EXPECT_EQ(text_of(0.1f), "0.1");
  EXPECT_EQ(text_of(1.0f / 3.0f), "0.33333334");
}

TEST(MetaTypeText, StringsWithQuotesEscapesAndNewlines) {
  const std::string samples[] = {
      "",
      "plain",
      "he said \"hi\"",
      "back\\slash",
      "line one\nline two\r\n",
      "tab\there",
      std::string("nul\0inside", 10),
      "\x01\x02\x1f control",
      "utf-8: \xc3\xa4\xe2\x82\xac",
      "/ slash and 'single' quotes",
  };
  for (const auto& s : samples) {
    SCOPED_TRACE(s);
    const std::string t = text_of(s);
    EXPECT_EQ(t.front(), '"');
    EXPECT_EQ(t.back(), '"');
    EXPECT_EQ(t.find('\n'), std::string::npos) << "newlines are escaped: " << t;
    EXPECT_EQ(parse<std::string>(t), s);
  }
  EXPECT_EQ(text_of(std::string("a\"b\\c\nd")), R"("a\"b\\c\nd")");
}

TEST(MetaTypeText, StringEscapesOnInput) {
  EXPECT_EQ(parse<std::string>(R"("\"\\\/\n\t\r\b\f")"), "\"\\/\n\t\r\b\f");
  EXPECT_EQ(parse<std::string>(R"("\u0041\u00e4\u20ac")"), "A\xc3\xa4\xe2\x82\xac");
  EXPECT_EQ(parse<std::string>(R"("\u0000")"), std::string(1, '\0'));
  EXPECT_EQ(parse<std::string>(R"("\uFFFF\uD7FF\uE000")"), "\xef\xbf\xbf\xed\x9f\xbf\xee\x80\x80");
}

TEST(MetaTypeText, SurrogatePairsAreOneCharacter) {
  // U+1F600 is the pair D83D DE00 in JSON; in UTF-8 it is the four bytes F0 9F 98 80.
  EXPECT_EQ(parse<std::string>(R"("\uD83D\uDE00")"), "\xf0\x9f\x98\x80");
  EXPECT_EQ(parse<std::string>(R"("a\ud83d\ude00b")"), std::string("a\xf0\x9f\x98\x80") + "b");
  EXPECT_EQ(parse<std::string>(R"("\uD800\uDC00")"), "\xf0\x90\x80\x80");  // U+10000, the first
  EXPECT_EQ(parse<std::string>(R"("\uDBFF\uDFFF")"), "\xf4\x8f\xbf\xbf");  // U+10FFFF, the last
  // Characters beyond the BMP are written as their UTF-8 bytes and read back unchanged.
  const std::string smile = "\xf0\x9f\x98\x80";
  EXPECT_EQ(text_of(smile), "\"" + smile + "\"");
  EXPECT_EQ(parse<std::string>(text_of(smile)), smile);
}

TEST(MetaTypeTextErrors, LoneSurrogates) {
  // Each error names the line and column of the backslash of the offending escape.
  const std::string high = text_error(vsd::meta_type<std::string>(), R"("ab\uD83Dcd")");
  EXPECT_THAT(high, StartsWith("1:4: "));
  EXPECT_THAT(high, HasSubstr("surrogate"));
  const std::string low = text_error(vsd::meta_type<std::string>(), R"("\uDE00")");
  EXPECT_THAT(low, StartsWith("1:2: "));
  EXPECT_THAT(low, HasSubstr("surrogate"));
  const std::string at_end = text_error(vsd::meta_type<std::string>(), R"("\uD83D")");
  EXPECT_THAT(at_end, StartsWith("1:2: "));
  EXPECT_THAT(at_end, HasSubstr("surrogate"));
  const std::string two_high = text_error(vsd::meta_type<std::string>(), R"("\uD83D\uD83D")");
  EXPECT_THAT(two_high, StartsWith("1:2: "));
  EXPECT_THAT(two_high, HasSubstr("surrogate"));
  const std::string later_line =
      text_error(vsd::meta_type<std::vector<std::string>>(), "[\"ok\",\n  \"x\\uDC00\"]");
  EXPECT_THAT(later_line, StartsWith("2:5: "));
  EXPECT_THAT(later_line, HasSubstr("surrogate"));
  EXPECT_THAT(text_error(vsd::meta_type<std::string>(), R"("\uD83D\u12")"), HasSubstr("\\u"));
  EXPECT_THAT(text_error(vsd::meta_type<std::string>(), R"("\uD83D\uZZZZ")"), HasSubstr("\\u"));
}

TEST(MetaTypeText, EigenVectorsAndQuaternions) {
  EXPECT_EQ(text_of(Eigen::Vector2d(1.5, -2)), "[1.5, -2]");
  EXPECT_EQ(text_of(Eigen::Vector3d(1, 2, 3)), "[1, 2, 3]");
  EXPECT_EQ(text_of(Eigen::Vector4d(1, 2, 3, 4)), "[1, 2, 3, 4]");
  EXPECT_EQ(text_of(Eigen::Quaterniond::Identity()), "[1, 0, 0, 0]");  // w first

  EXPECT_EQ(parse<Eigen::Vector3d>("[1, 2, 3]"), Eigen::Vector3d(1, 2, 3));
  EXPECT_EQ(parse<Eigen::Vector3d>("{x: 1, y: 2, z: 3}"), Eigen::Vector3d(1, 2, 3));
  EXPECT_EQ(parse<Eigen::Vector3d>("{z: 5}"), Eigen::Vector3d(0, 0, 5));
  EXPECT_EQ(parse<Eigen::Vector2d>(text_of(Eigen::Vector2d(0.1, 1e-9))), Eigen::Vector2d(0.1, 1e-9));
  EXPECT_EQ(parse<Eigen::Vector4d>("[0.5,0.25,\n0.125, -1]"), Eigen::Vector4d(0.5, 0.25, 0.125, -1));
  const Eigen::Quaterniond q = parse<Eigen::Quaterniond>("[0.5, 0.5, 0.5, 0.5]");
  EXPECT_EQ(q.w(), 0.5);
  EXPECT_EQ(q.x(), 0.5);
  EXPECT_EQ(q.z(), 0.5);
}

TEST(MetaTypeText, EigenFrames) {
  // A frame's text is its exact matrix: the translation and the rotation's rows.
  EXPECT_EQ(text_of(Eigen::Isometry3d(Eigen::Isometry3d::Identity())),
            R"({"translation": [0, 0, 0], "rotation": [[1, 0, 0], [0, 1, 0], [0, 0, 1]]})");

  const std::string exact =
      R"({"translation": [0.1, -2.5, 1e-300], "rotation": [[0, -1, 0], [1, 0, 0], [0, 0, 1]]})";
  EXPECT_EQ(text_of(parse<Eigen::Isometry3d>(exact)), exact);

  const Eigen::Isometry3d f = make_frame({1, 2, 3}, 0.7, {1, -2, 0.5});
  const Eigen::Isometry3d back = parse<Eigen::Isometry3d>(text_of(f));
  EXPECT_TRUE(equal(back, f)) << text_of(f) << " read back as " << text_of(back);
  EXPECT_EQ(back.matrix(), f.matrix());

  // Only the translation given: the rotation keeps its default (identity).
  const Eigen::Isometry3d t = parse<Eigen::Isometry3d>(R"({"translation": [4, 5, 6]})");
  EXPECT_EQ(t.translation(), Eigen::Vector3d(4, 5, 6));
  EXPECT_TRUE(t.linear().isIdentity(0));
  EXPECT_EQ(t.matrix().row(3), Eigen::RowVector4d(0, 0, 0, 1));
  // Rows are taken exactly, without normalising, so even a damaged matrix round-trips.
  const Eigen::Isometry3d scaled =
      parse<Eigen::Isometry3d>(R"({"rotation": [[2, 0, 0], [0, 2, 0], [0, 0, 2]]})");
  EXPECT_EQ(scaled.linear(), (2 * Eigen::Matrix3d::Identity()).eval());
  EXPECT_EQ(text_of(scaled), R"({"translation": [0, 0, 0], "rotation": [[2, 0, 0], [0, 2, 0], [0, 0, 2]]})");
}

TEST(MetaTypeText, EigenFrameRotationAsQuaternion) {
  // The older text gave the rotation as a quaternion [w, x, y, z]; it is read and normalised.
  const Eigen::Isometry3d n = parse<Eigen::Isometry3d>("{translation: [0, 0, 0], rotation: [2, 0, 0, 0]}");
  EXPECT_TRUE(n.linear().isIdentity(1e-15));
  const Eigen::Isometry3d z90 = parse<Eigen::Isometry3d>("{rotation: [1, 0, 0, 1]}");
  EXPECT_TRUE((z90.linear() * Eigen::Vector3d::UnitX()).isApprox(Eigen::Vector3d::UnitY(), 1e-15));
  const Eigen::Isometry3d quoted =
      parse<Eigen::Isometry3d>(R"({"translation": [1, 2, 3], "rotation": [1, 0, 0, 1]})");
  EXPECT_EQ(quoted.translation(), Eigen::Vector3d(1, 2, 3));
  EXPECT_TRUE(quoted.linear().isApprox(z90.linear(), 0));
  // As an object of w, x, y, z, quoted or bare keys; missing parts keep the current rotation's.
  const Eigen::Isometry3d named =
      parse<Eigen::Isometry3d>(R"({"rotation": {"w": 1, "x": 0, "y": 0, "z": 1}})");
  EXPECT_TRUE(named.linear().isApprox(z90.linear(), 0));
  const Eigen::Isometry3d bare = parse<Eigen::Isometry3d>("{rotation: {w: 1, z: 1}}");
  EXPECT_TRUE(bare.linear().isApprox(z90.linear(), 0));
  // The quaternion form of a rotation reads back close to the matrix.
  const Eigen::Isometry3d f = make_frame({1, 2, 3}, 0.7, {1, -2, 0.5});
  const Eigen::Quaterniond q(f.linear());
  const std::string old_text =
      "{translation: " + text_of(Eigen::Vector3d(f.translation())) + ", rotation: " + text_of(q) + "}";
  const Eigen::Isometry3d back = parse<Eigen::Isometry3d>(old_text);
  EXPECT_TRUE(back.isApprox(f, 1e-14)) << old_text;
  // The positional struct form [translation, rotation] still reads.
  const Eigen::Isometry3d positional = parse<Eigen::Isometry3d>("[[1, 2, 3], [1, 0, 0, 1]]");
  EXPECT_EQ(positional.translation(), Eigen::Vector3d(1, 2, 3));
  EXPECT_TRUE(positional.linear().isApprox(z90.linear(), 0));
  // The generic field API still sees the rotation as a quaternion.
  const auto& type = vsd::meta_type<Eigen::Isometry3d>();
  ASSERT_EQ(type.fields().size(), 2u);
  EXPECT_EQ(type.fields()[1].type, &vsd::meta_type<Eigen::Quaterniond>());
}

TEST(MetaTypeText, EigenFramesRoundTripExactly) {
  // Text carries the exact matrix: random rotations and translations come back bit for bit.
  std::srand(12345);
  for (int i = 0; i < 1000; ++i) {
    const Eigen::Vector3d axis = Eigen::Vector3d::Random();
    const double angle = Eigen::Vector2d::Random()[0] * 3.5;
    Eigen::Isometry3d f = Eigen::Isometry3d::Identity();
    f.translation() = Eigen::Vector3d::Random() * std::pow(10.0, i % 13 - 6);
    f.linear() = Eigen::AngleAxisd(angle, axis.norm() > 0 ? axis.normalized() : Eigen::Vector3d::UnitZ())
                     .toRotationMatrix();
    const std::string text = text_of(f);
    const Eigen::Isometry3d back = parse<Eigen::Isometry3d>(text);
    ASSERT_EQ(std::memcmp(back.matrix().data(), f.matrix().data(), sizeof(double) * 16), 0) << text;
    ASSERT_TRUE(equal(back, f)) << text;
    ASSERT_EQ(text_of(back), text);
  }
  // Negative zeros and the specials keep their bits too.
  Eigen::Isometry3d odd = Eigen::Isometry3d::Identity();
  odd.translation() = Eigen::Vector3d(-0.0, inf, -inf);
  odd.linear()(0, 1) = -0.0;
  odd.linear()(2, 2) = nan;
  const Eigen::Isometry3d back = parse<Eigen::Isometry3d>(text_of(odd));
  EXPECT_TRUE(equal(back, odd)) << text_of(odd);
  EXPECT_TRUE(std::signbit(back.translation().x()));
  EXPECT_TRUE(std::signbit(back.linear()(0, 1)));
  EXPECT_EQ(text_of(back), text_of(odd));
}

TEST(MetaTypeTextErrors, BadFrames) {
  const auto& t = vsd::meta_type<Eigen::Isometry3d>();
  const std::string two_rows = text_error(t, R"({"rotation": [[1, 0, 0], [0, 1, 0]]})");
  EXPECT_THAT(two_rows, StartsWith("1:35: "));
  EXPECT_THAT(two_rows, HasSubstr("3 rows of 3 numbers"));
  const std::string short_row = text_error(t, R"({"rotation": [[1, 0], [0, 1, 0], [0, 0, 1]]})");
  EXPECT_THAT(short_row, StartsWith("1:20: "));
  EXPECT_THAT(short_row, HasSubstr("3 rows of 3 numbers"));
  const std::string long_row = text_error(t, R"({"rotation": [[1, 0, 0, 0], [0, 1, 0], [0, 0, 1]]})");
  EXPECT_THAT(long_row, StartsWith("1:23: "));
  const std::string four_rows =
      text_error(t, "{\"rotation\": [[1, 0, 0], [0, 1, 0], [0, 0, 1],\n [0, 0, 0]]}");
  EXPECT_THAT(four_rows, StartsWith("1:46: "));
  const std::string not_a_number = text_error(t, R"({"rotation": [[1, 0, 0], [0, x, 0], [0, 0, 1]]})");
  EXPECT_THAT(not_a_number, StartsWith("1:30: "));
  const std::string unknown = text_error(t, R"({"translation": [0, 0, 0], "scale": 2})");
  EXPECT_THAT(unknown, StartsWith("1:28: "));
  EXPECT_THAT(unknown, HasSubstr("Isometry3d has no field 'scale'"));
  const std::string quaternion = text_error(t, R"({"rotation": [1, 0, 0]})");
  EXPECT_THAT(quaternion, StartsWith("1:22: "));
  EXPECT_THAT(quaternion, HasSubstr("expected ','"));
  EXPECT_THAT(text_error(t, "5"), StartsWith("1:1: "));
  EXPECT_THAT(text_error(t, R"({"rotation": )"), StartsWith("1:14: "));
  EXPECT_THAT(text_error(t, "{\"rotation\": " + std::string(10000, '[')), MatchesRegex("1:[0-9]+: .*"));
  // A failed read leaves the frame as it was.
  Eigen::Isometry3d f = make_frame({1, 2, 3}, 0.5, {0, 0, 1});
  const Eigen::Isometry3d before = f;
  EXPECT_THROW(t.from_text(&f, R"({"translation": [7, 8, 9], "rotation": [[1, 0, 0]]})"), vsd::Error);
  EXPECT_TRUE(equal(f, before));
}

TEST(MetaTypeText, Vectors) {
  EXPECT_EQ(text_of(std::vector<double>{}), "[]");
  EXPECT_EQ(text_of(std::vector<double>{1, 2.5, -3}), "[1, 2.5, -3]");
  EXPECT_EQ(text_of(std::vector<std::string>{"a", "b\"c"}), R"(["a", "b\"c"])");
  EXPECT_EQ(text_of(std::vector<bool>{true, false}), "[true, false]");
  EXPECT_EQ(text_of(std::vector<std::vector<std::int32_t>>{{1, 2}, {}, {3}}), "[[1, 2], [], [3]]");
  EXPECT_EQ(text_of(std::vector<Eigen::Vector3d>{{1, 2, 3}, {4, 5, 6}}), "[[1, 2, 3], [4, 5, 6]]");

  EXPECT_TRUE(parse<std::vector<double>>("[]").empty());
  EXPECT_TRUE(parse<std::vector<double>>("[ ]").empty());
  EXPECT_EQ(parse<std::vector<double>>("[1, 2.5, -3]"), (std::vector<double>{1, 2.5, -3}));
  EXPECT_EQ(parse<std::vector<std::string>>(R"(["a", "b\"c"])"), (std::vector<std::string>{"a", "b\"c"}));
  EXPECT_EQ(parse<std::vector<bool>>("[true,false,true]"), (std::vector<bool>{true, false, true}));
  EXPECT_EQ(parse<std::vector<std::vector<std::int32_t>>>("[[1, 2], [], [3]]"),
            (std::vector<std::vector<std::int32_t>>{{1, 2}, {}, {3}}));
  const auto pts = parse<std::vector<Eigen::Vector3d>>(R"([[1, 2, 3], {"x": 4, "y": 5, "z": 6}])");
  ASSERT_EQ(pts.size(), 2u);
  EXPECT_EQ(pts[1], Eigen::Vector3d(4, 5, 6));
  const std::vector<std::uint64_t> big{0, std::numeric_limits<std::uint64_t>::max()};
  EXPECT_EQ(parse<std::vector<std::uint64_t>>(text_of(big)), big);
}

TEST(MetaTypeText, ValuesSpanningSeveralLines) {
  EXPECT_EQ(parse<std::vector<std::int32_t>>("[\n  1,\n  2\n]\n"), (std::vector<std::int32_t>{1, 2}));
}

// ---- user enums, flags and structs ------------------------------------------------------------------------

TEST(MetaTypeEnum, NamesAndValues) {
  const auto& t = vsd::meta_type<MtColor>();
  EXPECT_EQ(t.name(), "MtColor");
  EXPECT_EQ(t.kind(), vsd::TypeKind::Enum);
  EXPECT_EQ(t.size(), sizeof(MtColor));
  ASSERT_EQ(t.enum_values().size(), 3u);
  EXPECT_EQ(t.enum_values()[0].name, "Red");
  EXPECT_EQ(t.enum_values()[0].value, 0);
  EXPECT_EQ(t.enum_values()[1].name, "Green");
  EXPECT_EQ(t.enum_values()[1].value, 5);
  EXPECT_EQ(t.enum_values()[2].name, "Blue");
  EXPECT_EQ(t.enum_values()[2].value, -3);
  EXPECT_EQ(t.enum_name(5), "Green");
  EXPECT_EQ(t.enum_name(42), "");
  std::int64_t v = 0;
  EXPECT_TRUE(t.enum_value("Blue", v));
  EXPECT_EQ(v, -3);
  EXPECT_FALSE(t.enum_value("Purple", v));
}

TEST(MetaTypeEnum, TextRoundTrip) {
  EXPECT_EQ(text_of(MtColor::Red), R"("Red")");
  EXPECT_EQ(text_of(MtColor::Green), R"("Green")");
  EXPECT_EQ(text_of(MtColor::Blue), R"("Blue")");
  EXPECT_EQ(parse<MtColor>(R"("Green")"), MtColor::Green);
  EXPECT_EQ(parse<MtColor>(R"( "Blue" )"), MtColor::Blue);
  EXPECT_EQ(parse<MtColor>("5"), MtColor::Green) << "a number names a value too";
  for (const MtColor c : {MtColor::Red, MtColor::Green, MtColor::Blue})
    EXPECT_EQ(parse<MtColor>(text_of(c)), c);
  EXPECT_EQ(text_of(std::vector<MtColor>{MtColor::Red, MtColor::Blue}), R"(["Red", "Blue"])");
}

TEST(MetaTypeEnum, OlderBareNamesStillRead) {
  EXPECT_EQ(parse<MtColor>("Green"), MtColor::Green);
  EXPECT_EQ(parse<MtColor>(" Blue "), MtColor::Blue);
  EXPECT_EQ(parse<std::vector<MtColor>>("[Red, \"Blue\", 5]"),
            (std::vector<MtColor>{MtColor::Red, MtColor::Blue, MtColor::Green}));
}

TEST(MetaTypeEnum, UnknownNumericValueRoundTrips) {
  const auto odd = static_cast<MtColor>(42);
  EXPECT_EQ(text_of(odd), "42");
  EXPECT_EQ(parse<MtColor>("42"), odd);
  const auto negative = static_cast<MtColor>(-7);
  EXPECT_EQ(text_of(negative), "-7");
  EXPECT_EQ(parse<MtColor>("-7"), negative);
  EXPECT_EQ(binary_round_trip(odd), odd);
}

TEST(MetaTypeEnum, UnsignedUnderlyingTypeAboveTheSignedRange) {
  // MtLevel is an enum : uint8_t whose value High is 200 (above int8's range).
  EXPECT_EQ(text_of(MtLevel::Low), R"("Low")");
  EXPECT_EQ(text_of(MtLevel::High), R"("High")");
  EXPECT_EQ(parse<MtLevel>(R"("High")"), MtLevel::High);
  EXPECT_EQ(text_of(static_cast<MtLevel>(250)), "250");
  EXPECT_EQ(parse<MtLevel>("250"), static_cast<MtLevel>(250));
  EXPECT_EQ(binary_round_trip(MtLevel::High), MtLevel::High);
}

TEST(MetaTypeEnum, NumberOutsideTheUnderlyingTypeIsAnError) {
  // 300 does not fit an enum : uint8_t; it must not wrap around to 44.
  const std::string e = text_error(vsd::meta_type<MtLevel>(), "300");
  EXPECT_THAT(e, StartsWith("1:1: "));
  EXPECT_THAT(e, HasSubstr("300"));
  EXPECT_THAT(e, HasSubstr("MtLevel"));
}

TEST(MetaTypeFlags, TextForms) {
  const auto& t = vsd::meta_type<MtAccess>();
  EXPECT_EQ(t.kind(), vsd::TypeKind::Flags);
  EXPECT_EQ(t.name(), "MtAccess");
  // Names joined by '|' in one string; unnamed bits as a number in the same string; nothing set is 0.
  EXPECT_EQ(text_of(MtAccess::Read), R"("Read")");
  EXPECT_EQ(text_of(MtAccess::Read | MtAccess::Write), R"("Read|Write")");
  EXPECT_EQ(text_of(MtAccess::Read | MtAccess::Write | MtAccess::Exec), R"("Read|Write|Exec")");
  EXPECT_EQ(text_of(static_cast<MtAccess>(0)), "0");
  EXPECT_EQ(text_of(static_cast<MtAccess>(1 | 8)), R"("Read|8")");  // an unnamed bit stays a number
  EXPECT_EQ(text_of(static_cast<MtAccess>(8 | 16)), "24");          // only unnamed bits: a number
}

TEST(MetaTypeFlags, ParseAndRoundTrip) {
  EXPECT_EQ(parse<MtAccess>(R"("Read|Write")"), MtAccess::Read | MtAccess::Write);
  EXPECT_EQ(parse<MtAccess>(R"(" Write | Exec ")"), MtAccess::Write | MtAccess::Exec);
  EXPECT_EQ(parse<MtAccess>("0"), static_cast<MtAccess>(0));
  EXPECT_EQ(parse<MtAccess>("6"), MtAccess::Write | MtAccess::Exec);
  EXPECT_EQ(parse<MtAccess>(R"("Read|8")"), static_cast<MtAccess>(9));
  EXPECT_EQ(parse<MtAccess>(R"("8|Read")"), static_cast<MtAccess>(9));
  EXPECT_EQ(parse<MtAccess>(R"("Read")"), MtAccess::Read);
  EXPECT_EQ(parse<MtAccess>(R"("0")"), static_cast<MtAccess>(0));
  // The older bare forms.
  EXPECT_EQ(parse<MtAccess>("Read|Write"), MtAccess::Read | MtAccess::Write);
  EXPECT_EQ(parse<MtAccess>(" Write | Exec "), MtAccess::Write | MtAccess::Exec);
  EXPECT_EQ(parse<MtAccess>("Read|8"), static_cast<MtAccess>(9));
  EXPECT_EQ(parse<MtAccess>("Exec"), MtAccess::Exec);
  for (std::uint32_t bits = 0; bits < 16; ++bits) {
    const auto v = static_cast<MtAccess>(bits);
    EXPECT_EQ(parse<MtAccess>(text_of(v)), v) << text_of(v);
    EXPECT_EQ(binary_round_trip(v), v);
  }
}

TEST(MetaTypeStruct, DescribesItsFields) {
  const auto& t = vsd::meta_type<MtPart>();
  EXPECT_EQ(t.name(), "MtPart");
  EXPECT_EQ(t.kind(), vsd::TypeKind::Struct);
  EXPECT_EQ(t.size(), sizeof(MtPart));
  ASSERT_EQ(t.fields().size(), 6u);
  EXPECT_EQ(t.fields()[0].name, "name");
  EXPECT_EQ(t.fields()[0].type, &vsd::meta_type<std::string>());
  EXPECT_EQ(t.fields()[1].name, "pose");
  EXPECT_EQ(t.fields()[1].type, &vsd::meta_type<MtPose>());
  EXPECT_EQ(t.fields()[1].offset, offsetof(MtPart, pose));
  EXPECT_EQ(t.fields()[2].type, &vsd::meta_type<std::vector<Eigen::Vector3d>>());
  EXPECT_EQ(t.fields()[3].type, &vsd::meta_type<MtColor>());
}

TEST(MetaTypeFlags, SixtyFourBits) {
  // A flags type of 64 bits: an unnamed top bit is written, and read back, as an unsigned number.
  const auto top = static_cast<MtWide>(std::uint64_t{1} << 63);
  EXPECT_EQ(text_of(top), "9223372036854775808");
  EXPECT_EQ(parse<MtWide>(text_of(top)), top);
  const auto both = static_cast<MtWide>((std::uint64_t{1} << 63) | 1);
  EXPECT_EQ(text_of(both), R"("Low|9223372036854775808")");
  EXPECT_EQ(parse<MtWide>(text_of(both)), both);
  EXPECT_EQ(parse<MtWide>("18446744073709551615"), static_cast<MtWide>(~std::uint64_t{0}));
  EXPECT_THAT(text_error(vsd::meta_type<MtWide>(), "18446744073709551616"), StartsWith("1:1: "));
}

TEST(MetaTypeStruct, NumericStructIsWrittenAsAList) {
  EXPECT_EQ(text_of(MtPose{1, 2, 0.5}), "[1, 2, 0.5]");
  const MtPose p = parse<MtPose>("[1, 2, 0.5]");
  EXPECT_EQ(p.x, 1);
  EXPECT_EQ(p.y, 2);
  EXPECT_EQ(p.theta, 0.5);
}

TEST(MetaTypeStruct, NamedFormInAnyOrderAndPartial) {
  const MtPose p = parse<MtPose>(R"({"theta": 0.5, "x": 1, "y": 2})");
  EXPECT_EQ(p.x, 1);
  EXPECT_EQ(p.y, 2);
  EXPECT_EQ(p.theta, 0.5);
  const MtPose q = parse<MtPose>(R"({"y": -4})");
  EXPECT_EQ(q.x, 0);
  EXPECT_EQ(q.y, -4);
  const MtPose e = parse<MtPose>("{}");
  EXPECT_EQ(e.theta, 0);
}

TEST(MetaTypeStruct, OlderBareKeysStillRead) {
  const MtPose p = parse<MtPose>("{theta: 0.5, x: 1, \"y\": 2}");  // and mixed with quoted keys
  EXPECT_EQ(p.x, 1);
  EXPECT_EQ(p.y, 2);
  EXPECT_EQ(p.theta, 0.5);
  const MtPart part =
      parse<MtPart>("{name: \"n\", color: Blue, pose: {theta: 2}, points: [{x: 1, y: 2, z: 3}]}");
  EXPECT_EQ(part.name, "n");
  EXPECT_EQ(part.color, MtColor::Blue);
  EXPECT_EQ(part.pose.theta, 2);
  ASSERT_EQ(part.points.size(), 1u);
  EXPECT_EQ(part.points[0], Eigen::Vector3d(1, 2, 3));
  // A key that is no identifier is only possible quoted; it is then simply an unknown field.
  EXPECT_THAT(text_error(vsd::meta_type<MtPose>(), R"({"x y": 1})"), HasSubstr("MtPose has no field 'x y'"));
  EXPECT_THAT(text_error(vsd::meta_type<MtPose>(), "{1: 1}"), StartsWith("1:2: expected a key"));
}

TEST(MetaTypeStruct, NestedStructAndVectorFields) {
  MtPart part;
  part.name = "gear \"A\"";
  part.pose = {1, 2, 0.5};
  part.points = {{1, 2, 3}, {-1, 0.25, 1e10}};
  part.color = MtColor::Green;
  part.active = true;
  part.waypoints = {{0, 0, 0}, {3, 4, 1}};
  const std::string text = text_of(part);
  EXPECT_EQ(text, R"({"name": "gear \"A\"", "pose": [1, 2, 0.5], "points": [[1, 2, 3], [-1, 0.25, 1e+10]], )"
                  R"("color": "Green", "active": true, "waypoints": [[0, 0, 0], [3, 4, 1]]})");
  const MtPart back = parse<MtPart>(text);
  EXPECT_TRUE(equal(back, part));
  EXPECT_EQ(back.name, part.name);
  EXPECT_EQ(back.points, part.points);
  EXPECT_EQ(back.waypoints.size(), 2u);
  EXPECT_EQ(back.waypoints[1].y, 4);

  const MtPart partial = parse<MtPart>("{ \"color\": \"Blue\",\n  \"pose\": {\"theta\": 2} }");
  EXPECT_EQ(partial.color, MtColor::Blue);
  EXPECT_EQ(partial.pose.theta, 2);
  EXPECT_EQ(partial.name, "");
}

// ---- binary round trips -----------------------------------------------------------------------------------

TEST(MetaTypeBytes, ScalarsRoundTrip) {
  EXPECT_EQ(binary_round_trip(true), true);
  EXPECT_EQ(binary_round_trip(false), false);
  EXPECT_EQ(binary_round_trip(std::int8_t{-128}), -128);
  EXPECT_EQ(binary_round_trip(std::uint16_t{65535}), 65535);
  EXPECT_EQ(binary_round_trip(std::int32_t{-123456}), -123456);
  EXPECT_EQ(binary_round_trip(std::numeric_limits<std::int64_t>::min()),
            std::numeric_limits<std::int64_t>::min());
  EXPECT_EQ(binary_round_trip(std::numeric_limits<std::uint64_t>::max()),
            std::numeric_limits<std::uint64_t>::max());
  EXPECT_EQ(binary_round_trip(0.1f), 0.1f);
  EXPECT_EQ(binary_round_trip(0.1), 0.1);
  EXPECT_TRUE(std::signbit(binary_round_trip(-0.0)));
  EXPECT_TRUE(std::isnan(binary_round_trip(nan)));
  EXPECT_EQ(binary_round_trip(-inf), -inf);
}

// Recording frames a value with TypeOps::write_fixed where the type has one: it must write exactly what
// write_bytes writes (else a recorded bundle would not read back), and exist only where every value has
// the same size.
template <class T>
void expect_fixed_form(const T& v) {
  const vsd::TypeOps& ops = vsd::meta_type<T>().ops();
  ASSERT_NE(ops.write_fixed, nullptr) << vsd::meta_type<T>().name();
  const std::vector<std::uint8_t> general = bytes_of(v);
  ASSERT_EQ(ops.fixed_bytes, general.size()) << vsd::meta_type<T>().name();
  std::vector<std::uint8_t> fixed(ops.fixed_bytes + 8, 0xAB);  // the tail shows a write past the size
  ops.write_fixed(&v, fixed.data());
  EXPECT_TRUE(std::all_of(fixed.end() - 8, fixed.end(), [](std::uint8_t b) { return b == 0xAB; }));
  fixed.resize(ops.fixed_bytes);
  EXPECT_EQ(fixed, general) << vsd::meta_type<T>().name();
}

TEST(MetaTypeBytes, FixedFormIsTheGeneralFormForEveryFixedSizeType) {
  expect_fixed_form(true);
  expect_fixed_form(false);
  expect_fixed_form(std::int8_t{-7});
  expect_fixed_form(std::int16_t{-300});
  expect_fixed_form(std::int32_t{0x01020304});
  expect_fixed_form(std::numeric_limits<std::int64_t>::min());
  expect_fixed_form(std::uint8_t{200});
  expect_fixed_form(std::uint16_t{65535});
  expect_fixed_form(std::uint32_t{0xDEADBEEF});
  expect_fixed_form(std::numeric_limits<std::uint64_t>::max());
  expect_fixed_form(0.1f);
  expect_fixed_form(-0.0);
  expect_fixed_form(nan);
  expect_fixed_form(MtColor::Blue);
  expect_fixed_form(MtLevel::High);
  expect_fixed_form(MtAccess::Read | MtAccess::Exec);
  expect_fixed_form(Eigen::Vector2d(1, -2));
  expect_fixed_form(Eigen::Vector3d(1, 2, 3e-300));
  expect_fixed_form(Eigen::Vector4d(1, 2, 3, 4));
  expect_fixed_form(Eigen::Quaterniond(0.5, -0.5, 0.5, 0.5));
  Eigen::Isometry3d f = Eigen::Isometry3d::Identity();
  f.linear() = Eigen::AngleAxisd(0.3, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  f.translation() = Eigen::Vector3d(4, -5, 6);
  expect_fixed_form(f);
  // Values whose size varies have none.
  EXPECT_EQ(vsd::meta_type<std::string>().ops().write_fixed, nullptr);
  EXPECT_EQ(vsd::meta_type<std::vector<double>>().ops().write_fixed, nullptr);
  EXPECT_EQ(vsd::meta_type<std::vector<Eigen::Vector3d>>().ops().fixed_bytes, 0u);
}

TEST(MetaTypeBytes, EncodingSizes) {
  EXPECT_EQ(bytes_of(true).size(), 1u);
  EXPECT_EQ(bytes_of(std::int32_t{1}).size(), 4u);
  EXPECT_EQ(bytes_of(1.0).size(), 8u);
  EXPECT_EQ(bytes_of(std::string("abc")).size(), 4u);  // varint size + bytes
  EXPECT_EQ(bytes_of(std::vector<double>{1, 2}).size(), 17u);
  EXPECT_EQ(bytes_of(Eigen::Vector3d(1, 2, 3)).size(), 24u);
  EXPECT_EQ(bytes_of(std::string(200, 'x')).size(), 202u);  // two-byte varint
  const auto b = bytes_of(std::int32_t{0x01020304});
  EXPECT_EQ(b, (std::vector<std::uint8_t>{4, 3, 2, 1})) << "little-endian";
}

TEST(MetaTypeBytes, StringsAndVectorsRoundTrip) {
  const std::string s("nul\0and \"quotes\"\n", 17);
  EXPECT_EQ(binary_round_trip(s), s);
  EXPECT_EQ(binary_round_trip(std::string()), "");
  EXPECT_EQ(binary_round_trip(std::vector<double>{}), std::vector<double>{});
  EXPECT_EQ(binary_round_trip(std::vector<double>{1, -2.5, 1e-300}), (std::vector<double>{1, -2.5, 1e-300}));
  EXPECT_EQ(binary_round_trip(std::vector<std::string>{"a", "", "ccc"}),
            (std::vector<std::string>{"a", "", "ccc"}));
  EXPECT_EQ(binary_round_trip(std::vector<bool>{true, false, true}), (std::vector<bool>{true, false, true}));
  EXPECT_EQ(binary_round_trip(std::vector<std::vector<std::int32_t>>{{1}, {}, {2, 3}}),
            (std::vector<std::vector<std::int32_t>>{{1}, {}, {2, 3}}));
  const std::vector<Eigen::Vector3d> pts{{1, 2, 3}, {4, 5, 6}};
  EXPECT_EQ(binary_round_trip(pts), pts);
}

TEST(MetaTypeBytes, EigenRoundTrip) {
  EXPECT_EQ(binary_round_trip(Eigen::Vector2d(1, 2)), Eigen::Vector2d(1, 2));
  EXPECT_EQ(binary_round_trip(Eigen::Vector4d(1, 2, 3, 4)), Eigen::Vector4d(1, 2, 3, 4));
  const Eigen::Quaterniond q(0.5, 0.5, 0.5, 0.5);
  EXPECT_EQ(binary_round_trip(q).coeffs(), q.coeffs());
  const Eigen::Isometry3d id = Eigen::Isometry3d::Identity();
  EXPECT_TRUE(binary_round_trip(id).isApprox(id, 0));
  const Eigen::Isometry3d f = make_frame({1, 2, 3}, 1.2, {0.3, 0.4, -1});
  const Eigen::Isometry3d back = binary_round_trip(f);
  EXPECT_TRUE(back.isApprox(f, 1e-14));
  EXPECT_EQ(back.translation(), f.translation());
}

TEST(MetaTypeBytes, UserTypesRoundTrip) {
  MtPart part;
  part.name = "p";
  part.pose = {1, 2, 3};
  part.points = {{7, 8, 9}};
  part.color = MtColor::Blue;
  part.active = true;
  part.waypoints = {{1, 1, 1}};
  const MtPart back = binary_round_trip(part);
  EXPECT_TRUE(equal(back, part));
  EXPECT_EQ(back.color, MtColor::Blue);
  EXPECT_TRUE(back.active);
  EXPECT_EQ(binary_round_trip(MtAccess::Read | MtAccess::Exec), MtAccess::Read | MtAccess::Exec);
}

TEST(MetaTypeBytes, SeveralValuesInOneBuffer) {
  std::vector<std::uint8_t> buf;
  vsd::ByteWriter w(buf);
  const double d = 2.5;
  const std::string s = "xyz";
  const std::int16_t i = -3;
  vsd::meta_type<double>().write_bytes(&d, w);
  vsd::meta_type<std::string>().write_bytes(&s, w);
  vsd::meta_type<std::int16_t>().write_bytes(&i, w);
  EXPECT_EQ(w.size(), 8u + 4u + 2u);

  vsd::ByteReader r(buf.data(), buf.size());
  double d2 = 0;
  std::string s2;
  std::int16_t i2 = 0;
  vsd::meta_type<double>().read_bytes(&d2, r);
  EXPECT_EQ(r.position(), 8u);
  vsd::meta_type<std::string>().read_bytes(&s2, r);
  vsd::meta_type<std::int16_t>().read_bytes(&i2, r);
  EXPECT_TRUE(r.at_end());
  EXPECT_EQ(d2, d);
  EXPECT_EQ(s2, s);
  EXPECT_EQ(i2, i);
}

TEST(MetaTypeBytes, VarintRoundTrip) {
  for (const std::uint64_t v : {std::uint64_t{0}, std::uint64_t{127}, std::uint64_t{128}, std::uint64_t{300},
                                std::uint64_t{1} << 35, std::numeric_limits<std::uint64_t>::max()}) {
    std::vector<std::uint8_t> buf;
    vsd::ByteWriter w(buf);
    w.varint(v);
    vsd::ByteReader r(buf.data(), buf.size());
    EXPECT_EQ(r.varint(), v);
    EXPECT_TRUE(r.at_end());
  }
}

// ---- equality and hashing ---------------------------------------------------------------------------------

TEST(MetaTypeEquality, EqualValuesHashEqual) {
  EXPECT_TRUE(equal(1.5, 1.5));
  EXPECT_FALSE(equal(1.5, 2.5));
  EXPECT_EQ(hash_of(1.5), hash_of(1.5));
  EXPECT_TRUE(equal(0.0, -0.0));
  EXPECT_EQ(hash_of(0.0), hash_of(-0.0));
  EXPECT_TRUE(equal(0.0f, -0.0f));
  EXPECT_EQ(hash_of(0.0f), hash_of(-0.0f));
  EXPECT_TRUE(equal(nan, nan)) << "NaN equals NaN for change detection";
  EXPECT_EQ(hash_of(nan), hash_of(nan));

  EXPECT_TRUE(equal(std::string("abc"), std::string("abc")));
  EXPECT_EQ(hash_of(std::string("abc")), hash_of(std::string("abc")));
  EXPECT_FALSE(equal(std::string("abc"), std::string("abd")));

  EXPECT_TRUE(equal(std::vector<double>{0.0, 1}, std::vector<double>{-0.0, 1}));
  EXPECT_EQ(hash_of(std::vector<double>{0.0, 1}), hash_of(std::vector<double>{-0.0, 1}));
  EXPECT_FALSE(equal(std::vector<double>{1}, std::vector<double>{1, 1}));

  EXPECT_TRUE(equal(MtPose{0.0, 1, 2}, MtPose{-0.0, 1, 2}));
  EXPECT_EQ(hash_of(MtPose{0.0, 1, 2}), hash_of(MtPose{-0.0, 1, 2}));
  EXPECT_FALSE(equal(MtPose{0, 1, 2}, MtPose{0, 1, 3}));

  EXPECT_TRUE(equal(MtColor::Green, MtColor::Green));
  EXPECT_FALSE(equal(MtColor::Green, MtColor::Red));
  EXPECT_EQ(hash_of(MtColor::Green), hash_of(MtColor::Green));

  const Eigen::Isometry3d f = make_frame({1, 2, 3}, 0.5, {0, 0, 1});
  const Eigen::Isometry3d g = f;
  EXPECT_TRUE(equal(f, g));
  EXPECT_EQ(hash_of(f), hash_of(g));
  EXPECT_FALSE(equal(f, make_frame({1, 2, 3}, 0.6, {0, 0, 1})));
  EXPECT_FALSE(equal(f, make_frame({1, 2, 4}, 0.5, {0, 0, 1})));

  MtPart a;
  a.name = "x";
  a.points = {{1, 2, 3}};
  MtPart b = a;
  EXPECT_TRUE(equal(a, b));
  EXPECT_EQ(hash_of(a), hash_of(b));
  b.points[0].z() = 4;
  EXPECT_FALSE(equal(a, b));
}

TEST(MetaTypeEquality, AllNaNsAreEqualAndHashAlike) {
  // equal() treats every NaN as equal to every NaN, so all NaNs must hash alike (sign and payload too).
  const double neg_nan = -nan;
  const double payload_nan = std::nan("123");
  ASSERT_TRUE(std::signbit(neg_nan));
  EXPECT_TRUE(equal(nan, neg_nan));
  EXPECT_TRUE(equal(nan, payload_nan));
  EXPECT_EQ(hash_of(nan), hash_of(neg_nan));
  EXPECT_EQ(hash_of(nan), hash_of(payload_nan));
  EXPECT_EQ(hash_of(std::vector<double>{nan}), hash_of(std::vector<double>{neg_nan}));
  EXPECT_EQ(hash_of(std::numeric_limits<float>::quiet_NaN()),
            hash_of(-std::numeric_limits<float>::quiet_NaN()));
}

TEST(MetaTypeEquality, EqualityAfterRoundTrips) {
  MtPart part;
  part.name = "n";
  part.points = {{0.1, 0.2, 0.3}};
  part.waypoints = {{1.0 / 3.0, 2.0 / 3.0, -0.0}};
  EXPECT_TRUE(equal(parse<MtPart>(text_of(part)), part));
  EXPECT_TRUE(equal(binary_round_trip(part), part));
  const Eigen::Isometry3d f = make_frame({0.1, 0.2, 0.3}, 2.0, {1, 1, 1});
  EXPECT_TRUE(equal(binary_round_trip(f), f)) << "a frame equals itself after a binary round trip";
}

// ---- text errors: vsd::Error with line:col and what was wrong
// ----------------------------------------------

TEST(MetaTypeTextErrors, TextReaderNamesTheOrigin) {
  vsd::TextReader in("\n  x", "robot.vsd");
  in.skip_ws();
  EXPECT_EQ(in.line(), 2u);
  EXPECT_EQ(in.column(), 3u);
  try {
    in.fail("something is wrong");
    FAIL() << "fail() must throw";
  } catch (const vsd::Error& e) {
    EXPECT_STREQ(e.what(), "robot.vsd:2:3: something is wrong");
  }
}

TEST(MetaTypeTextErrors, UnknownEnumName) {
  const std::string e = text_error(vsd::meta_type<MtColor>(), "Purple");
  EXPECT_THAT(e, StartsWith("1:1: "));
  EXPECT_THAT(e, HasSubstr("'Purple' is not a value of MtColor"));
  // Inside a vector: the column of the offending name.
  const std::string v = text_error(vsd::meta_type<std::vector<MtColor>>(), "[Red, Purple]");
  EXPECT_THAT(v, StartsWith("1:7: "));
  EXPECT_THAT(v, HasSubstr("Purple"));
  // Quoted: the column of the name inside the quotes.
  const std::string q = text_error(vsd::meta_type<std::vector<MtColor>>(), R"(["Red", "Purple"])");
  EXPECT_THAT(q, StartsWith("1:10: "));
  EXPECT_THAT(q, HasSubstr("'Purple' is not a value of MtColor"));
  EXPECT_THAT(text_error(vsd::meta_type<MtColor>(), R"("Red|Blue")"), StartsWith("1:5: expected '\"'"));
  EXPECT_THAT(text_error(vsd::meta_type<MtColor>(), R"("Red)"), HasSubstr("ended"));
  EXPECT_THAT(text_error(vsd::meta_type<MtColor>(), R"("")"), StartsWith("1:2: "));
}

TEST(MetaTypeTextErrors, UnknownFlagName) {
  const std::string e = text_error(vsd::meta_type<MtAccess>(), "Read|Bogus");
  EXPECT_THAT(e, StartsWith("1:6: "));
  EXPECT_THAT(e, HasSubstr("'Bogus' is not a value of MtAccess"));
  // Inside the quotes: still the line and column of the offending name.
  const std::string q = text_error(vsd::meta_type<MtAccess>(), R"("Read|Bogus")");
  EXPECT_THAT(q, StartsWith("1:7: "));
  EXPECT_THAT(q, HasSubstr("'Bogus' is not a value of MtAccess"));
  const std::string nested =
      text_error(vsd::meta_type<std::vector<MtAccess>>(), "[\"Read\",\n  \"Write|Exec|Nope\"]");
  EXPECT_THAT(nested, StartsWith("2:15: "));
  EXPECT_THAT(nested, HasSubstr("'Nope'"));
  const std::string number = text_error(vsd::meta_type<MtAccess>(), R"("Read|1x")");
  EXPECT_THAT(number, StartsWith("1:7: "));
  const std::string unclosed = text_error(vsd::meta_type<MtAccess>(), R"("Read|Write)");
  EXPECT_THAT(unclosed, StartsWith("1:12: "));
  EXPECT_THAT(unclosed, HasSubstr("ended"));
  EXPECT_THAT(text_error(vsd::meta_type<MtAccess>(), R"("Read||Write")"), StartsWith("1:7: "));
  EXPECT_THAT(text_error(vsd::meta_type<MtAccess>(), R"("Read|")"), StartsWith("1:7: "));
}

TEST(MetaTypeTextErrors, IntegerOutOfRange) {
  const std::string u8 = text_error(vsd::meta_type<std::uint8_t>(), "300");
  EXPECT_THAT(u8, StartsWith("1:1: "));
  EXPECT_THAT(u8, HasSubstr("300 is out of range for uint8"));

  const std::string i8 = text_error(vsd::meta_type<std::int8_t>(), "-129");
  EXPECT_THAT(i8, StartsWith("1:1: "));
  EXPECT_THAT(i8, HasSubstr("-129 is out of range for int8"));

  const std::string in_vector = text_error(vsd::meta_type<std::vector<std::uint8_t>>(), "[1, 300]");
  EXPECT_THAT(in_vector, StartsWith("1:5: "));
  EXPECT_THAT(in_vector, HasSubstr("out of range for uint8"));

  const std::string later_line = text_error(vsd::meta_type<std::vector<std::uint8_t>>(), "[1,\n 2,\n 300]");
  EXPECT_THAT(later_line, StartsWith("3:2: "));
}

TEST(MetaTypeTextErrors, NegativeForUnsigned) {
  const std::string e = text_error(vsd::meta_type<std::uint32_t>(), "-1");
  EXPECT_THAT(e, StartsWith("1:1: "));
  EXPECT_THAT(e, HasSubstr("'-1'"));
  EXPECT_THAT(e, HasSubstr("unsigned"));
}

TEST(MetaTypeTextErrors, IntegerBeyond64Bits) {
  const std::string e = text_error(vsd::meta_type<std::int64_t>(), "9223372036854775808");
  EXPECT_THAT(e, StartsWith("1:1: "));
  EXPECT_THAT(e, HasSubstr("9223372036854775808"));
  EXPECT_THAT(e, HasSubstr("range"));
  const std::string u = text_error(vsd::meta_type<std::uint64_t>(), " 18446744073709551616");
  EXPECT_THAT(u, StartsWith("1:2: "));
  EXPECT_THAT(u, HasSubstr("range"));
}

TEST(MetaTypeTextErrors, NotANumber) {
  EXPECT_THAT(text_error(vsd::meta_type<std::int32_t>(), "1.5"), StartsWith("1:1: '1.5' is not an integer"));
  EXPECT_THAT(text_error(vsd::meta_type<double>(), "1.5x"), StartsWith("1:1: '1.5x' is not a number"));
  EXPECT_THAT(text_error(vsd::meta_type<double>(), ""), StartsWith("1:1: expected a number"));
  EXPECT_THAT(text_error(vsd::meta_type<double>(), "  \"3\""), StartsWith("1:3: expected a number"));
}

TEST(MetaTypeTextErrors, FloatOutOfRange) {
  // 1e300 cannot be a float: it must not silently become infinity.
  const std::string e = text_error(vsd::meta_type<float>(), "1e300");
  EXPECT_THAT(e, StartsWith("1:1: "));
  EXPECT_THAT(e, HasSubstr("1e300"));
  EXPECT_THAT(e, HasSubstr("float"));
}

TEST(MetaTypeTextErrors, BadBool) {
  const std::string e = text_error(vsd::meta_type<bool>(), "yes");
  EXPECT_THAT(e, StartsWith("1:1: "));
  EXPECT_THAT(e, HasSubstr("expected true or false, found 'yes'"));
  EXPECT_THAT(text_error(vsd::meta_type<bool>(), "1"), StartsWith("1:1: "));
}

TEST(MetaTypeTextErrors, MissingBracket) {
  const std::string ended = text_error(vsd::meta_type<std::vector<std::int32_t>>(), "[1, 2");
  EXPECT_THAT(ended, StartsWith("1:6: "));
  EXPECT_THAT(ended, HasSubstr("ended"));

  const std::string no_comma = text_error(vsd::meta_type<std::vector<std::int32_t>>(), "[1 2]");
  EXPECT_THAT(no_comma, StartsWith("1:4: "));
  EXPECT_THAT(no_comma, HasSubstr("expected ','"));
  EXPECT_THAT(no_comma, HasSubstr("'2'"));

  const std::string no_open = text_error(vsd::meta_type<std::vector<std::int32_t>>(), "1, 2]");
  EXPECT_THAT(no_open, StartsWith("1:1: "));
  EXPECT_THAT(no_open, HasSubstr("expected '['"));

  const std::string struct_open = text_error(vsd::meta_type<MtPose>(), "{x: 1");
  EXPECT_THAT(struct_open, StartsWith("1:6: "));
  EXPECT_THAT(struct_open, HasSubstr("expected '}'"));

  const std::string list_struct = text_error(vsd::meta_type<Eigen::Vector3d>(), "[1, 2, 3");
  EXPECT_THAT(list_struct, StartsWith("1:9: "));
  EXPECT_THAT(list_struct, HasSubstr("Vector3d"));

  const std::string neither = text_error(vsd::meta_type<MtPose>(), "1, 2, 3");
  EXPECT_THAT(neither, StartsWith("1:1: "));
  EXPECT_THAT(neither, HasSubstr("MtPose"));
}

TEST(MetaTypeTextErrors, WrongNumberOfPositionalFields) {
  const std::string too_many = text_error(vsd::meta_type<MtPose>(), "[1, 2, 3, 4]");
  EXPECT_THAT(too_many, StartsWith("1:9: "));
  EXPECT_THAT(too_many, HasSubstr("MtPose has 3 fields"));
  const std::string too_few = text_error(vsd::meta_type<Eigen::Vector3d>(), "[1, 2]");
  EXPECT_THAT(too_few, StartsWith("1:6: "));
}

TEST(MetaTypeTextErrors, TrailingCharacters) {
  const std::string e = text_error(vsd::meta_type<double>(), "1.5 x");
  EXPECT_THAT(e, StartsWith("1:5: "));
  EXPECT_THAT(e, HasSubstr("unexpected 'x' after the value"));
  EXPECT_THAT(text_error(vsd::meta_type<std::vector<std::int32_t>>(), "[1, 2] 3"), StartsWith("1:8: "));
  EXPECT_THAT(text_error(vsd::meta_type<std::string>(), "\"a\"\n\"b\""), StartsWith("2:1: "));
}

TEST(MetaTypeTextErrors, UnknownStructField) {
  const std::string e = text_error(vsd::meta_type<MtPose>(), "{x: 1, q: 2}");
  EXPECT_THAT(e, StartsWith("1:8: "));
  EXPECT_THAT(e, HasSubstr("MtPose has no field 'q'"));
  const std::string quoted = text_error(vsd::meta_type<MtPose>(), R"({"x": 1, "q": 2})");
  EXPECT_THAT(quoted, StartsWith("1:10: "));
  EXPECT_THAT(quoted, HasSubstr("MtPose has no field 'q'"));
  const std::string nested = text_error(vsd::meta_type<MtPart>(), "{name: \"a\",\n pose: {rho: 1}}");
  EXPECT_THAT(nested, StartsWith("2:9: "));
  EXPECT_THAT(nested, HasSubstr("MtPose has no field 'rho'"));
}

TEST(MetaTypeTextErrors, StringErrors) {
  const std::string unterminated = text_error(vsd::meta_type<std::string>(), "\"abc");
  EXPECT_THAT(unterminated, MatchesRegex("1:[0-9]+: .*"));
  EXPECT_THAT(unterminated, HasSubstr("unterminated string"));

  const std::string multi_line = text_error(vsd::meta_type<std::vector<std::string>>(), "[\"a\",\n \"b");
  EXPECT_THAT(multi_line, MatchesRegex("2:[0-9]+: .*"));
  EXPECT_THAT(multi_line, HasSubstr("unterminated string"));

  const std::string escape = text_error(vsd::meta_type<std::string>(), "\"ab\\");
  EXPECT_THAT(escape, MatchesRegex("1:[0-9]+: .*"));
  EXPECT_THAT(escape, HasSubstr("unterminated"));

  const std::string unknown = text_error(vsd::meta_type<std::string>(), R"("a\qb")");
  EXPECT_THAT(unknown, MatchesRegex("1:[0-9]+: .*"));
  EXPECT_THAT(unknown, HasSubstr("unknown escape"));

  const std::string bad_u = text_error(vsd::meta_type<std::string>(), R"("\u12G4")");
  EXPECT_THAT(bad_u, MatchesRegex("1:[0-9]+: .*"));
  EXPECT_THAT(bad_u, HasSubstr("\\u"));

  const std::string not_quoted = text_error(vsd::meta_type<std::string>(), "abc");
  EXPECT_THAT(not_quoted, StartsWith("1:1: "));
  EXPECT_THAT(not_quoted, HasSubstr("quoted string"));
}

TEST(MetaTypeTextErrors, DeepNestingIsAnErrorNotACrash) {
  const std::string deep(10000, '[');
  const std::string e1 = text_error(vsd::meta_type<std::vector<std::int32_t>>(), deep);
  EXPECT_THAT(e1, StartsWith("1:2: "));
  EXPECT_THAT(e1, HasSubstr("number"));
  const std::string e2 = text_error(vsd::meta_type<std::vector<std::vector<std::vector<double>>>>(), deep);
  EXPECT_THAT(e2, StartsWith("1:4: "));
  const std::string e3 = text_error(vsd::meta_type<MtPart>(), "{points: " + deep);
  EXPECT_THAT(e3, MatchesRegex("1:[0-9]+: .*"));
  const std::string e4 = text_error(vsd::meta_type<std::vector<std::int32_t>>(), std::string(10000, ']'));
  EXPECT_THAT(e4, StartsWith("1:1: "));
}

TEST(MetaTypeTextErrors, NestingGuardThrowsBeyondItsDepth) {
  vsd::TextReader in("");
  std::vector<std::unique_ptr<vsd::TextReader::Nest>> levels;
  bool threw = false;
  for (int i = 0; i < 10000 && !threw; ++i) {
    try {
      levels.push_back(std::make_unique<vsd::TextReader::Nest>(in));
    } catch (const vsd::Error& e) {
      threw = true;
      EXPECT_THAT(e.what(), HasSubstr("nested deeper than"));
      EXPECT_THAT(e.what(), StartsWith("1:1: "));
    }
  }
  EXPECT_TRUE(threw);
  EXPECT_GE(levels.size(), 64u) << "reasonable nesting is allowed";
}

// ---- TextReader: skipping values and moving back --------------------------------------------------------

// The texts skip_value() skips one after another in @p text.
std::vector<std::string> skipped_values(std::string_view text) {
  vsd::TextReader in(text);
  std::vector<std::string> out;
  while (!in.at_end()) {
    const std::size_t start = in.token_start();
    in.skip_value();
    out.emplace_back(text.substr(start, in.position() - start));
  }
  return out;
}

std::string repeated(std::string_view part, int n) {
  std::string s;
  for (int i = 0; i < n; ++i) s += part;
  return s;
}

std::string skip_error(std::string_view text) {
  try {
    vsd::TextReader in(text);
    in.skip_value();
  } catch (const vsd::Error& e) {
    return e.what();
  }
  return "<no error>";
}

TEST(TextReader, SkipValueSkipsExactlyOneJsonValue) {
  EXPECT_THAT(skipped_values(R"({"a": [1, {"b": "x\"}y"}, [], {}], "c": null} [true, false, -1.5e3, "nan"])"
                             R"( "s]" 12 -0 1E+2 {} [] "" null)"),
              testing::ElementsAre(R"({"a": [1, {"b": "x\"}y"}, [], {}], "c": null})",
                                   R"([true, false, -1.5e3, "nan"])", R"("s]")", "12", "-0", "1E+2", "{}",
                                   "[]", R"("")", "null"));
  // Every value written by vsd is one value to skip.
  MtPart part;
  part.name = "a\n\"]}";
  part.points = {{1, nan, -inf}};
  part.waypoints = {{1, 2, 3}};
  const std::string text = text_of(part) + " " + text_of(make_frame({1, 2, 3}, 0.3, {0, 1, 0})) + " " +
                           text_of(MtAccess::Read | MtAccess::Exec) + " " + text_of(MtColor::Blue);
  EXPECT_EQ(skipped_values(text).size(), 4u) << text;
}

TEST(TextReader, SkipValueTakesTheOlderForms) {
  EXPECT_THAT(skipped_values("{x: 1, name: \"a\", color: Red, access: Read | Write|8, ref: @42} Read|Write "
                             "8|Exec @7 \"@7\" nan -inf +inf Green vsd::Node [@1, @2] [nan, inf]"),
              testing::ElementsAre("{x: 1, name: \"a\", color: Red, access: Read | Write|8, ref: @42}",
                                   "Read|Write", "8|Exec", "@7", "\"@7\"", "nan", "-inf", "+inf", "Green",
                                   "vsd::Node", "[@1, @2]", "[nan, inf]"));
}

TEST(TextReader, SkipValueRejectsBadInputWithThePosition) {
  EXPECT_THAT(skip_error(""), StartsWith("1:1: expected a value but the text ended"));
  EXPECT_THAT(skip_error("  ]"), StartsWith("1:3: expected a value, found ']'"));
  EXPECT_THAT(skip_error("[1, ]"), StartsWith("1:5: expected a value, found ']'"));
  EXPECT_THAT(skip_error("[1 2]"), StartsWith("1:4: expected ']' but found '2'"));
  EXPECT_THAT(skip_error("[1, 2"), StartsWith("1:6: "));
  EXPECT_THAT(skip_error(R"({"a" 1})"), StartsWith("1:6: expected ':'"));
  EXPECT_THAT(skip_error(R"({"a": })"), StartsWith("1:7: expected a value"));
  EXPECT_THAT(skip_error(R"({"a": 1,})"), StartsWith("1:9: expected a key"));
  EXPECT_THAT(skip_error("{1: 2}"), StartsWith("1:2: expected a key"));
  EXPECT_THAT(skip_error("{\"a\": [1,\n  1.2.3]}"), StartsWith("2:3: '1.2.3' is not a number"));
  EXPECT_THAT(skip_error("-"), StartsWith("1:1: '-' is not a number"));
  EXPECT_THAT(skip_error("\"abc"), HasSubstr("unterminated string"));
  EXPECT_THAT(skip_error(R"("\uD83D")"), StartsWith("1:2: "));
  EXPECT_THAT(skip_error("@"), StartsWith("1:2: expected a number"));
  EXPECT_THAT(skip_error("@x"), StartsWith("1:2: "));
  EXPECT_THAT(skip_error("Read|"), StartsWith("1:6: expected a value but the text ended"));
  EXPECT_THAT(skip_error("#"), StartsWith("1:1: expected a value, found '#'"));
  // A number beyond double's range is still one well-formed value.
  EXPECT_EQ(skip_error("1e999"), "<no error>");
}

TEST(TextReader, SkipValueGuardsItsNesting) {
  // Too deep a value throws (no stack overflow), whether arrays, objects or both.
  for (const std::string& deep :
       {std::string(100000, '['), repeated("{\"a\": ", 50000), repeated("{a: [", 50000)}) {
    const std::string e = skip_error(deep);
    EXPECT_THAT(e, MatchesRegex("1:[0-9]+: .*"));
    EXPECT_THAT(e, HasSubstr("nested deeper than"));
  }
  // Reasonable nesting is fine, and the guard is released afterwards.
  const std::string nested = std::string(64, '[') + std::string(64, ']');
  const std::string two = nested + " " + nested;
  vsd::TextReader in(two);
  in.skip_value();
  in.skip_value();
  EXPECT_TRUE(in.at_end());
  // Closed deep values one after another do not add up.
  std::string many;
  for (int i = 0; i < 1000; ++i) many += "[[[[1]]]] ";
  EXPECT_EQ(skipped_values(many).size(), 1000u);
}

TEST(TextReader, SeekReadsAValueAgain) {
  // A reader that sees a key before it can use the value skips it, then comes back to it.
  const std::string text = R"({"later": [1, 2], "first": 3})";
  vsd::TextReader in(text, "file.json");
  EXPECT_EQ(in.text(), text);
  in.expect('{');
  EXPECT_EQ(in.key(), "later");
  in.expect(':');
  const std::size_t later = in.token_start();
  in.skip_value();
  in.expect(',');
  EXPECT_EQ(in.key(), "first");
  in.expect(':');
  EXPECT_EQ(in.integer(), 3);
  in.expect('}');
  in.expect_end();
  const std::size_t end = in.position();

  in.seek(later);
  EXPECT_EQ(in.position(), later);
  EXPECT_EQ(in.column(), 11u);
  std::vector<std::int32_t> v;
  vsd::meta_type<std::vector<std::int32_t>>().read_text(&v, in);
  EXPECT_EQ(v, (std::vector<std::int32_t>{1, 2}));
  in.seek(end);
  EXPECT_TRUE(in.at_end());
  in.seek(text.size() + 100);  // past the end: clamped
  EXPECT_EQ(in.position(), text.size());
  EXPECT_TRUE(in.at_end());
  in.seek(0);
  EXPECT_EQ(in.peek(), '{');
  // Errors after a seek name the position sought.
  in.seek(later + 1);
  try {
    in.fail("here");
    FAIL() << "fail() must throw";
  } catch (const vsd::Error& e) {
    EXPECT_STREQ(e.what(), "file.json:1:12: here");
  }
}

TEST(TextReader, KeysQuotedOrBare) {
  vsd::TextReader in(R"("a b" c "d\"e" ::)");
  EXPECT_EQ(in.key(), "a b");
  EXPECT_EQ(in.key(), "c");
  EXPECT_EQ(in.key(), "d\"e");
  EXPECT_THROW((void)in.key(), vsd::Error);
}

TEST(MetaTypeTextErrors, ErrorsLeaveTheTargetUsable) {
  // A failed parse into an existing value throws; the value is still a valid object afterwards.
  std::vector<std::string> v{"keep"};
  EXPECT_THROW(vsd::meta_type<std::vector<std::string>>().from_text(&v, "[\"a\", 3]"), vsd::Error);
  v.push_back("more");
  EXPECT_FALSE(v.empty());
}

// ---- binary errors: vsd::Error with "byte N"
// ----------------------------------------------------------------

TEST(MetaTypeBytesErrors, TruncatedData) {
  auto b = bytes_of(1.5);
  b.resize(5);
  const std::string e = bytes_error<double>(b);
  EXPECT_THAT(e, StartsWith("byte 0: "));
  EXPECT_THAT(e, HasSubstr("truncated"));

  EXPECT_THAT(bytes_error<std::int32_t>({}), StartsWith("byte 0: "));

  auto v = bytes_of(std::vector<double>{1, 2, 3});
  v.resize(v.size() - 1);  // the last double is cut short
  const std::string ve = bytes_error<std::vector<double>>(v);
  EXPECT_THAT(ve, StartsWith("byte "));
  EXPECT_THAT(ve, HasSubstr("exceeds")) << "the size announces 24 bytes but only 23 remain";

  auto s = bytes_of(std::vector<std::string>{"abc", "defg"});
  s.resize(s.size() - 2);
  const std::string se = bytes_error<std::vector<std::string>>(s);
  EXPECT_THAT(se, StartsWith("byte 5: ")) << "the second string's size is at byte 5";

  auto f = bytes_of(Eigen::Isometry3d(Eigen::Isometry3d::Identity()));
  f.resize(30);
  const std::string fe = bytes_error<Eigen::Isometry3d>(f);
  EXPECT_THAT(fe, StartsWith("byte 24: ")) << "the rotation starts at byte 24";
  EXPECT_THAT(fe, HasSubstr("truncated"));
}

TEST(MetaTypeBytesErrors, AbsurdSizesThrowWithoutAllocating) {
  // A size far larger than the data: must be rejected before anything is allocated.
  std::vector<std::uint8_t> b;
  vsd::ByteWriter w(b);
  w.varint(std::uint64_t{1} << 60);
  for (int i = 0; i < 16; ++i) w.u8(0);
  for (const std::string& e :
       {bytes_error<std::vector<double>>(b), bytes_error<std::vector<std::string>>(b),
        bytes_error<std::string>(b), bytes_error<std::vector<MtPose>>(b), bytes_error<std::vector<bool>>(b),
        bytes_error<std::vector<std::vector<std::int32_t>>>(b)}) {
    EXPECT_THAT(e, StartsWith("byte 0: "));
    EXPECT_THAT(e, HasSubstr("exceeds"));
  }
  // Just over what the data can hold for 8-byte elements.
  std::vector<std::uint8_t> c;
  vsd::ByteWriter cw(c);
  cw.varint(3);
  for (int i = 0; i < 23; ++i) cw.u8(0);
  EXPECT_THAT(bytes_error<std::vector<double>>(c), StartsWith("byte 0: "));
  // The maximum varint.
  std::vector<std::uint8_t> m;
  vsd::ByteWriter mw(m);
  mw.varint(std::numeric_limits<std::uint64_t>::max());
  EXPECT_THAT(bytes_error<std::vector<std::int32_t>>(m), StartsWith("byte 0: "));
}

// A count that the bytes could hold at one byte per element, of elements that take far more memory (a
// frame: 128 bytes): memory grows with what is really read, not with what the count announces.
TEST(MetaTypeBytesErrors, CountsOfBigElementsDoNotReserveAhead) {
  VSD_TEST_RUN_CAPPED();
  std::vector<std::uint8_t> b;
  vsd::ByteWriter w(b);
  w.varint(4'000'000);             // 512 MB of frames announced ...
  b.resize(b.size() + 4'000'000);  // ... in 4 MB: one frame takes 96 bytes, so they run short
  vsd_test::cap_memory(std::size_t{64} << 20);
  EXPECT_THAT(bytes_error<std::vector<Eigen::Isometry3d>>(b), HasSubstr("truncated data"));
}

TEST(MetaTypeBytesErrors, OverlongVarint) {
  const std::vector<std::uint8_t> b(11, 0xFF);
  const std::string e = bytes_error<std::string>(b);
  EXPECT_THAT(e, StartsWith("byte "));
  EXPECT_THAT(e, HasSubstr("varint"));
  const std::vector<std::uint8_t> cut{0x80, 0x80};
  EXPECT_THAT(bytes_error<std::string>(cut), HasSubstr("truncated"));
}

TEST(MetaTypeBytesErrors, BoolByteMustBeZeroOrOne) {
  const std::string e = bytes_error<bool>({7});
  EXPECT_THAT(e, HasSubstr("a bool must be 0 or 1, found 7"));
  EXPECT_THAT(e, StartsWith("byte 0: ")) << "the bad byte is byte 0";

  // In a vector<bool>: size at byte 0, elements at bytes 1 and 2.
  const std::string v = bytes_error<std::vector<bool>>({2, 1, 7});
  EXPECT_THAT(v, HasSubstr("found 7"));
  EXPECT_THAT(v, StartsWith("byte 2: ")) << "the bad byte is byte 2";
}

TEST(MetaTypeBytesErrors, TruncatedUserStruct) {
  MtPart part;
  part.name = "abc";
  part.points = {{1, 2, 3}};
  auto b = bytes_of(part);
  for (std::size_t n = 0; n < b.size(); ++n) {
    const std::vector<std::uint8_t> cut(b.begin(), b.begin() + static_cast<std::ptrdiff_t>(n));
    EXPECT_THAT(bytes_error<MtPart>(cut), StartsWith("byte ")) << "cut at " << n;
  }
}

}  // namespace
