// The paper's 8-axis robot — a KUKA iiwa14 on a linear axis — following a Cartesian path, first in
// simulation (the database is the robot), then, by configuration only, against hardware adapters: the arm
// over UDP (FRI-like protocol) to the robot simulator process, the linear axis on a simulated fieldbus drive.
//
//   vsd_eight_axis IIWA14.URDF ROBOT_SIMULATOR [OUTDIR]
//
// IIWA14.URDF is ../shared/data/urdf/iiwa14.urdf (the copy in tests/scene/data); its fixed world joint is
// made a prismatic axis here. Prints the tracking error of both runs, writes OUTDIR/eight_axis.csv and,
// when gnuplot is on the PATH, OUTDIR/eight_axis.png; exit code 0 when both errors stay bounded.
#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <sstream>
#include <string>
#include <vector>

#include "eight_axis_urdf.hpp"
#include "simulator_process.hpp"
#include "vsd/robotics.hpp"

namespace {

constexpr double duration = 4.0;  // s
constexpr double dt = 0.01;       // control period, s
constexpr double bound = 0.02;    // m: the tracking error the check accepts

std::string read_text(const std::string& path) {
  std::ifstream in(path);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

// The path: 0.6 m along the rail direction with a smooth start and stop, and a 5 cm vertical wave.
Eigen::Isometry3d path(const Eigen::Isometry3d& start, double t) {
  const double s = std::clamp(t / duration, 0.0, 1.0);
  const double smooth = s * s * (3 - 2 * s);
  Eigen::Isometry3d p = start;
  p.translation() += Eigen::Vector3d(0.6 * 0.6 * smooth, 0.6 * 0.8 * smooth, 0.05 * std::sin(2 * M_PI * s));
  return p;
}

struct Run {
  std::vector<double> time, error;
  double max_error = 0, rms = 0;
  std::string status;
};

Run follow(const std::string& urdf_text, const std::string& config) {
  vsd::Environment env;
  env.use<vsd::robotics::Module>();
  env.scheduler().set_base_step(dt);
  vsd::scene::UrdfOptions o;
  o.load_meshes = false;
  auto rep = vsd::scene::load_urdf_text(env.main_state().database(), urdf_text, "iiwa14 on a rail", ".", o);
  auto& tree = vsd::robotics::build_kinematics(*rep.scene);
  auto& ctrl = env.main_state().create<vsd::robotics::JointController>();
  auto& hw = env.main_state().create<vsd::robotics::HardwareBinding>();
  hw.set_config(config);
  rep.scene->add_extension(ctrl);
  rep.scene->add_extension(hw);
  const vsd::robotics::Model& model = tree.model();
  const int tip = model.find_body("iiwa_link_ee");
  // The start: axis at 0, the arm bent (layout: the rail first, then iiwa_joint_1 ... 7).
  tree.set_positions(std::vector<double>{0.0, 0.0, 0.5, 0.0, -1.2, 0.0, 0.6, 0.0});
  vsd::robotics::Model::Data d = model.make_data();
  model.forward(tree.positions(), d);
  const Eigen::Isometry3d start = model.pose(d, tip).isometry();
  ctrl.set_tip("iiwa_link_ee");
  ctrl.set_cartesian_gain(40.0);  // 1/s: the lag behind a moving target is about speed / gain
  ctrl.set_target_pose(start);
  ctrl.set_mode(vsd::robotics::ControlMode::Cartesian);
  // Connect (the binding holds until every adapter delivers), then follow the path.
  for (int k = 0; k < 100 && hw.holding(); ++k) env.step();
  Run r;
  for (int k = 1; k * dt <= duration + 1e-9; ++k) {
    const double t = k * dt;
    ctrl.set_target_pose(path(start, t));
    env.step();
    model.forward(tree.positions(), d);  // the database: measured when bound to hardware
    const double e = (model.pose(d, tip).translation - path(start, t).translation()).norm();
    r.time.push_back(t);
    r.error.push_back(e);
    r.max_error = std::max(r.max_error, e);
    r.rms += e * e;
  }
  r.rms = std::sqrt(r.rms / static_cast<double>(r.error.size()));
  r.status = std::string(vsd::meta_type<vsd::robotics::BindingStatus>().enum_name(
                 static_cast<std::int64_t>(hw.status()))) +
             (hw.fault().empty() ? "" : ": " + hw.fault());
  return r;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 3) {
    std::cerr << "usage: vsd_eight_axis IIWA14.URDF ROBOT_SIMULATOR [OUTDIR]\n";
    return 2;
  }
  const std::filesystem::path out = argc > 3 ? argv[3] : ".";
  std::filesystem::create_directories(out);
  const auto urdf = vsd_example::eight_axis_urdf(read_text(argv[1]));
  if (!urdf) {
    std::cerr << argv[1] << ": no fixed joint 'world_iiwa_joint' to turn into the linear axis\n";
    return 1;
  }
  const std::string& xml = *urdf;

  try {
    const Run sim = follow(xml, "sim");
    std::cout << "simulation: max tracking error " << sim.max_error * 1000 << " mm, rms " << sim.rms * 1000
              << " mm (" << sim.status << ")\n";
    // The same program against the adapters: the simulator answers with a 20 ms first-order lag.
    vsd_example::SimulatorProcess robot(argv[2],
                                        {"--dof", "7", "--lag", "0.02", "--initial", "0,0.5,0,-1.2,0,0.6,0"});
    std::string joints;
    for (int i = 1; i <= 7; ++i)
      joints += (i > 1 ? "," : "") + std::string("iiwa_joint_") + std::to_string(i);
    const std::string config =
        "udp://127.0.0.1:" + std::to_string(robot.port()) + "?joints=" + joints +
        "&timeout=0.5;fieldbus://?joints=world_iiwa_joint&velocity=1&lower=-2&upper=3";
    std::cout << "hardware config: " << config << '\n';
    const Run hw = follow(xml, config);
    std::cout << "udp + fieldbus: max tracking error " << hw.max_error * 1000 << " mm, rms " << hw.rms * 1000
              << " mm (" << hw.status << ")\n";

    const auto csv_path = out / "eight_axis.csv";
    {
      std::ofstream csv(csv_path);
      csv << "time,simulation_error_mm,adapters_error_mm\n";
      for (std::size_t i = 0; i < sim.time.size() && i < hw.time.size(); ++i)
        csv << sim.time[i] << ',' << sim.error[i] * 1000 << ',' << hw.error[i] * 1000 << '\n';
    }
    std::cout << "tracking errors in " << csv_path.string() << '\n';
    if (std::system("command -v gnuplot > /dev/null 2>&1") == 0) {
      const auto script = out / "eight_axis.gp";
      std::ofstream gp(script);
      gp << "set terminal png size 900,500\nset output '" << (out / "eight_axis.png").string() << "'\n"
         << "set datafile separator ','\nset xlabel 'time (s)'\nset ylabel 'tracking error (mm)'\n"
         << "set title '8-axis robot (iiwa14 on a linear axis) following a Cartesian path'\n"
         << "plot '" << csv_path.string() << "' using 1:2 with lines lw 2 title 'simulation', '"
         << csv_path.string() << "' using 1:3 with lines lw 2 title 'UDP + fieldbus adapters'\n";
      gp.close();
      std::cout << (std::system(("gnuplot '" + script.string() + "'").c_str()) == 0
                        ? "plot: " + (out / "eight_axis.png").string()
                        : std::string("gnuplot failed: no plot"))
                << '\n';
    } else {
      std::cout << "gnuplot not found: skipping the plot (the CSV has the data)\n";
    }
    const bool ok = sim.max_error < bound && hw.max_error < bound && hw.status == "Running";
    std::cout << "check: tracking error " << (ok ? "bounded" : "NOT bounded") << " (below " << bound * 1000
              << " mm) in simulation and against the robot simulator\n";
    return ok ? 0 : 1;
  } catch (const std::exception& e) {
    std::cerr << "eight_axis: " << e.what() << '\n';
    return 1;
  }
}
