#include "text_file.hpp"

#include <cerrno>
#include <cstring>
#include <fstream>
#include <istream>

#include "vsd/core/error.hpp"

namespace vsd::analysis::detail {

std::string read_text(std::istream& in, std::string_view source) {
  std::string text;
  char buf[1 << 16];
  while (in.read(buf, sizeof buf) || in.gcount() > 0) text.append(buf, static_cast<std::size_t>(in.gcount()));
  if (in.bad()) vsd::detail::throw_error(std::string(source) + ": read error");
  return text;
}

std::string read_text_file(const std::filesystem::path& path) {
  // A directory opens like a file and reads as nothing: it would pass for an empty net.
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec))
    vsd::detail::throw_error(path.string() + ": is a directory, not a file");
  errno = 0;
  std::ifstream in(path, std::ios::binary);
  if (!in)
    vsd::detail::throw_error(path.string() + ": cannot open the file for reading" +
                             (errno != 0 ? std::string(" (") + std::strerror(errno) + ")" : std::string()));
  return read_text(in, path.string());
}

void write_text_file(const std::filesystem::path& path, std::string_view text) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  if (!out) vsd::detail::throw_error(path.string() + ": cannot open the file for writing");
  out.write(text.data(), static_cast<std::streamsize>(text.size()));
  out.close();
  if (!out) vsd::detail::throw_error(path.string() + ": write error");
}

}  // namespace vsd::analysis::detail
