// Native compilation (docs/soml.md, "Native compilation"): the functions of a script compiled to C++ by
// `vsd-soml compile` (one library for this test binary, VSD_SOML_NATIVE_LIB, built by
// vsd_add_soml_module from soml/native/arith.soml and a seeded random corpus) give exactly what the VM
// gives: results, printed lines, and errors word for word with their SOML++ call stacks — overflow,
// division by zero, the instruction budget and the depth limit. A library of another version of the
// script, a missing file and a file that is no native library are refused with a clear error, and the
// program keeps running in the VM.
#include <gtest/gtest.h>

#include <fstream>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "../core/test_util.hpp"
#include "vsd/core.hpp"
#include "vsd/soml.hpp"

namespace {

using vsd_test::error_of;

std::string read_file(const std::string& path) {
  std::ifstream in(path);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

// One program in an Environment of its own, run by the VM or (native) with the test library loaded.
struct Script {
  vsd::Registry reg;
  vsd::Environment env{0, reg};
  std::ostringstream out;
  vsd::soml::Program* program = nullptr;
  Script(const std::string& file, const std::string& text, bool native, std::uint64_t budget = 10'000'000) {
    vsd::soml::RunOptions o;
    o.out = &out;
    o.instruction_budget = budget;
    program = &env.use<vsd::soml::Module>().load(env.main_state(), file, text, o);
    if (native) program->load_native(VSD_SOML_NATIVE_LIB);
  }
  // The result of fn(args) as text, or the error's text; then what it printed.
  std::string call(const std::string& fn, const std::vector<vsd::Value>& args) {
    std::string r;
    try {
      r = program->root().call(fn, args).to_text();
    } catch (const vsd::Error& e) {
      r = std::string("error: ") + e.what();
    }
    r += "\nprinted: " + out.str();
    out.str("");
    return r;
  }
};

std::vector<vsd::Value> ints(std::int64_t a, std::int64_t b) { return {vsd::Value(a), vsd::Value(b)}; }
std::vector<vsd::Value> one(std::int64_t a) { return {vsd::Value(a)}; }

const std::string kArith = VSD_SOML_NATIVE_DIR "/arith.soml";

TEST(SomlNative, ArithmeticMatchesTheVm) {
  const std::string text = read_file(kArith);
  Script vm("arith.soml", text, false), native("arith.soml", text, true);
  EXPECT_EQ(vm.program->native_functions(), 0u);
  EXPECT_GE(native.program->native_functions(), 20u);
  struct Case {
    const char* fn;
    std::vector<vsd::Value> args;
  };
  const std::vector<Case> cases = {
      {"fib", {vsd::Value(std::int64_t{20})}},
      {"count_loop", {vsd::Value(std::int64_t{100000})}},
      {"loop", {vsd::Value(std::int64_t{100000})}},
      {"poly", {vsd::Value(2.5)}},
      {"poly", {vsd::Value(-7.25)}},
      {"mixed", {vsd::Value(std::int64_t{9}), vsd::Value(0.25)}},
      {"divmod", ints(1234567, 89)},
      {"divmod", ints(-17, 5)},
      {"divmod", ints(INT64_MIN, -1)},  // overflow of the division
      {"divmod", ints(7, 0)},           // division by zero
      {"mul", ints(INT64_MAX / 2, 3)},  // overflow with file:line:col
      {"sub", ints(INT64_MIN, 1)},
      {"neg", one(INT64_MIN)},
      {"absolute", one(-5)},
      {"absolute", one(INT64_MIN)},
      {"to_int", {vsd::Value(1e300)}},
      {"to_int", {vsd::Value(-3.75)}},
      {"show", {vsd::Value(std::int64_t{21}), vsd::Value(0.5)}},
      {"even", {vsd::Value(std::int64_t{101})}},
      {"collatz", {vsd::Value(std::int64_t{27})}},
      {"nested", {vsd::Value(std::int64_t{60})}},
      {"label_length", {vsd::Value(std::int64_t{12345})}},  // a string: the VM runs it, native or not
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.fn);
    EXPECT_EQ(vm.call(c.fn, c.args), native.call(c.fn, c.args));
  }
  // The errors carry the position of the operator and the call stack, as the VM's.
  const std::string overflow = native.call("mul", ints(INT64_MAX / 2, 3));
  EXPECT_NE(overflow.find("integer overflow: 4611686018427387903 * 3 does not fit an int (64 bits)\n"
                          "  at mul (arith.soml:17:"),
            std::string::npos)
      << overflow;
}

TEST(SomlNative, BudgetAndDepthFailAtTheSamePointAsTheVm) {
  const std::string text = read_file(kArith);
  for (const std::uint64_t budget : {1ull, 2ull, 7ull, 1000ull, 54321ull}) {
    Script vm("arith.soml", text, false, budget), native("arith.soml", text, true, budget);
    SCOPED_TRACE(budget);
    // A loop (backward jumps) and a recursion (calls) exhaust the budget where the VM's does.
    EXPECT_EQ(vm.call("outer", {vsd::Value(std::int64_t{0})}),
              native.call("outer", {vsd::Value(std::int64_t{0})}));
    EXPECT_EQ(vm.call("fib", {vsd::Value(std::int64_t{25})}),
              native.call("fib", {vsd::Value(std::int64_t{25})}));
    EXPECT_EQ(vm.call("count_loop", {vsd::Value(std::int64_t{1000})}),
              native.call("count_loop", {vsd::Value(std::int64_t{1000})}));
  }
  Script vm("arith.soml", text, false), native("arith.soml", text, true);
  const std::string deep = native.call("forever", {vsd::Value(std::int64_t{0})});
  EXPECT_EQ(vm.call("forever", {vsd::Value(std::int64_t{0})}), deep);
  EXPECT_NE(deep.find("call depth limit (256) reached calling forever\n  at forever (arith.soml:22:"),
            std::string::npos)
      << deep.substr(0, 300);
  const std::string endless = native.call("outer", {vsd::Value(std::int64_t{0})});
  EXPECT_NE(
      endless.find("instruction budget exhausted (10000000 jumps and calls): an endless loop?\n  at spin "
                   "(arith.soml:"),
      std::string::npos)
      << endless;
  EXPECT_NE(endless.find("\n  at outer (arith.soml:27:"), std::string::npos) << endless;
}

// A seeded corpus of random well-typed functions (native_random_gen.cpp, built with the library):
// every function on inputs small, large and at the edges gives the VM's result or error.
TEST(SomlNative, RandomProgramsMatchTheVm) {
  const std::string text = read_file(VSD_SOML_NATIVE_RANDOM);
  Script vm("random.soml", text, false, 200'000), native("random.soml", text, true, 200'000);
  ASSERT_GE(native.program->native_functions(), std::size_t{VSD_SOML_NATIVE_RANDOM_COUNT});
  const std::int64_t inputs[] = {0,    1,         -1,        7,         -13,
                                 1000, 123456789, INT64_MAX, INT64_MIN, 4611686018427387904};
  int errors = 0, values = 0;
  for (int f = 0; f < VSD_SOML_NATIVE_RANDOM_COUNT; ++f) {
    const std::string fn = "g" + std::to_string(f);
    for (int k = 0; k < 6; ++k) {
      const auto args = ints(inputs[(f + k) % 10], inputs[(3 * f + 7 * k + 1) % 10]);
      const std::string want = vm.call(fn, args);
      ASSERT_EQ(want, native.call(fn, args)) << fn << " " << args[0].to_text() << " " << args[1].to_text();
      (want.starts_with("error") ? errors : values) += 1;
    }
  }
  // The corpus exercises both outcomes.
  EXPECT_GT(values, 50);
  EXPECT_GT(errors, 10);
}

TEST(SomlNative, AnotherVersionOfTheScriptIsRefused) {
  Script changed("arith.soml", read_file(kArith) + "int extra(int n) { return n + 1; }\n", false);
  const std::string e = error_of([&] { changed.program->load_native(VSD_SOML_NATIVE_LIB); });
  EXPECT_NE(e.find("holds no native code of this version of arith.soml (image "), std::string::npos) << e;
  EXPECT_NE(e.find("regenerate it with vsd-soml compile"), std::string::npos) << e;
  EXPECT_EQ(changed.program->native_functions(), 0u);
  EXPECT_EQ(changed.call("extra", {vsd::Value(std::int64_t{41})}), "42\nprinted: ");  // the VM goes on
}

TEST(SomlNative, MissingOrBadLibraryIsAClearError) {
  Script run("arith.soml", read_file(kArith), false);
  const std::string missing = error_of([&] { run.program->load_native("/nonexistent/soml_native.so"); });
  EXPECT_NE(missing.find("cannot load the SOML++ native library '/nonexistent/soml_native.so'"),
            std::string::npos)
      << missing;
  const std::string not_lib = error_of([&] { run.program->load_native(kArith); });
  EXPECT_NE(not_lib.find("cannot load the SOML++ native library"), std::string::npos) << not_lib;
  EXPECT_EQ(run.call("fib", {vsd::Value(std::int64_t{10})}), "55\nprinted: ");
}

// A program that ran in the VM goes on natively once the library is loaded, with the same results.
TEST(SomlNative, LoadedMidRunGivesTheSameResults) {
  const std::string text = read_file(kArith);
  Script run("arith.soml", text, false);
  const std::string before = run.call("nested", {vsd::Value(std::int64_t{40})});
  run.program->load_native(VSD_SOML_NATIVE_LIB);
  EXPECT_EQ(run.call("nested", {vsd::Value(std::int64_t{40})}), before);
}

}  // namespace

namespace {

// A debugger needs the VM: while one is attached, every call runs there (its breakpoints stop), with the
// library loaded; detached, native code runs again.
TEST(SomlNative, AnAttachedDebuggerRunsTheVm) {
  Script run("arith.soml", read_file(kArith), true);
  ASSERT_GT(run.program->native_functions(), 0u);
  int stops = 0;
  {
    vsd::soml::Debugger d(*run.program);
    d.break_at("arith.soml:3");  // fib
    d.on_stop([&](vsd::soml::Debugger&, const vsd::soml::Stop&) {
      ++stops;
      return vsd::soml::Resume::Continue;
    });
    EXPECT_EQ(run.call("fib", {vsd::Value(std::int64_t{4})}), "3\nprinted: ");
  }
  EXPECT_EQ(stops, 9);  // fib(4) makes 9 calls
  EXPECT_EQ(run.call("fib", {vsd::Value(std::int64_t{4})}), "3\nprinted: ");
  EXPECT_EQ(stops, 9);
}

}  // namespace
