/** @file
 *  @brief ByteWriter / ByteReader: the little-endian binary encoding of values and transaction bundles.
 *
 *  Integers are fixed-width little-endian, sizes are LEB128 varints, strings are a size then bytes.
 *  The reader checks every length against what remains, so a hostile size never allocates.
 */
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <string>
#include <string_view>
#include <vector>

#include "vsd/core/config.hpp"

namespace vsd {

/// @brief Appends binary data to a growing buffer.
class ByteWriter {
 public:
  explicit ByteWriter(std::vector<std::uint8_t>& out) noexcept : out_(&out) {}

  void u8(std::uint8_t v) { out_->push_back(v); }
  template <class T>
  void fixed(T v) {  // little-endian hosts only (static_assert in bytes.cpp)
    const auto at = out_->size();
    out_->resize(at + sizeof(T));
    std::memcpy(out_->data() + at, &v, sizeof(T));
  }
  void varint(std::uint64_t v) {
    while (v >= 0x80) {
      out_->push_back(static_cast<std::uint8_t>(v | 0x80));
      v >>= 7;
    }
    out_->push_back(static_cast<std::uint8_t>(v));
  }
  void string(std::string_view s) {
    varint(s.size());
    out_->insert(out_->end(), s.begin(), s.end());
  }
  void raw(const void* p, std::size_t n) {
    if (n == 0) return;  // p may be null (an empty vector)
    const auto* b = static_cast<const std::uint8_t*>(p);
    out_->insert(out_->end(), b, b + n);
  }
  [[nodiscard]] std::size_t size() const noexcept { return out_->size(); }
  [[nodiscard]] std::vector<std::uint8_t>& buffer() noexcept { return *out_; }

 private:
  std::vector<std::uint8_t>* out_;
};

/// @brief Reads what ByteWriter wrote; throws vsd::Error("byte N: ...") on truncated or absurd data.
class ByteReader {
 public:
  ByteReader(const std::uint8_t* data, std::size_t size) noexcept : data_(data), size_(size) {}

  std::uint8_t u8() {
    need(1);
    return data_[pos_++];
  }
  template <class T>
  T fixed() {
    need(sizeof(T));
    T v;
    std::memcpy(&v, data_ + pos_, sizeof(T));
    pos_ += sizeof(T);
    return v;
  }
  std::uint64_t varint() {
    // Most varints of a file are one byte (sizes, small ids, enum values): no loop for them.
    if (VSD_LIKELY(pos_ < size_) && data_[pos_] < 0x80) return data_[pos_++];
    return varint_long();
  }
  /// @brief A size that announces @p min_element_bytes per element: rejects sizes the data cannot hold.
  std::size_t size_prefix(std::size_t min_element_bytes = 1) {
    const std::size_t at = pos_;
    const std::uint64_t n = varint();
    if (VSD_UNLIKELY(min_element_bytes <= 1 ? n > remaining() : n > remaining() / min_element_bytes))
      size_too_big(at, n);
    return static_cast<std::size_t>(n);
  }
  std::string string();
  std::string_view string_view() {
    const std::size_t n = size_prefix(1);
    std::string_view s(reinterpret_cast<const char*>(data_ + pos_), n);
    pos_ += n;
    return s;
  }
  void raw(void* p, std::size_t n) {
    need(n);
    if (n != 0) std::memcpy(p, data_ + pos_, n);  // p may be null when n is 0 (an empty vector)
    pos_ += n;
  }

  /// @brief Steps over @p n bytes and returns where they start.
  const std::uint8_t* skip(std::size_t n) {
    need(n);
    const std::uint8_t* at = data_ + pos_;
    pos_ += n;
    return at;
  }
  [[nodiscard]] std::size_t position() const noexcept { return pos_; }
  [[nodiscard]] std::size_t remaining() const noexcept { return size_ - pos_; }
  [[nodiscard]] bool at_end() const noexcept { return pos_ == size_; }
  [[noreturn]] void fail(std::string_view what) const;
  /// @brief Like fail(), reporting byte @p pos.
  [[noreturn]] void fail_at(std::size_t pos, std::string_view what) const;

 private:
  void need(std::size_t n) const {
    if (VSD_UNLIKELY(n > size_ - pos_)) fail("truncated data");
  }
  std::uint64_t varint_long();
  [[noreturn]] void size_too_big(std::size_t at, std::uint64_t n);
  const std::uint8_t* data_;
  std::size_t size_;
  std::size_t pos_ = 0;
};

}  // namespace vsd
