// SOML++ runtime benchmarks: the bytecode VM side by side with Lua 5.4 (embedded in this binary), LuaJIT
// 2.1 (loaded at run time, luajit_peer.hpp) and hand-written C++ on the same functions, transition firings
// per second, re-testing after one property change, and checking and loading a large script. Command and
// figures: benchmarks/README.md, section "SOML++ runtime".
#include <benchmark/benchmark.h>

#include <Eigen/Geometry>
#include <cmath>
#include <fstream>
#include <memory>
#include <sstream>
#include <stdexcept>
#include <string>
#include <unordered_map>

#include "vsd/core.hpp"
#include "vsd/soml.hpp"

#if VSD_BENCH_HAVE_LUAJIT
#include "luajit_peer.hpp"
#endif

#if VSD_BENCH_HAVE_LUA
extern "C" {
#include <lauxlib.h>
#include <lua.h>
#include <lualib.h>
}
#endif

namespace {

struct Soml {
  vsd::Registry reg;
  vsd::Environment env{0, reg};
  vsd::soml::Program* program = nullptr;
  explicit Soml(const std::string& text, std::uint64_t budget = 1'000'000'000) {
    vsd::soml::RunOptions o;
    o.instruction_budget = budget;
    program = &env.use<vsd::soml::Module>().load(env.main_state(), "bench.soml", text, o);
  }
};

// ---- fib(27), the plain counting loop and the arithmetic loop, five ways side by side (issue 25) -------
// BM_<engine><workload>: engines Soml (the bytecode VM), Lua (5.4, linked), LuaJit (2.1, JIT on) and
// LuaJitInterp (the same with jit.off(): its interpreter), both loaded through luajit_peer.hpp, and Cpp
// (hand-written C++). Every engine's result is checked against the known value before timing and after
// every iteration (a wrong result marks the benchmark failed); the input comes in at run time.
// The functions (benchmarks/soml/functions.soml, read at run time: the same text that
// vsd_add_soml_module compiled into the native library VSD_BENCH_SOML_NATIVE).
std::string read_text(const char* path) {
  std::ifstream in(path);
  std::stringstream ss;
  ss << in.rdbuf();
  if (ss.str().empty()) throw std::runtime_error(std::string("cannot read ") + path);
  return ss.str();
}
std::string functions_text() { return read_text(VSD_BENCH_SOML_FUNCTIONS); }

// The same functions in Lua 5.1 / 5.4 (both run it: integers in 5.4, doubles in LuaJIT, exact here).
constexpr const char* kLua = R"(
function fib(n) if n < 2 then return n end return fib(n - 1) + fib(n - 2) end
function count_loop(n)
  local s = 0
  for i = 0, n - 1 do s = s + i end
  return s
end
function loop(n)
  local s = 0
  for i = 0, n - 1 do s = s + i * 3 % 7 end
  return s
end
)";

// The C++ twins. The loops pass the sum through an empty asm statement each iteration: the add stays one
// scalar add per iteration, as in the scripts (no closed form, no vector instructions, which no checked
// 64-bit arithmetic of SOML++ could have either); fib's argument is opaque at the call.
template <class T>
inline void keep_scalar(T& x) {
  asm("" : "+r"(x));
}
[[gnu::noinline]] std::int64_t cpp_fib(std::int64_t n) { return n < 2 ? n : cpp_fib(n - 1) + cpp_fib(n - 2); }
[[gnu::noinline]] std::int64_t cpp_count_loop(std::int64_t n) {
  std::int64_t s = 0;
  for (std::int64_t i = 0; i < n; i++) {
    s += i;
    keep_scalar(s);
  }
  return s;
}
[[gnu::noinline]] std::int64_t cpp_loop(std::int64_t n) {
  std::int64_t s = 0;
  for (std::int64_t i = 0; i < n; i++) {
    s = s + i * 3 % 7;
    keep_scalar(s);
  }
  return s;
}

struct Workload {
  const char* name;  // in the benchmark's name
  const char* fn;    // in the scripts
  std::int64_t n;
  std::int64_t want;
  std::int64_t (*cpp)(std::int64_t);
  double calls;  // function calls per run (fib), 0 for a loop
};
// fib(27) = 196418 makes 2 fib(28) - 1 = 635621 calls; the counting loop sums 0 .. 10^7-1; i * 3 % 7 runs
// through 0 3 6 2 5 1 4 (21 per 7), 10^7 = 7 * 1428571 + 3, so the sum is 1428571 * 21 + 0 + 3 + 6.
const Workload kWorkloads[] = {
    {"Fib27", "fib", 27, 196418, cpp_fib, 2.0 * 317811.0 - 1.0},
    {"CountLoop1e7", "count_loop", 10'000'000, 49'999'995'000'000, cpp_count_loop, 0},
    {"Loop1e7", "loop", 10'000'000, 30'000'000, cpp_loop, 0},
};

// Times engine.call(fn, n), checked against the known value.
template <class Engine>
void run_workload(benchmark::State& state, Engine& engine, const Workload& w) {
  if (engine.call(w.fn, w.n) != w.want) {
    state.SkipWithError("wrong result before timing");
    return;
  }
  for (auto _ : state) {
    const std::int64_t r = engine.call(w.fn, w.n);
    if (r != w.want) state.SkipWithError("wrong result");
    benchmark::DoNotOptimize(r);
  }
  if (w.calls > 0)
    state.counters["calls"] = benchmark::Counter(w.calls, benchmark::Counter::kIsIterationInvariantRate);
}

struct SomlEngine : Soml {
  explicit SomlEngine(bool native = false) : Soml(functions_text()) {
    if (native && program->load_native(VSD_BENCH_SOML_NATIVE) < 3) throw std::runtime_error("not native");
  }
  std::int64_t call(const char* fn, std::int64_t n) {
    return program->root().call(fn, {vsd::Value(n)}).as<std::int64_t>();
  }
};

struct CppEngine {
  const Workload* w;
  std::int64_t call(const char* /*fn*/, std::int64_t n) {
    benchmark::DoNotOptimize(n);  // opaque: the compiler cannot compute the result ahead
    return w->cpp(n);
  }
};

#if VSD_BENCH_HAVE_LUA
struct LuaEngine {
  lua_State* L = luaL_newstate();
  LuaEngine() {
    luaL_openlibs(L);
    if (luaL_dostring(L, kLua) != LUA_OK) throw std::runtime_error(lua_tostring(L, -1));
  }
  ~LuaEngine() { lua_close(L); }
  LuaEngine(const LuaEngine&) = delete;
  LuaEngine& operator=(const LuaEngine&) = delete;
  std::int64_t call(const char* fn, std::int64_t n) {
    lua_getglobal(L, fn);
    lua_pushinteger(L, n);
    lua_call(L, 1, 1);
    const lua_Integer r = lua_tointeger(L, -1);
    lua_pop(L, 1);
    return r;
  }
};
#endif

// Registered per workload, the engines next to each other in the output.
const bool kRegistered = [] {
  for (const Workload& w : kWorkloads) {
    const std::string name = w.name;
    benchmark::RegisterBenchmark(("BM_Soml" + name).c_str(), [&w](benchmark::State& s) {
      SomlEngine e;
      run_workload(s, e, w);
    })->Unit(benchmark::kMillisecond);
    // The same script compiled to native code (vsd_add_soml_module; docs/soml.md "Native compilation").
    benchmark::RegisterBenchmark(("BM_SomlNative" + name).c_str(), [&w](benchmark::State& s) {
      SomlEngine e(true);
      run_workload(s, e, w);
    })->Unit(benchmark::kMillisecond);
#if VSD_BENCH_HAVE_LUA
    benchmark::RegisterBenchmark(("BM_Lua" + name).c_str(), [&w](benchmark::State& s) {
      LuaEngine e;
      run_workload(s, e, w);
    })->Unit(benchmark::kMillisecond);
#endif
#if VSD_BENCH_HAVE_LUAJIT
    for (const bool jit : {true, false}) {
      benchmark::RegisterBenchmark(((jit ? "BM_LuaJit" : "BM_LuaJitInterp") + name).c_str(),
                                   [&w, jit](benchmark::State& s) {
                                     bench::LuaJit e(kLua, jit);
                                     run_workload(s, e, w);
                                   })
          ->Unit(benchmark::kMillisecond);
    }
#endif
    benchmark::RegisterBenchmark(("BM_Cpp" + name).c_str(), [&w](benchmark::State& s) {
      CppEngine e{&w};
      run_workload(s, e, w);
    })->Unit(benchmark::kMillisecond);
  }
  return true;
}();

// 10^6 frame-times-point products `p = t * p` (docs/soml.md 4.14: one XOP instruction calling Eigen),
// beside Lua with the 3-vector and the frame written by hand (tables, a rotation matrix and a
// translation), as a Lua script without a vector library would. Both rotate by 0.001 rad about z and
// translate by (0.1, 0.2, 0.3); the results agree.
constexpr int kFrameSteps = 1'000'000;
constexpr double kFrameAngle = 0.001;

constexpr const char* kFrameSoml = R"(
double frame_loop(int n, double angle) {
  Isometry3d t = Isometry3d(Vector3d(0.1, 0.2, 0.3), Quaterniond::from_axis_angle(Vector3d(0, 0, 1), angle));
  Vector3d p = Vector3d(1, 0, 0);
  for (int i = 0; i < n; i++) p = t * p;
  return p.x + p.y + p.z;
}
)";

double frame_loop_eigen(int n, double angle) {
  Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
  t.translation() = Eigen::Vector3d(0.1, 0.2, 0.3);
  t.linear() = Eigen::AngleAxisd(angle, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  Eigen::Vector3d p(1, 0, 0);
  for (int i = 0; i < n; ++i) p = t * p;
  return p.sum();
}

void BM_SomlFrameApply1e6(benchmark::State& state) {
  Soml s(kFrameSoml);
  const vsd::Value n(std::int64_t{kFrameSteps}), angle(kFrameAngle);
  const double want = frame_loop_eigen(kFrameSteps, kFrameAngle);
  for (auto _ : state) {
    const double got = s.program->root().call("frame_loop", {n, angle}).as<double>();
    if (std::abs(got - want) > 1e-6) state.SkipWithError("SOML++ and Eigen disagree");
    benchmark::DoNotOptimize(got);
  }
  state.SetItemsProcessed(state.iterations() * kFrameSteps);
}
BENCHMARK(BM_SomlFrameApply1e6)->Unit(benchmark::kMillisecond);

#if VSD_BENCH_HAVE_LUA
constexpr const char* kFrameLua = R"(
local function apply(t, p)
  local r, o = t.r, t.t
  return { r[1] * p[1] + r[2] * p[2] + r[3] * p[3] + o[1],
           r[4] * p[1] + r[5] * p[2] + r[6] * p[3] + o[2],
           r[7] * p[1] + r[8] * p[2] + r[9] * p[3] + o[3] }
end
function frame_loop(n, angle)
  local c, s = math.cos(angle), math.sin(angle)
  local t = { r = { c, -s, 0, s, c, 0, 0, 0, 1 }, t = { 0.1, 0.2, 0.3 } }
  local p = { 1, 0, 0 }
  for i = 1, n do p = apply(t, p) end
  return p[1] + p[2] + p[3]
end
)";

void BM_LuaFrameApply1e6(benchmark::State& state) {
  lua_State* L = luaL_newstate();
  luaL_openlibs(L);
  if (luaL_dostring(L, kFrameLua) != LUA_OK) {
    state.SkipWithError(lua_tostring(L, -1));
    lua_close(L);
    return;
  }
  const double want = frame_loop_eigen(kFrameSteps, kFrameAngle);
  for (auto _ : state) {
    lua_getglobal(L, "frame_loop");
    lua_pushinteger(L, kFrameSteps);
    lua_pushnumber(L, kFrameAngle);
    lua_call(L, 2, 1);
    const double got = lua_tonumber(L, -1);
    lua_pop(L, 1);
    if (std::abs(got - want) > 1e-6) state.SkipWithError("Lua and Eigen disagree");
    benchmark::DoNotOptimize(got);
  }
  state.SetItemsProcessed(state.iterations() * kFrameSteps);
  lua_close(L);
}
BENCHMARK(BM_LuaFrameApply1e6)->Unit(benchmark::kMillisecond);
#endif

// A ring of two black-token transitions: every firing moves the one token on.
void BM_SomlFiringsBlack(benchmark::State& state) {
  Soml s(R"(
place a = 1;
place b;
transition t1;
transition t2;
arrow a -> t1;
arrow t1 -> b;
arrow b -> t2;
arrow t2 -> a;
)");
  for (auto _ : state) benchmark::DoNotOptimize(s.program->step(1000));
  state.SetItemsProcessed(state.iterations() * 1000);
}
BENCHMARK(BM_SomlFiringsBlack);

// Object tokens circulating through two transitions whose conditions read a property of the mark
// (benchmarks/soml/firings.soml): in the VM, and with the conditions compiled to native code (the same
// script in the library VSD_BENCH_SOML_NATIVE). Every step must fire 1000 times.
void firings_object_condition(benchmark::State& state, bool native) {
  Soml s(read_text(VSD_BENCH_SOML_FIRINGS));
  if (native && s.program->load_native(VSD_BENCH_SOML_NATIVE) < 2) state.SkipWithError("conditions not native");
  for (auto _ : state)
    if (s.program->step(1000) != 1000) state.SkipWithError("the ring stopped");
  state.SetItemsProcessed(state.iterations() * 1000);
}
void BM_SomlFiringsObjectCondition(benchmark::State& state) { firings_object_condition(state, false); }
void BM_SomlNativeFiringsObjectCondition(benchmark::State& state) { firings_object_condition(state, true); }
BENCHMARK(BM_SomlFiringsObjectCondition);
BENCHMARK(BM_SomlNativeFiringsObjectCondition);

// One property change re-tests the one transition that reads it, however many others watch others.
void BM_SomlRetestAfterChange(benchmark::State& state) {
  const int n = static_cast<int>(state.range(0));
  std::string text;
  for (int i = 0; i < n; ++i) text += "int v" + std::to_string(i) + " = 0;\n";
  text += "place p = 1;\n";
  for (int i = 0; i < n; ++i) {
    text += "transition t" + std::to_string(i) + " { when v" + std::to_string(i) + " > 5; }\n";
    text += "arrow p -> t" + std::to_string(i) + ";\n";
  }
  Soml s(text);
  s.program->run_until_quiet();
  vsd::Node& root = s.program->root();
  const vsd::MetaProperty& v0 = root.meta().property("v0");
  std::int64_t x = 0;
  for (auto _ : state) {
    v0.set<std::int64_t>(root, ++x % 5);
    benchmark::DoNotOptimize(s.program->enabled_any());
  }
}
BENCHMARK(BM_SomlRetestAfterChange)->Arg(1)->Arg(100)->Arg(10000);

// ---- What a loaded program costs the setters of its state (issue 21) ----------------------------------
// A program's executor hears changes through a per-class vsd::Watch of what its conditions read. A typed
// set on an instance of a class no condition reads keeps the one-branch fast path: compare
// BM_SomlSetUnwatched/0 (no program) with /1 (a program whose condition reads another class). A set of a
// property a condition reads reaches the executor (BM_SomlSetWatched/0: the program's own watch) and is
// compared with the path every set took before, a state-wide property listener doing the executor's
// (instance, property) lookup (BM_SomlSetWatched/1: no program, that listener and lookup table alone — the
// old executor's hearing, without its marking work, so the comparison favours the old path).
class BenchTank : public vsd::Node {
  VSD_INSTANCE(BenchTank, vsd::Node)
  VSD_PROPERTY(double, level, 0.0)
};

constexpr const char* kReadsCounter = R"(
object c {
  int n = 0;
  place a = 1;
  place b;
  transition t { when n > 1000000; }
  arrow a -> t;
  arrow t -> b;
}
)";

constexpr const char* kReadsTank = R"(
shared<BenchTank> tank;
place a = 1;
place b;
transition t { when tank != null && tank.level > 1000000000000.0; }
arrow a -> t;
arrow t -> b;
)";

struct TankState {
  vsd::Registry reg;
  vsd::Environment env{0, reg};
  BenchTank* tank = nullptr;
  TankState() {
    reg.add<BenchTank>();
    tank = &env.main_state().create<BenchTank>();
    env.main_state().database().add_child(*tank);
  }
};

void BM_SomlSetUnwatched(benchmark::State& state) {
  TankState t;
  if (state.range(0) == 1) {
    vsd::soml::Program& p = t.env.use<vsd::soml::Module>().load(t.env.main_state(), "bench.soml", kReadsCounter);
    p.run_until_quiet();  // its condition has read c.n: the executor watches that class
  }
  double x = 1.0;
  t.tank->set_level(x);  // the load's savepoint recorded: the first set finds nobody listens any more
  if (t.tank->observed()) state.SkipWithError("the tank's class is watched");
  for (auto _ : state) {
    x += 1.0;
    t.tank->set_level(x);
    benchmark::ClobberMemory();
  }
  benchmark::DoNotOptimize(t.tank->level());
}
BENCHMARK(BM_SomlSetUnwatched)->Arg(0)->Arg(1);

struct DepKey {
  std::uint64_t id;
  const vsd::MetaProperty* prop;
  bool operator==(const DepKey&) const = default;
};
struct DepHash {
  std::size_t operator()(const DepKey& k) const noexcept {
    return std::hash<std::uint64_t>()(k.id * 0x9E3779B97F4A7C15ULL ^ reinterpret_cast<std::uintptr_t>(k.prop));
  }
};

void BM_SomlSetWatched(benchmark::State& state) {
  TankState t;
  vsd::soml::Program* p = nullptr;
  if (state.range(0) == 0) {
    p = &t.env.use<vsd::soml::Module>().load(t.env.main_state(), "bench.soml", kReadsTank);
    p->root().set("tank", vsd::Value(vsd::SharedRef<vsd::Node>(t.tank)));
    p->run_until_quiet();  // the condition read tank.level: the executor watches BenchTank.level
    if (!t.tank->observed()) state.SkipWithError("the executor does not watch the tank");
  }
  std::unordered_map<DepKey, std::vector<std::uint32_t>, DepHash> old_table;
  std::uint64_t heard = 0;
  vsd::Connection old_listener;
  if (state.range(0) == 1) {
    // The executor as it was: every set of every instance of the state came here.
    old_table[DepKey{t.tank->id(), &BenchTank::vsd_prop_level()}] = {0};
    old_listener = t.env.main_state().on_property_changed().connect(
        [&](vsd::SimStateInstance& inst, const vsd::MetaProperty& prop) {
          auto it = old_table.find(DepKey{inst.id(), &prop});
          if (it != old_table.end()) heard += it->second.size();
        });
  }
  double x = 0;
  for (auto _ : state) {
    x += 1.0;
    t.tank->set_level(x);
    benchmark::ClobberMemory();
  }
  benchmark::DoNotOptimize(heard);
  if (p != nullptr && p->enabled_any()) state.SkipWithError("the transition became enabled");
}
BENCHMARK(BM_SomlSetWatched)->Arg(0)->Arg(1);

// Checking and loading a script of about 10,000 lines.
void BM_SomlLoad10kLines(benchmark::State& state) {
  std::string text = "int total = 0;\n";
  for (int i = 0; i < 1000; ++i) {
    const std::string k = std::to_string(i);
    text += "class C" + k + " : Node {\n  int a = " + k +
            ";\n  double b = 1.5;\n  int f(int x) {\n    int y = x * a;\n"
            "    if (y > 10) { y = y - 10; } else { y = y + 1; }\n    while (y > 100) { y = y / 2; }\n    "
            "return y;\n  }\n}\n";
  }
  int lines = 0;
  for (char c : text) lines += c == '\n';
  for (auto _ : state) {
    vsd::Registry reg;
    vsd::Environment env(0, reg);
    auto& m = env.use<vsd::soml::Module>();
    benchmark::DoNotOptimize(&m.load(env.main_state(), "big.soml", text));
  }
  state.counters["lines"] = lines;
}
BENCHMARK(BM_SomlLoad10kLines)->Unit(benchmark::kMillisecond);

}  // namespace
