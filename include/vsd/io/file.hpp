/** @file
 *  @brief Whole-file reads with a size limit, and atomic writes: a crash or a failed write mid-save
 *  leaves the previous file intact.
 */
#pragma once

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <span>
#include <vector>

namespace vsd::io {

/// @brief Writes @p bytes to @p path atomically: into a temporary file in the same directory (a short
/// random name, so any legal file name works), flushed to disk, then renamed over the file, and the
/// directory flushed. Readers see the old file or the new one, never a mix; a write that fails (a full
/// disk) leaves the old file whole and no temporary file behind.
///
/// - A symbolic link is written through: the final target of its chain is replaced, the links stay
///   (a loop of links is an error).
/// - An existing file keeps its mode (and its owner and group where the system allows); a new file gets
///   the mode the umask leaves of 0666.
/// - Refused, with the file named and nothing changed: anything that is not a regular file (a directory,
///   a device such as /dev/full, a pipe), a read-only file (no write bit in its mode, even for root), a
///   file the user may not write.
/// @throws vsd::Error naming the file, what failed and the system's reason.
void write_file_atomically(const std::filesystem::path& path, std::span<const std::uint8_t> bytes);

/// @brief Reads a whole file. A regular file's size is checked against @p max_bytes (and against the
/// memory the process may use) before anything is allocated; a pipe, standard input (`/dev/stdin`) or a
/// character device is read as a stream until it ends, up to @p max_bytes.
/// @throws vsd::Error naming the file: it cannot be opened or read, is a directory, is larger than
/// @p max_bytes or than memory, or memory runs out.
std::vector<std::uint8_t> read_file(const std::filesystem::path& path,
                                    std::size_t max_bytes = std::size_t{1} << 32);

}  // namespace vsd::io
