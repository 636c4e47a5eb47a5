/** @file
 *  @brief Whole-file reads with a size limit, and atomic writes: a crash mid-save leaves the previous
 *  file intact.
 */
#pragma once

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <span>
#include <vector>

namespace vsd::io {

/// @brief Writes @p bytes to @p path atomically: into a temporary file in the same directory, flushed to
/// disk, then renamed over @p path. Readers see the old file or the new one, never a mix.
/// @throws vsd::Error naming the file and the system's reason.
void write_file_atomically(const std::filesystem::path& path, std::span<const std::uint8_t> bytes);

/// @brief Reads a whole file. @throws vsd::Error when it cannot be read or is larger than @p max_bytes.
std::vector<std::uint8_t> read_file(const std::filesystem::path& path,
                                    std::size_t max_bytes = std::size_t{1} << 32);

}  // namespace vsd::io
