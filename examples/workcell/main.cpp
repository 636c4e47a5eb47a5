// A virtual work cell under supervisory control (the paper, sections 3 and 4): a SOML++ net supervises
// a 3D simulation in which a robot, driven by the same database, moves boxes from an infeed area to a
// target area.
//
// The plant, all of it ordinary database content stepped by the core Scheduler:
//   - vsd::scene + vsd::robotics: the KUKA iiwa14 (URDF) with a JointController in Cartesian mode, run by
//     the "robotics control" task;
//   - vsd::physics: a table and three boxes (collision hulls with rigid bodies); the boxes fall onto the
//     table and settle, and settle again where the robot puts them down;
//   - vsd::collision: a gripper pad on the robot's flange; its contact with a box is the "touch" event;
//   - vsd::scene's SpatialView: the pad is "attached to" the flange and a grasped box "grabbed by" the
//     pad, so both follow the arm without changing their parents.
// The supervisor, examples/workcell/workcell.soml, sees the plant only through properties (events σ:
// `arrived`, `touched`, `resting`) and commands it only through methods (γ: move_to, grasp, release) of
// two small C++ classes below, Robot and Box. Its conditions are re-tested when those properties change.
//
//   vsd_workcell IIWA14.URDF [workcell.soml] [OUTDIR] [--serve [PORT]]
//
// Prints a log of what the supervisor commands and what the plant reports, writes OUTDIR/workcell.csv
// (robot tool tip and box positions over time; with gnuplot also OUTDIR/workcell.png, the heights), and
// ends with check lines; exit code 0 when every box rests on its slot of the target area and every job
// token reached `done`. With --serve (and vsd::web built), the cell runs in real time and is shown in the
// browser (docs/web.md) on 127.0.0.1:PORT (8080 by default; 0 picks a free port) while it runs and after,
// until Ctrl-C or SIGTERM; the page can pause it, edit it and fire the supervisor's transitions.
#include <atomic>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "scene_kit.hpp"
#include "serve_option.hpp"
#include "vsd/collision.hpp"
#include "vsd/physics.hpp"
#include "vsd/robotics.hpp"
#include "vsd/soml.hpp"
#ifdef VSD_WORKCELL_WEB
#include "live_view.hpp"
#endif

#ifndef VSD_WORKCELL_SCRIPT
#define VSD_WORKCELL_SCRIPT "workcell.soml"
#endif

namespace cell {

using vsd::scene::Node3D;

constexpr double table_top = 0.25;    // m, height of the table surface
constexpr double box_size = 0.05;     // m, the boxes are cubes
constexpr double tool_length = 0.05;  // m, from the flange (iiwa_link_ee_kuka) to the pad's contact face
constexpr double rest_speed = 0.005;  // m/s: slower than this ...
constexpr int rest_steps = 20;        // ... for this many steps (0.2 s) is "at rest"

/// A box: a collision hull with a rigid body, plus what the cell's sensors say about it.
class Box : public vsd::scene::Hull {
  VSD_INSTANCE(Box, vsd::scene::Hull)
  VSD_PROPERTY(double, height, box_size)  // m, for the supervisor's approach heights
  VSD_PROPERTY(bool, resting, false)      // σ: lies still (not held, slow for rest_steps steps)

 public:
  int slow_steps = 0;  // the sensor's counter (this program's state, not part of the model)
};

/// The supervisor's interface to the arm: a node whose properties report the arm's state (σ) and whose
/// methods command it (γ). It turns "the pad 12 cm above that box" into a Cartesian target of the
/// JointController, which the "robotics control" task then follows.
class Robot : public vsd::Node {
  VSD_INSTANCE(Robot, vsd::Node)
  VSD_PROPERTY(double, time, 0.0)                            // the plant's clock (s)
  VSD_PROPERTY(bool, arrived, true)                          // σ: the last motion is finished
  VSD_PROPERTY(vsd::SharedRef<vsd::Node>, touched, nullptr)  // σ: the box the pad touches (collision)
  VSD_PROPERTY(vsd::SharedRef<vsd::Node>, holding, nullptr)  // the grasped box

 public:
  // Wiring made by main(): this program's C++ objects, so plain pointers rather than properties.
  vsd::robotics::JointController* controller = nullptr;
  vsd::scene::SpatialView* view = nullptr;
  Node3D* base = nullptr;    // the KinematicTree's base: controller targets are in its frame
  Node3D* flange = nullptr;  // iiwa_link_ee_kuka: the flange, its z axis the tool axis
  Node3D* pad = nullptr;
  std::uint64_t step = 0;               // the sensors' step counter
  std::uint64_t commanded_in_step = 0;  // when the last command came

  /// γ: moves the pad's contact face to @p height above @p where's origin, the tool pointing down.
  void move_to(vsd::SharedRef<vsd::Node> where, double height) {
    auto* n = dynamic_cast<Node3D*>(where.get());
    if (n == nullptr) throw vsd::Error("Robot.move_to: the target is not a 3D node");
    Eigen::Isometry3d f = Eigen::Isometry3d::Identity();
    f.translation() = n->world_frame().translation() + Eigen::Vector3d(0, 0, height + tool_length);
    f.rotate(Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitY()));  // the flange's z axis points down
    command(f);
  }
  /// γ: closes the gripper on @p box: the arm stops where it is and the box becomes part of the robot:
  /// it is grabbed by the pad (the SpatialView carries it along) and loses its rigid body, so physics
  /// treats it as moving scenery instead of integrating it. (vsd::physics has no kinematic bodies yet;
  /// a held dynamic body would drift away from the pad with whatever velocity its last contact gave it.)
  void grasp(vsd::SharedRef<vsd::Node> box) {
    auto* b = dynamic_cast<Box*>(box.get());
    if (b == nullptr) throw vsd::Error("Robot.grasp: not a box");
    if (holding()) throw vsd::Error("Robot.grasp: already holding " + holding()->name());
    command(flange->world_frame());
    view->relate(*b, *pad, vsd::scene::SpatialRelation::GrabbedBy);
    if (auto* body = b->find_extension<vsd::physics::RigidBody>()) b->remove_extension(*body);
    b->set_resting(false);
    b->slow_steps = 0;
    set_holding(box);
  }
  /// γ: opens the gripper: the box gets a rigid body again and is left to physics.
  void release() {
    auto* b = dynamic_cast<Box*>(holding().get());
    if (b == nullptr) throw vsd::Error("Robot.release: holding nothing");
    view->release(*b);
    b->add_extension(b->state().create<vsd::physics::RigidBody>());
    set_holding(nullptr);
  }
  /// The plant's clock as text, for the supervisor's log.
  std::string clock() const {
    char s[32];
    std::snprintf(s, sizeof s, "%.2f", time());
    return s;
  }
  VSD_METHOD(move_to)
  VSD_METHOD(grasp)
  VSD_METHOD(release)
  VSD_METHOD(clock)

 private:
  void command(const Eigen::Isometry3d& flange_in_world) {
    controller->set_target_pose(base->world_frame().inverse() * flange_in_world);
    controller->set_mode(vsd::robotics::ControlMode::Cartesian);
    // `arrived` is the cell's own flag: false from now until the controller reports this target done
    // in a later step.
    set_arrived(false);
    commanded_in_step = step;
  }
};

/// Registers the cell's classes (so the script can name Box and Robot).
class CellModule : public vsd::Module {
 public:
  std::string_view name() const override { return "workcell"; }
  void register_types(vsd::Registry& r) override {
    r.add<Box>();
    r.add<Robot>();
  }
};

using vsd_example::at;
using vsd_example::read_text;

std::string where(const Node3D& n) {
  const Eigen::Vector3d p = n.world_frame().translation();
  char s[80];
  std::snprintf(s, sizeof s, "(%.3f, %.3f, %.3f)", p.x(), p.y(), p.z());
  return s;
}

}  // namespace cell

int main(int argc, char** argv) try {
  using namespace cell;
  using vsd::scene::GeometryKind;
  // Positional arguments, and --serve [PORT] anywhere.
  std::vector<std::string> args(argv + 1, argv + argc);
  int serve_port = -1;  // -1: not serving
  if (std::string error; !vsd_example::take_serve_option(args, serve_port, error)) {
    std::cerr << "vsd_workcell: " << error << '\n';
    return 2;
  }
  if (args.empty() || args.size() > 3) {
    std::cerr << "usage: vsd_workcell IIWA14.URDF [workcell.soml] [OUTDIR] [--serve [PORT]]\n";
    return 2;
  }
#ifndef VSD_WORKCELL_WEB
  if (serve_port >= 0) {
    std::cerr << "vsd_workcell: --serve needs vsd::web, which this build left out (see the configure messages)\n";
    return 2;
  }
#endif
  const std::string urdf_path = args[0];
  const std::string script = args.size() > 1 ? args[1] : VSD_WORKCELL_SCRIPT;
  const std::filesystem::path out = args.size() > 2 ? args[2] : ".";
  std::filesystem::create_directories(out);

  vsd::Environment env;
  env.scheduler().set_base_step(0.01);  // 10 ms: control, physics write-back, collision, sensors
  env.use<vsd::robotics::Module>();     // "robotics control", phase controllers
  env.use<vsd::physics::Module>();      // "physics", phase dynamics (ODE steps 1 ms inside)
  auto& collision = env.use<vsd::collision::Module>(0.01);  // "collision update", phase collision
  env.use<CellModule>();
  auto& soml = env.use<vsd::soml::Module>();  // "soml nets": event-driven, after the periodic tasks
  vsd::SimState& s = env.main_state();

  // --- The robot: the URDF (no meshes needed) with its kinematics and a Cartesian controller.
  vsd::scene::UrdfOptions urdf_options;
  urdf_options.load_meshes = false;
  auto urdf = vsd::scene::load_urdf(s.database(), urdf_path, urdf_options);
  auto& tree = vsd::robotics::build_kinematics(*urdf.scene);
  auto& controller = s.create<vsd::robotics::JointController>();
  urdf.scene->add_extension(controller);
  // The flange frame with z along the tool (the URDF's iiwa_link_ee has its x axis there instead).
  controller.set_tip("iiwa_link_ee_kuka");
  controller.set_cartesian_gain(8.0);        // 1/s: smooth approach, no overshoot
  controller.set_cartesian_tolerance(5e-4);  // m and rad: "arrived"
  Node3D* flange = urdf.scene->find_link("iiwa_link_ee_kuka");
  if (flange == nullptr) throw vsd::Error(urdf_path + ": no link iiwa_link_ee_kuka");

  // --- The cell: one subtree for what collision detection watches (the room and the gripper pad);
  // the room, with the table and the boxes, is one physics world. The robot stays outside both (its
  // URDF collision meshes are not loaded here).
  auto& cell_node = s.create<vsd::scene::Scene>();
  cell_node.set_name("cell");
  s.database().add_child(cell_node);
  auto& room = s.create<vsd::scene::Scene>();
  room.set_name("room");
  cell_node.add_child(room);
  room.add_extension(s.create<vsd::physics::World>());

  vsd_example::SceneKit kit(s, cell_node);
  kit.hull(s.create<vsd::scene::Hull>(), "floor", kit.geometry(GeometryKind::Plane, {}), at(0, 0, 0), room);
  kit.hull(s.create<vsd::scene::Hull>(), "table", kit.geometry(GeometryKind::Box, {0.45, 1.0, 0.04}),
       at(0.525, 0, table_top - 0.02), room);

  // Three boxes dropped onto the infeed area (y < 0); three slots on the target area (y > 0).
  auto& box_shape = kit.geometry(GeometryKind::Box, {box_size, box_size, box_size});
  std::vector<Box*> boxes;
  std::vector<Node3D*> slots;
  for (int i = 0; i < 3; ++i) {
    const double x = 0.42 + 0.1 * i;
    auto& b = s.create<Box>();
    kit.hull(b, "box" + std::to_string(i + 1), box_shape, at(x, -0.3, table_top + 0.1 + 0.05 * i), room);
    b.add_extension(s.create<vsd::physics::RigidBody>());
    boxes.push_back(&b);
    auto& slot = s.create<Node3D>();
    slot.set_name("slot" + std::to_string(i + 1));
    slot.set_frame(at(x, 0.3, table_top));
    cell_node.add_child(slot);
    slots.push_back(&slot);
  }

  // The gripper pad: a thin collision hull "attached to" the flange through the SpatialView (a tool
  // on the flange), its contact face tool_length in front of the flange.
  auto& pad = s.create<vsd::scene::Hull>();
  kit.hull(pad, "gripper pad", kit.geometry(GeometryKind::Box, {0.04, 0.04, 0.01}), Eigen::Isometry3d::Identity(),
       cell_node);
  vsd::scene::SpatialView view(s);

  // --- The robot's start: the tool pointing down above the middle of the table. The IK seed matters:
  // the Cartesian controller has no null-space motion, so the arm keeps the posture it starts in, and
  // one near a joint limit (where the controller clamps) bends the straight-line motions.
  const vsd::robotics::Model& model = tree.model();
  {
    Eigen::Isometry3d home = at(0.52, 0.0, table_top + 0.2 + tool_length);
    home.rotate(Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitY()));
    vsd::robotics::IkOptions o;
    o.time_budget = 1.0;
    vsd::robotics::IkSolver ik(model, model.find_body("iiwa_link_ee_kuka"), o);
    const std::vector<double> seed{0.0, 0.3, 0.0, -1.5, 0.0, 1.2, 0.0};  // elbow up, wrist bent down
    const auto r = ik.solve(urdf.scene->world_frame().inverse() * home, seed);
    if (!r.success) throw vsd::Error("no IK solution for the home pose");
    tree.set_positions(r.q);
  }
  pad.set_world_frame(flange->world_frame() * at(0, 0, tool_length - 0.005));
  view.relate(pad, *flange, vsd::scene::SpatialRelation::AttachedTo);

  // --- The robot's interface node, which the script reaches through `cell.robot`.
  auto& robot = s.create<Robot>();
  robot.set_name("robot");
  s.database().add_child(robot);
  robot.controller = &controller;
  robot.view = &view;
  robot.base = urdf.scene;
  robot.flange = flange;
  robot.pad = &pad;

  // --- Events from collision detection: the pad touching a box sets `robot.touched`.
  vsd::collision::Options copt;
  copt.root = &cell_node;
  copt.pair_filter = [&pad](const vsd::scene::Hull& a, const vsd::scene::Hull& b) {
    return (&a == &pad && dynamic_cast<const Box*>(&b) != nullptr) ||
           (&b == &pad && dynamic_cast<const Box*>(&a) != nullptr);
  };
  auto& contacts = collision.world(s, copt);
  auto other = [&pad](vsd::scene::Hull& a, vsd::scene::Hull& b) -> vsd::scene::Hull& {
    return &a == &pad ? b : a;
  };
  auto c_begin = contacts.on_contact_begin().connect([&](vsd::scene::Hull& a, vsd::scene::Hull& b) {
    vsd::scene::Hull& box = other(a, b);
    std::printf("t=%.2f s  collision: the pad touches %s\n", env.time(), box.name().c_str());
    robot.set_touched(vsd::SharedRef<vsd::Node>(&box));
  });
  auto c_end = contacts.on_contact_end().connect([&](vsd::scene::Hull& a, vsd::scene::Hull& b) {
    vsd::scene::Hull& box = other(a, b);
    std::printf("t=%.2f s  collision: the pad leaves %s\n", env.time(), box.name().c_str());
    if (robot.touched().get() == &box) robot.set_touched(nullptr);
  });

  // --- The cell's sensors: the discrete events σ derived from the continuous state, after control,
  // physics and collision in each step. Only changes reach the net (a setter that stores the same
  // value signals nothing).
  env.scheduler().add_periodic(
      "cell sensors", env.scheduler().base_step(),
      [&](const vsd::StepInfo& info) {
        robot.step = info.step;
        robot.set_time(info.time);
        if (!robot.arrived() && info.step > robot.commanded_in_step && controller.done()) {
          std::printf("t=%.2f s  robot: arrived, pad at %s\n", info.time, where(pad).c_str());
          robot.set_arrived(true);
        }
        if (!controller.fault().empty()) throw vsd::Error("robot controller: " + controller.fault());
        for (Box* b : boxes) {
          const auto* body = b->find_extension<vsd::physics::RigidBody>();  // none while held
          const bool slow = body != nullptr && body->linear_velocity().norm() < rest_speed &&
                            body->angular_velocity().norm() < rest_speed / box_size;
          b->slow_steps = slow ? b->slow_steps + 1 : 0;
          if (b->slow_steps >= rest_steps && !b->resting())
            std::printf("t=%.2f s  physics: %s at rest at %s\n", info.time, b->name().c_str(),
                        where(*b).c_str());
          b->set_resting(b->slow_steps >= rest_steps);
        }
      },
      vsd::Phase::sensors);

  // --- The supervisor.
  vsd::soml::Program& net = soml.load(s, script, read_text(script));
  vsd::Node* supervisor = net.object("cell");
  if (supervisor == nullptr) throw vsd::Error(script + ": no object 'cell' (the supervisor)");
  const char* places[] = {"waiting",  "approaching", "descending", "lifting",   "carrying",
                          "lowering", "settling",    "done",       "robot_free"};
  for (const char* p : places)
    if (net.place(p, supervisor) == nullptr)
      throw vsd::Error(script + ": object 'cell' has no place '" + p + "'");
  supervisor->set("robot", vsd::Value(vsd::SharedRef<vsd::Node>(&robot)));
  for (std::size_t i = 0; i < boxes.size(); ++i)
    supervisor->call("add_job", {vsd::Value(vsd::SharedRef<vsd::Node>(boxes[i])),
                                 vsd::Value(vsd::SharedRef<vsd::Node>(slots[i]))});
  std::printf("t=0.00 s  cell: %zu boxes dropped onto the infeed area, %zu jobs queued\n", boxes.size(),
              boxes.size());

  // --- Run until every job is done (or a time limit), recording the tip and the boxes.
  const auto csv_path = out / "workcell.csv";
  std::ofstream csv(csv_path);
  csv << "time,pad_x,pad_y,pad_z";  // the pad's centre: the robot's tool tip
  for (Box* b : boxes) csv << ',' << b->name() << "_x," << b->name() << "_y," << b->name() << "_z";
  csv << '\n';
  vsd::soml::Place* done = net.place("done", supervisor);
  constexpr double time_limit = 60.0;
  bool nudged = false;
#ifdef VSD_WORKCELL_WEB
  // --serve: the cell in the browser. The server answers between steps (its scheduler tasks); the loop
  // keeps real time and waits while the page has paused it.
  std::unique_ptr<vsd_example::LiveView> live;
  if (serve_port >= 0) live = std::make_unique<vsd_example::LiveView>(env, s, serve_port);
#endif
  while (env.time() < time_limit && done->count() < static_cast<std::int64_t>(boxes.size())) {
#ifdef VSD_WORKCELL_WEB
    if (live && !live->pace(env)) break;
#endif
    // The scenario's disturbance (the plant's, not the supervisor's): while the robot comes down onto
    // box2, an operator slides the box 7 cm aside. The descent then ends without a contact, and the
    // supervisor has to notice and try again.
    const Eigen::Vector3d pad_at = pad.world_frame().translation();
    const Eigen::Vector3d box2_at = boxes[1]->world_frame().translation();
    if (!nudged && !robot.holding() && (pad_at - box2_at).head<2>().norm() < 0.005 &&
        pad_at.z() < box2_at.z() + 0.06) {
      nudged = true;
      boxes[1]->set_world_frame(at(box2_at.x(), box2_at.y() + 0.07, box2_at.z()));
      std::printf("t=%.2f s  operator: slides box2 aside to %s while the robot comes down onto it\n",
                  env.time(), where(*boxes[1]).c_str());
    }
    env.step();
    if (robot.step % 5 == 0) {
      const Eigen::Vector3d t = pad.world_frame().translation();
      csv << env.time() << ',' << t.x() << ',' << t.y() << ',' << t.z();
      for (Box* b : boxes) {
        const Eigen::Vector3d p = b->world_frame().translation();
        csv << ',' << p.x() << ',' << p.y() << ',' << p.z();
      }
      csv << '\n';
    }
  }
  csv.close();
  // A plot of the heights over time, when gnuplot is there: the pad going down and up, each box lifted
  // and put down.
  if (std::system("command -v gnuplot > /dev/null 2>&1") == 0) {
    const auto gp_path = out / "workcell.gp";
    std::ofstream gp(gp_path);
    gp << "set terminal png size 1000,500 noenhanced\nset output '" << (out / "workcell.png").string()
       << "'\n"
       << "set datafile separator ','\nset key autotitle columnhead outside\nset xlabel 'time (s)'\n"
       << "set ylabel 'height (m)'\nset title 'work cell: gripper pad and boxes (SOML++ supervisor)'\nplot ";
    for (std::size_t i = 0; i <= boxes.size(); ++i)
      gp << (i ? ", " : "") << "'" << csv_path.string() << "' using 1:" << 4 + 3 * i << " with lines lw 2";
    gp << '\n';
    gp.close();
    if (std::system(("gnuplot '" + gp_path.string() + "'").c_str()) == 0)
      std::printf("plot: %s\n", (out / "workcell.png").string().c_str());
  }

  // --- Checks.
  std::printf(
      "%.2f s simulated in %llu steps: %llu firings, %llu condition tests (a condition is re-tested only "
      "when a property it read changed)\n",
      env.time(), static_cast<unsigned long long>(env.scheduler().steps()),
      static_cast<unsigned long long>(net.firings()), static_cast<unsigned long long>(net.condition_tests()));
  for (const std::string& e : net.condition_errors()) std::printf("condition error: %s\n", e.c_str());
  int on_target = 0;
  for (std::size_t i = 0; i < boxes.size(); ++i) {
    const Eigen::Vector3d p = boxes[i]->world_frame().translation();
    const Eigen::Vector3d slot = slots[i]->world_frame().translation();
    const bool ok = boxes[i]->resting() && std::abs(p.z() - (table_top + box_size / 2)) < 0.003 &&
                    (p.head<2>() - slot.head<2>()).norm() < 0.01;
    std::printf("  %s at %s, %s %s\n", boxes[i]->name().c_str(), where(*boxes[i]).c_str(),
                ok ? "resting on" : "NOT resting on", slots[i]->name().c_str());
    on_target += ok ? 1 : 0;
  }
  std::string marking;
  for (const char* p : places)
    marking += std::string(marking.empty() ? "" : ", ") + p + " " +
               std::to_string(net.place(p, supervisor)->count());
  std::printf("final marking: %s\n", marking.c_str());
  std::printf("robot tip and box positions in %s\n", csv_path.string().c_str());
  const bool all = on_target == static_cast<int>(boxes.size());
  std::printf("check: %d of %zu boxes on the target area\n", on_target, boxes.size());
  const bool marked = done->count() == static_cast<std::int64_t>(boxes.size()) &&
                      net.place("robot_free", supervisor)->count() == 1;
  std::printf("check: final marking %s\n", marked ? "all jobs done, robot free" : "NOT complete");
#ifdef VSD_WORKCELL_WEB
  if (live) live->linger();
#endif
  return all && marked && net.condition_errors().empty() ? 0 : 1;
} catch (const std::exception& e) {
  std::fprintf(stderr, "vsd_workcell: %s\n", e.what());
  return 1;
}
