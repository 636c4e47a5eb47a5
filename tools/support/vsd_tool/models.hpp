/** @file
 *  @brief What every vsd-* tool knows: the classes of all modules that were built, and vsd files of
 *  classes it does not know.
 */
#pragma once

#include <cstdint>
#include <memory>
#include <span>
#include <string_view>

#include "vsd/core/fwd.hpp"
#include "vsd/io/snapshot.hpp"

namespace vsd::tool {

/// @brief Registers in @p registry the classes and types of every vsd module this tool was built with
/// (scene, robotics, physics, SOML++'s net classes, ...), so that every tool reads every file the others
/// write (`vsd-io tree` of what `vsd-scene --json` wrote), and every other C++ class linked into the
/// program (a tool built with a user's classes knows them).
void register_classes(Registry& registry);

/// @brief A tool's own Registry, with the classes of every module registered (register_classes()), and an
/// Environment on it: run-time classes a file defines, and stand-ins, go when the workspace goes, so a tool
/// run in-process (the tests) leaves nothing behind.
class Workspace {
 public:
  Workspace();
  Workspace(const Workspace&) = delete;
  Workspace& operator=(const Workspace&) = delete;
  ~Workspace();

  [[nodiscard]] Registry& registry() noexcept { return *registry_; }
  [[nodiscard]] Environment& env() noexcept { return *env_; }
  [[nodiscard]] SimState& state() noexcept;

 private:
  std::unique_ptr<Registry> registry_;
  std::unique_ptr<Environment> env_;  // destroyed before the registry its instances' classes live in
};

/// @brief Loads the vsd file (either format) at @p path ("-": standard input, see read_input()) into the
/// empty @p state. Classes that neither the tool nor the file defines (a user's C++ classes) are loaded
/// through stand-ins with their saved values (vsd::io::UnknownClasses::Placeholder): the report names them
/// and warns. @throws vsd::Error as vsd::io::load_bytes() and read_input() do.
io::LoadReport load_vsd(SimState& state, std::string_view path);
/// @brief load_vsd() of bytes already read; errors name @p origin.
io::LoadReport load_vsd_bytes(SimState& state, std::span<const std::uint8_t> bytes, std::string_view origin);

}  // namespace vsd::tool
