/** @file
 *  @brief ListEditor<T>: typed editing of a reference-list property, recorded and signalled like a setter.
 *
 *  VSD_PROPERTY gives every `RefList<T>` / `SharedRefList<T>` property `name` a member `edit_name()`
 *  that returns a ListEditor. Reading goes through the list itself (`name()`, which iterates as T*);
 *  every edit goes through the holder (`SimStateInstance::list_insert` / `list_erase`), so it is checked,
 *  recorded when the SimState records, and announced to the property's listeners:
 *
 *  @code
 *  cell.edit_tools().push_back(gripper);   // Cell: VSD_PROPERTY(vsd::SharedRefList<Tool>, tools, {})
 *  cell.edit_tools().erase(0);
 *  for (Tool* t : cell.tools()) ...
 *  @endcode
 *
 *  An editor is a small handle (holder and property); it stays usable as long as its holder lives.
 */
#pragma once

#include <cstddef>

#include "vsd/core/instance.hpp"
#include "vsd/core/reference.hpp"

namespace vsd {

template <class T>
class ListEditor {
 public:
  using List = detail::TypedRefList<T, RefListBase>;

  ListEditor(SimStateInstance& holder, const MetaProperty& property) noexcept
      : holder_(&holder), property_(&property) {}

  /// @brief The list as it is now (typed iteration, size, operator[]).
  [[nodiscard]] const List& list() const noexcept {
    return *static_cast<const List*>(property_->address(*holder_));
  }
  [[nodiscard]] std::size_t size() const noexcept { return list().size(); }
  [[nodiscard]] bool empty() const noexcept { return list().empty(); }
  [[nodiscard]] T* operator[](std::size_t i) const noexcept { return list()[i]; }
  [[nodiscard]] auto begin() const noexcept { return list().begin(); }
  [[nodiscard]] auto end() const noexcept { return list().end(); }
  /// @brief Position of @p x, or RefListBase::npos.
  [[nodiscard]] std::size_t index_of(const T& x) const noexcept { return list().index_of(&x); }
  [[nodiscard]] bool contains(const T& x) const noexcept { return list().contains(&x); }

  /// @brief Appends @p x. @throws vsd::Error as SimStateInstance::list_insert does (another SimState, a
  /// composite cycle, an instance being deleted); nothing changes then.
  void push_back(T& x) { holder_->list_insert(*property_, size(), x); }
  /// @brief Inserts @p x at @p index (index == size() appends). @throws vsd::Error, see push_back().
  void insert(std::size_t index, T& x) { holder_->list_insert(*property_, index, x); }
  /// @brief Removes element @p index; an element of a composite list that nothing else holds is deleted.
  /// @throws vsd::Error when @p index is out of range.
  void erase(std::size_t index) { holder_->list_erase(*property_, index); }
  /// @brief Removes the first occurrence of @p x; false when it is not in the list.
  bool remove(const T& x) {
    const std::size_t i = index_of(x);
    if (i == RefListBase::npos) return false;
    erase(i);
    return true;
  }
  /// @brief Removes every element, last first (each removal is its own recorded change).
  void clear() {
    while (!empty()) erase(size() - 1);
  }

 private:
  SimStateInstance* holder_;
  const MetaProperty* property_;
};

}  // namespace vsd
