// The FRI-like datagram format of UdpAdapter and the robot simulator: encoding, decoding, CRC-32.
#include "vsd/robotics/fri_protocol.hpp"

#include <array>
#include <bit>
#include <cstring>

#include "vsd/core/error.hpp"

namespace vsd::robotics::fri {

namespace {

constexpr std::array<std::uint8_t, 4> magic = {'V', 'S', 'D', 'R'};

constexpr std::array<std::uint32_t, 256> crc_table() {
  std::array<std::uint32_t, 256> t{};
  for (std::uint32_t i = 0; i < 256; ++i) {
    std::uint32_t c = i;
    for (int k = 0; k < 8; ++k) c = (c & 1U) != 0 ? 0xEDB88320U ^ (c >> 1) : c >> 1;
    t[i] = c;
  }
  return t;
}
constexpr auto table = crc_table();

// Little-endian on the wire whatever the host is.
void put_u16(std::uint8_t* p, std::uint16_t v) {
  p[0] = static_cast<std::uint8_t>(v);
  p[1] = static_cast<std::uint8_t>(v >> 8);
}
void put_u32(std::uint8_t* p, std::uint32_t v) {
  for (int i = 0; i < 4; ++i) p[i] = static_cast<std::uint8_t>(v >> (8 * i));
}
void put_f64(std::uint8_t* p, double v) {
  const auto b = std::bit_cast<std::uint64_t>(v);
  for (int i = 0; i < 8; ++i) p[i] = static_cast<std::uint8_t>(b >> (8 * i));
}
std::uint16_t get_u16(const std::uint8_t* p) {
  return static_cast<std::uint16_t>(p[0] | (static_cast<unsigned>(p[1]) << 8));
}
std::uint32_t get_u32(const std::uint8_t* p) {
  std::uint32_t v = 0;
  for (int i = 3; i >= 0; --i) v = (v << 8) | p[i];
  return v;
}
double get_f64(const std::uint8_t* p) {
  std::uint64_t v = 0;
  for (int i = 7; i >= 0; --i) v = (v << 8) | p[i];
  return std::bit_cast<double>(v);
}

}  // namespace

std::uint32_t crc32(std::span<const std::uint8_t> bytes) noexcept {
  std::uint32_t c = 0xFFFFFFFFU;
  for (std::uint8_t b : bytes) c = table[(c ^ b) & 0xFFU] ^ (c >> 8);
  return c ^ 0xFFFFFFFFU;
}

std::vector<std::uint8_t> encode(const Message& m) {
  const std::size_t n = m.position.size();
  if (n > max_joints)
    throw vsd::Error("fri::encode: " + std::to_string(n) + " joints, at most " + std::to_string(max_joints));
  if (!m.velocity.empty() && m.velocity.size() != n)
    throw vsd::Error("fri::encode: " + std::to_string(m.velocity.size()) + " velocities for " +
                     std::to_string(n) + " positions");
  std::vector<std::uint8_t> out(datagram_size(n), 0);
  std::uint8_t* p = out.data();
  std::memcpy(p, magic.data(), 4);
  p[4] = protocol_version;
  p[5] = static_cast<std::uint8_t>(m.kind);
  put_u16(p + 6, static_cast<std::uint16_t>(n));
  put_u32(p + 8, m.sequence);
  put_u32(p + 12, m.flags);
  put_f64(p + 16, m.time);
  for (std::size_t i = 0; i < n; ++i) {
    put_f64(p + header_size + 8 * i, m.position[i]);
    put_f64(p + header_size + 8 * (n + i), m.velocity.empty() ? 0.0 : m.velocity[i]);
  }
  const std::size_t body = header_size + 16 * n;
  put_u32(p + body, crc32(std::span<const std::uint8_t>(p, body)));
  return out;
}

Decoded decode(std::span<const std::uint8_t> bytes) {
  Decoded d;
  auto reject = [&d](DecodeError e, std::string what) {
    d.error = e;
    d.what = std::move(what);
    return d;
  };
  // The version is read before anything else of the layout: another version may be laid out otherwise.
  if (bytes.size() < 8)
    return reject(DecodeError::TooShort, std::to_string(bytes.size()) + " bytes, shorter than a header");
  if (std::memcmp(bytes.data(), magic.data(), 4) != 0)
    return reject(DecodeError::BadMagic, "no \"VSDR\" magic");
  d.version = bytes[4];
  if (d.version != protocol_version)
    return reject(DecodeError::WrongVersion, "protocol version " + std::to_string(d.version) + ", expected " +
                                                 std::to_string(protocol_version));
  if (bytes[5] != static_cast<std::uint8_t>(Kind::Command) &&
      bytes[5] != static_cast<std::uint8_t>(Kind::State))
    return reject(DecodeError::BadKind, "unknown kind " + std::to_string(bytes[5]));
  const std::size_t n = get_u16(bytes.data() + 6);
  if (n > max_joints || bytes.size() != datagram_size(n))
    return reject(DecodeError::BadLength, std::to_string(bytes.size()) + " bytes for " + std::to_string(n) +
                                              " joints (expected " + std::to_string(datagram_size(n)) + ")");
  const std::size_t body = header_size + 16 * n;
  if (crc32(bytes.first(body)) != get_u32(bytes.data() + body))
    return reject(DecodeError::BadChecksum, "CRC-32 mismatch (a damaged datagram)");
  Message& m = d.message;
  m.kind = static_cast<Kind>(bytes[5]);
  m.sequence = get_u32(bytes.data() + 8);
  m.flags = get_u32(bytes.data() + 12);
  m.time = get_f64(bytes.data() + 16);
  m.position.resize(n);
  m.velocity.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    m.position[i] = get_f64(bytes.data() + header_size + 8 * i);
    m.velocity[i] = get_f64(bytes.data() + header_size + 8 * (n + i));
  }
  return d;
}

}  // namespace vsd::robotics::fri
