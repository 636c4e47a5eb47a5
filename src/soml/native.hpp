// Internal: native compilation (docs/soml.md, "Native compilation") — the C++ generator (native_gen.cpp)
// and what the runtime needs to load and call a native library (native.cpp). Not installed.
#pragma once

#include <cstdint>
#include <ostream>
#include <string>
#include <vector>

#include "image.hpp"
#include "vsd/soml/native_abi.hpp"

namespace vsd::soml {

/// A hash of what the VM runs of @p img (functions' code, kinds, positions, constants, strings, print
/// kinds; not the script's file name): a native library is used only by a program of the same hash.
std::uint64_t image_hash(const ProgramImage& img);

/// Per function of @p img: whether native_library_source translates it (every instruction in the native
/// subset, every function it calls too).
std::vector<char> native_functions(const ProgramImage& img);

/// The C++ of a native library holding the translatable functions of each of @p images (one module per
/// image, @p scripts their names for messages).
void native_library_source(std::ostream& out, const std::vector<const ProgramImage*>& images,
                           const std::vector<std::string>& scripts);

}  // namespace vsd::soml
