// A minimal PNG writer for the work cells' plots (`--png`): an RGB canvas with lines and filled rectangles,
// encoded as an 8-bit truecolour PNG whose image data is one fixed-Huffman deflate block (runs at distance
// 1, one pixel and one row back: plots are mostly flat colour, so this is small without zlib, which is not
// among vsd's dependencies). It is an example helper, not library API: vsd has no imaging concept, and a
// plot is the application's business.
//
// write_png() writes a temporary file next to the target and renames it over the target, so a failed
// write (unwritable directory, full disk) leaves any earlier file intact and says what failed.
#pragma once

#include <algorithm>
#include <array>
#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

#include "vsd/core/error.hpp"

namespace vsd_example {

struct Rgb {
  std::uint8_t r = 0, g = 0, b = 0;
};

class Image {
 public:
  Image(int width, int height, Rgb background)
      : w_(std::max(width, 1)), h_(std::max(height, 1)), px_(static_cast<std::size_t>(w_) * h_, background) {}
  int width() const { return w_; }
  int height() const { return h_; }
  Rgb at(int x, int y) const { return px_[static_cast<std::size_t>(y) * w_ + x]; }
  /// Sets one pixel; a pixel outside the canvas is ignored (plots clip).
  void set(int x, int y, Rgb c) {
    if (x >= 0 && y >= 0 && x < w_ && y < h_) px_[static_cast<std::size_t>(y) * w_ + x] = c;
  }
  /// Fills the rectangle [x0, x1] x [y0, y1] (inclusive, any order), clipped.
  void fill(int x0, int y0, int x1, int y1, Rgb c) {
    if (x0 > x1) std::swap(x0, x1);
    if (y0 > y1) std::swap(y0, y1);
    for (int y = std::max(y0, 0); y <= std::min(y1, h_ - 1); ++y)
      for (int x = std::max(x0, 0); x <= std::min(x1, w_ - 1); ++x) px_[static_cast<std::size_t>(y) * w_ + x] = c;
  }
  /// A line from (x0, y0) to (x1, y1) in pixels (Bresenham on the rounded end points), clipped.
  void line(double x0, double y0, double x1, double y1, Rgb c) {
    if (!std::isfinite(x0) || !std::isfinite(y0) || !std::isfinite(x1) || !std::isfinite(y1)) return;
    const double lim = 1e6;  // far outside any canvas: keeps the loop bounded for wild values
    long ax = std::lround(std::clamp(x0, -lim, lim)), ay = std::lround(std::clamp(y0, -lim, lim));
    const long bx = std::lround(std::clamp(x1, -lim, lim)), by = std::lround(std::clamp(y1, -lim, lim));
    const long dx = std::labs(bx - ax), dy = -std::labs(by - ay);
    const long sx = ax < bx ? 1 : -1, sy = ay < by ? 1 : -1;
    long err = dx + dy;
    for (;;) {
      set(static_cast<int>(std::clamp(ax, -1L, static_cast<long>(w_))),
          static_cast<int>(std::clamp(ay, -1L, static_cast<long>(h_))), c);
      if (ax == bx && ay == by) break;
      const long e2 = 2 * err;
      if (e2 >= dy) err += dy, ax += sx;
      if (e2 <= dx) err += dx, ay += sy;
    }
  }

 private:
  int w_, h_;
  std::vector<Rgb> px_;
};

namespace png_detail {

inline std::uint32_t crc32(const std::uint8_t* p, std::size_t n, std::uint32_t c = 0) {
  c = ~c;
  for (std::size_t i = 0; i < n; ++i) {
    c ^= p[i];
    for (int k = 0; k < 8; ++k) c = (c >> 1) ^ (0xEDB88320u & (0u - (c & 1u)));
  }
  return ~c;
}

inline std::uint32_t adler32(const std::vector<std::uint8_t>& d) {
  std::uint32_t a = 1, b = 0;
  for (std::uint8_t x : d) {
    a = (a + x) % 65521u;
    b = (b + a) % 65521u;
  }
  return (b << 16) | a;
}

// Deflate's bit stream: values least significant bit first; Huffman codes most significant bit first.
struct Bits {
  std::vector<std::uint8_t> out;
  std::uint32_t acc = 0;
  int n = 0;
  void put(std::uint32_t v, int bits) {
    for (int i = 0; i < bits; ++i) {
      acc |= ((v >> i) & 1u) << n;
      if (++n == 8) out.push_back(static_cast<std::uint8_t>(acc)), acc = 0, n = 0;
    }
  }
  void code(std::uint32_t c, int bits) {
    for (int i = bits - 1; i >= 0; --i) put((c >> i) & 1u, 1);
  }
  void flush() {
    if (n > 0) out.push_back(static_cast<std::uint8_t>(acc)), acc = 0, n = 0;
  }
};

// The fixed Huffman code of literal/length symbol s (RFC 1951, 3.2.6).
inline void fixed_symbol(Bits& b, int s) {
  if (s < 144) b.code(0x30 + s, 8);
  else if (s < 256) b.code(0x190 + s - 144, 9);
  else if (s < 280) b.code(s - 256, 7);
  else b.code(0xC0 + s - 280, 8);
}

/// A zlib stream (RFC 1950) of @p d: one final fixed-Huffman block of literals and back references.
inline std::vector<std::uint8_t> zlib_fixed(const std::vector<std::uint8_t>& d, std::size_t row) {
  static constexpr std::array<int, 29> len_base{3,  4,  5,  6,  7,  8,  9,  10, 11,  13,  15,  17,  19,  23, 27,
                                                31, 35, 43, 51, 59, 67, 83, 99, 115, 131, 163, 195, 227, 258};
  static constexpr std::array<int, 29> len_extra{0, 0, 0, 0, 0, 0, 0, 0, 1, 1, 1, 1, 2, 2, 2,
                                                 2, 3, 3, 3, 3, 4, 4, 4, 4, 5, 5, 5, 5, 0};
  static constexpr std::array<int, 30> dist_base{1,   2,   3,   4,   5,   7,    9,    13,   17,   25,
                                                 33,  49,  65,  97,  129, 193,  257,  385,  513,  769,
                                                 1025, 1537, 2049, 3073, 4097, 6145, 8193, 12289, 16385, 24577};
  Bits b;
  b.out = {0x78, 0x01};  // deflate, 32 K window, no dictionary, fastest (header check: 0x7801 % 31 == 0)
  b.put(1, 1);           // final block
  b.put(1, 2);           // fixed Huffman codes
  const std::size_t dists[] = {1, 3, row};
  for (std::size_t i = 0; i < d.size();) {
    std::size_t best = 0, best_dist = 0;
    for (std::size_t dist : dists) {
      if (dist == 0 || dist > i || dist > 32768) continue;
      std::size_t m = 0;
      while (m < 258 && i + m < d.size() && d[i + m] == d[i + m - dist]) ++m;
      if (m > best) best = m, best_dist = dist;
    }
    if (best < 3) {
      fixed_symbol(b, d[i]);
      ++i;
      continue;
    }
    int k = 28;
    while (len_base[static_cast<std::size_t>(k)] > static_cast<int>(best)) --k;
    fixed_symbol(b, 257 + k);
    b.put(static_cast<std::uint32_t>(best) - len_base[static_cast<std::size_t>(k)], len_extra[static_cast<std::size_t>(k)]);
    int j = 29;
    while (dist_base[static_cast<std::size_t>(j)] > static_cast<int>(best_dist)) --j;
    b.code(static_cast<std::uint32_t>(j), 5);
    b.put(static_cast<std::uint32_t>(best_dist) - dist_base[static_cast<std::size_t>(j)], j < 4 ? 0 : j / 2 - 1);
    i += best;
  }
  fixed_symbol(b, 256);  // end of block
  b.flush();
  const std::uint32_t a = adler32(d);
  for (int s = 24; s >= 0; s -= 8) b.out.push_back(static_cast<std::uint8_t>(a >> s));
  return b.out;
}

inline void chunk(std::string& png, const char* type, const std::vector<std::uint8_t>& data) {
  std::vector<std::uint8_t> body(type, type + 4);
  body.insert(body.end(), data.begin(), data.end());
  auto be32 = [&](std::uint32_t v) {
    for (int s = 24; s >= 0; s -= 8) png.push_back(static_cast<char>(v >> s));
  };
  be32(static_cast<std::uint32_t>(data.size()));
  png.append(reinterpret_cast<const char*>(body.data()), body.size());
  be32(crc32(body.data(), body.size()));
}

}  // namespace png_detail

/// The PNG file's bytes: 8-bit RGB, no interlace, filter 0 on every row.
inline std::string encode_png(const Image& img) {
  using namespace png_detail;
  const auto w = static_cast<std::uint32_t>(img.width()), h = static_cast<std::uint32_t>(img.height());
  std::vector<std::uint8_t> raw;
  raw.reserve((3 * static_cast<std::size_t>(w) + 1) * h);
  for (std::uint32_t y = 0; y < h; ++y) {
    raw.push_back(0);
    for (std::uint32_t x = 0; x < w; ++x) {
      const Rgb c = img.at(static_cast<int>(x), static_cast<int>(y));
      raw.insert(raw.end(), {c.r, c.g, c.b});
    }
  }
  std::string png("\x89PNG\r\n\x1a\n", 8);
  std::vector<std::uint8_t> ihdr;
  for (std::uint32_t v : {w, h})
    for (int s = 24; s >= 0; s -= 8) ihdr.push_back(static_cast<std::uint8_t>(v >> s));
  ihdr.insert(ihdr.end(), {8, 2, 0, 0, 0});  // bit depth 8, truecolour, deflate, filter 0, no interlace
  chunk(png, "IHDR", ihdr);
  chunk(png, "IDAT", zlib_fixed(raw, 3 * static_cast<std::size_t>(w) + 1));
  chunk(png, "IEND", {});
  return png;
}

/// Writes @p img to @p path through a temporary file in the same directory that is renamed over it.
/// @throws vsd::Error "cannot write PATH: REASON" (the target is left as it was).
inline void write_png(const std::string& path, const Image& img) {
  const std::string bytes = encode_png(img);
  const std::string tmp = path + ".tmp";
  auto fail = [&](const char* what) {
    const std::string reason = std::strerror(errno);
    std::remove(tmp.c_str());
    throw vsd::Error("cannot write " + path + ": " + what + reason);
  };
  std::FILE* f = std::fopen(tmp.c_str(), "wb");
  if (f == nullptr) fail("");
  const bool wrote = std::fwrite(bytes.data(), 1, bytes.size(), f) == bytes.size();
  if (std::fclose(f) != 0 || !wrote) fail("");
  if (std::rename(tmp.c_str(), path.c_str()) != 0) fail("rename: ");
}

}  // namespace vsd_example
