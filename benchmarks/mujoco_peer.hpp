// MuJoCo models from text, for the benchmarks that use MuJoCo as a peer (bench_robotics.cpp,
// bench_physics.cpp): MuJoCo 2.2 loads XML (MJCF or URDF) from files only, so the text goes through an
// in-memory virtual file system.
#pragma once

#include <mujoco/mujoco.h>

#include <cstring>
#include <memory>
#include <stdexcept>
#include <string>

namespace vsd_bench {

/// @brief The model described by @p xml, loaded as a file named @p name (its extension says MJCF or URDF).
/// @throws std::runtime_error with MuJoCo's message when it does not load.
inline mjModel* load_mujoco(const std::string& name, const std::string& xml) {
  auto vfs = std::make_unique<mjVFS>();  // ~2 MB: not on the stack
  mj_defaultVFS(vfs.get());
  if (mj_makeEmptyFileVFS(vfs.get(), name.c_str(), static_cast<int>(xml.size())) != 0)
    throw std::runtime_error("MuJoCo: no room for " + name + " in its virtual file system");
  std::memcpy(vfs->filedata[mj_findFileVFS(vfs.get(), name.c_str())], xml.data(), xml.size());
  char error[1000] = "";
  mjModel* m = mj_loadXML(name.c_str(), vfs.get(), error, sizeof error);
  mj_deleteVFS(vfs.get());
  if (m == nullptr) throw std::runtime_error("MuJoCo could not load " + name + ": " + error);
  return m;
}

}  // namespace vsd_bench
