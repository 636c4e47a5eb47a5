/** @file
 *  @brief Extension: adds data and behaviour to a node or to another extension.
 */
#pragma once

#include "vsd/core/named_model_instance.hpp"

namespace vsd {

class Extension : public NamedModelInstance {
  VSD_INSTANCE(Extension, NamedModelInstance)

 public:
  /// @brief The node or extension this extension is attached to, or nullptr.
  [[nodiscard]] NamedModelInstance* owner() const noexcept;
};

}  // namespace vsd

namespace vsd {
template <class E>
E* NamedModelInstance::find_extension() const noexcept {
  for (Extension* e : extensions_)
    if (E* x = e->template as<E>()) return x;
  return nullptr;
}
}  // namespace vsd
