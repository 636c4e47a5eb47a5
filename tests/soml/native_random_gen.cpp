// Writes a seeded corpus of random well-typed SOML++ functions (int arithmetic, comparisons, if/else,
// counting loops, calls of earlier functions, min/max/abs, int <-> double) and, when NETS is given, that
// many random nets of object tokens whose conditions and actions read and write properties, for the
// VM-versus-native differential test (native_test.cpp): `vsd_soml_native_random_gen SEED COUNT OUT.soml
// [NETS]`. Run at build time; the same arguments always write the same file, whichever compiler built the
// generator: every draw is sequenced (the operands of `+` are not, and GCC and clang order them apart).
#include <algorithm>
#include <cstdint>
#include <fstream>
#include <iostream>
#include <random>
#include <string>
#include <vector>

namespace {

struct Gen {
  std::mt19937_64 rng;
  int fn = 0;  // the function being written: it may call g0 .. g<fn-1>
  // What expressions read: a function's parameters and locals, or (nets) properties of the mark, of its
  // peer (maybe null) and of the net's object.
  std::vector<std::string> vars = {"a", "b", "x", "y", "s"};
  int pick(int n) { return static_cast<int>(rng() % static_cast<std::uint64_t>(n)); }

  std::string var() { return vars[static_cast<std::size_t>(pick(static_cast<int>(vars.size())))]; }
  bool small = false;  // constants in [-10, 10] only (nets: fewer firings fail)
  std::string constant() {
    if (small) return std::to_string(pick(21) - 10);
    switch (pick(8)) {
      case 0:
        return "4611686018427387904";  // 2^62: products and sums near the edge
      case 1:
        return "9223372036854775807";
      case 2:
        return "(-9223372036854775807 - 1)";
      default:
        return std::to_string(pick(41) - 20);
    }
  }
  std::string expr(int depth) {
    if (depth <= 0) return pick(3) == 0 ? constant() : var();
    switch (const int k = pick(12)) {
      case 0:
        return var();
      case 1:
        return constant();
      case 2:
        return "-(" + expr(depth - 1) + ")";
      case 3:
      case 4: {
        const std::string l = expr(depth - 1);
        return std::string(k == 3 ? "min(" : "max(") + l + ", " + expr(depth - 1) + ")";
      }
      case 5:
        return "abs(" + expr(depth - 1) + ")";
      case 6:
        return "int(double(" + expr(depth - 1) + ") * 1.5)";
      case 7:
        if (fn > 0) {
          const std::string g = "g" + std::to_string(pick(fn));
          const std::string l = expr(depth - 1);
          return g + "(" + l + ", " + expr(depth - 1) + ")";
        }
        return var();
      default: {
        static const char* ops[] = {"+", "-", "*", "/", "%"};
        const std::string l = expr(depth - 1);
        const char* op = ops[pick(5)];
        return "(" + l + " " + op + " " + expr(depth - 1) + ")";
      }
    }
  }
  std::string cond(int depth) {
    static const char* cmps[] = {"<", "<=", "==", "!=", ">", ">="};
    std::string c = expr(depth);
    c = c + " " + cmps[pick(6)];
    c = c + " " + expr(depth);
    if (pick(4) == 0) c = "(" + c + ") && (" + cond(depth - 1) + ")";
    if (pick(6) == 0) c = "!(" + c + ")";
    return c;
  }
  void stmts(std::string& out, int depth, int n, const std::string& indent) {
    for (int k = 0; k < n; ++k) {
      const int kind = depth > 0 ? pick(6) : 0;
      if (kind <= 2) {
        static const char* targets[] = {"x", "y", "s"};
        const char* target = targets[pick(3)];
        out += indent + target + " = " + expr(2) + ";\n";
      } else if (kind == 3) {
        out += indent + "if (" + cond(1) + ") {\n";
        stmts(out, depth - 1, 1 + pick(2), indent + "  ");
        out += indent + "} else {\n";
        stmts(out, depth - 1, 1 + pick(2), indent + "  ");
        out += indent + "}\n";
      } else if (kind == 4) {
        const std::string i = "i" + std::to_string(depth);
        out +=
            indent + "for (int " + i + " = 0; " + i + " < " + std::to_string(pick(6)) + "; " + i + "++) {\n";
        out += indent + "  s = s + " + i + ";\n";
        stmts(out, depth - 1, 1 + pick(2), indent + "  ");
        out += indent + "}\n";
      } else {
        const std::string v = var();
        out += indent + "while (" + v + " > " + std::to_string(pick(50)) +
               ") { x = x / 2 - 1; y = y - 3; s = s / 2; }\n";
      }
    }
  }

  // An action's statements: stores into the mark's properties (int, bool, double, a reference to a
  // static object), its peer's (a null peer fails: the firing is undone), the net object's; a method
  // call on the mark; ifs; prints.
  void action(std::string& out, int net, int depth, int n, const std::string& indent) {
    for (int k = 0; k < n; ++k) {
      switch (depth > 0 ? pick(9) : pick(7)) {
        case 0:
        case 1:
          out += indent + (pick(2) == 0 ? "mark.a" : "mark.b");
          out += " = " + expr(2) + ";\n";
          break;
        case 2:
          out += indent + "c = " + expr(1) + ";\n";
          break;
        case 3:
          out += indent + "mark.f = " + cond(1) + ";\n";
          break;
        case 4:
          out += indent + "mark.w = mark.w * 0.5 + double(" + expr(1) + ");\n";
          break;
        case 5:
          out += indent + (pick(3) == 0 ? "mark.peer.b = " + expr(1) : "mark.add(" + expr(1) + ")") + ";\n";
          break;
        case 6:
          if (pick(2) == 0)
            out += indent + "print(" + expr(1) + ", int(mark.w));\n";
          else
            out += indent + "mark.peer = k" + std::to_string(net) + "_" + std::to_string(pick(3)) + ";\n";
          break;
        default:
          out += indent + "if (" + cond(1) + ") {\n";
          action(out, net, depth - 1, 1 + pick(2), indent + "  ");
          out += indent + "} else {\n";
          action(out, net, depth - 1, 1 + pick(2), indent + "  ");
          out += indent + "}\n";
      }
    }
  }

  // Net @p k: a class of tokens (fields, a constructor, methods) whose three objects start in place
  // n<k>.p0, and a net object with three places and four transitions with random conditions and actions
  // over the mark's and its own properties; `link` fires first and sets the peers (the last one null).
  void net(std::string& out, int k) {
    const std::string K = std::to_string(k), T = "Tok" + K;
    out += "class " + T + " : Node {\n  int a = 0;\n  int b = 0;\n  double w = 1.0;\n  bool f = false;\n" +
           "  shared<" + T + "> peer;\n  start n" + K + ".p0;\n  " + T +
           "(int x, int y) { a = x; b = y; }\n  void add(int d) { a = a + d; b = b - d; }\n" +
           "  int sum() { return a + b; }\n}\n";
    out += "object n" + K + " {\n  int c = " + std::to_string(pick(21) - 10) + ";\n";
    for (int p = 0; p < 3; ++p) out += "  place<" + T + "> p" + std::to_string(p) + ";\n";
    out += "  place go = 1;\n  transition link { do { k" + K + "_0.peer = k" + K + "_1; k" + K + "_1.peer = k" +
           K + "_2; } }\n  arrow go -> link;\n";
    vars = {"mark.a", "mark.b", "c", "mark.sum()", "mark.peer.a"};
    small = true;
    for (int t = 0; t < 4; ++t) {
      const std::string name = "t" + std::to_string(t);
      out += "  transition " + name + " {\n";
      if (pick(4) != 0) {
        out += "    when " + std::string(pick(3) == 0 ? "mark.f || " : "");
        out += cond(1) + ";\n";
      }
      out += "    do {\n";
      action(out, k, 2, 1 + pick(3), "      ");
      out += "    }\n  }\n";
      // t0, t1, t2 make a ring p0 -> p1 -> p2 -> p0; t3 goes anywhere.
      const int from = t < 3 ? t : pick(3), to = t < 3 ? (t + 1) % 3 : pick(3);
      out += "  arrow p" + std::to_string(from) + " -> " + name + ";\n  arrow " + name + " -> p" +
             std::to_string(to) + ";\n";
    }
    vars = {"a", "b", "x", "y", "s"};
    small = false;
    out += "}\n";
    for (int j = 0; j < 3; ++j)
    {
      const int x = pick(11) - 5;
      out += "object k" + K + "_" + std::to_string(j) + " : " + T + "(" + std::to_string(x) + ", " +
             std::to_string(pick(11) - 5) + ");\n";
    }
  }
};

}  // namespace

int main(int argc, char** argv) {
  if (argc != 4 && argc != 5) {
    std::cerr << "usage: vsd_soml_native_random_gen SEED COUNT OUT.soml [NETS]\n";
    return 2;
  }
  Gen g{std::mt19937_64(std::stoull(argv[1]))};
  const int count = std::stoi(argv[2]);
  std::string out =
      "// Generated by vsd_soml_native_random_gen " + std::string(argv[1]) + " " + argv[2] + ".\n";
  for (int f = 0; f < count; ++f) {
    g.fn = f;
    out += "int g" + std::to_string(f) + "(int a, int b) {\n  int x = a;\n  int y = b;\n  int s = 0;\n";
    g.stmts(out, 2, 2 + g.pick(4), "  ");
    out += "  return s + x - y;\n}\n";
  }
  // NETS random nets (their conditions and actions call g0 .. g9).
  g.fn = std::min(count, 10);
  const int nets = argc == 5 ? std::stoi(argv[4]) : 0;
  for (int k = 0; k < nets; ++k) g.net(out, k);
  std::ofstream file(argv[3]);
  file << out;
  return file ? 0 : 1;
}
