// Printable names and JSON strings (tools/support/vsd_tool/text.hpp).
#include "vsd_tool/text.hpp"

#include <gtest/gtest.h>

#include <string>

namespace vsd_tool_text_test {
namespace {

using vsd::tool::json_string;
using vsd::tool::printable;
using vsd::tool::printable_lines;

TEST(ToolText, ControlCharactersBecomeQuestionMarks) {
  EXPECT_EQ(printable("plain name"), "plain name");
  EXPECT_EQ(printable("tab\tkept"), "tab\tkept");
  EXPECT_EQ(printable("esc\x1b[2Jbell\x07nul" + std::string(1, '\0') + "del\x7f"), "esc?[2Jbell?nul?del?");
  EXPECT_EQ(printable("line\nbreak\r"), "line?break?");
  EXPECT_EQ(printable_lines("line\nbreak\r"), "line\nbreak?");
  EXPECT_EQ(printable("c1 \xc2\x9b" "31m"), "c1 ?31m");   // U+009B (CSI) in UTF-8
  EXPECT_EQ(printable("ümlaut é 日本"), "ümlaut é 日本");  // UTF-8 is kept
}

TEST(ToolText, JsonStringsAreAlwaysValidJson) {
  EXPECT_EQ(json_string("plain"), "\"plain\"");
  EXPECT_EQ(json_string("q\"b\\s/"), "\"q\\\"b\\\\s/\"");
  EXPECT_EQ(json_string("\n\t\r\b\f"), "\"\\n\\t\\r\\u0008\\u000c\"");
  EXPECT_EQ(json_string(std::string("\x01\x1f\x7f", 3)), "\"\\u0001\\u001f\x7f\"");  // DEL is valid JSON
  EXPECT_EQ(json_string(std::string(1, '\0')), "\"\\u0000\"");
  EXPECT_EQ(json_string("ü日本😀"), "\"ü日本😀\"");
  // Bytes that are not UTF-8: the replacement character U+FFFD, never the raw byte.
  const std::string fffd = "\xEF\xBF\xBD";
  EXPECT_EQ(json_string("a\xff" "b"), "\"a" + fffd + "b\"");
  EXPECT_EQ(json_string("\xc3"), "\"" + fffd + "\"");                        // a cut sequence
  EXPECT_EQ(json_string("\xc0\xaf"), "\"" + fffd + fffd + "\"");              // an overlong '/'
  EXPECT_EQ(json_string("\xed\xa0\x80"), "\"" + fffd + fffd + fffd + "\"");  // a surrogate
}

}  // namespace
}  // namespace vsd_tool_text_test
