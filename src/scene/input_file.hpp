// Reading a whole input (a URDF, a mesh) into memory before any third-party parser sees it: a limit on
// its size, clear words for a directory or a missing file, and pipes and standard input ("-") read like
// files, since the parsers are then handed text, never a path.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>

namespace vsd::scene::detail {

/// @brief The bytes of @p path ("-": standard input), at most @p max_bytes of them.
/// @param what names the input in messages ("URDF file", "mesh file").
/// @throws vsd::Error "'<path>': is a directory, not a <what>" / "cannot open the <what>: <reason>" / "the
/// <what> of N bytes is larger than the limit of M bytes" / "read error".
std::string read_input(const std::filesystem::path& path, std::uintmax_t max_bytes, std::string_view what);

}  // namespace vsd::scene::detail
