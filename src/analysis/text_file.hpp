// Whole-file text reading and writing for the net formats (PNML, SOML++), with vsd::Error messages
// that name the file.
#pragma once

#include <filesystem>
#include <string>
#include <string_view>

namespace vsd::analysis::detail {

/// @brief The bytes of @p path. @throws vsd::Error "<path>: cannot open the file for reading" / "read error".
std::string read_text_file(const std::filesystem::path& path);

/// @brief Replaces the content of @p path by @p text. @throws vsd::Error naming the file on failure.
void write_text_file(const std::filesystem::path& path, std::string_view text);

}  // namespace vsd::analysis::detail
