#include "text_file.hpp"

#include <fstream>
#include <sstream>

#include "vsd/core/error.hpp"

namespace vsd::analysis::detail {

std::string read_text_file(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) vsd::detail::throw_error(path.string() + ": cannot open the file for reading");
  std::ostringstream buf;
  buf << in.rdbuf();
  if (in.bad()) vsd::detail::throw_error(path.string() + ": read error");
  return std::move(buf).str();
}

void write_text_file(const std::filesystem::path& path, std::string_view text) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  if (!out) vsd::detail::throw_error(path.string() + ": cannot open the file for writing");
  out.write(text.data(), static_cast<std::streamsize>(text.size()));
  out.close();
  if (!out) vsd::detail::throw_error(path.string() + ": write error");
}

}  // namespace vsd::analysis::detail
