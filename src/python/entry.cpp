// The hand-written entry points: the module itself, errors, Environment, SimState, Transaction, signals,
// classes defined from Python, and vsd::io's entry points when it is built (SOML++: soml.cpp).
#include <pybind11/stl.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "vsd/core/database.hpp"
#include "vsd/core/registry.hpp"
#include "vsdpy.hpp"
#ifdef VSDPY_WITH_IO
#include "vsd/io/snapshot.hpp"
#endif

namespace vsdpy {

namespace {

using vsd::MetaInstance;
using vsd::SimState;
using vsd::SimStateInstance;

py::object python_callback_error_hook;


// A listener connected from Python; disconnects when closed or collected.
struct PyConnection {
  vsd::Connection connection;
  std::shared_ptr<StateBox> box;  // keeps the state's environment alive while connected
  void disconnect() {
    connection.disconnect();
    box.reset();
  }
};

// Calls a Python listener from the stepping thread: takes the GIL for the call only. A listener that
// raises must not unwind through vsd's signal dispatch: the error is reported (sys.unraisablehook) and
// the step goes on.
template <class... A>
void call_listener(const py::object& fn, const char* where, A&&... args) {
  py::gil_scoped_acquire gil;
  try {
    fn(std::forward<A>(args)...);
  } catch (py::error_already_set& e) {
    e.discard_as_unraisable(where);
  }
}

// Holds a py::object so that its copies and its destruction take the GIL (signal slots are destroyed
// whenever the state drops them).
struct Callback {
  std::shared_ptr<py::object> fn;
  explicit Callback(py::object f)
      : fn(new py::object(std::move(f)), [](py::object* p) {
          py::gil_scoped_acquire gil;
          delete p;
        }) {}
};

PyConnection connect_instance_signal(const std::shared_ptr<StateBox>& box, vsd::SimState::InstanceSink sink,
                                     py::object fn, const char* where, bool deleting = false) {
  Callback cb(std::move(fn));
  std::weak_ptr<StateBox> weak = box;
  PyConnection c;
  c.box = box;
  c.connection = sink.connect([cb, weak, where, deleting](SimStateInstance& inst) {
    py::gil_scoped_acquire gil;
    auto b = weak.lock();
    if (!b) return;
    const vsd::SimStateInstance* outer = b->dying;
    if (deleting) b->dying = &inst;
    call_listener(*cb.fn, where, wrap(b, &inst));
    b->dying = outer;
  });
  return c;
}

vsd::Transaction transaction_of(py::handle o) {
  if (py::isinstance<py::bytes>(o) || py::isinstance<py::bytearray>(o)) {
    const std::string s = o.cast<std::string>();
    return vsd::Transaction::from_bytes(std::vector<std::uint8_t>(s.begin(), s.end()));
  }
  return o.cast<vsd::Transaction>();
}

// A class defined in Python: a run-time vsd class with the given properties (name, type name, default).
std::string define_class(const std::string& name, const std::string& base,
                         const std::vector<std::tuple<std::string, std::string, py::object>>& props) {
  vsd::Registry& reg = registry();
  const MetaInstance& b = reg.get_class(base);
  vsd::ClassBuilder builder(name, b);
  for (const auto& [pname, tname, def] : props) {
    const vsd::MetaType& t = reg.get_type(tname);
    vsd::Value v = def.is_none() ? vsd::Value(t) : from_py(t, def, "default of " + name + "." + pname);
    builder.property(pname, t, std::move(v));
  }
  return builder.define(reg).name();
}

}  // namespace

EnvBox::~EnvBox() {
  for (auto& [s, w] : states)
    if (auto b = w.lock()) b->alive = false;
  py::gil_scoped_release release;  // modules may join threads that call back into Python
  // A plugin's objects first: the Environment's tasks and listeners refer to them, and their own
  // destructors may still use the Environment.
  while (!plugin_objects.empty()) plugin_objects.pop_back();
  env.reset();
}

std::chrono::milliseconds milliseconds_of(double seconds, const char* what) {
  if (!(seconds >= 0) || !std::isfinite(seconds))
    throw py::value_error(std::string(what) + ": seconds must be a finite number >= 0");
  // Clamped far below the range of the count (a wait of a billion seconds is "forever" here).
  return std::chrono::milliseconds(static_cast<long long>(std::ceil(std::min(seconds, 1e9) * 1000.0)));
}

std::shared_ptr<StateBox> box_of(const std::shared_ptr<EnvBox>& env, vsd::SimState& s) {
  auto& w = env->states[&s];
  if (auto b = w.lock()) return b;
  auto b = std::make_shared<StateBox>();
  b->state = &s;
  b->env = env;
  w = b;
  return b;
}

vsd::Registry& registry() { return vsd::Registry::global(); }

void bind_entry_points(py::module_& m) {
  static py::exception<vsd::Error> error(m, "Error", PyExc_RuntimeError);
  static py::exception<void> dead(m, "DeadInstanceError", error.ptr());
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const vsd::Error& e) {
      PyErr_SetString(error.ptr(), e.what());
    }
  });

  py::class_<vsd::Transaction>(m, "Transaction", "A bundle of recorded changes (bytes; invertible)")
      .def(py::init<>())
      .def_static("from_bytes", [](py::bytes b) { return transaction_of(b); })
      .def("bytes", [](const vsd::Transaction& t) {
        return py::bytes(reinterpret_cast<const char*>(t.bytes().data()), t.bytes().size());
      })
      .def("inverted", &vsd::Transaction::inverted)
      .def("describe", &vsd::Transaction::describe)
      .def("__len__", &vsd::Transaction::size)
      .def("__repr__", [](const vsd::Transaction& t) {
        return "<vsd.Transaction " + std::to_string(t.size()) + " operation(s), " +
               std::to_string(t.bytes().size()) + " bytes>";
      });

  py::class_<PyConnection>(m, "Connection", "A Python listener of a vsd signal")
      .def("disconnect", &PyConnection::disconnect)
      .def("__enter__", [](PyConnection& c) -> PyConnection& { return c; })
      .def("__exit__", [](PyConnection& c, py::args) { c.disconnect(); });

  py::class_<PyState>(m, "SimState", "One state of the simulation: its instances, signals and transactions")
      .def_property_readonly("name", [](const PyState& s) { return s.get().name(); })
      .def_property_readonly("database", [](const PyState& s) { return wrap(s.box, &s.get().database()); })
      .def_property_readonly("size", [](const PyState& s) { return s.get().size(); })
      .def(
          "create",
          [](const PyState& s, py::handle cls, py::kwargs kw) {
            std::string name = PyUnicode_Check(cls.ptr()) ? cls.cast<std::string>()
                               : py::hasattr(cls, "_vsd_class") ? cls.attr("_vsd_class").cast<std::string>()
                                                                : std::string();
            if (name.empty()) throw py::type_error("create expects a vsd class or a class name");
            const MetaInstance* c = registry().find_class(name);
            if (c == nullptr) throw py::key_error("unknown class '" + name + "'");
            py::object obj = wrap(s.box, &s.get().create(*c));
            for (auto item : kw) py::setattr(obj, item.first, item.second);
            return obj;
          },
          py::arg("cls"), "Creates an instance of a class (a vsd class or its name); keywords set properties")
      .def("find",
           [](const PyState& s, vsd::Id id) { return wrap(s.box, s.get().find(id)); })
      .def("destroy", [](const PyState& s, const Handle& h) { s.get().destroy(h.get()); })
      .def("instances", [](const PyState& s) {
        py::list l;
        for (SimStateInstance* i : s.get().instances()) l.append(wrap(s.box, i));
        return l;
      })
      .def("index", [](const PyState& s, py::handle cls) { s.get();
             return instance_list(s.box, cls);
           },
           "The instances of a class (subclasses included), in the order column() uses")
      .def("column", [](const PyState& s, py::handle cls, const std::string& p) {
             s.get();
             return column(s.box, cls, p);
           },
           "One property of every instance of a class as a NumPy array (or a list), in index() order")
      .def("set_column",
           [](const PyState& s, py::handle cls, const std::string& p, py::handle values) {
             s.get();
             set_column(s.box, cls, p, values);
           },
           "Sets one property of every instance of a class from an array, through the setters")
      .def("start_recording", [](const PyState& s) { s.get().start_recording(); })
      .def("take_recording", [](const PyState& s) { return s.get().take_recording(); })
      .def("stop_recording", [](const PyState& s) { return s.get().stop_recording(); })
      .def_property_readonly("recording", [](const PyState& s) { return s.get().recording(); })
      .def("apply", [](const PyState& s, py::handle t) {
        const vsd::Transaction tr = transaction_of(t);
        SimState& st = s.get();
        py::gil_scoped_release release;
        st.apply(tr);
      })
      .def("snapshot", [](const PyState& s) { return s.get().snapshot(); })
      .def("equals", [](const PyState& a, const PyState& b) {
        std::string diff;
        const bool eq = a.get().equals(b.get(), &diff);
        return py::make_tuple(eq, diff);
      })
      .def("on_created", [](const PyState& s, py::object fn) {
        return connect_instance_signal(s.box, s.get().on_created(), std::move(fn), "vsd on_created listener");
      })
      .def("on_deleted", [](const PyState& s, py::object fn) {
        return connect_instance_signal(s.box, s.get().on_deleted(), std::move(fn), "vsd on_deleted listener", true);
      })
      .def(
          "on_property_changed",
          [](const PyState& s, py::object fn, py::object cls) {
            Callback cb(std::move(fn));
            std::weak_ptr<StateBox> weak = s.box;
            auto listener = [cb, weak](SimStateInstance& inst, const vsd::MetaProperty& p) {
              py::gil_scoped_acquire gil;
              auto b = weak.lock();
              if (!b) return;
              call_listener(*cb.fn, "vsd on_property_changed listener", wrap(b, &inst), p.name());
            };
            PyConnection c;
            c.box = s.box;
            if (cls.is_none()) {
              c.connection = s.get().on_property_changed().connect(listener);
            } else {
              const std::string name = PyUnicode_Check(cls.ptr()) ? cls.cast<std::string>()
                                                                  : cls.attr("_vsd_class").cast<std::string>();
              c.connection = s.get().on_property_changed(registry().get_class(name)).connect(listener);
            }
            return c;
          },
          py::arg("fn"), py::arg("cls") = py::none(),
          "Calls fn(instance, property_name) after every change (of instances of cls, when given)")
      .def("__eq__", [](const PyState& a, const PyState& b) { return a.box == b.box; })
      .def("__hash__", [](const PyState& s) { return reinterpret_cast<std::uintptr_t>(s.box.get()); })
      .def("__repr__", [](const PyState& s) {
        return s.box->alive ? "<vsd.SimState '" + s.box->state->name() + "'>" : std::string("<vsd.SimState (removed)>");
      });

  py::class_<PyEnvironment>(m, "Environment", "The whole simulation: its states, modules and scheduler")
      .def(py::init([](std::uint16_t site) {
             PyEnvironment e;
             e.box = std::make_shared<EnvBox>();
             e.box->env = std::make_unique<vsd::Environment>(site);
             return e;
           }),
           py::arg("site") = 0)
      .def_property_readonly("main_state", [](const PyEnvironment& e) {
        return PyState{box_of(e.box, e.box->env->main_state())};
      })
      .def("create_state", [](const PyEnvironment& e, std::string name) {
        return PyState{box_of(e.box, e.box->env->create_state(std::move(name)))};
      })
      .def("remove_state", [](const PyEnvironment& e, const PyState& s) {
        if (s.box->env != e.box) throw py::value_error("the state belongs to another environment");
        SimState& st = s.get();
        if (st.is_main()) throw py::value_error("the main state cannot be removed");
        s.box->alive = false;
        e.box->states.erase(&st);
        e.box->env->remove_state(st);
      })
      .def("states", [](const PyEnvironment& e) {
        std::vector<PyState> out;
        for (SimState* s : e.box->env->states()) out.push_back(PyState{box_of(e.box, *s)});
        return out;
      })
      .def_property_readonly("time", [](const PyEnvironment& e) { return e.box->env->time(); })
      .def_property(
          "base_step", [](const PyEnvironment& e) { return e.box->env->scheduler().base_step(); },
          [](const PyEnvironment& e, double s) { e.box->env->scheduler().set_base_step(s); })
      .def("step", [](const PyEnvironment& e) {
        py::gil_scoped_release release;  // listeners take the GIL for their own calls
        e.box->env->step();
      })
      .def("run_for", [](const PyEnvironment& e, double seconds) {
        if (!(seconds >= 0)) throw py::value_error("run_for: seconds must be >= 0");
        py::gil_scoped_release release;
        e.box->env->run_for(seconds);
      })
      .def("add_task",
           [](const PyEnvironment& e, const std::string& name, py::object fn, double period, int phase) {
             Callback cb(std::move(fn));
             vsd::Scheduler& sch = e.box->env->scheduler();
             return sch.add_periodic(name, period > 0 ? period : sch.base_step(),
                                     [cb](const vsd::StepInfo& info) {
                                       call_listener(*cb.fn, "vsd scheduler task", info.time, info.step);
                                     },
                                     static_cast<vsd::Phase>(phase));
           },
           py::arg("name"), py::arg("fn"), py::arg("period") = 0.0, py::arg("phase") = 700,
           "Runs fn(time, step) on the stepping thread every `period` seconds (every step when 0), in "
           "scheduler phase `phase` (700: outputs); returns the task's id")
      .def("remove_task", [](const PyEnvironment& e, vsd::Scheduler::TaskId id) { e.box->env->scheduler().remove(id); });

  m.def("define_class", &define_class, py::arg("name"), py::arg("base"), py::arg("properties"),
        "Defines a run-time vsd class (name, base class name, [(property, type name, default)])");
  m.def("type_names", [] {
    std::vector<std::string> names;
    for (const vsd::MetaType* t : registry().types()) names.push_back(t->name());
    return names;
  });

#ifdef VSDPY_WITH_IO
  py::module_ io = m.def_submodule("io", "vsd::io: saving and loading SimStates");
  io.def("save", [](const PyState& s, const std::string& path) {
    const SimState& st = s.get();
    py::gil_scoped_release release;
    return vsd::io::save(st, path).instances;
  }, "Saves the whole state (binary, or vsd-text JSON for a .json name); returns the number of instances");
  io.def("load", [](const PyState& s, const std::string& path) {
    SimState& st = s.get();
    py::gil_scoped_release release;
    return vsd::io::load(st, path).instances;
  }, "Loads a state file into an empty state; returns the number of instances");
#endif
}

}  // namespace vsdpy

PYBIND11_MODULE(_core, m) {
  m.doc() = "vsd's Python bindings (the compiled part; import vsd)";
  vsdpy::bind_entry_points(m);
  vsdpy::bind_instances(m);
  vsdpy::bind_modules(m);
  vsdpy::bind_plugins(m);
#ifdef VSDPY_WITH_SOML
  vsdpy::bind_soml(m);
#endif
#ifdef VSDPY_WITH_WEB
  vsdpy::bind_web(m);
#endif
#ifdef VSDPY_WITH_DIST
  vsdpy::bind_dist(m);
#endif
#ifdef VSDPY_WITH_ANALYSIS
  vsdpy::bind_analysis(m);
#endif
}
