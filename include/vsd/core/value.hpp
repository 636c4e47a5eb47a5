/** @file
 *  @brief Value: an owning, type-erased value of any MetaType — the currency of generic access.
 *
 *  Small values (up to 48 bytes, alignment up to 16: strings, vectors, Eigen vectors and quaternions,
 *  references) live inside the Value; larger ones (Isometry3d) on the heap.
 *  Generic property access, method calls (vsdMetaCall), scripting and persistence exchange Values.
 */
#pragma once

#include <cstddef>
#include <new>
#include <string>
#include <string_view>
#include <type_traits>
#include <utility>

#include "vsd/core/error.hpp"
#include "vsd/core/meta_type.hpp"

namespace vsd {

class Value {
 public:
  static constexpr std::size_t inline_size = 48;  // references (48 bytes) and lists of them fit
  static constexpr std::size_t inline_align = 16;

  /// @brief An empty value (no type).
  Value() noexcept = default;
  /// @brief The default value of @p type.
  explicit Value(const MetaType& type) : type_(&type) { type.construct(alloc()); }
  /// @brief A copy of the value at @p src, which has type @p type.
  Value(const MetaType& type, const void* src) : type_(&type) { type.copy_construct(alloc(), src); }
  /// @brief Holds @p v with the MetaType of its C++ type (string literals become std::string).
  template <class T>
  requires(!std::is_same_v<std::decay_t<T>, Value> && is_meta_type_v<std::decay_t<T>>) Value(T&& v)
      : type_(&meta_type<std::decay_t<T>>()) {  // NOLINT(google-explicit-constructor)
    ::new (alloc()) std::decay_t<T>(std::forward<T>(v));
  }
  Value(const char* s) : Value(std::string(s)) {}  // NOLINT(google-explicit-constructor)

  Value(const Value& o) : type_(o.type_) {
    if (type_ != nullptr) type_->copy_construct(alloc(), o.data());
  }
  Value(Value&& o) noexcept : type_(o.type_) {
    if (type_ == nullptr) return;
    if (on_heap()) {
      heap_ = std::exchange(o.heap_, nullptr);
      o.type_ = nullptr;
    } else {
      type_->move_construct(buf_, o.buf_);
      o.reset();
    }
  }
  Value& operator=(const Value& o) {
    if (this != &o) {
      Value copy(o);
      *this = std::move(copy);
    }
    return *this;
  }
  Value& operator=(Value&& o) noexcept {
    if (this != &o) {
      reset();
      ::new (this) Value(std::move(o));
    }
    return *this;
  }
  ~Value() { reset(); }

  /// @brief The MetaType held, or nullptr when empty.
  [[nodiscard]] const MetaType* type() const noexcept { return type_; }
  [[nodiscard]] bool empty() const noexcept { return type_ == nullptr; }
  [[nodiscard]] const void* data() const noexcept {
    return type_ == nullptr ? nullptr : (on_heap() ? heap_ : buf_);
  }
  [[nodiscard]] void* data() noexcept { return type_ == nullptr ? nullptr : (on_heap() ? heap_ : buf_); }

  /// @brief True when this holds a T.
  template <class T>
  [[nodiscard]] bool is() const noexcept {
    return type_ != nullptr && type_->template is<T>();
  }
  /// @brief The held T, or nullptr when this holds something else.
  template <class T>
  [[nodiscard]] const T* try_as() const noexcept {
    return is<T>() ? static_cast<const T*>(data()) : nullptr;
  }
  /// @brief The held T; throws vsd::Error naming both types when this holds something else.
  template <class T>
  [[nodiscard]] const T& as() const {
    if (VSD_UNLIKELY(!is<T>())) throw_mismatch(meta_type<T>());
    return *static_cast<const T*>(data());
  }
  template <class T>
  [[nodiscard]] T& as() {
    if (VSD_UNLIKELY(!is<T>())) throw_mismatch(meta_type<T>());
    return *static_cast<T*>(data());
  }

  /// @brief This value converted to @p target: the same value when types match, numbers convert when
  /// the number is representable; anything else throws vsd::Error.
  [[nodiscard]] Value convert_to(const MetaType& target) const;

  /// @brief The text form ("<empty>" when empty).
  [[nodiscard]] std::string to_text() const;
  /// @brief Parses @p text as a value of @p type.
  /// @param origin names the text in errors (a file, "property speed", ...); empty: "<TYPE value>".
  /// @throws vsd::Error "origin:line:col: what" on bad text.
  static Value from_text(const MetaType& type, std::string_view text, const RefResolver* refs = nullptr,
                         std::string_view origin = {});

  /// @brief Same type and equal values (two empty values are equal).
  friend bool operator==(const Value& a, const Value& b) {
    if (a.type_ != b.type_) return false;
    return a.type_ == nullptr || a.type_->equal(a.data(), b.data());
  }

  void reset() noexcept {
    if (type_ == nullptr) return;
    type_->destroy(data());
    if (on_heap()) ::operator delete(heap_, std::align_val_t(type_->alignment()));
    type_ = nullptr;
  }

 private:
  [[nodiscard]] bool on_heap() const noexcept {
    return type_->size() > inline_size || type_->alignment() > inline_align;
  }
  void* alloc() {
    if (!on_heap()) return buf_;
    heap_ = ::operator new(type_->size(), std::align_val_t(type_->alignment()));
    return heap_;
  }
  [[noreturn]] void throw_mismatch(const MetaType& wanted) const;

  const MetaType* type_ = nullptr;
  union {
    alignas(inline_align) unsigned char buf_[inline_size];
    void* heap_;
  };
};

}  // namespace vsd
