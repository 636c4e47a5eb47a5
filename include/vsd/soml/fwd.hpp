/** @file
 *  @brief Forward declarations of vsd::soml, the SOML++ module (the paper's VSDNet).
 */
#pragma once

namespace vsd::soml {
struct SourceLoc;
class Source;
struct Diagnostic;
class Diagnostics;
enum class TokenKind : unsigned char;
struct Token;
class Lexer;
struct TypeName;
struct Expr;
struct Stmt;
struct Decl;
struct Script;
class Parser;
struct Type;
struct Binding;
struct CheckResult;
}  // namespace vsd::soml
