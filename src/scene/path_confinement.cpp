#include "path_confinement.hpp"

#include <algorithm>

namespace vsd::scene::detail {

namespace fs = std::filesystem;

namespace {

// True when @p p (normalised, absolute) is @p root or lies below it, compared component by component
// (so /a/bc is not inside /a/b).
bool inside(const fs::path& p, const fs::path& root) {
  auto r = root.begin();
  auto q = p.begin();
  for (; r != root.end(); ++r, ++q) {
    if (r->empty()) continue;  // a trailing separator of the root
    if (q == p.end() || *q != *r) return false;
  }
  return true;
}

}  // namespace

PathConfinement::PathConfinement(const std::vector<fs::path>& roots, bool allow_outside)
    : allow_outside_(allow_outside) {
  for (const fs::path& r : roots) {
    std::error_code ec;
    fs::path c = fs::canonical(r.empty() ? fs::path(".") : r, ec);
    if (!ec && fs::is_directory(c, ec) && std::find(roots_.begin(), roots_.end(), c) == roots_.end())
      roots_.push_back(std::move(c));
  }
}

PathConfinement::Verdict PathConfinement::admit(const fs::path& path, fs::path& resolved,
                                                std::string& why) const {
  std::error_code ec;
  // weakly_canonical resolves `..` and every symbolic link of the part that exists: a link inside a root
  // that points out of it is outside.
  const fs::path weak = fs::weakly_canonical(fs::absolute(path, ec), ec);
  if (ec) return Verdict::Missing;
  if (!allow_outside_ && std::none_of(roots_.begin(), roots_.end(),
                                      [&](const fs::path& r) { return inside(weak, r); })) {
    why = "'" + weak.string() + "' is outside the folders models may read from (" + roots_text() + ")";
    return Verdict::Refused;
  }
  const fs::file_status st = fs::status(weak, ec);
  if (st.type() == fs::file_type::not_found || (ec && st.type() == fs::file_type::none))
    return Verdict::Missing;
  if (st.type() != fs::file_type::regular) {
    why = "'" + weak.string() + "' is not a regular file";
    return Verdict::Refused;
  }
  resolved = weak;
  return Verdict::Admitted;
}

std::string PathConfinement::roots_text() const {
  if (roots_.empty()) return "none";
  std::string s;
  for (const fs::path& r : roots_) s += (s.empty() ? "" : ", ") + r.string();
  return s;
}

}  // namespace vsd::scene::detail
