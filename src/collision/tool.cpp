// The vsd-collide command-line tool (see vsd/collision/tool.hpp).
#include "vsd/collision/tool.hpp"

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <iostream>
#include <string>
#include <vector>

#include "shape_text.hpp"
#include "vsd/collision/collision_world.hpp"
#include "vsd/collision/module.hpp"
#include "vsd/core/element_index.hpp"
#include "vsd/core/environment.hpp"
#include "vsd/core/error.hpp"
#include "vsd/core/sim_state.hpp"
#include "vsd/io/snapshot.hpp"
#include "vsd/scene/hull.hpp"
#include "vsd/scene/link.hpp"
#include "vsd/scene/urdf_loader.hpp"

namespace vsd::collision {

namespace {

constexpr std::string_view usage =
    R"(vsd-collide: list the contacts (and distances) between the hulls of a scene
Usage:
  vsd-collide <file> [--package-path DIR]... [--no-meshes] [--visual] [--same-link] [--distances]
      <file> is a URDF (.urdf, .xml) or a scene saved by vsd::io (.json vsd-text, .vsds binary).
      Prints the hulls in the collision world, then every pair in contact with its contact points
      (position, normal from the first hull to the second, depth).
      --package-path DIR  where package://pkg/... mesh URIs are looked up (DIR/pkg/...); repeatable
      --no-meshes         do not read mesh files (mesh hulls are then left out)
      --visual            visual hulls too (by default only collision hulls)
      --same-link         also pairs of hulls of the same link (skipped by default: they move together)
      --distances         also the distance between every pair of hulls (with the nearest points)
  vsd-collide --help
Exit status: 0 done (warnings or not), 1 the file could not be loaded, 2 a usage error.
)";

const scene::Link* link_of(const scene::Hull& h) {
  for (const vsd::Node* p = h.parent(); p != nullptr; p = p->parent())
    if (const auto* l = p->as<scene::Link>()) return l;
  return nullptr;
}

// "link/hull" when the hull belongs to a link, else the hull's name (or its id).
std::string label(const scene::Hull& h) {
  std::string name = h.name().empty() ? "#" + std::to_string(h.id()) : h.name();
  if (const auto* l = link_of(h)) return l->name() + "/" + name;
  return name;
}

}  // namespace

int run_tool(std::span<const std::string_view> args, std::ostream& out, std::ostream& err) {
  std::string file;
  scene::UrdfOptions urdf;
  bool visual = false, same_link = false, distances = false;
  for (std::size_t i = 0; i < args.size(); ++i) {
    const std::string_view a = args[i];
    if (a == "--help" || a == "-h") {
      out << usage;
      return 0;
    }
    if (a == "--package-path") {
      if (i + 1 >= args.size()) {
        err << "vsd-collide: --package-path needs a directory\n" << usage;
        return 2;
      }
      urdf.package_paths.emplace_back(std::string(args[++i]));
    } else if (a == "--no-meshes") {
      urdf.load_meshes = false;
    } else if (a == "--visual") {
      visual = true;
    } else if (a == "--same-link") {
      same_link = true;
    } else if (a == "--distances") {
      distances = true;
    } else if (a.starts_with("-")) {
      err << "vsd-collide: unknown option '" << a << "'\n" << usage;
      return 2;
    } else if (file.empty()) {
      file = std::string(a);
    } else {
      err << "vsd-collide: more than one file given\n" << usage;
      return 2;
    }
  }
  if (file.empty()) {
    err << "vsd-collide: no file given\n" << usage;
    return 2;
  }
  Environment env;
  env.use<Module>();
  SimState& state = env.main_state();
  std::vector<std::string> warnings;
  try {
    const std::filesystem::path path(file);
    std::string ext = path.extension().string();
    for (auto& ch : ext) ch = static_cast<char>(std::tolower(static_cast<unsigned char>(ch)));
    if (ext == ".urdf" || ext == ".xml") {
      warnings = scene::load_urdf(state.database(), path, urdf).warnings;
    } else {
      warnings = io::load(state, path).warnings;
    }
  } catch (const std::exception& e) {
    err << "vsd-collide: " << e.what() << '\n';
    return 1;
  }
  for (const auto& w : warnings) err << "warning: " << w << '\n';

  Options options;
  options.include_visual = visual;
  if (!same_link)
    options.pair_filter = [](const scene::Hull& a, const scene::Hull& b) {
      const scene::Link* la = link_of(a);
      return la == nullptr || la != link_of(b);
    };
  CollisionWorld world(state, options);
  try {
    world.update();
  } catch (const vsd::Error& e) {
    // Degenerate hulls are left out; everything else was computed. Report and go on.
    for (const auto& p : world.problems()) err << "warning: left out: " << p << '\n';
    if (world.problems().empty()) err << "warning: " << e.what() << '\n';
  }
  // Hulls whose mesh has no vertices (not loaded): skipped, not an error.
  for (const auto& w : world.warnings()) err << "warning: left out: " << w << '\n';

  std::vector<scene::Hull*> hulls;
  state.index().for_each(scene::Hull::static_meta(), true, [&](SimStateInstance& i) {
    auto& h = static_cast<scene::Hull&>(i);
    if (world.contains(h)) hulls.push_back(&h);
  });
  std::sort(hulls.begin(), hulls.end(),
            [](const scene::Hull* a, const scene::Hull* b) { return a->id() < b->id(); });
  out << hulls.size() << " hulls, " << world.shape_count() << " shapes, "
      << world.problems().size() + world.warnings().size() << " left out\n";
  const auto pairs = world.contact_pairs();
  out << pairs.size() << " pairs in contact\n";
  for (const auto& [a, b] : pairs) {
    out << "contact " << label(*a) << " - " << label(*b) << '\n';
    for (const Contact& c : world.contacts())
      if (c.a == a && c.b == b)
        out << "  at " << describe_vector(c.position) << " normal " << describe_vector(c.normal) << " depth "
            << describe_number(c.depth) << '\n';
  }
  if (distances) {
    for (std::size_t i = 0; i < hulls.size(); ++i) {
      for (std::size_t j = i + 1; j < hulls.size(); ++j) {
        if (!same_link && link_of(*hulls[i]) != nullptr && link_of(*hulls[i]) == link_of(*hulls[j])) continue;
        try {
          const DistanceResult d = world.distance(*hulls[i], *hulls[j]);
          out << "distance " << label(*hulls[i]) << " - " << label(*hulls[j]) << ": "
              << describe_number(d.distance) << " between " << describe_vector(d.point_a) << " and "
              << describe_vector(d.point_b) << '\n';
        } catch (const vsd::Error&) {
          // a hull without usable geometry: listed above as left out
        }
      }
    }
  }
  return 0;
}

}  // namespace vsd::collision
