// Which files a model may make vsd::scene read. A URDF names mesh files, and a mesh file may pull in more
// (an OBJ's mtllib); left alone, `../../etc/passwd`, `/proc/self/environ` or a symbolic link out of the
// folder would be read and parsed. A PathConfinement admits a path only when, with `..` and symbolic
// links resolved, it lies inside one of its root folders and is a regular file (no device, FIFO or
// directory); the caller may lift the folder rule, never the regular-file rule.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

namespace vsd::scene::detail {

class PathConfinement {
 public:
  /// @param roots the folders files may come from (those that do not exist are dropped)
  /// @param allow_outside true: any folder (only the regular-file rule holds)
  PathConfinement(const std::vector<std::filesystem::path>& roots, bool allow_outside);

  enum class Verdict { Admitted, Missing, Refused };
  /// @brief Whether @p path may be read. Admitted: @p resolved is its canonical path. Refused: @p why
  /// says why (outside the roots, or not a regular file). Missing: it does not exist. The folder rule is
  /// decided before existence, so a refusal says nothing about whether a file outside exists.
  Verdict admit(const std::filesystem::path& path, std::filesystem::path& resolved, std::string& why) const;

  [[nodiscard]] bool allows_outside() const noexcept { return allow_outside_; }
  /// "/a, /b" (for messages).
  [[nodiscard]] std::string roots_text() const;

 private:
  std::vector<std::filesystem::path> roots_;  // canonical
  bool allow_outside_;
};

}  // namespace vsd::scene::detail
