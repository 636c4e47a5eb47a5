// vsd-collide (see tool.hpp).
#include "tool.hpp"

#include <algorithm>
#include <cstdio>
#include <ostream>
#include <string>
#include <vector>

#include "vsd/collision/collision_world.hpp"
#include "vsd/collision/module.hpp"
#include "vsd/core/element_index.hpp"
#include "vsd/core/environment.hpp"
#include "vsd/core/error.hpp"
#include "vsd/core/sim_state.hpp"
#include "vsd/scene/hull.hpp"
#include "vsd/scene/link.hpp"
#include "vsd_tool/arguments.hpp"
#include "vsd_tool/models.hpp"
#include "vsd_tool/runner.hpp"
#include "vsd_tool/scene_input.hpp"
#include "vsd_tool/text.hpp"

namespace vsd::tool::vsd_collide {

namespace {

using collision::CollisionWorld;
using collision::Contact;
using collision::DistanceResult;

constexpr std::string_view usage =
    R"(vsd-collide: list the contacts (and distances) between the hulls of a scene
Usage:
  vsd-collide <file> [--package-path DIR]... [--no-meshes] [--visual] [--same-link] [--distances]
      <file> is a URDF (.urdf, .xml) or a scene saved by vsd::io (.json vsd-text, .vsds binary); "-" reads
      standard input (XML is taken as a URDF).
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

const Tool tool{"vsd-collide", usage};

std::string number(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.6g", v + 0.0);  // + 0.0: no "-0"
  return buf;
}

std::string vector_text(const Eigen::Vector3d& v) {
  return "[" + number(v.x()) + ", " + number(v.y()) + ", " + number(v.z()) + "]";
}

const scene::Link* link_of(const scene::Hull& h) {
  for (const vsd::Node* p = h.parent(); p != nullptr; p = p->parent())
    if (const auto* l = p->as<scene::Link>()) return l;
  return nullptr;
}

// "link/hull" when the hull belongs to a link, else the hull's name (or its id).
std::string label(const scene::Hull& h) {
  std::string name = h.name().empty() ? "#" + std::to_string(h.id()) : printable(h.name());
  if (const auto* l = link_of(h)) return printable(l->name()) + "/" + name;
  return name;
}

int body(std::span<const std::string_view> args, std::ostream& out, std::ostream& err) {
  const Arguments cli(args, {repeated("--package-path"), flag("--no-meshes"), flag("--visual"),
                             flag("--same-link"), flag("--distances")});
  cli.expect_positional(1, 1, "one file");
  scene::UrdfOptions urdf;
  for (const std::string_view p : cli.values("--package-path")) urdf.package_paths.emplace_back(std::string(p));
  urdf.load_meshes = !cli.has("--no-meshes");
  const bool visual = cli.has("--visual"), same_link = cli.has("--same-link"), distances = cli.has("--distances");
  Workspace ws;
  ws.env().use<collision::Module>();
  SimState& state = ws.state();
  print_warnings(load_scene_input(state, cli.positional()[0], urdf).warnings, err);

  collision::Options options;
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
    for (const auto& p : world.problems()) err << "warning: left out: " << printable(p) << '\n';
    if (world.problems().empty()) err << "warning: " << printable(e.what()) << '\n';
  }
  // Hulls whose mesh has no vertices (not loaded): skipped, not an error.
  for (const auto& w : world.warnings()) err << "warning: left out: " << printable(w) << '\n';

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
        out << "  at " << vector_text(c.position) << " normal " << vector_text(c.normal) << " depth "
            << number(c.depth) << '\n';
  }
  if (distances) {
    for (std::size_t i = 0; i < hulls.size(); ++i) {
      for (std::size_t j = i + 1; j < hulls.size(); ++j) {
        if (!same_link && link_of(*hulls[i]) != nullptr && link_of(*hulls[i]) == link_of(*hulls[j])) continue;
        try {
          const DistanceResult d = world.distance(*hulls[i], *hulls[j]);
          out << "distance " << label(*hulls[i]) << " - " << label(*hulls[j]) << ": "
              << number(d.distance) << " between " << vector_text(d.point_a) << " and "
              << vector_text(d.point_b) << '\n';
        } catch (const vsd::Error&) {
          // a hull without usable geometry: listed above as left out
        }
      }
    }
  }
  return exit_ok;
}

}  // namespace

int run(std::span<const std::string_view> args, std::ostream& out, std::ostream& err) {
  return tool::run(tool, args, out, err, body);
}

}  // namespace vsd::tool::vsd_collide
