// vsd.soml: loading SOML++ scripts (a Program handle back) and the debugger (docs/python.md, "SOML++").
// The debugger's stop handler is a Python callable: it runs on the thread that steps, with the GIL taken
// for its call, and returns how to go on.
#include <pybind11/stl.h>

#include <memory>
#include <string>

#include "vsd/core/error.hpp"
#include "vsd/soml/debugger.hpp"
#include "vsd/soml/module.hpp"
#include "vsd/soml/net_classes.hpp"
#include "vsdpy.hpp"

namespace vsdpy {

namespace {

// A loaded program as Python holds it: valid while its state's SOML++ module still has it.
struct PyProgram {
  std::shared_ptr<StateBox> box;
  vsd::soml::Program* program = nullptr;
  std::string name;
  vsd::soml::Program& get() const {
    if (box->alive)
      if (auto* m = box->env->env->module<vsd::soml::Module>())
        for (vsd::soml::Program* p : m->programs(*box->state))
          if (p == program) return *p;
    throw vsd::Error("soml program '" + name + "': it is gone (its state was removed)");
  }
};

// The debugger of one program. Shared with the stop handler while it runs, so that dropping the last
// Python reference inside the handler cannot destroy the debugger under its own call.
struct PyDebugger {
  std::shared_ptr<StateBox> box;  // the Environment outlives the debugger
  std::unique_ptr<vsd::soml::Debugger> debugger;
  std::shared_ptr<py::object> on_stop;  // deleted with the GIL (see stop_handler)
  vsd::soml::Debugger& get() const {
    if (!debugger) throw vsd::Error("soml debugger: detached");
    return *debugger;
  }
  ~PyDebugger() {
    py::gil_scoped_release release;  // ~Debugger may drop the handler, which takes the GIL for it
    debugger.reset();
  }
};

vsd::soml::Resume resume_of(py::handle r) {
  if (r.is_none()) return vsd::soml::Resume::Continue;
  if (!PyUnicode_Check(r.ptr()))
    throw py::type_error("soml debugger: on_stop must return None, 'continue', 'step', 'next' or 'finish', not " +
                         std::string(py::str(r.get_type().attr("__name__"))));
  const auto s = r.cast<std::string>();
  if (s == "continue") return vsd::soml::Resume::Continue;
  if (s == "step") return vsd::soml::Resume::Step;
  if (s == "next") return vsd::soml::Resume::Next;
  if (s == "finish") return vsd::soml::Resume::Finish;
  throw py::value_error("soml debugger: on_stop returned '" + s + "'; expected 'continue', 'step', 'next' or 'finish'");
}

const char* reason_name(vsd::soml::StopReason r) {
  switch (r) {
    case vsd::soml::StopReason::Breakpoint:
      return "breakpoint";
    case vsd::soml::StopReason::Transition:
      return "transition";
    case vsd::soml::StopReason::Step:
      break;
  }
  return "step";
}

// One dict per item, filled by @p fill.
template <class T, class F>
py::list dicts(const std::vector<T>& items, F fill) {
  py::list l;
  for (const T& item : items) {
    py::dict d;
    fill(d, item);
    l.append(d);
  }
  return l;
}

void set_stop_handler(const std::shared_ptr<PyDebugger>& d, py::object fn) {
  if (fn.is_none()) {
    d->get().on_stop(nullptr);
    d->on_stop.reset();
    return;
  }
  if (!PyCallable_Check(fn.ptr())) throw py::type_error("soml debugger: on_stop expects a callable or None");
  auto callback = std::shared_ptr<py::object>(new py::object(std::move(fn)), [](py::object* p) {
    py::gil_scoped_acquire gil;
    delete p;
  });
  std::weak_ptr<PyDebugger> weak = d;
  d->get().on_stop([callback, weak](vsd::soml::Debugger&, const vsd::soml::Stop& stop) {
    py::gil_scoped_acquire gil;
    auto self = weak.lock();
    if (!self) return vsd::soml::Resume::Continue;
    try {
      py::dict s;
      s["reason"] = reason_name(stop.reason);
      s["breakpoint"] = stop.breakpoint;
      s["function"] = stop.function;
      s["line"] = stop.line;
      s["transition"] =
          wrap(self->box, const_cast<vsd::soml::Transition*>(stop.transition));  // None when not at one
      s["mark"] = stop.mark;
      return resume_of((*callback)(py::cast(self), s));
    } catch (py::error_already_set& e) {
      e.discard_as_unraisable("vsd soml debugger on_stop");
    } catch (py::builtin_exception& e) {  // resume_of's TypeError / ValueError
      e.set_error();
      py::error_already_set err;
      err.discard_as_unraisable("vsd soml debugger on_stop");
    } catch (const std::exception& e) {
      PyErr_SetString(PyExc_RuntimeError, e.what());
      py::error_already_set err;
      err.discard_as_unraisable("vsd soml debugger on_stop");
    }
    return vsd::soml::Resume::Continue;  // a failing handler does not stop the program
  });
  d->on_stop = std::move(callback);
}

}  // namespace

void bind_soml(py::module_& m) {
  py::module_ soml = m.def_submodule("soml", "vsd::soml: SOML++ scripts and their debugger");
  py::class_<PyProgram>(soml, "Program", "A loaded SOML++ program (vsd.soml.load's result)")
      .def_property_readonly("name", [](const PyProgram& p) { return p.name; })
      .def_property_readonly("root", [](const PyProgram& p) { return wrap(p.box, &p.get().root()); },
                             "The script object's node")
      .def_property_readonly("firings", [](const PyProgram& p) { return p.get().firings(); })
      .def("__repr__", [](const PyProgram& p) { return "<vsd.soml.Program '" + p.name + "'>"; });
  soml.def(
      "load",
      [](const PyEnvironment& e, const PyState& s, const std::string& name, const std::string& text) {
        auto& mod = e.box->env->use<vsd::soml::Module>();
        vsd::SimState& st = s.get();
        if (s.box->env != e.box) throw py::value_error("soml.load: the state belongs to another environment");
        vsd::soml::Program* p = nullptr;
        {
          py::gil_scoped_release release;
          p = &mod.load(st, name, text);
        }
        return PyProgram{s.box, p, name};
      },
      py::arg("env"), py::arg("state"), py::arg("name"), py::arg("text"),
      "Loads a SOML++ script into a state of env (its nets fire in every step); returns the Program");

  py::class_<PyDebugger, std::shared_ptr<PyDebugger>>(
      soml, "Debugger",
      "A debugger attached to one program: breakpoints, and a stop handler on_stop(debugger, stop) that "
      "returns None/'continue', 'step', 'next' or 'finish'")
      .def(py::init([](const PyProgram& p) {
             auto d = std::make_shared<PyDebugger>();
             d->box = p.box;
             d->debugger = std::make_unique<vsd::soml::Debugger>(p.get());
             return d;
           }),
           py::arg("program"))
      .def(
          "break_at",
          [](const PyDebugger& d, py::handle where) {
            if (PyLong_Check(where.ptr())) {
              const auto line = where.cast<long long>();
              if (line < 1 || line > 0xFFFFFFFFLL) throw py::value_error("soml debugger: line " + std::to_string(line) + " is not a line");
              return d.get().break_at_line(static_cast<std::uint32_t>(line));
            }
            if (!PyUnicode_Check(where.ptr())) throw py::type_error("soml debugger: break_at expects a line or 'FILE:LINE'");
            return d.get().break_at(where.cast<std::string>());
          },
          py::arg("location"), "Stops at a source line (an int, 'LINE' or 'FILE:LINE'); returns the breakpoint's id")
      .def("break_on_transition", [](const PyDebugger& d, const std::string& t) { return d.get().break_on_transition(t); },
           "Stops before transition 'owner.name' (or every transition of that name) fires; returns the id")
      .def("remove", [](const PyDebugger& d, int id) { return d.get().remove(id); })
      .def_property_readonly("breakpoints", [](const PyDebugger& d) {
        return dicts(d.get().breakpoints(), [](py::dict& x, const vsd::soml::Breakpoint& b) {
          x["id"] = b.id;
          x["line"] = b.line;
          x["transition"] = b.transition;
          x["hits"] = b.hits;
        });
      })
      .def("on_stop", &set_stop_handler, py::arg("fn"),
           "Sets the stop handler fn(debugger, stop) (None: every stop continues); stop is a dict "
           "{reason, breakpoint, function, line, transition, mark}")
      .def("step_into_next", [](const PyDebugger& d, bool on) { d.get().step_into_next(on); }, py::arg("on") = true)
      .def_property_readonly("stopped", [](const PyDebugger& d) { return d.get().stopped(); })
      .def_property_readonly("attached", [](const PyDebugger& d) { return d.debugger && d.debugger->attached(); })
      .def("call_stack", [](const PyDebugger& d) {
        return dicts(d.get().call_stack(), [](py::dict& x, const vsd::soml::StackFrame& f) {
          x["function"] = f.function;
          x["file"] = f.file;
          x["line"] = f.line;
        });
      }, "The SOML++ call stack at a stop, innermost first: [{function, file, line}]")
      .def("locals", [](const PyDebugger& d, std::size_t frame) {
        py::dict x;
        for (const auto& v : d.get().locals(frame)) x[py::str(v.name)] = v.value;
        return x;
      }, py::arg("frame") = 0, "A frame's parameters and locals as {name: value as printed}")
      .def("print", [](const PyDebugger& d, const std::string& path, std::size_t frame) { return d.get().print(path, frame); },
           py::arg("path"), py::arg("frame") = 0)
      .def("marking", [](const PyDebugger& d) { return d.get().marking(); })
      .def("detach", [](PyDebugger& d) {
        if (d.debugger && d.debugger->stopped()) throw vsd::Error("soml debugger: cannot detach inside its stop handler");
        py::gil_scoped_release release;
        d.debugger.reset();
      }, "Removes the breakpoints and the handler; the debugger cannot be used after");
}

}  // namespace vsdpy
