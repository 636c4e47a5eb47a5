/** @file
 *  @brief Registry: finds every MetaInstance and MetaType by name, and owns run-time classes.
 *
 *  Built-in classes register themselves when the program starts (and again, harmlessly, when a module
 *  registers them explicitly with `add<T>()`: static linking may drop the automatic path, never the
 *  explicit one). All methods are thread-safe.
 *
 *  Class names: a class's full name is its namespace, "::", and its short name ("scene::Node3D"; see
 *  VSD_CLASS_NAMESPACE), or just the short name for classes of no namespace (vsd's own classes, Node,
 *  Database, ...). Files and transaction bundles carry full names. A lookup takes a full name, or a short
 *  name where exactly one class has it: "Node3D" finds "scene::Node3D" unless another namespace has a
 *  Node3D too (an error naming both) — a class whose full name *is* the short name is found first.
 *
 *  Lifetime: the global registry is never destroyed. A private registry (an Environment's or a tool's)
 *  owns the run-time classes and types defined in it and destroys them with itself, subclasses first;
 *  no instance of them may outlive it.
 */
#pragma once

#include <memory>
#include <mutex>
#include <shared_mutex>
#include <span>
#include <string>
#include <string_view>
#include <unordered_map>
#include <unordered_set>
#include <vector>

#include "vsd/core/meta_instance.hpp"
#include "vsd/core/meta_type.hpp"

namespace vsd {

class Registry {
 public:
  /// @brief The program's registry.
  static Registry& global();

  Registry();
  ~Registry();
  Registry(const Registry&) = delete;
  Registry& operator=(const Registry&) = delete;

  /// @brief Registers a class and the types of its properties. Registering the same class again is a
  /// no-op. @throws vsd::Error when another class already has its name.
  void add(const MetaInstance& cls);
  /// @brief Registers a type. @throws vsd::Error when another type already has its name.
  void add(const MetaType& type);
  template <class T>
  const MetaInstance& add() {
    add(T::static_meta());
    return T::static_meta();
  }
  template <class T>
  const MetaType& add_type() {
    add(meta_type<T>());
    return meta_type<T>();
  }

  /// @brief The class of full name @p name, else the one class whose short name it is; nullptr when none.
  /// @throws vsd::Error naming the candidates when a short name belongs to classes of several namespaces.
  [[nodiscard]] const MetaInstance* find_class(std::string_view name) const;
  /// @brief The class of full name @p name only (no short-name lookup); nullptr when none.
  [[nodiscard]] const MetaInstance* find_class_exact(std::string_view name) const;
  /// @brief find_class() that never returns nullptr. @throws vsd::Error naming the unknown class, or the
  /// candidates of an ambiguous short name.
  [[nodiscard]] const MetaInstance& get_class(std::string_view name) const;
  [[nodiscard]] const MetaType* find_type(std::string_view name) const;
  /// @brief The type named @p name; reference types of any known class ("ref<Robot>", "shared<Robot>",
  /// "list<Robot>", "shared_list<Robot>") and vectors of run-time types ("vector<Color>") are made on
  /// demand. @throws vsd::Error for unknown names.
  [[nodiscard]] const MetaType& get_type(std::string_view name);
  /// @brief The reference type of @p kind to @p target (made on demand for run-time classes).
  const MetaType& reference_type(TypeKind kind, const MetaInstance& target);
  [[nodiscard]] std::vector<const MetaInstance*> classes() const;
  [[nodiscard]] std::vector<const MetaType*> types() const;

  /// @brief Takes ownership of a run-time class built by ClassBuilder. @throws vsd::Error on a name clash,
  /// or when its base is a run-time class of another registry (a base must outlive its subclasses).
  const MetaInstance& define(std::unique_ptr<MetaInstance> cls);
  /// @brief Removes a run-time class that has no live instances and no subclasses.
  /// @throws vsd::Error otherwise, or for built-in classes.
  void undefine(const MetaInstance& cls);
  /// @brief Gives run-time class @p cls the methods that @p from declares (its name, base and properties
  /// are ignored; @p from is used up). For a class defined from a file's schema, which carries properties
  /// only: the program that runs the file's content binds its methods (vsd::soml attaching to a saved
  /// run). A method @p cls already declares with the same name and signature is kept; subclasses see the
  /// new ones. Call it before other threads use the class.
  /// @throws vsd::Error for built-in classes, classes of another registry, and a method that @p cls
  /// declares with another signature (then nothing changed).
  void add_methods(const MetaInstance& cls, ClassBuilder&& from);
  /// @brief Gives run-time class @p cls the full name @p name (a script that redefines its classes at
  /// run time retires the old versions under other names; vsd::soml). Instances keep their class; changes
  /// recorded from now on carry the new name.
  /// @throws vsd::Error for built-in classes, classes of another registry, a name that is taken or not a
  /// class name, and classes that reference types ("shared<X>") were made for (their names would lie).
  void rename(const MetaInstance& cls, std::string name);

  /// @brief Takes ownership of a run-time value type built by EnumBuilder or StructBuilder (or
  /// detail::make_runtime_vector). @throws vsd::Error when another type has its name.
  const MetaType& define(std::unique_ptr<MetaType> type);
  /// @brief Removes a run-time value type that no class property and no other type uses (the vectors of
  /// it that get_type made go with it). @throws vsd::Error otherwise, or for types this Registry does
  /// not own.
  void undefine(const MetaType& type);
  /// @brief The vector type of @p element: the C++ one when registered, else a run-time "vector<E>" made
  /// on demand for a run-time element type. @throws vsd::Error when there is neither.
  const MetaType& vector_type(const MetaType& element);
  /// @brief True when @p type is a run-time value type this Registry owns (not a reference type).
  [[nodiscard]] bool owns(const MetaType& type) const;

  /// @brief Undefines as many of @p classes and @p types (run-time ones of this registry) as nothing else
  /// uses, and keeps the rest: a class with live instances, a subclass or a referring property outside
  /// the lists, a type used outside them, and what those kept ones use. The reference types of removed
  /// classes and the vectors of removed types go with them. One pass over the registry, however many are
  /// removed: what a load that fails (or only checks) defined goes in time linear in the registry's size,
  /// where one undefine() per class and type was quadratic.
  void undefine_all(std::span<const MetaInstance* const> classes, std::span<const MetaType* const> types);

 private:
  void add_locked(const MetaInstance& cls);
  void index_locked(const MetaInstance& cls);
  void unindex_locked(const MetaInstance& cls);
  [[nodiscard]] const MetaInstance* find_class_locked(std::string_view name) const;
  void add_type_locked(const MetaType& type);
  void check_type_locked(const MetaType& type) const;
  [[nodiscard]] bool owns_locked(const MetaInstance& cls) const noexcept;
  static bool same_reference(const MetaType& a, const MetaType& b) noexcept;

  mutable std::shared_mutex mutex_;
  std::unordered_map<std::string, const MetaInstance*> classes_;  // by full name
  // Classes with a namespace, by short name (the part after the last "::").
  std::unordered_map<std::string, std::vector<const MetaInstance*>> short_names_;
  std::unordered_map<std::string, const MetaType*> types_;
  // Reference types and run-time value types. Declared before the classes so that they outlive them: a
  // run-time class's properties (and their default values) use these types until the class is gone.
  std::vector<std::unique_ptr<MetaType>> runtime_types_;
  std::vector<std::unique_ptr<MetaInstance>> runtime_classes_;
  std::unordered_set<const MetaInstance*> owned_classes_;  // those of runtime_classes_
};

}  // namespace vsd
