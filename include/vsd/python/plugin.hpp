// A plugin of the Python module: a shared library that builds something (a work cell, a test rig) into a
// vsd.Environment from C++, loaded with `vsd.load_plugin(path, env, args)` (docs/python.md, "Plugins").
//
//   #include "vsd/python/plugin.hpp"
//   void build(vsd::python::PluginContext& c) {
//     c.env.use<...>();                      // modules, states, nodes, scheduler tasks, SOML++ programs
//     c.keep = std::make_shared<MyCell>(c.env, c.args);  // what the tasks refer to
//   }
//   VSD_PYTHON_PLUGIN(build)
//
// The library is a CMake MODULE that links no vsd library: every vsd symbol it uses comes from the
// Python module (vsd._core, which holds all of vsd's built modules), made visible to the library when it
// is loaded. It must be built with the same compiler, standard library and vsd as the module: the
// loader compares plugin_abi and refuses another.
#pragma once

#include <memory>
#include <string>
#include <vector>

namespace vsd {
class Environment;
}

namespace vsd::python {

#define VSD_PYTHON_DETAIL_STR2(x) #x
#define VSD_PYTHON_DETAIL_STR(x) VSD_PYTHON_DETAIL_STR2(x)
#ifdef NDEBUG
#define VSD_PYTHON_DETAIL_CHECKS "release"
#else
#define VSD_PYTHON_DETAIL_CHECKS "debug"
#endif

/// The plugin interface's version, the compiler, libstdc++'s string ABI and the assertions: what a plugin
/// and the module must share for the C++ objects they pass (PluginContext, Environment) to match.
inline constexpr const char* plugin_abi = "vsd-python-plugin 1; " __VERSION__ "; cxx11-abi " VSD_PYTHON_DETAIL_STR(
    _GLIBCXX_USE_CXX11_ABI) "; " VSD_PYTHON_DETAIL_CHECKS;

/// What the plugin's function gets, and gives back.
struct PluginContext {
  Environment& env;               ///< the vsd.Environment it was loaded into
  std::vector<std::string> args;  ///< load_plugin's args
  /// What the plugin built and the Environment's tasks, listeners and programs refer to. The Python
  /// environment holds it and destroys it first when it goes, right before the Environment itself (which
  /// is not stepped after that). The library is never unloaded: the classes it registered stay in the
  /// Registry, and the Environment's modules and instances may run its code until the end.
  std::shared_ptr<void> keep;
  /// Figures for the caller: load_plugin returns them as a dict of str.
  std::vector<std::pair<std::string, std::string>> info;
};

/// The plugin's function: builds into c.env; throws (a std::exception) when it cannot.
using PluginFunction = void (*)(PluginContext& c);

}  // namespace vsd::python

/// Defines the two symbols the loader looks for: vsd_python_plugin_abi (plugin_abi as this library was
/// built) and vsd_python_plugin, which calls @p function and turns an exception into @p error.
#define VSD_PYTHON_PLUGIN(function)                                                                        \
  extern "C" __attribute__((visibility("default"))) const char* vsd_python_plugin_abi() {                  \
    return ::vsd::python::plugin_abi;                                                                      \
  }                                                                                                        \
  extern "C" __attribute__((visibility("default"))) void vsd_python_plugin(::vsd::python::PluginContext& c, \
                                                                           ::std::string& error) noexcept { \
    try {                                                                                                  \
      ::vsd::python::PluginFunction f = (function);                                                        \
      f(c);                                                                                                \
    } catch (const ::std::exception& e) {                                                                  \
      error = e.what();                                                                                    \
      if (error.empty()) error = "an exception without a message";                                         \
    } catch (...) {                                                                                        \
      error = "an exception that is not a std::exception";                                                 \
    }                                                                                                      \
  }
