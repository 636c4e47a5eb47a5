#include "input_file.hpp"

#include <cerrno>
#include <cstring>
#include <fstream>
#include <iostream>
#include <istream>

#include "vsd/core/error.hpp"

namespace vsd::scene::detail {

namespace fs = std::filesystem;

namespace {

// Reads @p in to its end, refusing more than @p max_bytes; chunked, so that an endless stream (a pipe,
// /dev/zero) stops at the limit instead of exhausting memory.
std::string read_stream(std::istream& in, std::uintmax_t max_bytes, const std::string& where) {
  std::string out;
  char chunk[1 << 16];
  while (in) {
    in.read(chunk, sizeof chunk);
    const auto got = static_cast<std::size_t>(in.gcount());
    if (out.size() + got > max_bytes)
      vsd::detail::throw_error(where + " is larger than the limit of " + std::to_string(max_bytes) + " bytes");
    out.append(chunk, got);
  }
  if (in.bad()) vsd::detail::throw_error(where + ": read error");
  return out;
}

}  // namespace

std::string read_input(const fs::path& path, std::uintmax_t max_bytes, std::string_view what) {
  const std::string kind(what);
  if (path == "-") return read_stream(std::cin, max_bytes, "standard input (the " + kind + ")");
  const std::string where = "'" + path.string() + "'";
  std::error_code ec;
  const fs::file_status st = fs::status(path, ec);
  if (st.type() == fs::file_type::directory) vsd::detail::throw_error(where + ": is a directory, not a " + kind);
  if (st.type() == fs::file_type::regular) {
    const std::uintmax_t size = fs::file_size(path, ec);
    if (!ec && size > max_bytes)
      vsd::detail::throw_error(where + ": the " + kind + " of " + std::to_string(size) +
                               " bytes is larger than the limit of " + std::to_string(max_bytes) + " bytes");
  }
  errno = 0;
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    const int e = errno;
    vsd::detail::throw_error(where + ": cannot open the " + kind +
                             (e != 0 ? ": " + std::string(std::strerror(e)) : std::string()));
  }
  return read_stream(in, max_bytes, where + ": the " + kind);
}

}  // namespace vsd::scene::detail
