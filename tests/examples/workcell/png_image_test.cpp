// The work cells' minimal PNG writer (examples/workcell/png_image.hpp): a valid PNG — signature, IHDR,
// every chunk's CRC, a zlib stream whose deflate data decodes (with the small inflater below, written
// from RFC 1951) to the pixels drawn, its Adler-32 — and a failed write that says why and keeps the file
// that was there.
#include "png_image.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>

namespace {

using vsd_example::Image;
using vsd_example::Rgb;

std::uint32_t be32(const std::string& s, std::size_t at) {
  std::uint32_t v = 0;
  for (int i = 0; i < 4; ++i) v = (v << 8) | static_cast<std::uint8_t>(s[at + static_cast<std::size_t>(i)]);
  return v;
}

// An inflater for what the writer emits and a little more: stored and fixed-Huffman blocks.
struct Inflater {
  const std::vector<std::uint8_t>& in;
  std::size_t pos = 0;
  int bit = 0;
  std::uint32_t get(int n) {
    std::uint32_t v = 0;
    for (int i = 0; i < n; ++i) {
      if (pos >= in.size()) throw std::runtime_error("deflate data ends early");
      v |= static_cast<std::uint32_t>((in[pos] >> bit) & 1) << i;
      if (++bit == 8) bit = 0, ++pos;
    }
    return v;
  }
  int fixed_symbol() {  // Huffman codes come most significant bit first
    std::uint32_t c = 0;
    for (int len = 1; len <= 9; ++len) {
      c = (c << 1) | get(1);
      if (len == 7 && c <= 0x17) return static_cast<int>(c) + 256;
      if (len == 8 && c >= 0x30 && c <= 0xBF) return static_cast<int>(c) - 0x30;
      if (len == 8 && c >= 0xC0 && c <= 0xC7) return static_cast<int>(c) - 0xC0 + 280;
      if (len == 9 && c >= 0x190) return static_cast<int>(c) - 0x190 + 144;
    }
    throw std::runtime_error("bad fixed code");
  }
  std::vector<std::uint8_t> run() {
    static const int lb[] = {3,  4,  5,  6,  7,  8,  9,  10, 11,  13,  15,  17,  19,  23, 27,
                             31, 35, 43, 51, 59, 67, 83, 99, 115, 131, 163, 195, 227, 258};
    static const int le[] = {0, 0, 0, 0, 0, 0, 0, 0, 1, 1, 1, 1, 2, 2, 2, 2, 3, 3, 3, 3, 4, 4, 4, 4, 5, 5, 5, 5, 0};
    static const int db[] = {1,   2,   3,   4,   5,   7,    9,    13,   17,   25,   33,   49,   65,    97,    129,
                             193, 257, 385, 513, 769, 1025, 1537, 2049, 3073, 4097, 6145, 8193, 12289, 16385, 24577};
    std::vector<std::uint8_t> out;
    for (bool last = false; !last;) {
      last = get(1) != 0;
      const std::uint32_t type = get(2);
      if (type == 0) {
        if (bit != 0) bit = 0, ++pos;
        const std::uint32_t len = get(16);
        get(16);
        for (std::uint32_t i = 0; i < len; ++i) out.push_back(static_cast<std::uint8_t>(get(8)));
      } else if (type == 1) {
        for (;;) {
          const int s = fixed_symbol();
          if (s < 256) {
            out.push_back(static_cast<std::uint8_t>(s));
          } else if (s == 256) {
            break;
          } else {
            const int k = s - 257;
            const int len = lb[k] + static_cast<int>(get(le[k]));
            std::uint32_t d = 0;
            for (int i = 0; i < 5; ++i) d = (d << 1) | get(1);
            const int dist = db[d] + static_cast<int>(get(d < 4 ? 0 : static_cast<int>(d) / 2 - 1));
            if (dist > static_cast<int>(out.size())) throw std::runtime_error("distance too far back");
            for (int i = 0; i < len; ++i) out.push_back(out[out.size() - static_cast<std::size_t>(dist)]);
          }
        }
      } else {
        throw std::runtime_error("dynamic Huffman block: not written by png_image.hpp");
      }
    }
    return out;
  }
};

TEST(PngImage, IsAValidPngOfThePixelsDrawn) {
  Image img(37, 23, Rgb{255, 255, 255});
  img.line(0, 0, 36, 22, Rgb{200, 30, 30});
  img.fill(5, 10, 20, 12, Rgb{30, 60, 200});
  img.set(100, 100, Rgb{1, 2, 3});  // outside: ignored
  const std::string png = vsd_example::encode_png(img);
  ASSERT_EQ(png.substr(0, 8), std::string("\x89PNG\r\n\x1a\n", 8));
  // Chunks: length, type, data, CRC over type and data.
  std::vector<std::string> types;
  std::vector<std::uint8_t> idat;
  for (std::size_t at = 8; at < png.size();) {
    ASSERT_LE(at + 12, png.size());
    const std::uint32_t n = be32(png, at);
    const std::string type = png.substr(at + 4, 4);
    ASSERT_LE(at + 12 + n, png.size());
    const auto* body = reinterpret_cast<const std::uint8_t*>(png.data() + at + 4);
    EXPECT_EQ(vsd_example::png_detail::crc32(body, 4 + n), be32(png, at + 8 + n)) << type;
    if (type == "IHDR") {
      ASSERT_EQ(n, 13u);
      EXPECT_EQ(be32(png, at + 8), 37u);
      EXPECT_EQ(be32(png, at + 12), 23u);
      EXPECT_EQ(png[at + 16], 8);  // bit depth
      EXPECT_EQ(png[at + 17], 2);  // truecolour
    }
    if (type == "IDAT") idat.insert(idat.end(), body + 4, body + 4 + n);
    types.push_back(type);
    at += 12 + n;
  }
  EXPECT_EQ(types, (std::vector<std::string>{"IHDR", "IDAT", "IEND"}));
  // The CRC itself against the standard check value.
  const std::string check = "123456789";
  EXPECT_EQ(vsd_example::png_detail::crc32(reinterpret_cast<const std::uint8_t*>(check.data()), 9), 0xCBF43926u);
  // zlib: header, deflate, Adler-32 of the raw rows.
  ASSERT_GE(idat.size(), 6u);
  EXPECT_EQ((idat[0] * 256 + idat[1]) % 31, 0);
  EXPECT_EQ(idat[0] & 0x0F, 8);  // deflate
  const std::vector<std::uint8_t> body(idat.begin() + 2, idat.end() - 4);
  const std::vector<std::uint8_t> raw = Inflater{body}.run();
  ASSERT_EQ(raw.size(), 23u * (1 + 3 * 37));
  const std::uint32_t adler = (std::uint32_t{idat[idat.size() - 4]} << 24) | (std::uint32_t{idat[idat.size() - 3]} << 16) |
                              (std::uint32_t{idat[idat.size() - 2]} << 8) | idat[idat.size() - 1];
  EXPECT_EQ(vsd_example::png_detail::adler32(raw), adler);
  for (int y = 0; y < 23; ++y) {
    const std::size_t row = static_cast<std::size_t>(y) * (1 + 3 * 37);
    EXPECT_EQ(raw[row], 0);  // filter: none
    for (int x = 0; x < 37; ++x) {
      const Rgb c = img.at(x, y);
      const std::size_t p = row + 1 + 3 * static_cast<std::size_t>(x);
      ASSERT_EQ(raw[p], c.r) << x << ',' << y;
      ASSERT_EQ(raw[p + 1], c.g);
      ASSERT_EQ(raw[p + 2], c.b);
    }
  }
  EXPECT_EQ(img.at(0, 0).r, 200);  // the line's ends
  EXPECT_EQ(img.at(36, 22).r, 200);
  EXPECT_EQ(img.at(5, 10).b, 200);
  // Flat colour compresses: a 1000 x 1000 white image is far smaller than its 3 MB of pixels.
  EXPECT_LT(vsd_example::encode_png(Image(1000, 1000, Rgb{255, 255, 255})).size(), 60'000u);
}

TEST(PngImage, AFailedWriteSaysWhyAndKeepsTheFileThatWasThere) {
  const auto dir = std::filesystem::temp_directory_path() / "vsd_png_image_test";
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  const auto path = (dir / "plot.png").string();
  std::ofstream(path) << "earlier";
  // The temporary file cannot be made (a directory of that name is in the way).
  std::filesystem::create_directory(path + ".tmp");
  try {
    vsd_example::write_png(path, Image(4, 4, Rgb{}));
    ADD_FAILURE() << "no error";
  } catch (const vsd::Error& e) {
    EXPECT_EQ(std::string(e.what()), "cannot write " + path + ": Is a directory");
  }
  std::ifstream in(path);
  std::string text;
  std::getline(in, text);
  EXPECT_EQ(text, "earlier");
  // Written: the file is replaced as a whole, no temporary file is left.
  std::filesystem::remove(path + ".tmp");
  vsd_example::write_png(path, Image(4, 4, Rgb{}));
  EXPECT_EQ(std::filesystem::file_size(path), vsd_example::encode_png(Image(4, 4, Rgb{})).size());
  EXPECT_FALSE(std::filesystem::exists(path + ".tmp"));
  EXPECT_THROW(vsd_example::write_png("/nonexistent-dir/plot.png", Image(4, 4, Rgb{})), vsd::Error);
  std::filesystem::remove_all(dir);
}

}  // namespace
