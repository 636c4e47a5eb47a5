// Objects falling onto a table and coming to rest, simulated by vsd::physics (ODE) on database nodes.
//
//   vsd_falling_objects [OUTDIR]
//
// Writes OUTDIR/falling_objects.csv (time, object, x, y, z, speed every 10 ms) and, when gnuplot is on
// the PATH, OUTDIR/falling_objects.png (height over time). Then it reads the CSV back and checks that at
// the end every object lies at rest on the table top: exit code 0 when so.
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "vsd/physics.hpp"

namespace {

using vsd::scene::GeometryKind;

constexpr double table_height = 0.75;  // top surface
constexpr double table_x = 0.6;        // half extents of the top
constexpr double table_y = 0.4;

struct Drop {
  std::string name;
  GeometryKind kind;
  Eigen::Vector3d size;  // box
  double radius;
  double length;
  Eigen::Vector3d where;
  double tilt;         // about x, radians
  double rest_height;  // centre height at rest on the table
};

Eigen::Isometry3d pose(const Eigen::Vector3d& p, double tilt = 0.0) {
  Eigen::Isometry3d f = Eigen::Isometry3d::Identity();
  f.translation() = p;
  f.rotate(Eigen::AngleAxisd(tilt, Eigen::Vector3d::UnitX()));
  return f;
}

}  // namespace

int main(int argc, char** argv) {
  const std::filesystem::path out = argc > 1 ? argv[1] : ".";
  std::filesystem::create_directories(out);

  vsd::Environment env;
  auto& physics = env.use<vsd::physics::Module>();
  env.scheduler().set_base_step(0.01);  // the database sees the motion every 10 ms; ODE steps every 1 ms
  vsd::SimState& s = env.main_state();

  auto& room = s.create<vsd::scene::Scene>();
  room.set_name("room");
  s.database().add_child(room);
  room.add_extension(s.create<vsd::physics::World>());

  auto geometry = [&](GeometryKind kind, Eigen::Vector3d size, double radius,
                      double length) -> vsd::scene::Geometry& {
    auto& g = s.create<vsd::scene::Geometry>();
    g.set_kind(kind);
    g.set_size(size);
    g.set_radius(radius);
    g.set_length(length);
    room.edit_geometries().push_back(g);
    return g;
  };
  auto material = [&](std::string name, double friction, double restitution,
                      double density) -> vsd::scene::Material& {
    auto& m = s.create<vsd::scene::Material>();
    m.set_name(std::move(name));
    m.set_friction(friction);
    m.set_restitution(restitution);
    m.set_density(density);
    room.edit_materials().push_back(m);
    return m;
  };
  auto hull = [&](std::string name, vsd::scene::Geometry& g, vsd::scene::Material& m,
                  const Eigen::Isometry3d& f) -> vsd::scene::Hull& {
    auto& h = s.create<vsd::scene::Hull>();
    h.set_name(std::move(name));
    h.set_role(vsd::scene::HullRole::Collision);
    h.set_geometry(&g);
    h.set_material(&m);
    h.set_frame(f);
    room.add_child(h);
    return h;
  };

  // Static scenery: the floor and a table (a top on four legs).
  auto& wood = material("wood", 0.6, 0.1, 700);
  auto& rubber = material("rubber", 0.9, 0.5, 1100);
  auto& steel = material("steel", 0.4, 0.2, 7800);
  hull("floor", geometry(GeometryKind::Plane, {}, 0, 0), wood, pose({0, 0, 0}));
  hull("table top", geometry(GeometryKind::Box, {2 * table_x, 2 * table_y, 0.05}, 0, 0), wood,
       pose({0, 0, table_height - 0.025}));
  auto& leg = geometry(GeometryKind::Box, {0.05, 0.05, table_height - 0.05}, 0, 0);
  for (double x : {-0.55, 0.55})
    for (double y : {-0.35, 0.35}) hull("leg", leg, wood, pose({x, y, (table_height - 0.05) / 2}));

  // What falls: boxes, balls and a can, dropped from different heights, some tilted.
  const std::vector<Drop> drops = {
      {"crate", GeometryKind::Box, {0.2, 0.2, 0.2}, 0, 0, {-0.35, -0.2, 1.3}, 0.4, table_height + 0.1},
      {"brick", GeometryKind::Box, {0.25, 0.12, 0.06}, 0, 0, {0.0, -0.2, 1.5}, 0.0, table_height + 0.03},
      {"dice", GeometryKind::Box, {0.08, 0.08, 0.08}, 0, 0, {0.35, -0.2, 1.7}, 0.7, table_height + 0.04},
      {"ball", GeometryKind::Sphere, {}, 0.08, 0, {-0.3, 0.2, 1.4}, 0.0, table_height + 0.08},
      {"marble", GeometryKind::Sphere, {}, 0.03, 0, {0.05, 0.2, 1.8}, 0.0, table_height + 0.03},
      {"can", GeometryKind::Cylinder, {}, 0.05, 0.15, {0.35, 0.2, 1.2}, 0.0, table_height + 0.075},
  };
  std::vector<vsd::scene::Hull*> objects;
  for (const Drop& d : drops) {
    auto& m = d.kind == GeometryKind::Sphere ? rubber : d.name == "can" ? steel : wood;
    auto& h = hull(d.name, geometry(d.kind, d.size, d.radius, d.length), m, pose(d.where, d.tilt));
    h.add_extension(s.create<vsd::physics::RigidBody>());
    objects.push_back(&h);
  }

  // Simulate 4 s; the CSV gets every object's pose every scheduler step.
  const auto csv_path = out / "falling_objects.csv";
  {
    std::ofstream csv(csv_path);
    csv << "time,object,x,y,z,speed\n";
    csv.precision(9);
    for (int step = 0; step <= 400; ++step) {
      if (step > 0) env.step();
      for (auto* h : objects) {
        const Eigen::Vector3d p = h->world_frame().translation();
        const auto* rb = h->find_extension<vsd::physics::RigidBody>();
        csv << env.time() << ',' << h->name() << ',' << p.x() << ',' << p.y() << ',' << p.z() << ','
            << rb->linear_velocity().norm() << '\n';
      }
    }
    if (!csv) {
      std::cerr << "cannot write " << csv_path << '\n';
      return 1;
    }
  }
  const auto st = physics.simulation().stats();
  std::cout << "simulated " << env.time() << " s: " << st.bodies << " bodies, " << st.geoms << " geoms, "
            << st.steps << " ODE steps; trajectories in " << csv_path.string() << '\n';

  // The plot, when gnuplot is there.
  if (std::system("command -v gnuplot > /dev/null 2>&1") == 0) {
    const auto script = out / "falling_objects.gp";
    std::ofstream gp(script);
    gp << "set terminal png size 900,500\nset output '" << (out / "falling_objects.png").string() << "'\n"
       << "set datafile separator ','\nset key autotitle columnhead\nset xlabel 'time (s)'\nset ylabel "
          "'height (m)'\nset key outside\n"
       << "set title 'objects falling onto a table (vsd::physics)'\nplot ";
    for (std::size_t i = 0; i < drops.size(); ++i)
      // Rows come in time order, one per object in drop order: every n-th row from row i is object i.
      gp << (i ? ", " : "") << "'" << csv_path.string() << "' every " << drops.size() << "::" << i
         << " using 1:5 with lines lw 2 title '" << drops[i].name << "'";
    gp << '\n';
    gp.close();
    if (std::system(("gnuplot '" + script.string() + "'").c_str()) == 0) {
      std::cout << "plot: " << (out / "falling_objects.png").string() << '\n';
    } else {
      std::cout << "gnuplot failed: no plot\n";
    }
  } else {
    std::cout << "gnuplot not found: skipping the plot (the CSV has the data)\n";
  }

  // Check the CSV as written: the last row of every object.
  std::ifstream in(csv_path);
  std::string line;
  std::getline(in, line);  // header
  std::map<std::string, std::vector<double>> last;
  while (std::getline(in, line)) {
    std::stringstream row(line);
    std::string cell;
    std::vector<std::string> cells;
    while (std::getline(row, cell, ',')) cells.push_back(cell);
    if (cells.size() != 6) {
      std::cerr << "malformed CSV row: " << line << '\n';
      return 1;
    }
    last[cells[1]] = {std::stod(cells[0]), std::stod(cells[2]), std::stod(cells[3]), std::stod(cells[4]),
                      std::stod(cells[5])};
  }
  int resting = 0;
  for (const Drop& d : drops) {
    const auto& v = last[d.name];
    const bool on_table = v.size() == 5 && std::abs(v[1]) < table_x && std::abs(v[2]) < table_y &&
                          std::abs(v[3] - d.rest_height) < 0.005;
    const bool at_rest = v.size() == 5 && v[4] < 0.01;
    std::cout << "  " << d.name << ": z " << (v.size() == 5 ? v[3] : NAN)
              << " (at rest on the table: " << d.rest_height << "), speed " << (v.size() == 5 ? v[4] : NAN)
              << (on_table && at_rest ? "" : "  <- NOT") << '\n';
    resting += on_table && at_rest ? 1 : 0;
  }
  std::cout << "check: " << resting << " of " << drops.size() << " objects at rest on the table\n";
  return resting == static_cast<int>(drops.size()) ? 0 : 1;
}
