// Static types of SOML++ (see types.hpp).
#include "vsd/soml/types.hpp"

#include "vsd/core/meta_instance.hpp"
#include "vsd/core/node.hpp"
#include "vsd/soml/ast.hpp"

namespace vsd::soml {

std::string ClassRef::name() const {
  if (decl != nullptr) return decl->name;
  if (meta != nullptr) return meta->name();
  return "?";
}

ClassRef ClassRef::base() const noexcept {
  if (decl != nullptr) {
    if (!decl->base.empty()) return decl->base;
    return ClassRef{nullptr, &Node::static_meta()};  // a script class without a base is a Node
  }
  if (meta != nullptr && meta->base() != nullptr) return ClassRef{nullptr, meta->base()};
  return {};
}

bool ClassRef::is_a(const ClassRef& other) const noexcept {
  if (other.empty() || empty()) return false;
  if (other.meta != nullptr) {
    const MetaInstance* b = builtin();
    return b != nullptr && b->is_a(*other.meta);
  }
  // other is a script class: walk the script part of the ancestry (the checker broke base cycles).
  for (const ClassDecl* d = decl; d != nullptr; d = d->base.decl)
    if (d == other.decl) return true;
  return false;
}

const MetaInstance* ClassRef::builtin() const noexcept {
  if (meta != nullptr) return meta;
  const ClassDecl* d = decl;
  while (d != nullptr && d->base.decl != nullptr) d = d->base.decl;
  if (d == nullptr) return nullptr;
  return d->base.meta != nullptr ? d->base.meta : &Node::static_meta();
}

bool Type::is_value() const noexcept {
  switch (kind) {
    case Kind::Bool:
    case Kind::Int:
    case Kind::Double:
    case Kind::String:
    case Kind::Enum:
    case Kind::Struct:
    case Kind::Vector:
    case Kind::Ref:
    case Kind::List:
    case Kind::Error:
      return true;
    default:
      return false;
  }
}

bool Type::same(const Type& o) const noexcept {
  if (kind != o.kind) return false;
  switch (kind) {
    case Kind::Enum:
      return enum_decl == o.enum_decl && (enum_decl != nullptr || meta == o.meta);
    case Kind::Struct:
      return meta == o.meta;
    case Kind::Vector:  // of a MetaType, or of a script enum (enum_decl; no MetaType before the load)
      return meta == o.meta && enum_decl == o.enum_decl;
    case Kind::Ref:
    case Kind::List:
      return cls == o.cls && shared == o.shared;
    case Kind::Place:
    case Kind::Transition:
    case Kind::Net:
    case Kind::Function:
      return decl == o.decl;
    case Kind::Class:
      return cls == o.cls;
    default:
      return true;
  }
}

std::string Type::name() const {
  switch (kind) {
    case Kind::Error:
      return "<error>";
    case Kind::Void:
      return "void";
    case Kind::Null:
      return "null";
    case Kind::Bool:
      return "bool";
    case Kind::Int:
      return "int";
    case Kind::Double:
      return "double";
    case Kind::String:
      return "string";
    case Kind::Enum:
      return enum_decl != nullptr ? enum_decl->name : (meta != nullptr ? meta->name() : "enum");
    case Kind::Struct:
      return meta != nullptr ? meta->name() : "?";
    case Kind::Vector:
      if (enum_decl != nullptr) return "vector<" + enum_decl->name + ">";
      return meta != nullptr ? meta->name() : "?";
    case Kind::Ref:
      return (shared ? "shared<" : "ref<") + cls.name() + ">";
    case Kind::List:
      return (shared ? "shared_list<" : "list<") + cls.name() + ">";
    case Kind::Place:
      return cls.empty() ? "place" : "place<" + cls.name() + ">";
    case Kind::Transition:
      return "transition";
    case Kind::Class:
      if (enum_decl != nullptr) return "enum " + enum_decl->name;
      if (meta != nullptr) return "enum " + meta->name();
      return "class " + cls.name();
    case Kind::Net:
      return "net";
    case Kind::Function:
      return "function";
  }
  return "?";
}

bool assignable(const Type& from, const Type& to) noexcept {
  using K = Type::Kind;
  if (from.is_error() || to.is_error()) return true;
  if (from.same(to)) return true;
  if (from.kind == K::Int && to.kind == K::Double) return true;
  if (to.kind == K::Ref) {
    if (from.kind == K::Null) return true;
    if (from.kind == K::Ref) return from.cls.is_a(to.cls);  // ref and shared mix; upcasts are implicit
  }
  return false;
}

}  // namespace vsd::soml
