// Files for the scene tests: a temporary directory, writing files, and small meshes in several formats.
#pragma once

#include <unistd.h>

#include <Eigen/Core>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>
#include <string_view>
#include <vector>

namespace vsd::scene::test {

namespace fs = std::filesystem;

inline bool any_contains(const std::vector<std::string>& v, std::string_view a, std::string_view b = {}) {
  for (const auto& s : v)
    if (s.find(a) != std::string::npos && s.find(b) != std::string::npos) return true;
  return false;
}

class TempDir {
 public:
  TempDir()
      : path_(fs::temp_directory_path() /
              ("vsd_scene_test_" + std::to_string(::getpid()) + "_" + std::to_string(counter_++))) {
    fs::create_directories(path_);
  }
  ~TempDir() {
    std::error_code ec;
    fs::remove_all(path_, ec);
  }
  [[nodiscard]] const fs::path& path() const { return path_; }

 private:
  static inline int counter_ = 0;
  fs::path path_;
};

inline void write(const fs::path& p, const std::string& text) {
  fs::create_directories(p.parent_path());
  std::ofstream(p, std::ios::binary) << text;
}

// A unit cube as 12 triangles, corners at 0 and 1.
inline constexpr int cube_faces[12][3] = {{0, 2, 1}, {0, 3, 2}, {4, 5, 6}, {4, 6, 7}, {0, 1, 5}, {0, 5, 4},
                                          {2, 3, 7}, {2, 7, 6}, {1, 2, 6}, {1, 6, 5}, {0, 4, 7}, {0, 7, 3}};
inline Eigen::Vector3d cube_corner(int i) {
  return {double((i & 1) ^ ((i >> 1) & 1)), double((i >> 1) & 1), double(i >> 2)};
}

inline std::string ascii_stl() {
  std::string s = "solid cube\n";
  for (const auto& f : cube_faces) {
    s += " facet normal 0 0 0\n  outer loop\n";
    for (int i : f) {
      const auto c = cube_corner(i);
      s += "   vertex " + std::to_string(c.x()) + " " + std::to_string(c.y()) + " " + std::to_string(c.z()) +
           "\n";
    }
    s += "  endloop\n endfacet\n";
  }
  return s + "endsolid cube\n";
}

inline std::string binary_stl() {
  std::string s(80, ' ');
  s.replace(0, 10, "binary cub");  // must not start with "solid"
  auto put_u32 = [&](std::uint32_t v) { s.append(reinterpret_cast<const char*>(&v), 4); };
  auto put_f = [&](float v) { s.append(reinterpret_cast<const char*>(&v), 4); };
  put_u32(12);
  for (const auto& f : cube_faces) {
    for (int k = 0; k < 3; ++k) put_f(0);
    for (int i : f) {
      const auto c = cube_corner(i);
      put_f(float(c.x()));
      put_f(float(c.y()));
      put_f(float(c.z()));
    }
    s.append(2, '\0');
  }
  return s;
}

// A cube with quads (triangulated on load) and texture coordinates.
inline std::string obj_cube() {
  std::string s = "# cube\n";
  for (int i = 0; i < 8; ++i) {
    const auto c = cube_corner(i);
    s += "v " + std::to_string(c.x()) + " " + std::to_string(c.y()) + " " + std::to_string(c.z()) + "\n";
  }
  s += "f 1 4 3 2\nf 5 6 7 8\nf 1 2 6 5\nf 3 4 8 7\nf 2 3 7 6\nf 1 5 8 4\n";
  return s;
}

}  // namespace vsd::scene::test
