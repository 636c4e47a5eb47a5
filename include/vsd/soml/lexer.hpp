/** @file
 *  @brief Tokens of SOML++ and the lexer that makes them.
 *
 *  The lexer turns a whole Source into a vector of tokens ending in `Eof` (the parser looks ahead and
 *  backtracks over it freely). It never fails: a bad character, an unterminated string or comment, an
 *  out-of-range number or invalid UTF-8 is reported to the Diagnostics and lexing goes on, yielding an
 *  `Error` token where nothing sensible can be made.
 */
#pragma once

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "vsd/soml/source.hpp"

namespace vsd::soml {

/// @brief The kinds of token.
enum class TokenKind : unsigned char {
  // literals and names
  Int,
  Float,
  String,
  Identifier,
  // punctuation
  LParen,
  RParen,
  LBrace,
  RBrace,
  LBracket,
  RBracket,
  Comma,
  Semicolon,
  Colon,
  ColonColon,
  Dot,
  Question,
  // operators
  Plus,
  Minus,
  Star,
  Slash,
  Percent,
  Bang,
  AmpAmp,
  PipePipe,
  EqualEqual,
  BangEqual,
  Less,
  LessEqual,
  Greater,
  GreaterEqual,
  Equal,
  PlusEqual,
  MinusEqual,
  StarEqual,
  SlashEqual,
  PercentEqual,
  PlusPlus,
  MinusMinus,
  Arrow,       // ->
  TildeArrow,  // ~>   (the inhibitor arrow -o is a Minus directly followed by the identifier o)
  // keywords
  KwArrow,
  KwAs,
  KwAuto,
  KwBreak,
  KwClass,
  KwContinue,
  KwDo,
  KwElse,
  KwEnum,
  KwFalse,
  KwFinish,
  KwFor,
  KwIf,
  KwInvoke,
  KwIs,
  KwMark,
  KwNet,
  KwNew,
  KwNull,
  KwObject,
  KwPlace,
  KwReturn,
  KwStart,
  KwThis,
  KwTransition,
  KwTrue,
  KwVoid,
  KwWhen,
  KwWhile,
  // end and errors
  Error,
  Eof
};

/// @brief How a token kind is written, for messages ("'->'", "identifier", "end of file").
[[nodiscard]] std::string_view token_kind_name(TokenKind k) noexcept;

/// @brief One token. `text` points into the Source's text.
struct Token {
  TokenKind kind = TokenKind::Eof;
  SourceLoc loc;
  std::string_view text;
  std::int64_t int_value = 0;  ///< Int
  double float_value = 0.0;    ///< Float
  // A String's value is not stored: tokens stay small (a big script has hundreds of thousands), and
  // decode_string_literal() makes it from `text` when the parser needs it.
};

/// @brief The value of a string literal token's text (escapes resolved, invalid bytes dropped; the
/// lexer has reported any problem already).
[[nodiscard]] std::string decode_string_literal(std::string_view token_text);

/// @brief Splits a Source into tokens.
class Lexer {
 public:
  /// @brief Lexes @p source, reporting problems to @p diagnostics.
  Lexer(const Source& source, Diagnostics& diagnostics) : source_(source), diag_(diagnostics) {}

  /// @brief All tokens of the source; the last one is Eof.
  [[nodiscard]] std::vector<Token> tokenize();

 private:
  Token next();
  void skip_space_and_comments();
  Token make(TokenKind k, std::size_t start);
  Token number(std::size_t start);
  Token string(std::size_t start);
  Token identifier(std::size_t start);
  [[nodiscard]] char peek(std::size_t ahead = 0) const noexcept {
    return pos_ + ahead < text().size() ? text()[pos_ + ahead] : '\0';
  }
  [[nodiscard]] bool at_end() const noexcept { return pos_ >= text().size(); }
  [[nodiscard]] const std::string& text() const noexcept { return source_.text(); }

  const Source& source_;
  Diagnostics& diag_;
  std::size_t pos_ = 0;
};

}  // namespace vsd::soml
