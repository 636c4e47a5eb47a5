// The tools' argument grammar and strict numbers (tools/support/vsd_tool/arguments.hpp).
#include "vsd_tool/arguments.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cstdint>
#include <limits>
#include <string>
#include <vector>

namespace vsd_tool_arguments_test {
namespace {

using testing::ElementsAre;
using testing::HasSubstr;
using vsd::tool::Arguments;
using vsd::tool::flag;
using vsd::tool::repeated;
using vsd::tool::UsageError;
using vsd::tool::with_value;

Arguments parse(std::vector<std::string_view> args) {
  return Arguments(args, {flag("--json"), with_value("--dt"), repeated("--path")});
}

std::string usage_error(std::vector<std::string_view> args) {
  try {
    (void)parse(args);
  } catch (const UsageError& e) {
    return e.what();
  }
  return "";
}

TEST(ToolArguments, OptionsFlagsAndPositionals) {
  const Arguments a = parse({"in.json", "--json", "--dt", "0.5", "--path=a", "--path", "b", "-", "--", "--dt"});
  EXPECT_TRUE(a.has("--json"));
  EXPECT_EQ(a.value("--dt"), "0.5");
  EXPECT_THAT(a.values("--path"), ElementsAre("a", "b"));
  EXPECT_THAT(a.positional(), ElementsAre("in.json", "-", "--dt"));  // "-" and anything after "--"
  EXPECT_FALSE(parse({}).has("--json"));
  EXPECT_EQ(parse({}).value("--dt"), std::nullopt);
}

TEST(ToolArguments, UsageErrors) {
  EXPECT_EQ(usage_error({"--bogus"}), "unknown option '--bogus'");
  EXPECT_EQ(usage_error({"--dt"}), "--dt needs a value");
  EXPECT_EQ(usage_error({"--dt", "1", "--dt", "2"}), "--dt is given twice");
  EXPECT_EQ(usage_error({"--json=yes"}), "--json takes no value");
  EXPECT_EQ(usage_error({"--bad\x1b[2J"}), "unknown option '--bad?[2J'");  // never echoed raw
  const Arguments a = parse({"a", "b"});
  EXPECT_NO_THROW(a.expect_positional(2, 2, "IN and OUT"));
  try {
    a.expect_positional(1, 1, "one FILE");
    FAIL();
  } catch (const UsageError& e) {
    EXPECT_STREQ(e.what(), "takes one FILE; 'b' is one too many");
  }
  EXPECT_THROW(a.expect_positional(3, 3, "three"), UsageError);
}

TEST(ToolArguments, RealsAreExactlyFiniteNumbersInRange) {
  using vsd::tool::parse_real;
  EXPECT_EQ(parse_real("0.25", "--dt", 0, 1), 0.25);
  EXPECT_EQ(parse_real("1e-3", "--dt", 0, 1), 0.001);
  EXPECT_EQ(parse_real("-2", "--x", -5, 5), -2);
  for (const char* bad : {"", "abc", "1x", " 1", "1 ", "+1", "0x10", "inf", "-inf", "nan", "1,5", "1e999"})
    EXPECT_THROW(parse_real(bad, "--dt", -1e300, 1e300), UsageError) << bad;
  try {
    parse_real("1e6", "--dt", 1e-6, 1);
    FAIL();
  } catch (const UsageError& e) {
    EXPECT_STREQ(e.what(), "--dt: '1e6' is out of range (1e-06 to 1)");
  }
  try {
    parse_real("abc", "--for", 0, 1);
    FAIL();
  } catch (const UsageError& e) {
    EXPECT_STREQ(e.what(), "--for: 'abc' is not a number");
  }
}

TEST(ToolArguments, IntegersAreExactlyIntegersInRange) {
  using vsd::tool::parse_integer;
  using vsd::tool::parse_unsigned;
  EXPECT_EQ(parse_integer("230", "--domain", 0, 230), 230);
  EXPECT_EQ(parse_integer("-7", "--n", -10, 10), -7);
  for (const char* bad : {"", "abc", "1.5", "1e3", " 1", "0x1", "--1"})
    EXPECT_THROW(parse_integer(bad, "--domain", -1000, 1000), UsageError) << bad;
  // Values that do not fit are out of range, never wrapped (99999999999 is not 1215752191).
  try {
    parse_integer("99999999999", "--domain", 0, 230);
    FAIL();
  } catch (const UsageError& e) {
    EXPECT_STREQ(e.what(), "--domain: '99999999999' is out of range (0 to 230)");
  }
  EXPECT_THROW(parse_integer("99999999999999999999999", "--n", INT64_MIN, INT64_MAX), UsageError);
  EXPECT_EQ(parse_unsigned("18446744073709551615", "--seed", UINT64_MAX), UINT64_MAX);
  EXPECT_THROW(parse_unsigned("18446744073709551616", "--seed", UINT64_MAX), UsageError);
  EXPECT_THROW(parse_unsigned("-1", "--seed", UINT64_MAX), UsageError);
  EXPECT_THROW(parse_unsigned("1025", "--threads", 1024), UsageError);
}

TEST(ToolArguments, ListsOfReals) {
  using vsd::tool::parse_reals;
  EXPECT_THAT(parse_reals("0,-1.5,2e-3", "--q"), ElementsAre(0, -1.5, 0.002));
  EXPECT_THAT(parse_reals("7", "--q"), ElementsAre(7));
  for (const char* bad : {"", ",", "1,", ",1", "1,,2", "1,x", "1, 2", "inf,0", "1,nan"})
    EXPECT_THROW(parse_reals(bad, "--q"), UsageError) << bad;
}

TEST(ToolArguments, TypedGetters) {
  const Arguments a = parse({"--dt", "0.5"});
  EXPECT_EQ(a.real("--dt", 1, 0, 1), 0.5);
  EXPECT_EQ(parse({}).real("--dt", 0.001, 0, 1), 0.001);
  EXPECT_THROW((void)parse({"--dt", "2"}).real("--dt", 1, 0, 1), UsageError);
  EXPECT_EQ(vsd::tool::number_text(0.001), "0.001");
  EXPECT_EQ(vsd::tool::number_text(-0.0), "0");
  EXPECT_EQ(vsd::tool::number_text(1e17), "1e+17");
}

}  // namespace
}  // namespace vsd_tool_arguments_test
