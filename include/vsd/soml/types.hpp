/** @file
 *  @brief Static types of SOML++ and the bindings of names, as the checker computes them.
 *
 *  A SOML++ type is either a value type that maps onto a MetaType (bool, int = int64, double, string,
 *  registry enums and structs, vectors), a script enum (a run-time enum once loaded), a reference to a
 *  class (a script class, object or net, or a registry MetaInstance such as Node), or one of the kinds
 *  that only name things (places, transitions, classes, functions). The `Error` type marks an
 *  expression that already had an error reported, so that one mistake yields one message.
 *
 *  A `Binding` says what a name or member resolved to: a local's frame slot, a script property or
 *  function (by declaration), a built-in class's MetaProperty or MetaMethod, a built-in function. The
 *  bytecode compiler of a later slice reads both and does no lookup of its own.
 */
#pragma once

#include <string>

#include "vsd/core/fwd.hpp"

namespace vsd::soml {

struct Decl;
struct ClassDecl;
struct EnumDecl;

/// @brief A class: a script class-like declaration, or a built-in (registry) MetaInstance.
struct ClassRef {
  const ClassDecl* decl = nullptr;     ///< script class, object, net or script object
  const MetaInstance* meta = nullptr;  ///< built-in class (when decl is null)

  [[nodiscard]] bool empty() const noexcept { return decl == nullptr && meta == nullptr; }
  [[nodiscard]] bool operator==(const ClassRef& o) const noexcept { return decl == o.decl && meta == o.meta; }
  /// @brief The class's name ("Demo", "Node", "object cell").
  [[nodiscard]] std::string name() const;
  /// @brief The base class (for a script class, as resolved by the checker).
  [[nodiscard]] ClassRef base() const noexcept;
  /// @brief True when this class is @p other or derives from it.
  [[nodiscard]] bool is_a(const ClassRef& other) const noexcept;
  /// @brief The nearest built-in class in the ancestry (Node for a script class without a base).
  [[nodiscard]] const MetaInstance* builtin() const noexcept;
};

/// @brief A static type.
struct Type {
  enum class Kind : unsigned char {
    Error,  ///< already reported: compatible with everything
    Void,
    Null,  ///< the type of `null`: converts to any reference
    Bool,
    Int,
    Double,
    String,
    Enum,        ///< script enum (enum_decl) or registry enum (meta)
    Struct,      ///< registry struct (meta): Vector3d, Isometry3d, ...
    Vector,      ///< std::vector of a MetaType (meta), or of a script enum (enum_decl, meta null: its
                 ///< MetaType, the run-time enum's vector, is made when the script loads)
    Ref,         ///< reference to an instance of cls (shared: shared aggregation)
    List,        ///< list of references to cls
    Place,       ///< a place (decl); cls is its token class, empty for black tokens
    Transition,  ///< a transition (decl)
    Class,       ///< a class used by name (cls), e.g. the callee of a conversion or `Mode` of `Mode::Idle`
    Net,         ///< a net (decl)
    Function     ///< a function name that is not called
  };

  Kind kind = Kind::Error;
  const MetaType* meta = nullptr;  ///< storage MetaType where there is one (int32 property, Vector3d, ...)
  const EnumDecl* enum_decl = nullptr;  ///< script enum (Enum; Vector: the element)
  ClassRef cls;                         ///< Ref, List, Place (token class), Class
  const Decl* decl = nullptr;           ///< Place, Transition, Net, Function
  bool shared = false;                  ///< Ref, List: shared (not counted) references

  static Type error() { return {}; }
  static Type of(Kind k) {
    Type t;
    t.kind = k;
    return t;
  }
  static Type reference(ClassRef c, bool shared = false) {
    Type t;
    t.kind = Kind::Ref;
    t.cls = c;
    t.shared = shared;
    return t;
  }

  [[nodiscard]] bool is_error() const noexcept { return kind == Kind::Error; }
  [[nodiscard]] bool is_numeric() const noexcept { return kind == Kind::Int || kind == Kind::Double; }
  /// @brief True for types a value of which can be stored (in a local, a property, an argument).
  [[nodiscard]] bool is_value() const noexcept;
  /// @brief Same type (storage MetaTypes of numbers do not matter: an int32 property is an int).
  [[nodiscard]] bool same(const Type& o) const noexcept;
  /// @brief The type as the user writes it ("int", "ref<Demo>", "place<Demo>").
  [[nodiscard]] std::string name() const;
};

/// @brief True when a value of type @p from may be used where @p to is expected: the same type, int to
/// double, null to a reference, a reference to a reference of a base class (ref and shared mix).
[[nodiscard]] bool assignable(const Type& from, const Type& to) noexcept;

/// @brief Built-in functions and members that are not in the meta-information.
enum class Builtin : unsigned char {
  None,
  Print,
  Sqrt,
  Abs,
  Floor,
  Ceil,
  Min,
  Max,
  Len,
  PlaceCount,  ///< place.count
  PlacePut,    ///< place.put(n) / place.put(obj)
  PlaceClear,  ///< place.clear()
  Size,        ///< vector/list .size()
  Push,        ///< vector/list .push(x)
  Find,        ///< find(path): the database node at a path ("/plant/tank", as Node::path()), or null
  StructOp     ///< a method of a registry struct (`v.norm()`) or `Quaterniond::from_axis_angle`: op in slot
};

/// @brief The operations on the Eigen structs (Vector2d/3d/4d, Quaterniond, Isometry3d) in code: the
/// operators, methods and static functions of docs/soml.md 4.14. Which struct an operation works on is
/// the static type of its first operand (the VM checks it); scalars are doubles.
enum class StructOp : unsigned char {
  Add,            ///< a + b (vectors of one size)
  Sub,            ///< a - b
  Neg,            ///< -a
  Scale,          ///< a * s, s * a (vector, scalar)
  Div,            ///< a / s
  Dot,            ///< a.dot(b): double
  Norm,           ///< a.norm(): double
  SquaredNorm,    ///< a.squared_norm(): double
  Normalized,     ///< a.normalized() (vectors, quaternions)
  Cross,          ///< a.cross(b) (Vector3d)
  Mul,            ///< q * q, T * T
  Apply,          ///< q * v (rotate), T * v (transform a point): Vector3d
  Inverse,        ///< q.inverse(), T.inverse()
  Conjugate,      ///< q.conjugate()
  FromAxisAngle,  ///< Quaterniond::from_axis_angle(Vector3d axis, double angle)
  Text            ///< string(a), "..." + a: the text print shows, `Vector3d(1, 2.5, 0)`
};

/// @brief What a name or member resolved to.
struct Binding {
  enum class Kind : unsigned char {
    None,
    Local,         ///< slot: frame slot (parameters first)
    Property,      ///< decl: PropertyDecl of a script class/object/place/transition/net
    MetaProperty,  ///< property: of a built-in class
    Function,      ///< decl: FunctionDecl
    MetaMethod,    ///< method: of a built-in class
    Builtin,       ///< builtin
    Conversion,    ///< int(x), double(x), string(x), bool(x): the target type is the call's type
    Place,         ///< decl: PlaceDecl
    Transition,    ///< decl: TransitionDecl
    Object,        ///< decl: ClassDecl of an object
    Class,         ///< the class (decl or meta): in `new`, `is`, `as`, and scoped names
    Enum,          ///< decl: EnumDecl (or the registry enum's MetaType in meta_type)
    EnumValue,     ///< slot: the value; decl: EnumDecl (or meta_type)
    Net,           ///< decl: ClassDecl of a net
    StructField,   ///< slot: field index of meta_type
    Mark,
    This,
    Construct  ///< meta_type: a registry struct named as a function, `Vector3d(1, 2, 3)`
  };

  Kind kind = Kind::None;
  const Decl* decl = nullptr;
  const MetaProperty* property = nullptr;
  const MetaMethod* method = nullptr;
  const MetaType* meta_type = nullptr;
  const MetaInstance* meta_class = nullptr;
  Builtin builtin = Builtin::None;
  int slot = -1;
  /// @brief For members reached without an object (`count` inside a class): how many enclosing scopes
  /// (transition, place, class, object, net, script: each is an instance at run time) out from the
  /// innermost one (0: `this`, 1: the instance around it, ...).
  int outer = 0;
};

}  // namespace vsd::soml
