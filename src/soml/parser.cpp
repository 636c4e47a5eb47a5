// The SOML++ parser (see parser.hpp): recursive descent for declarations and statements, Pratt parsing
// for expressions, recovery at statement and declaration boundaries.
#include "vsd/soml/parser.hpp"

#include <utility>

namespace vsd::soml {

namespace {

// Binding power of infix and postfix operators; 0 means "not an infix operator".
enum Precedence : int {
  PrecNone = 0,
  PrecAssign = 1,
  PrecConditional = 2,
  PrecOr = 3,
  PrecAnd = 4,
  PrecEquality = 5,
  PrecRelation = 6,
  PrecAdditive = 7,
  PrecTerm = 8,
  PrecUnary = 9,
  PrecPostfix = 10
};

int infix_precedence(TokenKind k) noexcept {
  switch (k) {
    case TokenKind::Equal:
    case TokenKind::PlusEqual:
    case TokenKind::MinusEqual:
    case TokenKind::StarEqual:
    case TokenKind::SlashEqual:
    case TokenKind::PercentEqual:
      return PrecAssign;
    case TokenKind::Question:
      return PrecConditional;
    case TokenKind::PipePipe:
      return PrecOr;
    case TokenKind::AmpAmp:
      return PrecAnd;
    case TokenKind::EqualEqual:
    case TokenKind::BangEqual:
      return PrecEquality;
    case TokenKind::Less:
    case TokenKind::LessEqual:
    case TokenKind::Greater:
    case TokenKind::GreaterEqual:
    case TokenKind::KwIs:
    case TokenKind::KwAs:
      return PrecRelation;
    case TokenKind::Plus:
    case TokenKind::Minus:
      return PrecAdditive;
    case TokenKind::Star:
    case TokenKind::Slash:
    case TokenKind::Percent:
      return PrecTerm;
    case TokenKind::LParen:
    case TokenKind::Dot:
    case TokenKind::LBracket:
    case TokenKind::PlusPlus:
    case TokenKind::MinusMinus:
      return PrecPostfix;
    default:
      return PrecNone;
  }
}

std::string join(const std::vector<std::string>& parts, const char* sep) {
  std::string s;
  for (const auto& p : parts) {
    if (!s.empty()) s += sep;
    s += p;
  }
  return s;
}

std::string describe(const Token& t) {
  switch (t.kind) {
    case TokenKind::Identifier:
      return "'" + std::string(t.text) + "'";
    case TokenKind::Int:
    case TokenKind::Float:
      return "number '" + std::string(t.text) + "'";
    case TokenKind::String:
      return "string";
    case TokenKind::Eof:
      return "end of file";
    default: {
      const std::string_view n = token_kind_name(t.kind);
      return n.front() == '\'' ? std::string(n) : "'" + std::string(n) + "'";
    }
  }
}

}  // namespace

std::string TypeName::spelling() const {
  if (is_void) return "void";
  if (is_auto) return "auto";
  std::string s = join(name, "::");
  if (!args.empty()) {
    s += '<';
    for (std::size_t i = 0; i < args.size(); ++i) s += (i ? ", " : "") + args[i].spelling();
    s += '>';
  }
  return s;
}

std::string NameExpr::spelling() const { return join(parts, "::"); }

std::string_view Decl::kind_name() const noexcept {
  switch (kind) {
    case DeclKind::Enum:
      return "enum";
    case DeclKind::Class:
      return "class";
    case DeclKind::Object:
      return "object";
    case DeclKind::Net:
      return "net";
    case DeclKind::Place:
      return "place";
    case DeclKind::Transition:
      return "transition";
    case DeclKind::Arrow:
      return "arrow";
    case DeclKind::Start:
      return "start place";
    case DeclKind::Function:
      return as<FunctionDecl>().is_constructor ? "constructor" : "function";
    case DeclKind::Property:
      return "property";
    case DeclKind::Script:
      return "script";
  }
  return "declaration";
}

class Parser::DepthGuard {
 public:
  explicit DepthGuard(Parser& p) : p_(p) {
    if (++p_.depth_ > max_depth) {
      --p_.depth_;  // the destructor of a guard whose constructor throws does not run
      p_.too_deep(p_.peek());
    }
  }
  ~DepthGuard() { --p_.depth_; }
  DepthGuard(const DepthGuard&) = delete;
  DepthGuard& operator=(const DepthGuard&) = delete;

 private:
  Parser& p_;
};

Script parse(const Source& source, Diagnostics& diagnostics) {
  Lexer lexer(source, diagnostics);
  Parser parser(source, lexer.tokenize(), diagnostics);
  return parser.parse_script();
}

Parser::Parser(const Source& source, std::vector<Token> tokens, Diagnostics& diagnostics)
    : source_(source), tokens_(std::move(tokens)), diag_(diagnostics) {
  if (tokens_.empty() || tokens_.back().kind != TokenKind::Eof) {
    Token eof;
    eof.loc = source_.locate(source_.text().size());
    tokens_.push_back(eof);
  }
}

// ---- tokens -------------------------------------------------------------------------------------------

const Token& Parser::peek(std::size_t ahead) const noexcept {
  const std::size_t i = pos_ + ahead;
  return i < tokens_.size() ? tokens_[i] : tokens_.back();
}

const Token& Parser::advance() {
  const Token& t = tokens_[pos_];
  if (pos_ + 1 < tokens_.size()) ++pos_;
  return t;
}

bool Parser::match(TokenKind k) {
  if (!check(k)) return false;
  advance();
  return true;
}

const Token& Parser::expect(TokenKind k, const char* what) {
  if (check(k)) return advance();
  fail(peek(), std::string("expected ") + what + ", found " + describe(peek()));
}

void Parser::fail(const Token& at, const std::string& message) {
  diag_.error(at.loc, message);
  throw Abort{};
}

// Reports nesting beyond max_depth once, then skips the rest of the deep region (up to the bracket, ';'
// or end that closes the level where it was found) so that recovery costs one exception, not one per
// remaining level.
void Parser::too_deep(const Token& at) {
  diag_.error(at.loc, "nesting is too deep (more than " + std::to_string(max_depth) + " levels)");
  int balance = 0;
  while (!check(TokenKind::Eof)) {
    const TokenKind k = peek().kind;
    if (k == TokenKind::LParen || k == TokenKind::LBrace || k == TokenKind::LBracket) {
      ++balance;
    } else if (k == TokenKind::RParen || k == TokenKind::RBrace || k == TokenKind::RBracket) {
      if (balance == 0) break;
      --balance;
    } else if (k == TokenKind::Semicolon && balance == 0) {
      break;
    }
    advance();
  }
  throw Abort{};
}

namespace {
bool starts_member(TokenKind k) noexcept {
  switch (k) {
    case TokenKind::KwClass:
    case TokenKind::KwObject:
    case TokenKind::KwNet:
    case TokenKind::KwEnum:
    case TokenKind::KwPlace:
    case TokenKind::KwTransition:
    case TokenKind::KwArrow:
    case TokenKind::KwStart:
    case TokenKind::KwWhen:
    case TokenKind::KwDo:
    case TokenKind::KwInvoke:
    case TokenKind::RBrace:
    case TokenKind::Eof:
      return true;
    default:
      return false;
  }
}
bool starts_statement(TokenKind k) noexcept {
  switch (k) {
    case TokenKind::KwIf:
    case TokenKind::KwWhile:
    case TokenKind::KwFor:
    case TokenKind::KwReturn:
    case TokenKind::KwFinish:
    case TokenKind::KwBreak:
    case TokenKind::KwContinue:
    case TokenKind::LBrace:
    case TokenKind::RBrace:
    case TokenKind::Eof:
      return true;
    default:
      return false;
  }
}
}  // namespace

// Skips to the start of the next member: after a ';' or a balanced '{...}', or before a keyword that
// starts a declaration or the '}' that closes the enclosing body. The caller has already made progress
// past the token that failed, so stopping at once is fine.
void Parser::sync_member() {
  int braces = 0;
  while (!check(TokenKind::Eof)) {
    if (braces == 0 && starts_member(peek().kind)) return;
    const TokenKind k = advance().kind;
    if (k == TokenKind::LBrace) ++braces;
    if (k == TokenKind::RBrace && --braces <= 0) return;
    if (k == TokenKind::Semicolon && braces == 0) return;
  }
}

// Skips to the start of the next statement: after a ';', or before a keyword or brace that starts one
// (a '{' after an error is usually the body of the statement that failed: parse it as a block).
void Parser::sync_statement() {
  while (!check(TokenKind::Eof)) {
    if (starts_statement(peek().kind)) return;
    if (advance().kind == TokenKind::Semicolon) return;
  }
}

// ---- declarations --------------------------------------------------------------------------------------

Script Parser::parse_script() {
  Script script;
  script.root = std::make_unique<ClassDecl>(DeclKind::Script, SourceLoc{});
  script.root->name = source_.name();
  parse_members(*script.root, false);
  return script;
}

void Parser::parse_members(ScopeDecl& scope, bool braced) {
  for (;;) {
    if (check(TokenKind::Eof)) {
      // Only the innermost unclosed body is reported: the ones around it end for the same reason.
      if (braced && !eof_reported_)
        diag_.error(peek().loc, "expected '}' to close " + std::string(scope.kind_name()) + " '" +
                                    scope.name + "', found end of file");
      eof_reported_ = true;
      return;
    }
    if (check(TokenKind::RBrace)) {
      if (braced) {
        advance();
        return;
      }
      diag_.error(peek().loc, "unexpected '}'");
      advance();
      continue;
    }
    const std::size_t before = pos_;
    try {
      parse_member(scope);
    } catch (const Abort&) {
      if (pos_ == before) advance();
      sync_member();
    }
  }
}

void Parser::parse_member(ScopeDecl& scope) {
  DepthGuard guard(*this);
  DeclPtr d;
  switch (peek().kind) {
    case TokenKind::KwEnum:
      d = parse_enum();
      break;
    case TokenKind::KwClass:
      d = parse_class(DeclKind::Class);
      break;
    case TokenKind::KwObject:
      d = parse_class(DeclKind::Object);
      break;
    case TokenKind::KwNet:
      d = parse_net();
      break;
    case TokenKind::KwPlace:
      d = parse_place(scope);
      break;
    case TokenKind::KwTransition:
      d = parse_transition();
      break;
    case TokenKind::KwArrow:
      d = parse_arrow();
      break;
    case TokenKind::KwStart:
      d = parse_start();
      break;
    case TokenKind::KwWhen:
    case TokenKind::KwDo:
    case TokenKind::KwInvoke:
      if (scope.kind == DeclKind::Transition) {
        parse_transition_clause(scope.as<TransitionDecl>());
        return;
      }
      fail(peek(), "'" + std::string(peek().text) + "' is only allowed inside a transition");
    case TokenKind::Identifier:
    case TokenKind::KwVoid:
    case TokenKind::KwAuto:
      parse_function_or_properties(scope);
      return;
    case TokenKind::Semicolon:
      advance();
      return;  // stray ';' after a body is harmless
    default:
      fail(peek(), "expected a declaration, found " + describe(peek()));
  }
  d->parent = &scope;
  scope.members.push_back(std::move(d));
}

std::vector<std::string> Parser::parse_qualified(SourceLoc* loc) {
  const Token& first = expect(TokenKind::Identifier, "a name");
  if (loc != nullptr) *loc = first.loc;
  std::vector<std::string> parts{std::string(first.text)};
  while (match(TokenKind::ColonColon))
    parts.emplace_back(expect(TokenKind::Identifier, "a name after '::'").text);
  return parts;
}

std::vector<std::string> Parser::parse_path(SourceLoc* loc) {
  const Token& first = expect(TokenKind::Identifier, "a name");
  if (loc != nullptr) *loc = first.loc;
  std::vector<std::string> parts{std::string(first.text)};
  while (match(TokenKind::Dot)) parts.emplace_back(expect(TokenKind::Identifier, "a name after '.'").text);
  return parts;
}

TypeName Parser::parse_type() {
  DepthGuard guard(*this);
  TypeName t;
  t.loc = peek().loc;
  if (match(TokenKind::KwVoid)) {
    t.is_void = true;
    return t;
  }
  if (match(TokenKind::KwAuto)) {
    t.is_auto = true;
    return t;
  }
  if (!check(TokenKind::Identifier)) fail(peek(), "expected a type, found " + describe(peek()));
  t.name = parse_qualified();
  if (match(TokenKind::Less)) {
    do {
      t.args.push_back(parse_type());
    } while (match(TokenKind::Comma));
    expect(TokenKind::Greater, "'>' to close the type arguments");
  }
  return t;
}

// True when a type can be read from token i on (advancing i past it). No diagnostics: used to tell
// declarations from expressions.
bool Parser::scan_type(std::size_t& i) const noexcept {
  const auto kind = [&](std::size_t j) { return j < tokens_.size() ? tokens_[j].kind : TokenKind::Eof; };
  if (kind(i) == TokenKind::KwVoid || kind(i) == TokenKind::KwAuto) {
    ++i;
    return true;
  }
  int depth = 0;
  for (;;) {
    if (kind(i) != TokenKind::Identifier) return false;
    ++i;
    while (kind(i) == TokenKind::ColonColon && kind(i + 1) == TokenKind::Identifier) i += 2;
    if (kind(i) == TokenKind::Less) {
      if (++depth > max_depth) return false;
      ++i;
      continue;  // the first argument
    }
    while (depth > 0) {
      if (kind(i) == TokenKind::Comma) {
        ++i;
        break;  // the next argument
      }
      if (kind(i) != TokenKind::Greater) return false;
      ++i;
      --depth;
    }
    if (depth == 0) return true;
  }
}

DeclPtr Parser::parse_enum() {
  advance();  // enum
  const Token& name = expect(TokenKind::Identifier, "the enum's name");
  auto e = std::make_unique<EnumDecl>(DeclKind::Enum, name.loc);
  e->name = std::string(name.text);
  expect(TokenKind::LBrace, "'{' to open the enum's values");
  while (!check(TokenKind::RBrace)) {
    const Token& v = expect(TokenKind::Identifier, "an enum value name");
    e->values.emplace_back(v.text);
    e->value_locs.push_back(v.loc);
    if (!match(TokenKind::Comma)) break;
  }
  expect(TokenKind::RBrace, "'}' to close the enum");
  match(TokenKind::Semicolon);
  return e;
}

std::vector<ExprPtr> Parser::parse_args() {
  std::vector<ExprPtr> args;
  if (!check(TokenKind::RParen)) {
    do {
      args.push_back(parse_expr());
    } while (match(TokenKind::Comma));
  }
  expect(TokenKind::RParen, "')' after the arguments");
  return args;
}

DeclPtr Parser::parse_class(DeclKind kind) {
  advance();  // class / object
  const Token& name =
      expect(TokenKind::Identifier, kind == DeclKind::Class ? "the class's name" : "the object's name");
  auto c = std::make_unique<ClassDecl>(kind, name.loc);
  c->name = std::string(name.text);
  if (match(TokenKind::Colon)) {
    c->base_name = parse_qualified(&c->base_loc);
    if (kind == DeclKind::Object && match(TokenKind::LParen)) {
      c->has_args = true;
      c->base_args = parse_args();
    }
  }
  if (kind == DeclKind::Object && match(TokenKind::Semicolon)) return c;
  expect(TokenKind::LBrace,
         kind == DeclKind::Class ? "'{' to open the class body" : "'{' or ';' after the object");
  parse_members(*c, true);
  match(TokenKind::Semicolon);
  return c;
}

std::vector<Param> Parser::parse_params(bool allow_places) {
  std::vector<Param> params;
  expect(TokenKind::LParen, "'(' to open the parameters");
  if (!check(TokenKind::RParen)) {
    do {
      Param p;
      if (check(TokenKind::KwPlace)) {
        const Token& kw = advance();
        if (!allow_places) fail(kw, "only nets take places as parameters");
        p.is_place = true;
        p.type_name.loc = kw.loc;
        if (match(TokenKind::Less)) {
          p.token_class = parse_qualified();
          expect(TokenKind::Greater, "'>' after the token class");
        }
      } else {
        p.type_name = parse_type();
      }
      const Token& n = expect(TokenKind::Identifier, "the parameter's name");
      p.name = std::string(n.text);
      p.loc = n.loc;
      params.push_back(std::move(p));
    } while (match(TokenKind::Comma));
  }
  expect(TokenKind::RParen, "')' after the parameters");
  return params;
}

DeclPtr Parser::parse_net() {
  const Token& kw = advance();  // net
  auto n = std::make_unique<ClassDecl>(DeclKind::Net, kw.loc);
  if (check(TokenKind::Identifier) && peek(1).kind == TokenKind::LParen) {
    n->result.is_void = true;
    n->result.loc = peek().loc;
  } else {
    n->result = parse_type();
  }
  const Token& name = expect(TokenKind::Identifier, "the net's name");
  n->name = std::string(name.text);
  n->loc = name.loc;
  n->params = parse_params(true);
  // Each port parameter is a place of the net, so arrows inside the net reach it by name; each value
  // parameter a property of the net instance, so its transitions read it by name.
  for (const Param& p : n->params) {
    if (!p.is_place) {
      auto prop = std::make_unique<PropertyDecl>(DeclKind::Property, p.loc);
      prop->name = p.name;
      prop->type_name = p.type_name;
      prop->is_param = true;
      prop->parent = n.get();
      n->members.push_back(std::move(prop));
      continue;
    }
    auto place = std::make_unique<PlaceDecl>(DeclKind::Place, p.loc);
    place->name = p.name;
    place->token_class = p.token_class;
    place->token_loc = p.type_name.loc;
    place->is_port = true;
    place->parent = n.get();
    n->members.push_back(std::move(place));
  }
  expect(TokenKind::LBrace, "'{' to open the net's body");
  parse_members(*n, true);
  match(TokenKind::Semicolon);
  return n;
}

DeclPtr Parser::parse_place(ScopeDecl& scope) {
  const Token& kw = advance();  // place
  auto p = std::make_unique<PlaceDecl>(DeclKind::Place, kw.loc);
  p->token_loc = kw.loc;
  if (match(TokenKind::Less)) {
    p->token_class = parse_qualified(&p->token_loc);
    expect(TokenKind::Greater, "'>' after the token class");
  }
  const Token& name = expect(TokenKind::Identifier, "the place's name");
  p->name = std::string(name.text);
  p->loc = name.loc;
  p->parent = &scope;
  if (match(TokenKind::Equal)) p->initial = parse_expr(PrecConditional);
  if (match(TokenKind::LBrace)) {
    parse_members(*p, true);
    match(TokenKind::Semicolon);
  } else {
    expect(TokenKind::Semicolon, "';' or '{' after the place");
  }
  return p;
}

DeclPtr Parser::parse_transition() {
  advance();  // transition
  const Token& name = expect(TokenKind::Identifier, "the transition's name");
  auto t = std::make_unique<TransitionDecl>(DeclKind::Transition, name.loc);
  t->name = std::string(name.text);
  if (match(TokenKind::Semicolon)) return t;
  if (match(TokenKind::Equal)) {
    t->subst_name = parse_qualified(&t->subst_loc);
    expect(TokenKind::LParen, "'(' after the substituting net's name");
    t->subst_args = parse_args();
    expect(TokenKind::Semicolon, "';' after the substitution");
    return t;
  }
  expect(TokenKind::LBrace, "'{', '=' or ';' after the transition's name");
  parse_members(*t, true);
  match(TokenKind::Semicolon);
  return t;
}

void Parser::parse_transition_clause(TransitionDecl& t) {
  const Token& kw = advance();
  switch (kw.kind) {
    case TokenKind::KwWhen: {
      if (t.when_expr || t.when_block)
        diag_.error(kw.loc, "transition '" + t.name + "' has more than one condition ('when')");
      if (check(TokenKind::LBrace)) {
        auto b = parse_block();
        if (!t.when_expr && !t.when_block) t.when_block = std::move(b);
      } else {
        auto e = parse_expr();
        expect(TokenKind::Semicolon, "';' after the condition");
        if (!t.when_expr && !t.when_block) t.when_expr = std::move(e);
      }
      return;
    }
    case TokenKind::KwDo: {
      if (t.action) diag_.error(kw.loc, "transition '" + t.name + "' has more than one action ('do')");
      auto b = parse_block();
      if (!t.action) t.action = std::move(b);
      return;
    }
    default: {  // invoke
      if (!t.invoke_name.empty())
        diag_.error(kw.loc, "transition '" + t.name + "' invokes more than one net");
      SourceLoc loc;
      auto name = parse_qualified(&loc);
      expect(TokenKind::LParen, "'(' after the invoked net's name");
      auto args = parse_args();
      expect(TokenKind::Semicolon, "';' after the invocation");
      if (t.invoke_name.empty()) {
        t.invoke_name = std::move(name);
        t.invoke_loc = loc;
        t.invoke_args = std::move(args);
      }
      return;
    }
  }
}

DeclPtr Parser::parse_arrow() {
  const Token& kw = advance();  // arrow
  auto a = std::make_unique<ArrowDecl>(DeclKind::Arrow, kw.loc);
  a->from = parse_path(&a->from_loc);
  const Token& op = peek();
  if (match(TokenKind::Arrow)) {
    a->arrow = ArrowKind::Normal;
  } else if (match(TokenKind::TildeArrow)) {
    a->arrow = ArrowKind::Communication;
  } else if (op.kind == TokenKind::Minus && peek(1).kind == TokenKind::Identifier && peek(1).text == "o" &&
             peek(1).loc.offset == op.loc.offset + 1) {
    advance();
    advance();
    a->arrow = ArrowKind::Inhibitor;
  } else {
    fail(op, "expected an arrow type ('->', '-o' or '~>'), found " + describe(op));
  }
  a->to = parse_path(&a->to_loc);
  if (match(TokenKind::Star)) {
    const Token& w = peek();
    a->weight_loc = w.loc;
    if (w.kind != TokenKind::Int) fail(w, "expected the arrow's weight (an integer), found " + describe(w));
    advance();
    a->weight = w.int_value;
  }
  if (match(TokenKind::KwWhen)) a->condition = parse_expr();
  expect(TokenKind::Semicolon, "';' after the arrow");
  return a;
}

DeclPtr Parser::parse_start() {
  const Token& kw = advance();  // start
  auto s = std::make_unique<StartDecl>(DeclKind::Start, kw.loc);
  SourceLoc loc;
  s->place = parse_path(&loc);
  s->loc = loc;
  expect(TokenKind::Semicolon, "';' after the start place");
  return s;
}

void Parser::parse_function_or_properties(ScopeDecl& scope) {
  // A constructor: the class's name directly followed by '('.
  if (check(TokenKind::Identifier) && peek(1).kind == TokenKind::LParen) {
    const Token& name = advance();
    auto f = std::make_unique<FunctionDecl>(DeclKind::Function, name.loc);
    f->name = std::string(name.text);
    f->is_constructor = true;
    f->result.is_void = true;
    f->result.loc = name.loc;
    f->params = parse_params(false);
    f->body = parse_block();
    f->parent = &scope;
    scope.members.push_back(std::move(f));
    return;
  }
  TypeName type = parse_type();
  const Token& name = expect(TokenKind::Identifier, "a name after the type");
  if (check(TokenKind::LParen)) {
    auto f = std::make_unique<FunctionDecl>(DeclKind::Function, name.loc);
    f->name = std::string(name.text);
    f->result = std::move(type);
    f->params = parse_params(false);
    f->body = parse_block();
    f->parent = &scope;
    scope.members.push_back(std::move(f));
    return;
  }
  const Token* n = &name;
  for (;;) {
    auto p = std::make_unique<PropertyDecl>(DeclKind::Property, n->loc);
    p->name = std::string(n->text);
    p->type_name = type;
    p->parent = &scope;
    if (match(TokenKind::Equal)) {
      // A bad initialiser loses the initialiser, not the property: later uses of it stay quiet.
      try {
        p->init = parse_expr(PrecConditional);
      } catch (const Abort&) {
        scope.members.push_back(std::move(p));
        throw;
      }
    }
    scope.members.push_back(std::move(p));
    if (!match(TokenKind::Comma)) break;
    n = &expect(TokenKind::Identifier, "the next property's name");
  }
  expect(TokenKind::Semicolon, "';' after the property");
}

// ---- statements ----------------------------------------------------------------------------------------

std::unique_ptr<BlockStmt> Parser::parse_block() {
  DepthGuard guard(*this);
  const Token& open = expect(TokenKind::LBrace, "'{'");
  auto block = std::make_unique<BlockStmt>(StmtKind::Block, open.loc);
  for (;;) {
    if (match(TokenKind::RBrace)) return block;
    if (check(TokenKind::Eof)) {
      if (!eof_reported_)
        diag_.error(peek().loc, "expected '}' to close the block opened at line " +
                                    std::to_string(open.loc.line) + ", found end of file");
      eof_reported_ = true;
      block->lost = true;
      return block;
    }
    const std::size_t before = pos_;
    try {
      block->body.push_back(parse_statement());
    } catch (const Abort&) {
      block->lost = true;
      if (pos_ == before && !check(TokenKind::RBrace)) advance();
      sync_statement();
    }
  }
}

bool Parser::is_declaration_start() const noexcept {
  if (check(TokenKind::KwAuto) || check(TokenKind::KwVoid)) return true;
  if (!check(TokenKind::Identifier)) return false;
  std::size_t i = pos_;
  return scan_type(i) && i < tokens_.size() && tokens_[i].kind == TokenKind::Identifier;
}

std::unique_ptr<LocalStmt> Parser::parse_local(bool expect_semicolon) {
  auto local = std::make_unique<LocalStmt>(StmtKind::Local, peek().loc);
  local->type_name = parse_type();
  const Token& name = expect(TokenKind::Identifier, "the variable's name");
  local->name = std::string(name.text);
  local->name_loc = name.loc;
  local->loc = name.loc;
  if (match(TokenKind::Equal)) {
    // A bad initialiser loses the initialiser, not the variable: later uses of it stay quiet.
    try {
      local->init = parse_expr(PrecConditional);
    } catch (const Abort&) {
      sync_statement();
      return local;
    }
  }
  if (expect_semicolon) expect(TokenKind::Semicolon, "';' after the variable");
  return local;
}

StmtPtr Parser::parse_statement() {
  DepthGuard guard(*this);
  const Token& t = peek();
  switch (t.kind) {
    case TokenKind::LBrace:
      return parse_block();
    case TokenKind::KwIf: {
      advance();
      auto s = std::make_unique<IfStmt>(StmtKind::If, t.loc);
      expect(TokenKind::LParen, "'(' after 'if'");
      s->cond = parse_expr();
      expect(TokenKind::RParen, "')' after the condition");
      s->then_stmt = parse_statement();
      if (match(TokenKind::KwElse)) s->else_stmt = parse_statement();
      return s;
    }
    case TokenKind::KwWhile: {
      advance();
      auto s = std::make_unique<WhileStmt>(StmtKind::While, t.loc);
      expect(TokenKind::LParen, "'(' after 'while'");
      s->cond = parse_expr();
      expect(TokenKind::RParen, "')' after the condition");
      s->body = parse_statement();
      return s;
    }
    case TokenKind::KwFor: {
      advance();
      const SourceLoc loc = t.loc;
      expect(TokenKind::LParen, "'(' after 'for'");
      if (is_declaration_start()) {
        std::size_t i = pos_;
        (void)scan_type(i);
        if (i + 1 < tokens_.size() && tokens_[i + 1].kind == TokenKind::Colon) {
          auto s = std::make_unique<ForEachStmt>(StmtKind::ForEach, loc);
          s->var = std::make_unique<LocalStmt>(StmtKind::Local, peek().loc);
          s->var->type_name = parse_type();
          const Token& name = expect(TokenKind::Identifier, "the loop variable's name");
          s->var->name = std::string(name.text);
          s->var->name_loc = s->var->loc = name.loc;
          expect(TokenKind::Colon, "':'");
          s->range = parse_expr();
          expect(TokenKind::RParen, "')' after the range");
          s->body = parse_statement();
          return s;
        }
      }
      auto s = std::make_unique<ForStmt>(StmtKind::For, loc);
      if (!check(TokenKind::Semicolon)) {
        if (is_declaration_start()) {
          s->init = parse_local(false);
        } else {
          auto e = std::make_unique<ExprStmt>(StmtKind::Expr, peek().loc);
          e->expr = parse_expr();
          s->init = std::move(e);
        }
      }
      expect(TokenKind::Semicolon, "';' after the loop's initialisation");
      if (!check(TokenKind::Semicolon)) s->cond = parse_expr();
      expect(TokenKind::Semicolon, "';' after the loop's condition");
      if (!check(TokenKind::RParen)) s->step = parse_expr();
      expect(TokenKind::RParen, "')' to close the loop's header");
      s->body = parse_statement();
      return s;
    }
    case TokenKind::KwReturn:
    case TokenKind::KwFinish: {
      advance();
      auto s = std::make_unique<ReturnStmt>(
          t.kind == TokenKind::KwReturn ? StmtKind::Return : StmtKind::Finish, t.loc);
      if (!check(TokenKind::Semicolon)) s->value = parse_expr();
      expect(TokenKind::Semicolon,
             t.kind == TokenKind::KwReturn ? "';' after 'return'" : "';' after 'finish'");
      return s;
    }
    case TokenKind::KwBreak:
    case TokenKind::KwContinue: {
      advance();
      expect(TokenKind::Semicolon, "';'");
      return std::make_unique<Stmt>(t.kind == TokenKind::KwBreak ? StmtKind::Break : StmtKind::Continue,
                                    t.loc);
    }
    default:
      break;
  }
  if (is_declaration_start()) return parse_local(true);
  auto s = std::make_unique<ExprStmt>(StmtKind::Expr, t.loc);
  s->expr = parse_expr();
  expect(TokenKind::Semicolon, "';' after the expression");
  return s;
}

// ---- expressions ---------------------------------------------------------------------------------------

ExprPtr Parser::parse_prefix() {
  const Token& t = peek();
  switch (t.kind) {
    case TokenKind::Int: {
      advance();
      auto e = std::make_unique<LiteralExpr>(ExprKind::Int, t.loc);
      e->int_value = t.int_value;
      return e;
    }
    case TokenKind::Float: {
      advance();
      auto e = std::make_unique<LiteralExpr>(ExprKind::Float, t.loc);
      e->float_value = t.float_value;
      return e;
    }
    case TokenKind::String: {
      advance();
      auto e = std::make_unique<LiteralExpr>(ExprKind::String, t.loc);
      e->string_value = decode_string_literal(t.text);
      return e;
    }
    case TokenKind::KwTrue:
    case TokenKind::KwFalse: {
      advance();
      auto e = std::make_unique<LiteralExpr>(ExprKind::Bool, t.loc);
      e->bool_value = t.kind == TokenKind::KwTrue;
      return e;
    }
    case TokenKind::KwNull:
      advance();
      return std::make_unique<LiteralExpr>(ExprKind::Null, t.loc);
    case TokenKind::KwThis:
      advance();
      return std::make_unique<NameExpr>(ExprKind::This, t.loc);
    case TokenKind::KwMark:
      advance();
      return std::make_unique<NameExpr>(ExprKind::Mark, t.loc);
    case TokenKind::Identifier: {
      auto e = std::make_unique<NameExpr>(ExprKind::Name, t.loc);
      e->parts = parse_qualified();
      return e;
    }
    case TokenKind::LParen: {
      advance();
      auto e = parse_expr();
      expect(TokenKind::RParen, "')'");
      return e;
    }
    case TokenKind::KwNew: {
      advance();
      auto e = std::make_unique<NewExpr>(ExprKind::New, t.loc);
      e->class_name.loc = peek().loc;
      e->class_name.name = parse_qualified();
      expect(TokenKind::LParen, "'(' after the class's name");
      e->args = parse_args();
      return e;
    }
    case TokenKind::Bang:
    case TokenKind::Minus:
    case TokenKind::Plus:
    case TokenKind::PlusPlus:
    case TokenKind::MinusMinus: {
      advance();
      auto e = std::make_unique<UnaryExpr>(ExprKind::Unary, t.loc);
      e->op = t.kind;
      e->operand = parse_expr(PrecUnary);
      return e;
    }
    default:
      fail(t, "expected an expression, found " + describe(t));
  }
}

ExprPtr Parser::parse_expr(int min_precedence) {
  DepthGuard guard(*this);
  ExprPtr left = parse_prefix();
  // Each turn of this loop makes the tree one level deeper on the left: it counts against the nesting
  // limit like a parenthesis would, so that no tree gets deeper than max_depth (the checker recurses).
  struct Chain {
    int& depth;
    int n = 0;
    ~Chain() { depth -= n; }
  } chain{depth_};
  for (;;) {
    const Token& op = peek();
    const int prec = infix_precedence(op.kind);
    if (prec == PrecNone || prec < min_precedence) return left;
    ++depth_;
    ++chain.n;
    if (depth_ > max_depth) too_deep(op);
    advance();
    switch (op.kind) {
      case TokenKind::Equal:
      case TokenKind::PlusEqual:
      case TokenKind::MinusEqual:
      case TokenKind::StarEqual:
      case TokenKind::SlashEqual:
      case TokenKind::PercentEqual: {
        auto e = std::make_unique<BinaryExpr>(ExprKind::Assign, op.loc);
        e->op = op.kind;
        e->lhs = std::move(left);
        e->rhs = parse_expr(PrecAssign);  // right-associative
        left = std::move(e);
        break;
      }
      case TokenKind::Question: {
        auto e = std::make_unique<ConditionalExpr>(ExprKind::Conditional, op.loc);
        e->cond = std::move(left);
        e->then_expr = parse_expr(PrecConditional);
        expect(TokenKind::Colon, "':' in the conditional expression");
        e->else_expr = parse_expr(PrecConditional);
        left = std::move(e);
        break;
      }
      case TokenKind::KwIs:
      case TokenKind::KwAs: {
        auto e = std::make_unique<NewExpr>(op.kind == TokenKind::KwIs ? ExprKind::Is : ExprKind::As, op.loc);
        e->operand = std::move(left);
        e->class_name.loc = peek().loc;
        e->class_name.name = parse_qualified();
        left = std::move(e);
        break;
      }
      case TokenKind::LParen: {
        auto e = std::make_unique<CallExpr>(ExprKind::Call, op.loc);
        e->callee = std::move(left);
        e->args = parse_args();
        left = std::move(e);
        break;
      }
      case TokenKind::Dot: {
        auto e = std::make_unique<MemberExpr>(ExprKind::Member, op.loc);
        e->object = std::move(left);
        const Token& name = expect(TokenKind::Identifier, "a member name after '.'");
        e->name = std::string(name.text);
        e->name_loc = name.loc;
        left = std::move(e);
        break;
      }
      case TokenKind::LBracket: {
        auto e = std::make_unique<IndexExpr>(ExprKind::Index, op.loc);
        e->object = std::move(left);
        e->index = parse_expr();
        expect(TokenKind::RBracket, "']' after the index");
        left = std::move(e);
        break;
      }
      case TokenKind::PlusPlus:
      case TokenKind::MinusMinus: {
        auto e = std::make_unique<UnaryExpr>(ExprKind::Postfix, op.loc);
        e->op = op.kind;
        e->operand = std::move(left);
        left = std::move(e);
        break;
      }
      default: {
        auto e = std::make_unique<BinaryExpr>(ExprKind::Binary, op.loc);
        e->op = op.kind;
        e->lhs = std::move(left);
        e->rhs = parse_expr(prec + 1);
        left = std::move(e);
        break;
      }
    }
  }
}

}  // namespace vsd::soml
