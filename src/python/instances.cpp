// Instances from Python: the handle type, one Python class per vsd class (made by vsd/__init__.py from
// what class_info() says), properties as descriptors, methods through vsdMetaCall, and columns.
#include <pybind11/numpy.h>
#include <pybind11/stl.h>

#include <string>
#include <vector>

#include "vsd/core/node.hpp"
#include "vsdpy.hpp"

namespace vsdpy {

namespace {

using vsd::MetaInstance;
using vsd::MetaProperty;
using vsd::MetaType;
using vsd::SimStateInstance;
using vsd::TypeKind;

// Python classes of vsd classes, by class. Made on first use by the factory vsd/__init__.py installs.
struct Classes {
  // By MetaInstance::index(), which no other class ever gets: a class that SOML++ or a closing
  // Environment undefined may leave its memory to a new class, never its index.
  std::unordered_map<std::size_t, py::object> by_class;
  py::object factory;      // vsd._class_for(name) -> Python class
  py::object handle_new;   // the pybind11 __new__ and __init__ of the handle type: the Python classes'
  py::object handle_init;  // own __new__ refuses direct construction (instances come from SimState.create)
};
Classes& classes() {
  static auto* c = new Classes();  // lives as long as the interpreter (never destroyed: holds Python objects)
  return *c;
}

py::object python_class(const MetaInstance& cls) {
  auto& c = classes();
  auto it = c.by_class.find(cls.index());
  if (it != c.by_class.end()) return it->second;
  py::object type = c.factory(cls.name());
  c.by_class.emplace(cls.index(), type);
  return type;
}

const MetaInstance& class_named(const std::string& name) {
  try {
    return registry().get_class(name);
  } catch (const vsd::Error& e) {
    throw py::key_error(e.what());
  }
}

const MetaInstance& class_of_arg(py::handle cls) {
  if (PyUnicode_Check(cls.ptr())) return class_named(cls.cast<std::string>());
  if (PyType_Check(cls.ptr()) && py::hasattr(cls, "_vsd_class"))
    return class_named(cls.attr("_vsd_class").cast<std::string>());
  throw py::type_error("expected a vsd class or a class name, got " + std::string(py::repr(cls)));
}

std::string who(const MetaProperty& p) { return "property '" + p.owner().name() + "." + p.name() + "'"; }

// The getter and setter of one property, bound in cpp_functions (as pybind11's def_readwrite binds its
// member): the common types are read and stored directly, everything else through a Value.
py::object get_property(const Handle& h, const MetaProperty* p) {
  const SimStateInstance& obj = h.get();
  const MetaType& t = p->type();
  const void* at = p->address(obj);
  if (t.is<double>()) return py::float_(*static_cast<const double*>(at));
  if (t.is<std::int32_t>()) return py::int_(*static_cast<const std::int32_t*>(at));
  if (t.is<bool>()) return py::bool_(*static_cast<const bool*>(at));
  return to_py(t, at, h.box);
}

void set_property(const Handle& h, const MetaProperty* p, py::handle v) {
  SimStateInstance& obj = h.get();
  if (p->has(vsd::ReadOnly)) throw py::attribute_error(who(*p) + " is read-only");
  const MetaType& t = p->type();
  if (t.is<double>() && PyFloat_CheckExact(v.ptr())) {
    p->set<double>(obj, PyFloat_AS_DOUBLE(v.ptr()));
    return;
  }
  vsd::Value value = from_py(t, v, who(*p));
  p->assign_raw(obj, value.data());
}

py::object call_method(const Handle& h, const vsd::MetaMethod* m, py::args args) {
  SimStateInstance& obj = h.get();
  const auto& types = m->arguments();
  if (args.size() != types.size())
    throw py::type_error(m->owner().name() + "." + m->name() + " takes " + std::to_string(types.size()) +
                         " argument(s), got " + std::to_string(args.size()) + " (" + m->signature() + ")");
  std::vector<vsd::Value> values;
  values.reserve(args.size());
  for (std::size_t i = 0; i < args.size(); ++i)
    values.push_back(from_py(*types[i], args[i],
                             m->owner().name() + "." + m->name() + " argument " + std::to_string(i + 1)));
  vsd::Value r;
  {
    py::gil_scoped_release release;  // a method may step, load or analyse; Python callbacks take the GIL
    r = m->invoke(obj, values);
  }
  if (r.empty()) return py::none();
  return to_py(*r.type(), r.data(), h.box);
}

py::object instance_method(py::handle f) {
  return py::reinterpret_steal<py::object>(PyInstanceMethod_New(f.ptr()));
}

// Instances of @p cls (subclasses too) in the element index's order.
std::vector<SimStateInstance*> instances_of(const vsd::SimState& s, const MetaInstance& cls) {
  std::vector<SimStateInstance*> out;
  out.reserve(s.index().count(cls));
  s.index().for_each(cls, true, [&](SimStateInstance& i) { out.push_back(&i); });
  return out;
}

// NumPy dtype of a column of @p t, with the number of doubles per row for the Eigen types.
template <class T>
py::array column_of(const std::vector<SimStateInstance*>& items, const MetaProperty& p) {
  py::array_t<T> a(static_cast<py::ssize_t>(items.size()));
  T* out = a.mutable_data();
  const std::size_t off = p.offset();
  for (std::size_t i = 0; i < items.size(); ++i)
    out[i] = *reinterpret_cast<const T*>(reinterpret_cast<const char*>(items[i]) + off);
  return a;
}

template <class T>
void set_column_of(const std::vector<SimStateInstance*>& items, const MetaProperty& p, py::handle values) {
  auto a = py::array_t<T, py::array::c_style | py::array::forcecast>::ensure(values);
  if (!a) {
    PyErr_Clear();
    throw py::type_error("column " + p.name() + " expects an array of numbers");
  }
  if (a.ndim() != 1 || static_cast<std::size_t>(a.shape(0)) != items.size())
    throw py::value_error("column " + p.name() + ": " + std::to_string(items.size()) +
                          " instances, got an array of shape " + std::string(py::str(a.attr("shape"))));
  const T* in = a.data();
  for (std::size_t i = 0; i < items.size(); ++i) p.set<T>(*items[i], in[i]);  // recorded and signalled
}

}  // namespace

py::object column(const std::shared_ptr<StateBox>& box, py::handle cls, const std::string& name) {
  const MetaInstance& c = class_of_arg(cls);
  const MetaProperty& p = [&]() -> const MetaProperty& {
    if (const MetaProperty* q = c.find_property(name)) return *q;
    throw py::attribute_error("class " + c.name() + " has no property '" + name + "'");
  }();
  const auto items = instances_of(*box->state, c);
  const MetaType& t = p.type();
  if (t.is<double>()) return column_of<double>(items, p);
  if (t.is<float>()) return column_of<float>(items, p);
  if (t.is<std::int32_t>()) return column_of<std::int32_t>(items, p);
  if (t.is<std::int64_t>()) return column_of<std::int64_t>(items, p);
  if (t.is<std::uint32_t>()) return column_of<std::uint32_t>(items, p);
  if (t.is<std::uint64_t>()) return column_of<std::uint64_t>(items, p);
  if (t.is<bool>()) return column_of<bool>(items, p);
  // Anything else: a list (strings, references) or, for the Eigen types, a stacked array.
  py::list l(items.size());
  for (std::size_t i = 0; i < items.size(); ++i) l[i] = to_py(t, p.address(*items[i]), box);
  if (t.kind() == TypeKind::Struct && !items.empty() && py::isinstance<py::array>(l[0]))
    return py::module_::import("numpy").attr("stack")(l);
  return l;
}

void set_column(const std::shared_ptr<StateBox>& box, py::handle cls, const std::string& name, py::handle values) {
  const MetaInstance& c = class_of_arg(cls);
  const MetaProperty* p = c.find_property(name);
  if (p == nullptr) throw py::attribute_error("class " + c.name() + " has no property '" + name + "'");
  if (p->has(vsd::ReadOnly)) throw py::attribute_error(who(*p) + " is read-only");
  const auto items = instances_of(*box->state, c);
  const MetaType& t = p->type();
  if (t.is<double>()) return set_column_of<double>(items, *p, values);
  if (t.is<float>()) return set_column_of<float>(items, *p, values);
  if (t.is<std::int32_t>()) return set_column_of<std::int32_t>(items, *p, values);
  if (t.is<std::int64_t>()) return set_column_of<std::int64_t>(items, *p, values);
  // Other types: element by element through the generic conversion (all converted before any is set).
  const auto seq = py::reinterpret_borrow<py::sequence>(values);
  if (!py::isinstance<py::sequence>(values) && !py::isinstance<py::array>(values))
    throw py::type_error("column " + name + " expects a sequence");
  if (static_cast<std::size_t>(py::len(values)) != items.size())
    throw py::value_error("column " + name + ": " + std::to_string(items.size()) + " instances, got " +
                          std::to_string(py::len(values)) + " values");
  std::vector<vsd::Value> converted;
  converted.reserve(items.size());
  for (std::size_t i = 0; i < items.size(); ++i)
    converted.push_back(from_py(t, values[py::int_(i)], who(*p) + "[" + std::to_string(i) + "]"));
  for (std::size_t i = 0; i < items.size(); ++i) p->assign_raw(*items[i], converted[i].data());
}

namespace {

std::string type_hint(const MetaType& t) {
  switch (t.kind()) {
    case TypeKind::Bool: return "bool";
    case TypeKind::Int:
    case TypeKind::UInt: return "int";
    case TypeKind::Float:
    case TypeKind::Double: return "float";
    case TypeKind::String: return "str";
    case TypeKind::Enum:
    case TypeKind::Flags: return t.name();
    case TypeKind::Struct:
      return t.fields().empty() || t.is<Eigen::Vector3d>() || t.is<Eigen::Isometry3d>() ||
                     t.name().rfind("Vector", 0) == 0 || t.name() == "Quaterniond"
                 ? "numpy.ndarray"
                 : "dict";
    case TypeKind::Vector: return "list[" + type_hint(*t.element()) + "]";
    case TypeKind::Ref:
    case TypeKind::SharedRef: return "Optional[" + (t.target() ? t.target()->name() : "Instance") + "]";
    case TypeKind::RefList:
    case TypeKind::SharedRefList: return "list[" + (t.target() ? t.target()->name() : "Instance") + "]";
  }
  return "object";
}

}  // namespace

void Handle::throw_dead() const {
  static py::handle dead = py::module_::import("vsd._core").attr("DeadInstanceError");
  PyErr_SetString(dead.ptr(), ("instance #" + std::to_string(id) + " is gone (deleted, or its state removed)").c_str());
  throw py::error_already_set();
}

py::object wrap(const std::shared_ptr<StateBox>& box, SimStateInstance* inst) {
  if (inst == nullptr) return py::none();
  py::object type = python_class(inst->meta());
  py::object obj = classes().handle_new(type);
  classes().handle_init(obj);
  Handle& h = obj.cast<Handle&>();
  h.box = box;
  h.ptr = inst;
  h.id = inst->id();
  return obj;
}

py::object wrap_in(const std::shared_ptr<EnvBox>& env, SimStateInstance* inst) {
  if (inst == nullptr) return py::none();
  return wrap(box_of(env, inst->state()), inst);
}

py::list instance_list(const std::shared_ptr<StateBox>& box, py::handle cls) {
  const auto items = instances_of(*box->state, class_of_arg(cls));
  py::list l(items.size());
  for (std::size_t i = 0; i < items.size(); ++i) l[i] = wrap(box, items[i]);
  return l;
}

void bind_instances(py::module_& m) {
  py::class_<Handle>(m, "_Handle", "An instance of the simulation database (any vsd class)")
      .def(py::init<>())
      .def_property_readonly("vsd_id", [](const Handle& h) { return h.get().id(); },
                             "The instance's id (stable, equal in every replica)")
      .def_property_readonly("vsd_alive", &Handle::alive, "False once the instance is deleted")
      .def_property_readonly("vsd_class", [](const Handle& h) { return h.get().meta().name(); },
                             "The full name of the instance's vsd class")
      .def("__eq__",
           [](const Handle& a, py::handle b) {
             return py::isinstance<Handle>(b) && b.cast<const Handle&>().ptr == a.ptr &&
                    b.cast<const Handle&>().id == a.id;
           })
      .def("__hash__", [](const Handle& h) { return static_cast<std::size_t>(h.id); })
      .def("__repr__", [](const Handle& h) {
        if (!h.alive()) return "<vsd dead instance #" + std::to_string(h.id) + ">";
        std::string r = "<vsd." + h.ptr->meta().name() + " #" + std::to_string(h.id);
        if (const MetaProperty* p = h.ptr->meta().find_property("name"); p != nullptr && p->type().is<std::string>())
          r += " '" + p->get<std::string>(*h.ptr) + "'";
        return r + ">";
      });
  classes().handle_new = m.attr("_Handle").attr("__new__");
  classes().handle_init = m.attr("_Handle").attr("__init__");

  // The benchmark's reference (benchmarks/python_bench.py): a plain C++ member bound with def_readwrite.
  struct BenchStruct {
    double x = 0.0;
  };
  py::class_<BenchStruct>(m, "_BenchStruct").def(py::init<>()).def_readwrite("x", &BenchStruct::x);

  m.def("_set_class_factory", [](py::object f) { classes().factory = std::move(f); });
  m.def("_register_class", [](const std::string& name, py::object cls) {
    classes().by_class[class_named(name).index()] = std::move(cls);
  });
  m.def("_forget_class", [](const std::string& name) {
    if (const MetaInstance* c = registry().find_class_exact(name)) classes().by_class.erase(c->index());
  });
  m.def(
      "class_info",
      [](const std::string& name) {
        const MetaInstance& c = class_named(name);
        py::dict d;
        d["name"] = c.name();
        d["index"] = c.index();
        d["base"] = c.base() != nullptr ? py::object(py::str(c.base()->name())) : py::object(py::none());
        d["abstract"] = c.is_abstract();
        d["runtime"] = c.is_runtime();
        py::list props;
        for (const MetaProperty* p : c.own_properties()) {
          auto getter = py::cpp_function([p](const Handle& h) { return get_property(h, p); });
          auto setter = py::cpp_function([p](const Handle& h, py::handle v) { set_property(h, p, v); });
          const std::string doc = p->type().name() + (p->has(vsd::ReadOnly) ? " (read-only)" : "");
          py::object prop = py::module_::import("builtins").attr("property")(getter, setter, py::none(), doc);
          props.append(py::make_tuple(p->name(), prop, p->type().name(), type_hint(p->type()),
                                      p->has(vsd::ReadOnly)));
        }
        d["properties"] = props;
        py::list methods;
        for (const vsd::MetaMethod* mm : c.methods()) {
          if (&mm->owner() != &c) continue;  // inherited ones come with the base's Python class
          auto f = py::cpp_function([mm](const Handle& h, py::args a) { return call_method(h, mm, a); },
                                    py::name(mm->name().c_str()));
          py::list args;
          for (const MetaType* t : mm->arguments()) args.append(type_hint(*t));
          methods.append(py::make_tuple(mm->name(), instance_method(f), mm->signature(), args,
                                        mm->result() != nullptr ? type_hint(*mm->result()) : "None"));
        }
        d["methods"] = methods;
        return d;
      },
      "What the registry knows about a class: name, base, own properties and methods");
  m.def("class_names", [] {
    std::vector<std::string> names;
    for (const MetaInstance* c : registry().classes()) names.push_back(c->name());
    return names;
  });
  m.def("_node_add_child", [](const Handle& parent, const Handle& child) {
    auto* p = parent.get().as<vsd::Node>();
    auto* c = child.get().as<vsd::Node>();
    if (p == nullptr || c == nullptr) throw py::type_error("add_child: both must be Nodes");
    p->add_child(*c);
  });
  m.def("_node_remove_child", [](const Handle& parent, const Handle& child) {
    auto* p = parent.get().as<vsd::Node>();
    auto* c = child.get().as<vsd::Node>();
    if (p == nullptr || c == nullptr) throw py::type_error("remove_child: both must be Nodes");
    p->remove_child(*c);
  });
  m.def("_add_extension", [](const Handle& owner, const Handle& ext) {
    auto* o = owner.get().as<vsd::NamedModelInstance>();
    auto* e = ext.get().as<vsd::Extension>();
    if (o == nullptr) throw py::type_error("add_extension: the owner must be a NamedModelInstance");
    if (e == nullptr) throw py::type_error("add_extension: expected an Extension, got a " + ext.get().meta().name());
    o->add_extension(*e);
  });
  m.def("_remove_extension", [](const Handle& owner, const Handle& ext) {
    auto* o = owner.get().as<vsd::NamedModelInstance>();
    auto* e = ext.get().as<vsd::Extension>();
    if (o == nullptr || e == nullptr) throw py::type_error("remove_extension: expects an owner and an Extension");
    o->remove_extension(*e);
  });
  m.def("_node_parent", [](const Handle& n) {
    auto* p = n.get().as<vsd::Node>();
    if (p == nullptr) throw py::type_error("parent: not a Node");
    return wrap(n.box, p->parent());
  });
  m.def("_node_path", [](const Handle& n) {
    auto* p = n.get().as<vsd::Node>();
    if (p == nullptr) throw py::type_error("path: not a Node");
    return p->path();
  });
}

}  // namespace vsdpy
