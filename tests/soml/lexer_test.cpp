// Tests of include/vsd/soml/lexer.hpp and source.hpp: tokens, positions, and bad input.
#include "vsd/soml/lexer.hpp"
#include "vsd/soml/checker.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <string>
#include <vector>

using testing::HasSubstr;
using vsd::soml::Diagnostics;
using vsd::soml::Lexer;
using vsd::soml::Source;
using vsd::soml::Token;
using vsd::soml::TokenKind;

namespace {

struct Lexed {
  Source source;
  Diagnostics diag;
  std::vector<Token> tokens;
  explicit Lexed(std::string text) : source("t.soml", std::move(text)), diag(source) {
    tokens = Lexer(source, diag).tokenize();
  }
  std::vector<TokenKind> kinds() const {
    std::vector<TokenKind> k;
    for (const Token& t : tokens) k.push_back(t.kind);
    return k;
  }
};

TEST(Lexer, SplitsKeywordsNamesAndOperators) {
  Lexed l("arrow p -> t; a ~> b; x -o y; i += 1; a::b <= c && !d || e != f");
  using K = TokenKind;
  EXPECT_EQ(l.kinds(),
            (std::vector<K>{K::KwArrow,    K::Identifier, K::Arrow,      K::Identifier, K::Semicolon,
                            K::Identifier, K::TildeArrow, K::Identifier, K::Semicolon,  K::Identifier,
                            K::Minus,      K::Identifier, K::Identifier, K::Semicolon,  K::Identifier,
                            K::PlusEqual,  K::Int,        K::Semicolon,  K::Identifier, K::ColonColon,
                            K::Identifier, K::LessEqual,  K::Identifier, K::AmpAmp,     K::Bang,
                            K::Identifier, K::PipePipe,   K::Identifier, K::BangEqual,  K::Identifier,
                            K::Eof}));
  EXPECT_FALSE(l.diag.has_errors());
}

TEST(Lexer, ReadsNumbersAndStrings) {
  Lexed l(R"(42 0x2A 1.5 .5 2e-3 1. "a\tb\"c\\" "µm")");
  ASSERT_EQ(l.tokens.size(), 9u);
  EXPECT_EQ(l.tokens[0].int_value, 42);
  EXPECT_EQ(l.tokens[1].int_value, 42);
  EXPECT_DOUBLE_EQ(l.tokens[2].float_value, 1.5);
  EXPECT_DOUBLE_EQ(l.tokens[3].float_value, 0.5);
  EXPECT_DOUBLE_EQ(l.tokens[4].float_value, 2e-3);
  EXPECT_EQ(l.tokens[5].kind, TokenKind::Float);
  EXPECT_EQ(vsd::soml::decode_string_literal(l.tokens[6].text), "a\tb\"c\\");
  EXPECT_EQ(vsd::soml::decode_string_literal(l.tokens[7].text), "µm");
  EXPECT_FALSE(l.diag.has_errors()) << l.diag.format();
}

TEST(Lexer, PositionsAreLineAndByteColumn) {
  Lexed l("class A {\n  int x;\n}");
  ASSERT_GE(l.tokens.size(), 5u);
  EXPECT_EQ(l.tokens[3].text, "int");
  EXPECT_EQ(l.tokens[3].loc.line, 2u);
  EXPECT_EQ(l.tokens[3].loc.column, 3u);
}

TEST(Lexer, SkipsComments) {
  Lexed l("a // line comment\n/* block\n comment */ b");
  EXPECT_EQ(l.kinds(),
            (std::vector<TokenKind>{TokenKind::Identifier, TokenKind::Identifier, TokenKind::Eof}));
}

TEST(Lexer, ReportsBadInputAndGoesOn) {
  Lexed l("a # b \"open\n c 99999999999999999999 /* never closed");
  EXPECT_EQ(l.diag.error_count(), 4u) << l.diag.format();
  const std::string out = l.diag.format();
  EXPECT_THAT(out, HasSubstr("t.soml:1:3: error: unexpected character '#'"));
  EXPECT_THAT(out, HasSubstr("t.soml:1:7: error: unterminated string"));
  EXPECT_THAT(out, HasSubstr("does not fit in int (64 bits)"));
  EXPECT_THAT(out, HasSubstr("t.soml:2:25: error: unterminated comment"));
  // The good tokens are still there.
  ASSERT_GE(l.tokens.size(), 4u);
  EXPECT_EQ(l.tokens[1].text, "b");
  EXPECT_EQ(l.tokens[3].text, "c");
}

TEST(Lexer, RejectsInvalidUtf8AndNulBytes) {
  std::string text = "a \xff\xfe b \"x\xc3\x28y\" ";
  text += '\0';
  text += " c";
  Lexed l(text);
  const std::string out = l.diag.format();
  EXPECT_THAT(out, HasSubstr("invalid UTF-8 in the source text"));
  EXPECT_THAT(out, HasSubstr("invalid UTF-8 in string"));
  EXPECT_THAT(out, HasSubstr("unexpected character byte 0x00"));
  EXPECT_EQ(l.diag.error_count(), 3u);
  // The rendering never prints the raw NUL or control bytes.
  EXPECT_EQ(out.find('\0'), std::string::npos);
  EXPECT_EQ(l.tokens.back().kind, TokenKind::Eof);
}

TEST(Lexer, StringsEndingInABackslashAtTheEndOfTheText) {
  for (const char* text : {"\"abc\\", "\"\\", "\"", "x = \"a\\\n"}) {
    Lexed l(text);
    EXPECT_THAT(l.diag.format(), HasSubstr("unterminated string")) << text;
    EXPECT_EQ(l.tokens.back().kind, TokenKind::Eof);
  }
}

TEST(Diagnostics, FormatShowsTheLineAndACaret) {
  Source src("robot.soml", "int a;\n  x = foo + 1;\n");
  Diagnostics d(src);
  d.error(src.locate(src.text().find("foo")), "undefined name 'foo'");
  EXPECT_EQ(d.format(), "robot.soml:2:7: error: undefined name 'foo'\n    x = foo + 1;\n        ^\n");
}

TEST(Diagnostics, KeepsAtMostAFixedNumberAndCountsAll) {
  Source src("s", "x");
  Diagnostics d(src);
  for (int i = 0; i < 1000; ++i) d.error(src.locate(0), "e");
  EXPECT_EQ(d.all().size(), Diagnostics::max_diagnostics);
  EXPECT_EQ(d.error_count(), 1000u);
  EXPECT_THAT(d.all().back().message, HasSubstr("too many errors"));
}

// Positions are 32-bit: a longer text would be located wrongly, so the front end refuses it whole.
TEST(Source, AScriptLongerThanTheLimitIsOneErrorAtItsStart) {
  constexpr std::size_t max_source_bytes = vsd::soml::max_source_bytes;
  std::string text(max_source_bytes + 1, ' ');
  text.replace(0, 9, "int x = ;");  // would be a syntax error: not reached
  const auto checked = vsd::soml::check_source("huge.soml", std::move(text));
  ASSERT_EQ(checked->diagnostics.all().size(), 1u);
  EXPECT_EQ(checked->source->text().size(), max_source_bytes);
  EXPECT_THAT(checked->diagnostics.format(),
              HasSubstr("huge.soml:1:1: error: the script is " + std::to_string(max_source_bytes + 1) +
                        " bytes, larger than the limit of " + std::to_string(max_source_bytes) +
                        " bytes of a SOML++ source"));
}

}  // namespace
