// Whole-file text reading and writing for the net formats (PNML, SOML++), with vsd::Error messages
// that name the file.
#pragma once

#include <filesystem>
#include <iosfwd>
#include <string>
#include <string_view>

namespace vsd::analysis::detail {

/// @brief The bytes of @p in up to its end (a pipe too). @throws vsd::Error "<source>: read error".
std::string read_text(std::istream& in, std::string_view source);

/// @brief The bytes of @p path (a regular file, a pipe, a device).
/// @throws vsd::Error "<path>: is a directory, not a file", "<path>: cannot open the file for reading
/// (<reason>)" or "<path>: read error".
std::string read_text_file(const std::filesystem::path& path);

/// @brief Replaces the content of @p path by @p text. @throws vsd::Error naming the file on failure.
void write_text_file(const std::filesystem::path& path, std::string_view text);

}  // namespace vsd::analysis::detail
