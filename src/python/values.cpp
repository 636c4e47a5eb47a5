// Conversions between vsd values (any MetaType) and Python objects, driven by the meta-information alone.
#include <pybind11/numpy.h>

#include <Eigen/Geometry>
#include <cstring>
#include <string>

#include "vsd/core/meta_type_eigen.hpp"
#include "vsd/core/reference.hpp"
#include "vsdpy.hpp"

namespace vsdpy {

namespace {

using vsd::MetaType;
using vsd::TypeKind;

// Python enum classes of vsd enum and flags types, made by vsd/__init__.py's factory on first use.
// A run-time enum that is undefined may leave its memory to another: an entry is used only while the
// type at its address still has its name and values.
struct EnumEntry {
  std::string name;
  std::vector<MetaType::EnumValue> values;
  py::object cls;
};
std::unordered_map<const MetaType*, EnumEntry>& enum_classes() {
  static auto* m = new std::unordered_map<const MetaType*, EnumEntry>();  // lives as long as the module
  return *m;
}

bool same_values(const std::vector<MetaType::EnumValue>& a, const std::vector<MetaType::EnumValue>& b) {
  if (a.size() != b.size()) return false;
  for (std::size_t i = 0; i < a.size(); ++i)
    if (a[i].name != b[i].name || a[i].value != b[i].value) return false;
  return true;
}

py::object enum_class(const MetaType& t) {
  auto& cache = enum_classes();
  auto it = cache.find(&t);
  if (it != cache.end() && it->second.name == t.name() && same_values(it->second.values, t.enum_values()))
    return it->second.cls;
  py::list values;
  for (const auto& v : t.enum_values()) values.append(py::make_tuple(v.name, v.value));
  py::object cls = py::module_::import("vsd").attr("_make_enum")(t.name(), values, t.kind() == TypeKind::Flags);
  cache[&t] = EnumEntry{t.name(), t.enum_values(), cls};
  return cls;
}

[[noreturn]] void type_error(const std::string& what, const MetaType& t, py::handle o) {
  throw py::type_error(what + " expects " + t.name() + ", got " +
                       std::string(py::str(py::type::of(o).attr("__name__"))) + " " +
                       std::string(py::repr(o)).substr(0, 80));
}

// The fixed-size Eigen types as flat double arrays: their coefficients and the NumPy shape.
struct EigenShape {
  int rows = 0, cols = 0;
};
EigenShape eigen_shape(const MetaType& t) {
  if (t.is<Eigen::Vector2d>()) return {2, 1};
  if (t.is<Eigen::Vector3d>()) return {3, 1};
  if (t.is<Eigen::Vector4d>()) return {4, 1};
  if (t.is<Eigen::Quaterniond>()) return {4, 1};
  if (t.is<Eigen::Isometry3d>()) return {4, 4};
  return {};
}

py::object eigen_to_py(const MetaType& t, const void* p, EigenShape s) {
  if (s.cols == 4) {
    py::array_t<double> a({4, 4});
    const auto& m = static_cast<const Eigen::Isometry3d*>(p)->matrix();
    for (int r = 0; r < 4; ++r)
      for (int c = 0; c < 4; ++c) a.mutable_at(r, c) = m(r, c);
    return a;
  }
  py::array_t<double> a(s.rows);
  double* out = a.mutable_data();
  if (t.is<Eigen::Quaterniond>()) {  // [w, x, y, z], as in vsd's text form
    const auto& q = *static_cast<const Eigen::Quaterniond*>(p);
    out[0] = q.w(), out[1] = q.x(), out[2] = q.y(), out[3] = q.z();
  } else {
    std::memcpy(out, p, sizeof(double) * static_cast<std::size_t>(s.rows));
  }
  return a;
}

void eigen_from_py(const MetaType& t, void* p, EigenShape s, py::handle o, const std::string& what) {
  if (py::isinstance<py::str>(o) || py::isinstance<py::bytes>(o)) type_error(what, t, o);
  auto a = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(o);
  if (!a) {
    PyErr_Clear();
    type_error(what, t, o);
  }
  const bool ok = s.cols == 4 ? (a.ndim() == 2 && a.shape(0) == 4 && a.shape(1) == 4)
                              : (a.ndim() == 1 && a.shape(0) == s.rows);
  if (!ok) {
    throw py::type_error(what + " expects " + t.name() + " (an array of shape " +
                         (s.cols == 4 ? std::string("(4, 4)") : "(" + std::to_string(s.rows) + ",)") +
                         "), got shape " + std::string(py::str(a.attr("shape"))));
  }
  const double* in = a.data();
  if (s.cols == 4) {
    auto& m = static_cast<Eigen::Isometry3d*>(p)->matrix();
    for (int r = 0; r < 4; ++r)
      for (int c = 0; c < 4; ++c) m(r, c) = in[r * 4 + c];
  } else if (t.is<Eigen::Quaterniond>()) {
    *static_cast<Eigen::Quaterniond*>(p) = Eigen::Quaterniond(in[0], in[1], in[2], in[3]);
  } else {
    std::memcpy(p, in, sizeof(double) * static_cast<std::size_t>(s.rows));
  }
}

bool is_number(py::handle o) {
  if (PyBool_Check(o.ptr())) return false;
  return PyFloat_Check(o.ptr()) || PyLong_Check(o.ptr()) || PyIndex_Check(o.ptr()) ||
         (!PyUnicode_Check(o.ptr()) && PyObject_HasAttrString(o.ptr(), "__float__"));
}

bool is_integer(py::handle o) { return !PyBool_Check(o.ptr()) && PyIndex_Check(o.ptr()); }

// Python int → int64 (or uint64 for unsigned 64-bit types), checked against the type's range.
void store_int(const MetaType& t, void* p, py::handle o, const std::string& what) {
  py::int_ i = py::reinterpret_steal<py::int_>(PyNumber_Index(o.ptr()));
  if (!i) throw py::error_already_set();
  if (t.is_unsigned() && t.size() == 8) {
    const unsigned long long v = PyLong_AsUnsignedLongLong(i.ptr());
    if (PyErr_Occurred()) {
      PyErr_Clear();
      throw py::value_error(what + ": " + std::string(py::str(o)) + " does not fit " + t.name());
    }
    std::memcpy(p, &v, 8);
    return;
  }
  int overflow = 0;
  const long long v = PyLong_AsLongLongAndOverflow(i.ptr(), &overflow);
  if (overflow != 0 || !t.integer_fits(v))
    throw py::value_error(what + ": " + std::string(py::str(o)) + " does not fit " + t.name());
  t.store_integer(p, v);
}

void fill(const MetaType& t, void* p, py::handle o, const std::string& what);

void fill_ref(const MetaType& t, void* p, py::handle o, const std::string& what) {
  vsd::SimStateInstance* target = nullptr;
  if (!o.is_none()) {
    if (!py::isinstance<Handle>(o)) type_error(what, t, o);
    target = &o.cast<Handle&>().get();
    if (t.target() != nullptr && !target->meta().is_a(*t.target()))
      throw py::type_error(what + " expects " + t.name() + ", got a " + target->meta().name());
  }
  // Every reference type has the layout of Ref<SimStateInstance>; the Value was made with the right
  // composite flag, so only its target changes.
  *static_cast<vsd::Ref<vsd::SimStateInstance>*>(p) = target;
}

void fill_ref_list(const MetaType& t, void* p, py::handle o, const std::string& what) {
  if (py::isinstance<py::str>(o) || !py::isinstance<py::sequence>(o)) type_error(what, t, o);
  auto& list = *static_cast<vsd::RefList<vsd::SimStateInstance>*>(p);
  const auto seq = py::reinterpret_borrow<py::sequence>(o);
  for (std::size_t i = 0; i < seq.size(); ++i) {
    py::object e = seq[i];
    if (!py::isinstance<Handle>(e)) type_error(what + " element " + std::to_string(i), t, e);
    vsd::SimStateInstance& target = e.cast<Handle&>().get();
    if (t.target() != nullptr && !target.meta().is_a(*t.target()))
      throw py::type_error(what + " element " + std::to_string(i) + ": expects a " + t.target()->name() +
                           ", got a " + target.meta().name());
    list.push_back(&target);
  }
}

void fill(const MetaType& t, void* p, py::handle o, const std::string& what) {
  switch (t.kind()) {
    case TypeKind::Bool:
      if (!PyBool_Check(o.ptr()) && !py::isinstance(o, py::module_::import("numpy").attr("bool_")))
        type_error(what, t, o);
      *static_cast<bool*>(p) = PyObject_IsTrue(o.ptr()) == 1;
      return;
    case TypeKind::Int:
    case TypeKind::UInt:
      if (!is_integer(o)) type_error(what, t, o);
      store_int(t, p, o, what);
      return;
    case TypeKind::Float:
    case TypeKind::Double: {
      if (!is_number(o)) type_error(what, t, o);
      const double d = PyFloat_AsDouble(o.ptr());
      if (d == -1.0 && PyErr_Occurred()) throw py::error_already_set();
      if (t.kind() == TypeKind::Float) {
        *static_cast<float*>(p) = static_cast<float>(d);
      } else {
        *static_cast<double*>(p) = d;
      }
      return;
    }
    case TypeKind::String:
      if (!PyUnicode_Check(o.ptr())) type_error(what, t, o);
      *static_cast<std::string*>(p) = o.cast<std::string>();
      return;
    case TypeKind::Enum:
    case TypeKind::Flags: {
      py::object cls = enum_class(t);
      std::int64_t v = 0;
      if (py::isinstance(o, cls)) {
        v = o.attr("value").cast<std::int64_t>();
      } else if (PyUnicode_Check(o.ptr())) {
        const auto name = o.cast<std::string>();
        if (!t.enum_value(name, v)) throw py::value_error(what + ": '" + name + "' is no value of " + t.name());
      } else if (is_integer(o) && !py::isinstance(o, py::module_::import("enum").attr("Enum"))) {
        v = o.cast<std::int64_t>();
        if (t.kind() == TypeKind::Enum && t.enum_name(v).empty())
          throw py::value_error(what + ": " + std::to_string(v) + " is no value of " + t.name());
        if (!t.integer_fits(v)) throw py::value_error(what + ": " + std::to_string(v) + " does not fit " + t.name());
      } else {
        type_error(what, t, o);
      }
      t.store_integer(p, v);
      return;
    }
    case TypeKind::Struct: {
      if (const EigenShape s = eigen_shape(t); s.rows != 0) {
        eigen_from_py(t, p, s, o, what);
        return;
      }
      if (!py::isinstance<py::dict>(o)) type_error(what, t, o);
      const auto d = py::reinterpret_borrow<py::dict>(o);
      for (auto item : d) {
        const auto key = py::str(item.first).cast<std::string>();
        bool found = false;
        for (const auto& f : t.fields()) {
          if (f.name != key) continue;
          found = true;
          vsd::Value fv = from_py(*f.type, item.second, what + "." + key);
          if (f.offset != MetaType::npos) {
            f.type->assign(static_cast<char*>(p) + f.offset, fv.data());
          } else {
            f.set(p, fv.data());
          }
        }
        if (!found) throw py::type_error(what + ": " + t.name() + " has no field '" + key + "'");
      }
      return;
    }
    case TypeKind::Vector: {
      if (py::isinstance<py::str>(o) || !py::isinstance<py::sequence>(o)) {
        if (!py::isinstance<py::array>(o)) type_error(what, t, o);
      }
      py::sequence seq = py::reinterpret_borrow<py::sequence>(o);
      if (py::isinstance<py::array>(o)) seq = o.attr("tolist")();
      for (std::size_t i = 0; i < seq.size(); ++i) {
        vsd::Value e = from_py(*t.element(), seq[i], what + "[" + std::to_string(i) + "]");
        t.vector_push(p, e.data());
      }
      return;
    }
    case TypeKind::Ref:
    case TypeKind::SharedRef:
      fill_ref(t, p, o, what);
      return;
    case TypeKind::RefList:
    case TypeKind::SharedRefList:
      fill_ref_list(t, p, o, what);
      return;
  }
  type_error(what, t, o);
}

}  // namespace

py::object to_py(const MetaType& t, const void* p, const std::shared_ptr<StateBox>& box) {
  switch (t.kind()) {
    case TypeKind::Bool:
      return py::bool_(*static_cast<const bool*>(p));
    case TypeKind::Int:
      return py::int_(t.load_integer(p));
    case TypeKind::UInt:
      if (t.size() == 8) return py::int_(*static_cast<const std::uint64_t*>(p));
      return py::int_(t.load_integer(p));
    case TypeKind::Float:
      return py::float_(*static_cast<const float*>(p));
    case TypeKind::Double:
      return py::float_(*static_cast<const double*>(p));
    case TypeKind::String:
      return py::str(*static_cast<const std::string*>(p));
    case TypeKind::Enum:
    case TypeKind::Flags:
      return enum_class(t)(t.load_integer(p));
    case TypeKind::Struct: {
      if (const EigenShape s = eigen_shape(t); s.rows != 0) return eigen_to_py(t, p, s);
      py::dict d;
      for (const auto& f : t.fields()) {
        if (f.offset != MetaType::npos) {
          d[py::str(f.name)] = to_py(*f.type, static_cast<const char*>(p) + f.offset, box);
        } else {
          vsd::Value v(*f.type);
          f.get(p, v.data());
          d[py::str(f.name)] = to_py(*f.type, v.data(), box);
        }
      }
      return d;
    }
    case TypeKind::Vector: {
      const std::size_t n = t.vector_size(p);
      py::list l(n);
      vsd::Value e(*t.element());
      for (std::size_t i = 0; i < n; ++i) {
        t.vector_get(p, i, e.data());
        l[i] = to_py(*t.element(), e.data(), box);
      }
      return l;
    }
    case TypeKind::Ref:
    case TypeKind::SharedRef:
      return wrap(box, static_cast<const vsd::RefBase*>(p)->get());
    case TypeKind::RefList:
    case TypeKind::SharedRefList: {
      const auto& list = *static_cast<const vsd::RefListBase*>(p);
      py::list l(list.size());
      for (std::size_t i = 0; i < list.size(); ++i) l[i] = wrap(box, list.at(i));
      return l;
    }
  }
  return py::none();
}

vsd::Value from_py(const MetaType& t, py::handle o, const std::string& what) {
  vsd::Value v(t);
  fill(t, v.data(), o, what);
  return v;
}

}  // namespace vsdpy
