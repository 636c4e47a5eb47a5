// Internal header of the Python extension module (vsd._core): the handles Python holds and the
// conversions between vsd values and Python objects. Not installed.
#pragma once

#include <pybind11/pybind11.h>

#include <chrono>
#include <memory>
#include <unordered_map>
#include <vector>

#include "vsd/core/environment.hpp"

namespace vsdpy {

namespace py = pybind11;

struct EnvBox;

/// One SimState as Python sees it. Handles share it; `alive` turns false when the state is removed, so a
/// handle never touches a SimState that is gone. It keeps its Environment alive.
struct StateBox {
  vsd::SimState* state = nullptr;
  bool alive = true;
  std::shared_ptr<EnvBox> env;
  // The instance an on_deleted listener is told about: it has left the id map already, but is whole
  // until the listeners return, so its handles work meanwhile.
  const vsd::SimStateInstance* dying = nullptr;
};

/// The Environment a Python `vsd.Environment` owns; destroyed when the last Python object that needs it
/// (the environment, a state, an instance handle, a connection) is gone.
struct EnvBox {
  std::unique_ptr<vsd::Environment> env;
  /// What plugins built (vsd.load_plugin): destroyed before the Environment, newest first.
  std::vector<std::shared_ptr<void>> plugin_objects;
  std::unordered_map<const vsd::SimState*, std::weak_ptr<StateBox>> states;
  ~EnvBox();
};

/// The StateBox of @p s (made on first use).
std::shared_ptr<StateBox> box_of(const std::shared_ptr<EnvBox>& env, vsd::SimState& s);

/// A reference from Python to one instance: dead once the instance (or its state) is deleted. The memory
/// of a deleted instance stays with its SimState's pool, so the check is the id lookup, never a read of it.
struct Handle {
  std::shared_ptr<StateBox> box;
  vsd::SimStateInstance* ptr = nullptr;
  vsd::Id id = vsd::null_id;

  [[nodiscard]] bool alive() const noexcept {
    return box != nullptr && box->alive && (box->state->find(id) == ptr || (ptr == box->dying && ptr != nullptr));
  }
  /// The instance; raises vsd.DeadInstanceError when it is gone.
  vsd::SimStateInstance& get() const {
    if (VSD_UNLIKELY(!alive())) throw_dead();
    return *ptr;
  }
  [[noreturn]] void throw_dead() const;
};

/// A Python environment: owns the C++ one through its EnvBox.
struct PyEnvironment {
  std::shared_ptr<EnvBox> box;
};

/// A Python SimState: a StateBox.
struct PyState {
  std::shared_ptr<StateBox> box;
  vsd::SimState& get() const {
    if (!box->alive) throw py::value_error("the state was removed");
    return *box->state;
  }
};

/// The Python object (of the Python class of its vsd class) for @p inst; None for nullptr.
py::object wrap(const std::shared_ptr<StateBox>& box, vsd::SimStateInstance* inst);
/// The Python object for @p inst, found through the state box of its SimState in @p env.
py::object wrap_in(const std::shared_ptr<EnvBox>& env, vsd::SimStateInstance* inst);

/// A value of type @p t at @p p as a Python object.
py::object to_py(const vsd::MetaType& t, const void* p, const std::shared_ptr<StateBox>& box);
/// A Python object as a Value of type @p t; raises TypeError naming @p what and the expected type.
vsd::Value from_py(const vsd::MetaType& t, py::handle o, const std::string& what);

/// The instances of a class (a Python vsd class or a class name; subclasses included), in index order.
py::list instance_list(const std::shared_ptr<StateBox>& box, py::handle cls);
/// Property @p name of every instance of @p cls (index order): a NumPy array for numbers, stacked arrays
/// for the Eigen types, else a list.
py::object column(const std::shared_ptr<StateBox>& box, py::handle cls, const std::string& name);
/// Sets property @p name of every instance of @p cls from @p values, through the setters.
void set_column(const std::shared_ptr<StateBox>& box, py::handle cls, const std::string& name, py::handle values);

/// @p seconds from Python as milliseconds (rounded up, so that a short wait is not none); raises
/// ValueError naming @p what for a negative, NaN or infinite number.
std::chrono::milliseconds milliseconds_of(double seconds, const char* what);

/// The registry the module uses (the global one).
vsd::Registry& registry();

// Parts of the module, each in its own file.
void bind_instances(py::module_& m);   // instances.cpp: handles, classes, properties, methods, columns
void bind_entry_points(py::module_& m);  // entry.cpp: Environment, SimState, Transaction, io, SOML++
void bind_modules(py::module_& m);       // modules.cpp: scene (URDF), robotics (FK, IK), physics, collision
void bind_plugins(py::module_& m);       // plugins.cpp: load_plugin
void bind_soml(py::module_& m);          // soml.cpp: load, Program, Debugger (when vsd::soml is built)
void bind_web(py::module_& m);           // web.cpp: the inspector's Server (when vsd::web is built)
void bind_dist(py::module_& m);          // dist.cpp: join a DDS domain (when vsd::dist is built)
void bind_analysis(py::module_& m);      // analysis.cpp: P/T nets, PNML, state spaces (when vsd::analysis is built)

}  // namespace vsdpy
