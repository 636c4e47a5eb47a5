/** @file
 *  @brief LuaJIT 2.1 in the same binary as Lua 5.4, loaded at run time into a link namespace of its own.
 *
 *  Lua 5.4 (linked normally) and LuaJIT export the same C names (`lua_pushinteger`, `luaL_openlibs`, ...)
 *  with different ABIs, so they cannot both be linked into one executable. `dlopen(RTLD_LOCAL)` is not
 *  enough either: LuaJIT's own library calls its public functions through the PLT (Debian's
 *  libluajit-5.1.so.2 has R_X86_64_JUMP_SLOT relocations for `lua_*` and `luaL_*`), and the dynamic
 *  linker resolves those in the global scope first, where Lua 5.4's functions of the same names already
 *  are: `luaL_openlibs` of LuaJIT would call Lua 5.4's `lua_pushcclosure`. So LuaJIT is loaded with
 *  `dlmopen(LM_ID_NEWLM)`: a new link namespace with its own copies of its dependencies, in which no Lua
 *  5.4 symbol is visible. Its functions are reached only through the pointers resolved here; this file
 *  includes no LuaJIT header (whose declarations would name the same `extern "C"` functions as Lua 5.4's
 *  with other types) and declares the few Lua 5.1 API functions it needs itself (the Lua 5.1 reference
 *  manual, section 3, and luajit.h). The library's path comes from CMake (VSD_BENCH_LUAJIT_SO).
 */
#pragma once

#include <dlfcn.h>

#include <cstddef>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <type_traits>

namespace bench {

struct LuaJitState;  // LuaJIT's lua_State, opaque

class LuaJit {
 public:
  /// Loads the library (once per process) and makes a state with the standard libraries and @p script
  /// run; @p jit false switches the JIT compiler off (`jit.off()`: the interpreter runs everything).
  LuaJit(const char* script, bool jit) {
    const Api& api = this->api();
    L_ = api.newstate();
    if (L_ == nullptr) throw std::runtime_error("LuaJIT: luaL_newstate failed");
    try {
      api.openlibs(L_);
      run(script);
      run(jit ? "jit.on()" : "jit.off() jit.flush()");
      // Which engine is on, as LuaJIT reports it (jit.status() is true when the JIT compiler is on).
      load("return jit.status()");
      pcall(0, 1);
      const bool on = api.toboolean(L_, -1) != 0;
      api.settop(L_, 0);
      if (on != jit) throw std::runtime_error("LuaJIT: the JIT compiler could not be switched");
    } catch (...) {
      api.close(L_);
      throw;
    }
  }
  ~LuaJit() { api().close(L_); }
  LuaJit(const LuaJit&) = delete;
  LuaJit& operator=(const LuaJit&) = delete;

  /// The global function @p fn called with the integer @p n; its result as an integer.
  std::int64_t call(const char* fn, std::int64_t n) {
    const Api& a = api();
    a.getfield(L_, kGlobalsIndex, fn);
    a.pushinteger(L_, static_cast<std::ptrdiff_t>(n));
    pcall(1, 1);
    const std::ptrdiff_t r = a.tointeger(L_, -1);
    a.settop(L_, 0);
    return r;
  }

 private:
  static constexpr int kGlobalsIndex = -10002;  // LUA_GLOBALSINDEX of Lua 5.1
  struct Api {
    LuaJitState* (*newstate)();
    void (*openlibs)(LuaJitState*);
    int (*loadstring)(LuaJitState*, const char*);
    int (*pcall)(LuaJitState*, int, int, int);
    void (*getfield)(LuaJitState*, int, const char*);
    void (*pushinteger)(LuaJitState*, std::ptrdiff_t);
    std::ptrdiff_t (*tointeger)(LuaJitState*, int);
    int (*toboolean)(LuaJitState*, int);
    const char* (*tolstring)(LuaJitState*, int, std::size_t*);
    void (*settop)(LuaJitState*, int);
    void (*close)(LuaJitState*);
  };

  static const Api& api() {
    static const Api a = [] {
      void* h = dlmopen(LM_ID_NEWLM, VSD_BENCH_LUAJIT_SO, RTLD_NOW | RTLD_LOCAL);
      if (h == nullptr) throw std::runtime_error(std::string("LuaJIT: ") + dlerror());
      auto get = [h](auto& fp, const char* name) {
        void* p = dlsym(h, name);
        if (p == nullptr) throw std::runtime_error(std::string("LuaJIT: no symbol ") + name);
        fp = reinterpret_cast<std::remove_reference_t<decltype(fp)>>(p);
      };
      Api r{};
      get(r.newstate, "luaL_newstate");
      get(r.openlibs, "luaL_openlibs");
      get(r.loadstring, "luaL_loadstring");
      get(r.pcall, "lua_pcall");
      get(r.getfield, "lua_getfield");
      get(r.pushinteger, "lua_pushinteger");
      get(r.tointeger, "lua_tointeger");
      get(r.toboolean, "lua_toboolean");
      get(r.tolstring, "lua_tolstring");
      get(r.settop, "lua_settop");
      get(r.close, "lua_close");
      return r;
    }();
    return a;
  }

  void load(const char* chunk) {
    if (api().loadstring(L_, chunk) != 0) fail();
  }
  void pcall(int nargs, int nresults) {
    if (api().pcall(L_, nargs, nresults, 0) != 0) fail();
  }
  void run(const char* chunk) {
    load(chunk);
    pcall(0, 0);
  }
  [[noreturn]] void fail() {
    const char* msg = api().tolstring(L_, -1, nullptr);
    std::string m = std::string("LuaJIT: ") + (msg != nullptr ? msg : "error");
    api().settop(L_, 0);
    throw std::runtime_error(m);
  }

  LuaJitState* L_ = nullptr;
};

}  // namespace bench
