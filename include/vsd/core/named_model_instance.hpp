/** @file
 *  @brief NamedModelInstance: a SimStateInstance with a name and a list of extensions.
 */
#pragma once

#include <string>

#include "vsd/core/declare.hpp"

namespace vsd {

class Extension;

class NamedModelInstance : public SimStateInstance {
  VSD_INSTANCE(NamedModelInstance, SimStateInstance)
  VSD_PROPERTY(std::string, name, "", Editable | Savable | Distributed)
  /// Extensions attached to this instance (composite: they go with it).
  VSD_PROPERTY(RefList<Extension>, extensions, {}, Savable | Distributed)

 public:
  /// @brief Attaches @p e (moving it from a former owner). @throws vsd::Error on a cycle.
  void add_extension(Extension& e);
  /// @brief Detaches @p e; it is deleted when nothing else holds it compositely.
  /// @throws vsd::Error when @p e is not attached here.
  void remove_extension(Extension& e);
  /// @brief The first attached extension that is an E, or nullptr.
  template <class E>
  [[nodiscard]] E* find_extension() const noexcept;
};

}  // namespace vsd

#include "vsd/core/extension.hpp"  // completes Extension for find_extension
