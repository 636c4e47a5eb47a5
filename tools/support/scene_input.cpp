// A URDF or a saved scene as the scene tools' input (see vsd_tool/scene_input.hpp).
#include "vsd_tool/scene_input.hpp"

#include <filesystem>

#include "vsd/core/sim_state.hpp"
#include "vsd_tool/input.hpp"
#include "vsd_tool/models.hpp"

namespace vsd::tool {

namespace {

scene::SceneReport load_urdf_bytes(SimState& state, std::string_view path, std::span<const std::uint8_t> bytes,
                                   const scene::UrdfOptions& options) {
  const std::filesystem::path folder =
      path == "-" ? std::filesystem::path() : std::filesystem::path(std::string(path)).parent_path();
  const std::string_view text(reinterpret_cast<const char*>(bytes.data()), bytes.size());
  return scene::load_urdf_text(state.database(), text, input_name(path), folder, options);
}

}  // namespace

scene::SceneReport load_urdf_input(SimState& state, std::string_view path, const scene::UrdfOptions& options) {
  register_classes(state.environment().registry());
  return load_urdf_bytes(state, path, read_input(path), options);
}

SceneInput load_scene_input(SimState& state, std::string_view path, const scene::UrdfOptions& options) {
  SceneInput in;
  register_classes(state.environment().registry());
  const std::vector<std::uint8_t> bytes = read_input(path);
  if (has_extension(path, ".urdf") || has_extension(path, ".xml") || looks_like_xml(bytes)) {
    in.urdf = load_urdf_bytes(state, path, bytes, options);
    in.warnings = in.urdf->warnings;
  } else {
    in.saved = load_vsd_bytes(state, bytes, input_name(path));
    in.warnings = in.saved->warnings;
  }
  return in;
}

}  // namespace vsd::tool
