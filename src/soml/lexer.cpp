// The SOML++ lexer: a hand-written scanner over the whole text (see lexer.hpp).
#include "vsd/soml/lexer.hpp"

#include <array>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <utility>

namespace vsd::soml {

namespace {

constexpr std::array<std::pair<std::string_view, TokenKind>, 29> keywords{{
    {"arrow", TokenKind::KwArrow},
    {"as", TokenKind::KwAs},
    {"auto", TokenKind::KwAuto},
    {"break", TokenKind::KwBreak},
    {"class", TokenKind::KwClass},
    {"continue", TokenKind::KwContinue},
    {"do", TokenKind::KwDo},
    {"else", TokenKind::KwElse},
    {"enum", TokenKind::KwEnum},
    {"false", TokenKind::KwFalse},
    {"finish", TokenKind::KwFinish},
    {"for", TokenKind::KwFor},
    {"if", TokenKind::KwIf},
    {"invoke", TokenKind::KwInvoke},
    {"is", TokenKind::KwIs},
    {"mark", TokenKind::KwMark},
    {"net", TokenKind::KwNet},
    {"new", TokenKind::KwNew},
    {"null", TokenKind::KwNull},
    {"object", TokenKind::KwObject},
    {"place", TokenKind::KwPlace},
    {"return", TokenKind::KwReturn},
    {"start", TokenKind::KwStart},
    {"this", TokenKind::KwThis},
    {"transition", TokenKind::KwTransition},
    {"true", TokenKind::KwTrue},
    {"void", TokenKind::KwVoid},
    {"when", TokenKind::KwWhen},
    {"while", TokenKind::KwWhile},
}};

bool is_alpha(char c) noexcept { return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || c == '_'; }
bool is_digit(char c) noexcept { return c >= '0' && c <= '9'; }
bool is_hex(char c) noexcept { return is_digit(c) || (c >= 'a' && c <= 'f') || (c >= 'A' && c <= 'F'); }

std::string describe_byte(unsigned char c) {
  static constexpr char hex[] = "0123456789abcdef";
  if (c >= 0x20 && c < 0x7f) return std::string("'") + static_cast<char>(c) + "'";
  return std::string("byte 0x") + hex[c >> 4] + hex[c & 15];
}

// Length of a valid UTF-8 sequence at s[at], or 0 when the bytes there are not valid UTF-8 (overlong
// forms and surrogates included).
std::size_t utf8_sequence(std::string_view s, std::size_t at) noexcept {
  const auto byte = [&](std::size_t i) -> unsigned {
    return at + i < s.size() ? static_cast<unsigned char>(s[at + i]) : 0u;
  };
  const unsigned c = byte(0);
  std::size_t n;
  unsigned min;
  if (c < 0x80) return 1;
  if (c >= 0xc2 && c <= 0xdf) {
    n = 2;
    min = 0x80;
  } else if (c >= 0xe0 && c <= 0xef) {
    n = 3;
    min = 0x800;
  } else if (c >= 0xf0 && c <= 0xf4) {
    n = 4;
    min = 0x10000;
  } else {
    return 0;
  }
  unsigned cp = c & (0x7fu >> n);
  for (std::size_t i = 1; i < n; ++i) {
    const unsigned b = byte(i);
    if ((b & 0xc0) != 0x80) return 0;
    cp = (cp << 6) | (b & 0x3f);
  }
  if (cp < min || cp > 0x10ffff || (cp >= 0xd800 && cp <= 0xdfff)) return 0;
  return n;
}

}  // namespace

std::string_view token_kind_name(TokenKind k) noexcept {
  switch (k) {
    case TokenKind::Int:
      return "integer";
    case TokenKind::Float:
      return "number";
    case TokenKind::String:
      return "string";
    case TokenKind::Identifier:
      return "identifier";
    case TokenKind::LParen:
      return "'('";
    case TokenKind::RParen:
      return "')'";
    case TokenKind::LBrace:
      return "'{'";
    case TokenKind::RBrace:
      return "'}'";
    case TokenKind::LBracket:
      return "'['";
    case TokenKind::RBracket:
      return "']'";
    case TokenKind::Comma:
      return "','";
    case TokenKind::Semicolon:
      return "';'";
    case TokenKind::Colon:
      return "':'";
    case TokenKind::ColonColon:
      return "'::'";
    case TokenKind::Dot:
      return "'.'";
    case TokenKind::Question:
      return "'?'";
    case TokenKind::Plus:
      return "'+'";
    case TokenKind::Minus:
      return "'-'";
    case TokenKind::Star:
      return "'*'";
    case TokenKind::Slash:
      return "'/'";
    case TokenKind::Percent:
      return "'%'";
    case TokenKind::Bang:
      return "'!'";
    case TokenKind::AmpAmp:
      return "'&&'";
    case TokenKind::PipePipe:
      return "'||'";
    case TokenKind::EqualEqual:
      return "'=='";
    case TokenKind::BangEqual:
      return "'!='";
    case TokenKind::Less:
      return "'<'";
    case TokenKind::LessEqual:
      return "'<='";
    case TokenKind::Greater:
      return "'>'";
    case TokenKind::GreaterEqual:
      return "'>='";
    case TokenKind::Equal:
      return "'='";
    case TokenKind::PlusEqual:
      return "'+='";
    case TokenKind::MinusEqual:
      return "'-='";
    case TokenKind::StarEqual:
      return "'*='";
    case TokenKind::SlashEqual:
      return "'/='";
    case TokenKind::PercentEqual:
      return "'%='";
    case TokenKind::PlusPlus:
      return "'++'";
    case TokenKind::MinusMinus:
      return "'--'";
    case TokenKind::Arrow:
      return "'->'";
    case TokenKind::TildeArrow:
      return "'~>'";
    case TokenKind::Error:
      return "invalid token";
    case TokenKind::Eof:
      return "end of file";
    default:
      for (const auto& [text, kind] : keywords)
        if (kind == k) return text;
      return "token";
  }
}

std::vector<Token> Lexer::tokenize() {
  std::vector<Token> tokens;
  // Typical scripts have one token per four to six bytes: one allocation instead of a dozen regrowths.
  tokens.reserve(text().size() / 4 + 16);
  for (;;) {
    tokens.push_back(next());
    if (tokens.back().kind == TokenKind::Eof) return tokens;
  }
}

Token Lexer::make(TokenKind k, std::size_t start) {
  Token t;
  t.kind = k;
  t.loc = source_.locate(start);
  t.text = std::string_view(text()).substr(start, pos_ - start);
  return t;
}

void Lexer::skip_space_and_comments() {
  for (;;) {
    const char c = peek();
    if (at_end()) return;
    if (c == ' ' || c == '\t' || c == '\n' || c == '\r' || c == '\f' || c == '\v') {
      ++pos_;
    } else if (c == '/' && peek(1) == '/') {
      while (!at_end() && peek() != '\n') ++pos_;
    } else if (c == '/' && peek(1) == '*') {
      const std::size_t start = pos_;
      pos_ += 2;
      while (!at_end() && !(peek() == '*' && peek(1) == '/')) ++pos_;
      if (at_end()) {
        diag_.error(source_.locate(start), "unterminated comment");
        return;
      }
      pos_ += 2;
    } else {
      return;
    }
  }
}

Token Lexer::next() {
  for (;;) {
    skip_space_and_comments();
    const std::size_t start = pos_;
    if (at_end()) return make(TokenKind::Eof, start);
    const char c = text()[pos_++];
    if (is_alpha(c)) return identifier(start);
    if (is_digit(c) || (c == '.' && is_digit(peek()))) return number(start);
    const auto one_or = [&](char second, TokenKind two, TokenKind one) {
      if (peek() == second) {
        ++pos_;
        return make(two, start);
      }
      return make(one, start);
    };
    switch (c) {
      case '(':
        return make(TokenKind::LParen, start);
      case ')':
        return make(TokenKind::RParen, start);
      case '{':
        return make(TokenKind::LBrace, start);
      case '}':
        return make(TokenKind::RBrace, start);
      case '[':
        return make(TokenKind::LBracket, start);
      case ']':
        return make(TokenKind::RBracket, start);
      case ',':
        return make(TokenKind::Comma, start);
      case ';':
        return make(TokenKind::Semicolon, start);
      case '.':
        return make(TokenKind::Dot, start);
      case '?':
        return make(TokenKind::Question, start);
      case ':':
        return one_or(':', TokenKind::ColonColon, TokenKind::Colon);
      case '*':
        return one_or('=', TokenKind::StarEqual, TokenKind::Star);
      case '/':
        return one_or('=', TokenKind::SlashEqual, TokenKind::Slash);
      case '%':
        return one_or('=', TokenKind::PercentEqual, TokenKind::Percent);
      case '!':
        return one_or('=', TokenKind::BangEqual, TokenKind::Bang);
      case '=':
        return one_or('=', TokenKind::EqualEqual, TokenKind::Equal);
      case '<':
        return one_or('=', TokenKind::LessEqual, TokenKind::Less);
      case '>':
        return one_or('=', TokenKind::GreaterEqual, TokenKind::Greater);
      case '+':
        if (peek() == '+') {
          ++pos_;
          return make(TokenKind::PlusPlus, start);
        }
        return one_or('=', TokenKind::PlusEqual, TokenKind::Plus);
      case '-':
        if (peek() == '-') {
          ++pos_;
          return make(TokenKind::MinusMinus, start);
        }
        if (peek() == '>') {
          ++pos_;
          return make(TokenKind::Arrow, start);
        }
        return one_or('=', TokenKind::MinusEqual, TokenKind::Minus);
      case '&':
        if (peek() == '&') {
          ++pos_;
          return make(TokenKind::AmpAmp, start);
        }
        break;
      case '|':
        if (peek() == '|') {
          ++pos_;
          return make(TokenKind::PipePipe, start);
        }
        break;
      case '~':
        if (peek() == '>') {
          ++pos_;
          return make(TokenKind::TildeArrow, start);
        }
        break;
      case '"':
        return string(start);
      default:
        break;
    }
    // Not a token: report the run of bad bytes once and go on after it.
    const auto u = static_cast<unsigned char>(c);
    if (u >= 0x80) {
      pos_ = start;
      const std::size_t n = utf8_sequence(text(), start);
      if (n == 0) {
        while (!at_end() && static_cast<unsigned char>(peek()) >= 0x80 && utf8_sequence(text(), pos_) == 0)
          ++pos_;
        diag_.error(source_.locate(start), "invalid UTF-8 in the source text");
      } else {
        pos_ += n;
        diag_.error(source_.locate(start), "unexpected character '" + text().substr(start, n) +
                                               "' (non-ASCII text belongs in strings and comments)");
      }
    } else {
      diag_.error(source_.locate(start), "unexpected character " + describe_byte(u));
    }
  }
}

Token Lexer::identifier(std::size_t start) {
  while (is_alpha(peek()) || is_digit(peek())) ++pos_;
  Token t = make(TokenKind::Identifier, start);
  for (const auto& [text, kind] : keywords)
    if (text == t.text) t.kind = kind;
  return t;
}

Token Lexer::number(std::size_t start) {
  pos_ = start;
  if (peek() == '0' && (peek(1) == 'x' || peek(1) == 'X')) {
    pos_ += 2;
    const std::size_t digits = pos_;
    while (is_hex(peek())) ++pos_;
    Token t = make(TokenKind::Int, start);
    if (pos_ == digits) {
      diag_.error(t.loc, "hexadecimal literal without digits");
      return t;
    }
    std::uint64_t v = 0;
    bool overflow = false;
    for (std::size_t i = digits; i < pos_; ++i) {
      const char h = text()[i];
      const unsigned d = is_digit(h) ? unsigned(h - '0') : unsigned((h | 0x20) - 'a' + 10);
      if (v > (std::uint64_t{0x7fffffffffffffff} >> 4)) overflow = true;
      v = (v << 4) | d;
    }
    if (overflow || v > std::uint64_t{0x7fffffffffffffff})
      diag_.error(t.loc, "integer literal '" + std::string(t.text) + "' does not fit in int (64 bits)");
    else
      t.int_value = static_cast<std::int64_t>(v);
    return t;
  }
  bool is_float = false;
  while (is_digit(peek())) ++pos_;
  if (peek() == '.' && is_digit(peek(1))) {
    is_float = true;
    ++pos_;
    while (is_digit(peek())) ++pos_;
  } else if (peek() == '.' && !is_alpha(peek(1)) && pos_ > start) {
    // "1." is a double, "v.x" and "a.b" are members; "1.x" would be a member of 1, which is an error later.
    is_float = true;
    ++pos_;
  }
  if ((peek() == 'e' || peek() == 'E') &&
      (is_digit(peek(1)) || ((peek(1) == '+' || peek(1) == '-') && is_digit(peek(2))))) {
    is_float = true;
    pos_ += 2;
    while (is_digit(peek())) ++pos_;
  }
  Token t = make(is_float ? TokenKind::Float : TokenKind::Int, start);
  if (is_alpha(peek())) {
    const std::size_t bad = pos_;
    while (is_alpha(peek()) || is_digit(peek())) ++pos_;
    diag_.error(source_.locate(bad), "invalid suffix '" + text().substr(bad, pos_ - bad) + "' on number");
  }
  const std::string digits(t.text);
  errno = 0;
  if (is_float) {
    t.float_value = std::strtod(digits.c_str(), nullptr);
    if (errno == ERANGE && std::isinf(t.float_value))
      diag_.error(t.loc, "number '" + digits + "' is too large for double");
  } else {
    const long long v = std::strtoll(digits.c_str(), nullptr, 10);
    if (errno == ERANGE)
      diag_.error(t.loc, "integer literal '" + digits + "' does not fit in int (64 bits)");
    else
      t.int_value = v;
  }
  return t;
}

namespace {

// One pass over a string literal starting at s[pos] (the opening quote). Appends the value to *out and
// reports problems through report(offset, message) when given. Returns the offset after the literal
// (after the closing quote, or at the line break or end where an unterminated literal stops).
template <class Report>
std::size_t scan_string(std::string_view s, std::size_t pos, std::string* out, Report report,
                        bool& terminated) {
  bool bad_utf8 = false;
  ++pos;  // opening quote
  while (pos < s.size() && s[pos] != '\n') {
    const char c = s[pos];
    if (c == '"') {
      terminated = true;
      return pos + 1;
    }
    if (c == '\\') {
      if (pos + 1 >= s.size() || s[pos + 1] == '\n') {
        ++pos;  // a backslash at the end of the line: the string is unterminated
        continue;
      }
      char v = 0;
      switch (s[pos + 1]) {
        case 'n':
          v = '\n';
          break;
        case 't':
          v = '\t';
          break;
        case 'r':
          v = '\r';
          break;
        case '\\':
          v = '\\';
          break;
        case '"':
          v = '"';
          break;
        case '0':
          v = '\0';
          break;
        default:
          report(pos, "unknown escape sequence '\\" + std::string(1, s[pos + 1]) + "'");
          pos += 2;
          continue;
      }
      if (out != nullptr) *out += v;
      pos += 2;
      continue;
    }
    const std::size_t n = static_cast<unsigned char>(c) < 0x80 ? 1 : utf8_sequence(s, pos);
    if (n == 0) {
      if (!bad_utf8) report(pos, "invalid UTF-8 in string");
      bad_utf8 = true;
      ++pos;
      continue;
    }
    if (out != nullptr) out->append(s, pos, n);
    pos += n;
  }
  terminated = false;
  return pos;
}

}  // namespace

std::string decode_string_literal(std::string_view token_text) {
  std::string value;
  bool terminated = false;
  if (token_text.empty() || token_text.front() != '"') return value;
  scan_string(
      token_text, 0, &value, [](std::size_t, const std::string&) {}, terminated);
  return value;
}

Token Lexer::string(std::size_t start) {
  bool terminated = false;
  pos_ = scan_string(
      text(), start, nullptr,
      [&](std::size_t at, const std::string& message) { diag_.error(source_.locate(at), message); },
      terminated);
  Token t = make(TokenKind::String, start);
  if (!terminated) diag_.error(t.loc, "unterminated string");
  return t;
}

}  // namespace vsd::soml
