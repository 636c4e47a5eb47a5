// vsd.load_plugin: a shared library that builds into an Environment from C++ (include/vsd/python/plugin.hpp,
// docs/python.md "Plugins"). The library links no vsd library; it gets vsd's symbols from this module,
// which is therefore made global (RTLD_GLOBAL) before the first plugin is opened.
#include <dlfcn.h>
#include <pybind11/stl.h>

#include <cstring>
#include <filesystem>
#include <string>
#include <vector>

#include "vsd/core/error.hpp"
#include "vsd/python/plugin.hpp"
#include "vsdpy.hpp"

namespace vsdpy {

namespace {

[[noreturn]] void raise(PyObject* type, const std::string& message) {
  PyErr_SetString(type, message.c_str());
  throw py::error_already_set();
}

// Re-opens this module's own file with RTLD_GLOBAL: Python opened it RTLD_LOCAL, and a plugin's
// undefined vsd symbols must resolve to this module's (one Registry, one copy of every class's meta).
void make_module_global() {
  static bool done = false;
  if (done) return;
  Dl_info info{};
  if (::dladdr(reinterpret_cast<void*>(&make_module_global), &info) == 0 || info.dli_fname == nullptr)
    raise(PyExc_ImportError, "load_plugin: cannot find the file of vsd._core (dladdr)");
  if (::dlopen(info.dli_fname, RTLD_NOW | RTLD_NOLOAD | RTLD_GLOBAL) == nullptr) {
    const char* e = ::dlerror();
    raise(PyExc_ImportError, std::string("load_plugin: cannot make vsd._core's symbols global: ") + (e ? e : "?"));
  }
  done = true;  // the extra reference is never dropped: the module is never unloaded
}

template <class F>
F symbol(void* lib, const std::string& path, const char* name) {
  ::dlerror();
  void* s = ::dlsym(lib, name);
  if (s == nullptr)
    raise(PyExc_ImportError, path + " is not a vsd Python plugin: it has no symbol " + name +
                                 " (VSD_PYTHON_PLUGIN(function) defines it)");
  F f = nullptr;
  static_assert(sizeof f == sizeof s);
  std::memcpy(&f, &s, sizeof f);  // object pointer to function pointer (POSIX guarantees it works)
  return f;
}

py::dict load_plugin(const std::string& path, const PyEnvironment& e, const std::vector<std::string>& args) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) raise(PyExc_FileNotFoundError, "load_plugin: no file " + path);
  make_module_global();
  // Never closed: the classes it registered stay in the Registry, and every Environment it built into
  // may hold its objects (modules, instances, tasks) — the code of all of them is in the library.
  void* lib = ::dlopen(path.c_str(), RTLD_NOW | RTLD_LOCAL);
  if (lib == nullptr) {
    const char* m = ::dlerror();
    raise(PyExc_ImportError, "load_plugin: cannot load " + path + ": " + (m ? m : "?"));
  }
  using Abi = const char* (*)();
  using Entry = void (*)(vsd::python::PluginContext&, std::string&);
  const std::string abi = symbol<Abi>(lib, path, "vsd_python_plugin_abi")();
  if (abi != vsd::python::plugin_abi)
    raise(PyExc_ImportError, "load_plugin: " + path + " was built for another ABI ('" + abi +
                                 "'); this module is '" + vsd::python::plugin_abi + "'");
  const Entry entry = symbol<Entry>(lib, path, "vsd_python_plugin");
  vsd::python::PluginContext c{*e.box->env, args, nullptr, {}};
  std::string error;
  {
    py::gil_scoped_release release;  // building may take a while (IK, loads); tasks may call Python
    entry(c, error);
  }
  if (c.keep) e.box->plugin_objects.push_back(std::move(c.keep));  // also after an error: tasks may use it
  if (!error.empty()) throw vsd::Error("load_plugin: " + path + ": " + error);
  py::dict d;
  for (auto& [k, v] : c.info) d[py::str(k)] = v;
  return d;
}

}  // namespace

void bind_plugins(py::module_& m) {
  m.def("load_plugin", &load_plugin, py::arg("path"), py::arg("env"), py::arg("args") = std::vector<std::string>{},
        "Loads a C++ plugin (a shared library made with VSD_PYTHON_PLUGIN) and lets it build into env; "
        "returns its figures as a dict of str");
}

}  // namespace vsdpy
