/** @file
 *  @brief Files the vsd-* tools read and write.
 *
 *  Every tool reads its input files through read_input(): a regular file, or a pipe, FIFO or terminal read
 *  as a stream (process substitution `<(...)` works), `-` for standard input; a directory is reported as
 *  one. Outputs are written through write_output(): atomically (vsd::io::write_file_atomically), so a
 *  write that fails leaves the old file whole; `-` writes to the tool's standard output.
 */
#pragma once

#include <cstddef>
#include <cstdint>
#include <iosfwd>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace vsd::tool {

/// @brief The most a tool reads from one input (as vsd::io::read_file): 4 GiB.
inline constexpr std::size_t max_input_bytes = std::size_t{1} << 32;

/// @brief The whole content of @p path ("-": standard input), at most @p max_bytes.
/// @throws vsd::Error naming the file: "is a directory", "cannot open ...: No such file or directory",
/// "is larger than N bytes", a read error; std::bad_alloc when the memory for it cannot be had.
std::vector<std::uint8_t> read_input(std::string_view path, std::size_t max_bytes = max_input_bytes);
/// @brief read_input() as text.
std::string read_text_input(std::string_view path, std::size_t max_bytes = max_input_bytes);
/// @brief How messages name input @p path: "standard input" for "-", else the path (printable()).
std::string input_name(std::string_view path);

/// @brief Writes @p bytes to @p path atomically (a temporary file in the same folder, renamed over it),
/// or to @p standard_output for "-". @throws vsd::Error naming the file and the reason.
void write_output(std::string_view path, std::span<const std::uint8_t> bytes, std::ostream& standard_output);
void write_output(std::string_view path, std::string_view text, std::ostream& standard_output);

/// @brief True when @p path ends in @p extension (".urdf"), in any case.
bool has_extension(std::string_view path, std::string_view extension);
/// @brief True when the first character after blanks (and a UTF-8 byte order mark) is '<': XML.
bool looks_like_xml(std::span<const std::uint8_t> bytes);

}  // namespace vsd::tool
