/** @file
 *  @brief The SOML++ parser: tokens to AST, with error recovery.
 *
 *  A recursive-descent parser for declarations and statements and a Pratt parser (precedence climbing
 *  over a rule per token) for expressions, after Wren's compiler. On a syntax error it reports one
 *  diagnostic, skips to the next statement or declaration boundary and goes on, so that one run reports
 *  every syntax error of a file. Nesting deeper than `max_depth` is an error (no stack overflow on
 *  hostile input).
 */
#pragma once

#include <cstddef>
#include <vector>

#include "vsd/soml/ast.hpp"
#include "vsd/soml/lexer.hpp"
#include "vsd/soml/source.hpp"

namespace vsd::soml {

/// @brief Parses a whole script. Syntax errors go to @p diagnostics; the returned AST holds everything
/// that could be parsed (a declaration with an error is dropped or kept partially).
[[nodiscard]] Script parse(const Source& source, Diagnostics& diagnostics);

/// @brief The parser behind `parse()`, for callers that already hold tokens.
class Parser {
 public:
  /// @brief Deepest nesting of blocks, declarations and expressions accepted (a chain of n binary
  /// operators counts as n levels: the tree it makes is that deep).
  static constexpr int max_depth = 256;

  Parser(const Source& source, std::vector<Token> tokens, Diagnostics& diagnostics);
  /// @brief Parses all tokens into a script.
  [[nodiscard]] Script parse_script();

 private:
  struct Abort {};  // unwinds to the nearest recovery point after a syntax error was reported
  class DepthGuard;

  // tokens
  [[nodiscard]] const Token& peek(std::size_t ahead = 0) const noexcept;
  [[nodiscard]] bool check(TokenKind k) const noexcept { return peek().kind == k; }
  bool match(TokenKind k);
  const Token& advance();
  const Token& expect(TokenKind k, const char* what);
  [[noreturn]] void fail(const Token& at, const std::string& message);
  [[noreturn]] void too_deep(const Token& at);
  void sync_member();
  void sync_statement();

  // declarations
  void parse_members(ScopeDecl& scope, bool braced);
  void parse_member(ScopeDecl& scope);
  std::vector<std::string> parse_qualified(SourceLoc* loc = nullptr);
  std::vector<std::string> parse_path(SourceLoc* loc = nullptr);
  TypeName parse_type();
  bool scan_type(std::size_t& i) const noexcept;
  DeclPtr parse_enum();
  DeclPtr parse_class(DeclKind kind);
  DeclPtr parse_net();
  DeclPtr parse_place(ScopeDecl& scope);
  DeclPtr parse_transition();
  void parse_transition_clause(struct TransitionDecl& t);
  DeclPtr parse_arrow();
  DeclPtr parse_start();
  std::vector<Param> parse_params(bool allow_places);
  void parse_function_or_properties(ScopeDecl& scope);
  std::vector<ExprPtr> parse_args();  // after '(' up to and including ')'

  // statements
  std::unique_ptr<BlockStmt> parse_block();
  StmtPtr parse_statement();
  bool is_declaration_start() const noexcept;
  std::unique_ptr<LocalStmt> parse_local(bool expect_semicolon);

  // expressions
  ExprPtr parse_expr(int min_precedence = 1);
  ExprPtr parse_prefix();

  const Source& source_;
  std::vector<Token> tokens_;
  Diagnostics& diag_;
  std::size_t pos_ = 0;
  int depth_ = 0;
  bool eof_reported_ = false;  // a missing '}' at the end is reported once, not once per open body
};

}  // namespace vsd::soml
