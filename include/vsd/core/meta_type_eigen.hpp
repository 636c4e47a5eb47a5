/** @file
 *  @brief MetaTypes of the Eigen vocabulary: Vector2d/3d/4d, Quaterniond and Isometry3d frames.
 *
 *  They are structs to the meta-information system: vectors have fields x, y, (z, w); a quaternion
 *  has w, x, y, z; a frame has a translation (Vector3d) and a rotation (Quaterniond). A struct whose
 *  fields are all numbers is written as a list, so a Vector3d reads `[1, 2, 3]`. A frame's text carries
 *  its exact matrix, the rotation as rows:
 *  `{"translation": [1, 2, 3], "rotation": [[1, 0, 0], [0, 1, 0], [0, 0, 1]]}`; a rotation given as a
 *  quaternion (`[w, x, y, z]` or `{"w": 1, ...}`, the older form) is read too and normalised.
 */
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "vsd/core/meta_type.hpp"

namespace vsd {

namespace detail {
// Eigen default-constructs its types uninitialised; a value must start from a defined state.
template <>
struct DefaultValue<Eigen::Vector2d> {
  static Eigen::Vector2d make() { return Eigen::Vector2d::Zero(); }
};
template <>
struct DefaultValue<Eigen::Vector3d> {
  static Eigen::Vector3d make() { return Eigen::Vector3d::Zero(); }
};
template <>
struct DefaultValue<Eigen::Vector4d> {
  static Eigen::Vector4d make() { return Eigen::Vector4d::Zero(); }
};
template <>
struct DefaultValue<Eigen::Quaterniond> {
  static Eigen::Quaterniond make() { return Eigen::Quaterniond::Identity(); }
};
template <>
struct DefaultValue<Eigen::Isometry3d> {
  static Eigen::Isometry3d make() { return Eigen::Isometry3d::Identity(); }
};
// The fixed binary forms (TypeOps::fixed_bytes) of what bytes_out writes: a vector's coefficients in order,
// a quaternion's fields w, x, y, z, a frame's translation then its linear part column by column.
template <int N>
struct FixedBytes<Eigen::Matrix<double, N, 1>> {
  static constexpr std::size_t size = N * sizeof(double);
  static void write(const void* obj, std::uint8_t* out) noexcept {
    std::memcpy(out, static_cast<const Eigen::Matrix<double, N, 1>*>(obj)->data(), size);
  }
};
template <>
struct FixedBytes<Eigen::Quaterniond> {
  static constexpr std::size_t size = 4 * sizeof(double);
  static void write(const void* obj, std::uint8_t* out) noexcept {
    const auto& q = *static_cast<const Eigen::Quaterniond*>(obj);
    const double wxyz[4] = {q.w(), q.x(), q.y(), q.z()};
    std::memcpy(out, wxyz, size);
  }
};
template <>
struct FixedBytes<Eigen::Isometry3d> {
  static constexpr std::size_t size = 12 * sizeof(double);
  static void write(const void* obj, std::uint8_t* out) noexcept {
    const double* m = static_cast<const Eigen::Isometry3d*>(obj)->matrix().data();  // 4x4, column-major
    std::memcpy(out, m + 12, 3 * sizeof(double));                                   // translation
    for (int c = 0; c < 3; ++c) std::memcpy(out + (3 + 3 * c) * sizeof(double), m + 4 * c, 3 * sizeof(double));
  }
};
}  // namespace detail

namespace detail {
template <class V, int I>
MetaType::Field eigen_coeff(const char* name) {
  return {name, &meta_type<double>(), MetaType::npos,
          [](const void* o, void* out) { *static_cast<double*>(out) = (*static_cast<const V*>(o))[I]; },
          [](void* o, const void* in) { (*static_cast<V*>(o))[I] = *static_cast<const double*>(in); }};
}
}  // namespace detail

template <>
struct TypeTraits<Eigen::Vector2d> {
  static MetaType make() {
    auto t = detail::make_type<Eigen::Vector2d>("Vector2d", TypeKind::Struct);
    t.add_field(detail::eigen_coeff<Eigen::Vector2d, 0>("x"))
        .add_field(detail::eigen_coeff<Eigen::Vector2d, 1>("y"));
    return t;
  }
};
template <>
struct TypeTraits<Eigen::Vector3d> {
  static MetaType make() {
    auto t = detail::make_type<Eigen::Vector3d>("Vector3d", TypeKind::Struct);
    t.add_field(detail::eigen_coeff<Eigen::Vector3d, 0>("x"))
        .add_field(detail::eigen_coeff<Eigen::Vector3d, 1>("y"))
        .add_field(detail::eigen_coeff<Eigen::Vector3d, 2>("z"));
    return t;
  }
};
template <>
struct TypeTraits<Eigen::Vector4d> {
  static MetaType make() {
    auto t = detail::make_type<Eigen::Vector4d>("Vector4d", TypeKind::Struct);
    t.add_field(detail::eigen_coeff<Eigen::Vector4d, 0>("x"))
        .add_field(detail::eigen_coeff<Eigen::Vector4d, 1>("y"))
        .add_field(detail::eigen_coeff<Eigen::Vector4d, 2>("z"))
        .add_field(detail::eigen_coeff<Eigen::Vector4d, 3>("w"));
    return t;
  }
};

namespace detail {
void make_quaternion_fields(MetaType& t);
void make_isometry_fields(MetaType& t);
void isometry_write_text(const Eigen::Isometry3d& v, std::string& out);
void isometry_read_text(Eigen::Isometry3d& v, TextReader& in);
}  // namespace detail

template <>
struct TypeTraits<Eigen::Quaterniond> {
  static MetaType make() {
    auto t = detail::make_type<Eigen::Quaterniond>("Quaterniond", TypeKind::Struct);
    detail::make_quaternion_fields(t);
    return t;
  }
};
namespace detail {
// A frame's bytes, text and equality use the exact matrix (translation and the 3x3 linear part): going
// through a quaternion rounds ordinary rotations in their last bits and cannot carry a damaged matrix.
// The fields (translation, rotation quaternion) remain for the generic field API.
template <>
inline bool equal_values<Eigen::Isometry3d>(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b) {
  for (int i = 0; i < 16; ++i)
    if (!equal_values(a.matrix().data()[i], b.matrix().data()[i])) return false;
  return true;
}
template <>
inline std::size_t hash_value<Eigen::Isometry3d>(const Eigen::Isometry3d& v) {
  std::size_t h = 16;
  for (int i = 0; i < 16; ++i) h = hash_combine(h, hash_value(v.matrix().data()[i]));
  return h;
}
template <>
inline void text_out<Eigen::Isometry3d>(const MetaType&, const Eigen::Isometry3d& v, std::string& out) {
  isometry_write_text(v, out);
}
template <>
inline void text_in<Eigen::Isometry3d>(const MetaType&, Eigen::Isometry3d& v, TextReader& in,
                                       const RefResolver*) {
  isometry_read_text(v, in);
}
template <>
inline void bytes_out<Eigen::Isometry3d>(const MetaType&, const Eigen::Isometry3d& v, ByteWriter& out) {
  out.raw(v.translation().data(), 3 * sizeof(double));
  const Eigen::Matrix3d linear = v.linear();
  out.raw(linear.data(), 9 * sizeof(double));
}
template <>
inline void bytes_in<Eigen::Isometry3d>(const MetaType&, Eigen::Isometry3d& v, ByteReader& in,
                                        const RefResolver*) {
  Eigen::Vector3d t;
  Eigen::Matrix3d linear;
  in.raw(t.data(), 3 * sizeof(double));
  in.raw(linear.data(), 9 * sizeof(double));
  v.setIdentity();
  v.translation() = t;
  v.linear() = linear;
}
}  // namespace detail

template <>
struct TypeTraits<Eigen::Isometry3d> {
  static MetaType make() {
    auto t = detail::make_type<Eigen::Isometry3d>("Isometry3d", TypeKind::Struct);
    detail::make_isometry_fields(t);
    return t;
  }
};

}  // namespace vsd
