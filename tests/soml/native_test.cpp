// Native compilation (docs/soml.md, "Native compilation"): the functions of a script compiled to C++ by
// `vsd-soml compile` (one library for this test binary, VSD_SOML_NATIVE_LIB, built by
// vsd_add_soml_module from soml/native/arith.soml and a seeded random corpus) give exactly what the VM
// gives: results, printed lines, and errors word for word with their SOML++ call stacks — overflow,
// division by zero, the instruction budget and the depth limit. A library of another version of the
// script, a missing file and a file that is no native library are refused with a clear error, and the
// program keeps running in the VM. Nets whose conditions and actions read and write properties (a seeded
// corpus of random nets) fire natively exactly as under the VM: the same token trace, printed lines,
// errors, undone firings and final database; a run saved by vsd::io continues under the other engine.
#include <gtest/gtest.h>

#include <fstream>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "../core/test_util.hpp"
#include "state_dump.hpp"
#include "vsd/core.hpp"
#include "vsd/soml.hpp"

#if VSD_SOML_TEST_IO
#include "vsd/io/snapshot.hpp"
#endif

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

// Properties of the narrower types (int16, uint8, float, bool): the same conversions and the same errors.
TEST(SomlNative, NarrowPropertiesMatchTheVm) {
  const std::string text = read_file(VSD_SOML_NATIVE_DIR "/props.soml");
  Script vm("props.soml", text, false), native("props.soml", text, true);
  EXPECT_EQ(native.program->native_functions(), 8u);  // the five functions and the three initialisers
  for (const char* fn : {"narrow", "unsigned8", "flip", "all"})
    for (const std::int64_t v : {std::int64_t{0}, std::int64_t{1}, std::int64_t{-1}, std::int64_t{255}, std::int64_t{256},
                                 std::int64_t{32767}, std::int64_t{32768}, std::int64_t{-32769}, INT64_MAX}) {
      SCOPED_TRACE(std::string(fn) + " " + std::to_string(v));
      EXPECT_EQ(vm.call(fn, one(v)), native.call(fn, one(v)));
    }
  for (const double v : {0.1, 1e40, -2.5, 3.0000001})
    EXPECT_EQ(vm.call("single", {vsd::Value(v)}), native.call("single", {vsd::Value(v)}));
  const std::string e = native.call("narrow", one(40000));
  EXPECT_NE(e.find("the value 40000 does not fit property 's' (int16)\n  at narrow (props.soml:5:"),
            std::string::npos)
      << e;
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

// Counted loops run natively without the per-iteration budget test while the budget covers every
// backward jump left (docs/soml.md 8.8): the budget still runs out at the same jump as in the VM, whether
// it runs out in the middle of the loop, in a second loop or a call after it, or just suffices.
TEST(SomlNative, CountedLoopsSpendTheBudgetAsTheVm) {
  const std::string text = read_file(kArith);
  struct Case {
    const char* fn;
    std::vector<vsd::Value> args;
  };
  const std::vector<Case> cases = {
      {"count_loop", one(1000)},         // 999 backward jumps: a budget of 1000 just suffices
      {"two_loops", one(500)},           // 499 + 500 jumps (the second loop <=)
      {"loop_exit", ints(1000, 600)},    // a break, then 299 jumps
      {"loop_exit", ints(5000, 4000)},   // a return from inside the loop
      {"loop_then_call", one(1000)},     // 999 jumps, then calls
      {"up_to", ints(INT64_MAX - 700, INT64_MAX)},  // the counter overflows at the end (<= INT64_MAX)
      {"grow", ints(1000, INT64_MAX / 500)},        // the sum overflows in the loop
  };
  for (const std::uint64_t budget : {1ull, 2ull, 3ull, 298ull, 299ull, 300ull, 301ull, 498ull, 499ull, 500ull,
                                     501ull, 502ull, 599ull, 600ull, 601ull, 700ull, 701ull, 702ull, 897ull,
                                     898ull, 899ull, 900ull, 901ull, 997ull, 998ull, 999ull, 1000ull, 1001ull,
                                     1002ull, 1010ull, 1020ull, 1021ull, 1022ull, 1023ull, 1024ull, 1025ull,
                                     4300ull, 4301ull, 4302ull, 100000ull}) {
    Script vm("arith.soml", text, false, budget), native("arith.soml", text, true, budget);
    SCOPED_TRACE(budget);
    for (const Case& c : cases) {
      SCOPED_TRACE(c.fn);
      EXPECT_EQ(vm.call(c.fn, c.args), native.call(c.fn, c.args));
    }
  }
  // The exact edge: 999 backward jumps need a budget of 1000.
  Script just("arith.soml", text, true, 1000), short_of("arith.soml", text, true, 999);
  EXPECT_EQ(just.call("count_loop", one(1000)), "499500\nprinted: ");
  const std::string e = short_of.call("count_loop", one(1000));
  EXPECT_NE(e.find("instruction budget exhausted (999 jumps and calls): an endless loop?\n  at count_loop "
                   "(arith.soml:6:"),
            std::string::npos)
      << e;
  const std::string o = just.call("up_to", ints(INT64_MAX - 5, INT64_MAX));
  EXPECT_NE(o.find("integer overflow: 9223372036854775807 + 1 does not fit an int (64 bits)"), std::string::npos)
      << o;
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

namespace {

using vsd_test::describe;

// The database without the script's source text and the executor's state (its choices: a failed firing
// has taken its random number, as under the VM).
std::string dump(const vsd::SimState& state) { return vsd_test::dump(state, {"soml::SourceFile", "soml::Executor"}); }

// One program whose nets fire step by step: its log holds every firing (paths, token moves), what it
// printed, each error of a failed firing and the failed conditions, in order.
struct NetRun {
  vsd::Registry reg;
  vsd::Environment env{0, reg};
  std::ostringstream out;
  vsd::soml::Program* program = nullptr;
  std::string log;
  std::size_t errors = 0, firings = 0;
  std::uint64_t budget = 200'000;
  vsd::soml::RunOptions options(std::uint64_t seed) {
    vsd::soml::RunOptions o;
    o.out = &out;
    o.seed = seed;
    o.instruction_budget = budget;
    return o;
  }
  void watch() {
    program->on_firing([this](const vsd::soml::Firing& f) {
      log += describe(env.main_state(), f) + "\n";
      ++firings;
    });
  }
  NetRun() { env.use<vsd::soml::Module>(); }
  NetRun(const std::string& text, bool native, std::uint64_t seed, std::uint64_t budget_per_call = 200'000)
      : budget(budget_per_call) {
    program = &env.use<vsd::soml::Module>().load(env.main_state(), "random.soml", text, options(seed));
    if (native) program->load_native(VSD_SOML_NATIVE_LIB);
    watch();
  }
  // Attaches to what the state holds (loaded by vsd::io), natively or not.
  void adopt(const std::string& text, bool native, std::uint64_t seed) {
    program = &env.use<vsd::soml::Module>().adopt(env.main_state(), "random.soml", text, options(seed));
    if (native) program->load_native(VSD_SOML_NATIVE_LIB);
    watch();
  }
  // @p n steps of one firing each; a failed firing must leave the database as it was (all or nothing).
  void steps(int n) {
    for (int i = 0; i < n; ++i) {
      const std::string before = dump(env.main_state());
      try {
        if (program->step(1) == 0) {
          log += "quiet\n";
          break;
        }
      } catch (const vsd::Error& e) {
        log += std::string("error: ") + e.what() + "\n";
        ++errors;
        EXPECT_EQ(dump(env.main_state()), before) << "a failed firing changed the database: " << e.what();
      }
      log += out.str();
      out.str("");
    }
    log += "failed conditions:\n";
    for (const std::string& c : program->condition_errors()) log += c + "\n";
  }
};

// The random nets (native_random_gen.cpp: VSD_SOML_NATIVE_RANDOM_NETS of them in the corpus) under
// several seeds: conditions, actions and the methods they call run natively and give the VM's run.
TEST(SomlNative, RandomNetsFireAsUnderTheVm) {
  const std::string text = read_file(VSD_SOML_NATIVE_RANDOM);
  std::size_t firings = 0, errors = 0;
  for (const std::uint64_t seed : {1u, 2u}) {
    SCOPED_TRACE(seed);
    NetRun vm(text, false, seed), native(text, true, seed);
    // Conditions, actions, methods and initialisers of the nets are native too.
    EXPECT_GE(native.program->native_functions(),
              std::size_t{VSD_SOML_NATIVE_RANDOM_COUNT + 10 * VSD_SOML_NATIVE_RANDOM_NETS});
    vm.steps(300);
    native.steps(300);
    ASSERT_EQ(vm.log, native.log);
    EXPECT_EQ(dump(vm.env.main_state()), dump(native.env.main_state()));
    firings += native.firings;
    errors += native.errors;
  }
  // The corpus exercises firings and failed firings (overflow, division by zero, null peers).
  EXPECT_GT(firings, 150u);
  EXPECT_GT(errors, 50u);
  // A budget of a few units per test and firing: conditions and actions (loops in the functions they
  // call, calls of methods) exhaust it at the same instruction as the VM's.
  for (const std::uint64_t budget : {2u, 3u}) {  // (the objects' constructors need 2 to load)
    NetRun vm(text, false, 1, budget), native(text, true, 1, budget);
    vm.steps(40);
    native.steps(40);
    EXPECT_EQ(vm.log, native.log);
    EXPECT_NE(native.log.find("instruction budget exhausted (" + std::to_string(budget) + " jumps and calls)"),
              std::string::npos)
        << native.log.substr(0, 2000);
  }
}

TEST(SomlNative, ALibraryOfAnotherClassLayoutIsRefused) {
  const std::string text = read_file(VSD_SOML_NATIVE_RANDOM);
  std::string changed = text;
  const std::size_t at = changed.find("double w = 1.0;", changed.find("class Tok0 "));
  ASSERT_NE(at, std::string::npos);
  changed.replace(at, 15, "float  w = 1.0;");
  NetRun a(text, false, 1), b(changed, false, 1);
  EXPECT_EQ(a.program->disassemble(), b.program->disassemble());  // the same code
  EXPECT_NE(a.program->image_hash(), b.program->image_hash());
  const std::string e = error_of([&] { b.program->load_native(VSD_SOML_NATIVE_LIB); });
  EXPECT_NE(e.find("holds no native code of this version of random.soml"), std::string::npos) << e;
  EXPECT_EQ(b.program->native_functions(), 0u);
  b.steps(20);
  EXPECT_GT(b.firings, 0u);
}

#if VSD_SOML_TEST_IO

// docs/soml.md 8.8: saving, attaching and migrating do not depend on native code. A run saved by vsd::io
// while native code ran continues under the VM exactly as the run that was never saved, and a run saved
// under the VM continues natively.
TEST(SomlNative, ASavedRunContinuesUnderTheOtherEngine) {
  const std::string text = read_file(VSD_SOML_NATIVE_RANDOM);
  constexpr int total = 120;
  for (const bool first_native : {true, false}) {
    NetRun ref(text, false, 5);
    ref.steps(total);
    ASSERT_GT(ref.firings, 20u);
    for (const int n : {0, 7, 60}) {
      SCOPED_TRACE(std::string(first_native ? "native, then the VM" : "the VM, then native") + ", split after " +
                   std::to_string(n));
      NetRun a(text, first_native, 5);
      a.steps(n);
      const auto bytes = vsd::io::save_bytes(a.env.main_state(), n % 2 == 0 ? vsd::io::Format::Text
                                                                             : vsd::io::Format::Binary);
      NetRun b;
      vsd::io::load_bytes(b.env.main_state(), bytes);
      b.adopt(text, !first_native, 5);
      EXPECT_EQ(b.program->native_functions() > 0, !first_native);
      b.steps(total - n);
      // The failed conditions are listed per program (an attach tests every transition again): compare
      // the firings, prints and errors.
      auto firing_lines = [](const std::string& log) { return log.substr(0, log.find("failed conditions:\n")); };
      EXPECT_EQ(firing_lines(a.log) + firing_lines(b.log), firing_lines(ref.log));
      EXPECT_EQ(dump(b.env.main_state()), dump(ref.env.main_state()));
      if (::testing::Test::HasFailure()) return;
    }
  }
}

#endif

}  // namespace
