#include "vsd/core/bytes.hpp"

#include <bit>
#include <string>

#include "vsd/core/error.hpp"

namespace vsd {

static_assert(std::endian::native == std::endian::little,
              "vsd's binary encoding assumes a little-endian host");

std::uint64_t ByteReader::varint_long() {
  std::uint64_t v = 0;
  for (int shift = 0; shift < 64; shift += 7) {
    const std::uint8_t b = u8();
    v |= static_cast<std::uint64_t>(b & 0x7F) << shift;
    if ((b & 0x80) == 0) return v;
  }
  fail("varint longer than 10 bytes");
}

void ByteReader::size_too_big(std::size_t at, std::uint64_t n) {
  pos_ = at;
  fail("size " + std::to_string(n) + " exceeds the " + std::to_string(remaining()) + " bytes that remain");
}

std::string ByteReader::string() { return std::string(string_view()); }

void ByteReader::fail(std::string_view what) const { fail_at(pos_, what); }

void ByteReader::fail_at(std::size_t pos, std::string_view what) const {
  throw Error("byte " + std::to_string(pos) + ": " + std::string(what));
}

}  // namespace vsd
