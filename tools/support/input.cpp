// Reading and writing the tools' files (see vsd_tool/input.hpp).
#include "vsd_tool/input.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cstring>
#include <ostream>

#include "vsd/core/error.hpp"
#include "vsd/io/file.hpp"
#include "vsd_tool/text.hpp"

namespace vsd::tool {

namespace {

// Closes a descriptor it opened (never standard input).
struct Descriptor {
  int fd = -1;
  bool owned = false;
  ~Descriptor() {
    if (owned && fd >= 0) ::close(fd);
  }
};

[[noreturn]] void fail(std::string_view path, const std::string& what) {
  throw Error(input_name(path) + ": " + what);
}

}  // namespace

std::string input_name(std::string_view path) { return path == "-" ? "standard input" : printable(path); }

std::vector<std::uint8_t> read_input(std::string_view path, std::size_t max_bytes) {
  Descriptor d;
  if (path == "-") {
    d.fd = STDIN_FILENO;
  } else {
    const std::string p(path);
    do {
      d.fd = ::open(p.c_str(), O_RDONLY | O_CLOEXEC);
    } while (d.fd < 0 && errno == EINTR);
    if (d.fd < 0) fail(path, std::string("cannot open: ") + std::strerror(errno));
    d.owned = true;
  }
  struct stat st {};
  if (::fstat(d.fd, &st) != 0) fail(path, std::string("cannot read: ") + std::strerror(errno));
  if (S_ISDIR(st.st_mode)) fail(path, "is a directory");
  auto read_some = [&](std::uint8_t* into, std::size_t n) {
    ssize_t got = 0;
    do {
      got = ::read(d.fd, into, n);
    } while (got < 0 && errno == EINTR);
    if (got < 0) fail(path, std::string("cannot read: ") + std::strerror(errno));
    return static_cast<std::size_t>(got);
  };
  auto too_large = [&] { fail(path, "is larger than " + std::to_string(max_bytes) + " bytes"); };
  std::vector<std::uint8_t> bytes;
  if (S_ISREG(st.st_mode)) {  // its size is known: one allocation
    if (static_cast<std::uint64_t>(st.st_size) > max_bytes) too_large();
    bytes.resize(static_cast<std::size_t>(st.st_size));
    std::size_t got = 0;
    while (got < bytes.size()) {
      const std::size_t n = read_some(bytes.data() + got, bytes.size() - got);
      if (n == 0) break;  // it shrank meanwhile
      got += n;
    }
    bytes.resize(got);
  }
  // Pipes, FIFOs, terminals and sockets are read until their end, in chunks (and a regular file that grew
  // since its size was taken).
  std::vector<std::uint8_t> chunk(std::size_t{1} << 16);
  for (;;) {
    const std::size_t n = read_some(chunk.data(), chunk.size());
    if (n == 0) break;
    if (n > max_bytes - bytes.size()) too_large();
    bytes.insert(bytes.end(), chunk.begin(), chunk.begin() + static_cast<std::ptrdiff_t>(n));
  }
  return bytes;
}

std::string read_text_input(std::string_view path, std::size_t max_bytes) {
  const std::vector<std::uint8_t> bytes = read_input(path, max_bytes);
  return std::string(bytes.begin(), bytes.end());
}

void write_output(std::string_view path, std::span<const std::uint8_t> bytes, std::ostream& standard_output) {
  if (path == "-") {
    standard_output.write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
    standard_output.flush();
    if (!standard_output) throw Error("cannot write to standard output");
    return;
  }
  io::write_file_atomically(std::filesystem::path(std::string(path)), bytes);
}

void write_output(std::string_view path, std::string_view text, std::ostream& standard_output) {
  write_output(path, std::span<const std::uint8_t>(reinterpret_cast<const std::uint8_t*>(text.data()), text.size()),
               standard_output);
}

bool has_extension(std::string_view path, std::string_view extension) {
  if (path.size() < extension.size()) return false;
  const std::string_view tail = path.substr(path.size() - extension.size());
  return std::equal(tail.begin(), tail.end(), extension.begin(), [](char a, char b) {
    return std::tolower(static_cast<unsigned char>(a)) == std::tolower(static_cast<unsigned char>(b));
  });
}

bool looks_like_xml(std::span<const std::uint8_t> bytes) {
  std::size_t i = bytes.size() >= 3 && bytes[0] == 0xEF && bytes[1] == 0xBB && bytes[2] == 0xBF ? 3 : 0;
  while (i < bytes.size() && std::isspace(bytes[i]) != 0) ++i;
  return i < bytes.size() && bytes[i] == '<';
}

}  // namespace vsd::tool
