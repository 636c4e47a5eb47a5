/** @file
 *  @brief Registry: finds every MetaInstance and MetaType by name, and owns run-time classes.
 *
 *  Built-in classes register themselves when the program starts (and again, harmlessly, when a module
 *  registers them explicitly with `add<T>()`: static linking may drop the automatic path, never the
 *  explicit one). All methods are thread-safe.
 *
 *  Lifetime: the global registry is never destroyed. A private registry (an Environment's or a tool's)
 *  owns the run-time classes and types defined in it and destroys them with itself, subclasses first;
 *  no instance of them may outlive it.
 */
#pragma once

#include <memory>
#include <mutex>
#include <shared_mutex>
#include <string>
#include <string_view>
#include <unordered_map>
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

  [[nodiscard]] const MetaInstance* find_class(std::string_view name) const;
  /// @throws vsd::Error naming the unknown class.
  [[nodiscard]] const MetaInstance& get_class(std::string_view name) const;
  [[nodiscard]] const MetaType* find_type(std::string_view name) const;
  /// @brief The type named @p name; reference types of any known class ("ref<Robot>", "shared<Robot>",
  /// "list<Robot>", "shared_list<Robot>") are made on demand. @throws vsd::Error for unknown names.
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

 private:
  void add_locked(const MetaInstance& cls);
  void add_type_locked(const MetaType& type);
  void check_type_locked(const MetaType& type) const;
  [[nodiscard]] bool owns_locked(const MetaInstance& cls) const noexcept;
  static bool same_reference(const MetaType& a, const MetaType& b) noexcept;

  mutable std::shared_mutex mutex_;
  std::unordered_map<std::string, const MetaInstance*> classes_;
  std::unordered_map<std::string, const MetaType*> types_;
  std::vector<std::unique_ptr<MetaInstance>> runtime_classes_;
  std::vector<std::unique_ptr<MetaType>> runtime_types_;
};

}  // namespace vsd
