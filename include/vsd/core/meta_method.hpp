/** @file
 *  @brief MetaMethod: a method of a class, with its signature in MetaTypes and a generic invoker.
 */
#pragma once

#include <functional>
#include <memory>
#include <span>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include "vsd/core/meta_type.hpp"
#include "vsd/core/value.hpp"

namespace vsd {

class Instance;
class MetaInstance;

class MetaMethod {
 public:
  /// @brief Calls the method on an instance with arguments already checked against the signature.
  using Invoker = std::function<Value(Instance& self, std::span<const Value> args)>;

  MetaMethod(std::string name, const MetaType* result, std::vector<const MetaType*> arguments,
             Invoker invoker)
      : name_(std::move(name)),
        result_(result),
        arguments_(std::move(arguments)),
        invoker_(std::move(invoker)) {}
  MetaMethod(const MetaMethod&) = delete;
  MetaMethod& operator=(const MetaMethod&) = delete;

  [[nodiscard]] const std::string& name() const noexcept { return name_; }
  /// @brief Result type, nullptr for void.
  [[nodiscard]] const MetaType* result() const noexcept { return result_; }
  [[nodiscard]] const std::vector<const MetaType*>& arguments() const noexcept { return arguments_; }
  [[nodiscard]] const MetaInstance& owner() const noexcept { return *owner_; }
  /// @brief "name(double, string) -> bool".
  [[nodiscard]] std::string signature() const;

  /// @brief Checks arity and argument types (numbers convert when exact), then calls.
  /// @throws vsd::Error naming the method, the argument and both types.
  Value invoke(Instance& self, std::span<const Value> args) const;

 private:
  friend class MetaInstance;
  std::string name_;
  const MetaType* result_;
  std::vector<const MetaType*> arguments_;
  Invoker invoker_;
  const MetaInstance* owner_ = nullptr;
};

namespace detail {

template <class M>
struct MethodTraits;
template <class C, class R, class... A>
struct MethodTraits<R (C::*)(A...)> {
  using Result = R;
  using Class = C;
  using Args = std::tuple<std::decay_t<A>...>;
};
template <class C, class R, class... A>
struct MethodTraits<R (C::*)(A...) const> : MethodTraits<R (C::*)(A...)> {};
template <class C, class R, class... A>
struct MethodTraits<R (C::*)(A...) noexcept> : MethodTraits<R (C::*)(A...)> {};
template <class C, class R, class... A>
struct MethodTraits<R (C::*)(A...) const noexcept> : MethodTraits<R (C::*)(A...)> {};

template <class T>
const MetaType* result_type() {
  if constexpr (std::is_void_v<T>) {
    return nullptr;
  } else {
    return &meta_type<std::decay_t<T>>();
  }
}

/// Builds the MetaMethod of member function @p M of class Self.
template <class Self, auto M>
std::unique_ptr<MetaMethod> make_method(std::string name) {
  using Tr = MethodTraits<decltype(M)>;
  using Args = typename Tr::Args;
  std::vector<const MetaType*> arg_types;
  [&]<std::size_t... I>(std::index_sequence<I...>) {
    (arg_types.push_back(&meta_type<std::tuple_element_t<I, Args>>()), ...);
  }
  (std::make_index_sequence<std::tuple_size_v<Args>>{});
  auto invoker = [](Instance& self, std::span<const Value> args) -> Value {
    return [&]<std::size_t... I>(std::index_sequence<I...>)->Value {
      auto& obj = static_cast<Self&>(self);
      if constexpr (std::is_void_v<typename Tr::Result>) {
        (obj.*M)(args[I].template as<std::tuple_element_t<I, Args>>()...);
        return Value();
      } else {
        return Value((obj.*M)(args[I].template as<std::tuple_element_t<I, Args>>()...));
      }
    }
    (std::make_index_sequence<std::tuple_size_v<Args>>{});
  };
  return std::make_unique<MetaMethod>(std::move(name), result_type<typename Tr::Result>(),
                                      std::move(arg_types), invoker);
}

}  // namespace detail

}  // namespace vsd
