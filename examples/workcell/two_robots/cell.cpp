// The two-robot work cell: the plant (robots, conveyor, parts under physics, sensors, geometric checks)
// and the run loop. See cell.hpp for what it is; docs/workcell.md for the layout.
#include "cell.hpp"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <fstream>
#include <iostream>
#include <limits>
#include <map>
#include <memory>
#include <sstream>
#include <utility>

#include "cycle_bound.hpp"
#include "eight_axis_urdf.hpp"
#include "infeed.hpp"
#include "trace_plot.hpp"
#include "scene_kit.hpp"
#include "vsd/collision.hpp"
#include "vsd/physics.hpp"
#include "vsd/robotics.hpp"
#include "vsd/soml.hpp"

namespace vsd_workcell {

using vsd::scene::Node3D;

namespace {

// This thread's CPU time (POSIX): a step's cost without the time the thread waited for a core.
double thread_cpu_seconds() {
  timespec t{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
}

// --- The layout (m, world frame, z up). Robot A's rail runs along y at x = -0.65, robot B's at x = +0.65,
// each arm facing the other; between them the shared zone, with the hand-over station in its middle.
// The conveyor has two lanes: lane A ends at `pick` (the node `conveyor`), which only A reaches, lane B at
// `pick_b` (`conveyor_b`), which only B reaches; `dest_a` only A reaches, `dest_b` only B (each is more than
// the iiwa14's 0.82 m reach from the other rail). Parts wait at the infeed, between the lanes' starts,
// until Meta Control diverts them (infeed.hpp).
constexpr double rail_x = 0.65;
constexpr double table_top = 0.25;  // every work surface
constexpr double tool_length = 0.05;
const Eigen::Vector2d pick_xy{-0.30, -0.75};
const Eigen::Vector2d pick_b_xy{0.30, -0.75};
const Eigen::Vector2d dest_a_xy{-0.30, 0.75};
const Eigen::Vector2d dest_b_xy{0.30, 0.75};
const Eigen::Vector2d station_xy{0.0, 0.0};
const Eigen::Vector2d gate_a_xy{-0.42, 0.0};
const Eigen::Vector2d gate_b_xy{0.42, 0.0};
// The shared zone: a column over the station, from the floor up.
const Eigen::Vector3d zone_min{-0.15, -0.30, 0.0};
const Eigen::Vector3d zone_max{0.15, 0.30, 2.0};
constexpr double arm_sphere = 0.06;    // radius of the spheres that stand for each arm
constexpr double belt_start = -1.60;   // y where parts come onto a lane (x = its pick x); the infeed's y
constexpr double belt_speed = 0.25;    // m/s
constexpr double belt_gap = 0.10;      // m between queued parts' centres
constexpr double rest_speed = 0.005;   // m/s: slower than this ...
constexpr double rest_time = 0.2;      // ... for this long is "at rest"
constexpr double outfeed_delay = 0.3;  // s a delivered part rests on its destination before it goes
constexpr double arrival_min = 2.0;    // s: the gap between two arrivals is uniform in
constexpr double arrival_spread = 4.0;  // [arrival_min, arrival_min + arrival_spread]

enum Stage : std::int64_t {
  on_belt = 0,
  at_sensor = 1,
  held = 2,
  on_station = 3,
  on_destination = 4,
  delivered = 5
};

using vsd_example::at;
using vsd_example::read_text;

// The run's random numbers (part kinds, arrival gaps): xorshift64*, so a seed gives the same run on every
// standard library.
struct Random {
  std::uint64_t s;
  explicit Random(std::uint64_t seed) : s(seed * 0x9E3779B97F4A7C15ull + 1) {}
  double uniform() {
    s ^= s >> 12;
    s ^= s << 25;
    s ^= s >> 27;
    return static_cast<double>((s * 0x2545F4914F6CDD1Dull) >> 11) * 0x1.0p-53;
  }
};

}  // namespace

/// A part: a collision hull that gets a rigid body whenever it lies somewhere (not on the belt, not held).
class Part : public vsd::scene::Hull {
  VSD_INSTANCE(Part, vsd::scene::Hull)
  VSD_PROPERTY(std::int64_t, kind, 1)  // 1: small (direct to dest_a), 2: large (hand-over to dest_b)
  VSD_PROPERTY(double, height, 0.05)
  VSD_PROPERTY(bool, resting, false)    // σ: lies still
  VSD_PROPERTY(std::int64_t, stage, 0)  // σ: see Stage

 public:
  double belt_y = 0;       // while on the belt
  double slow_for = 0;     // s below rest_speed
  double resting_for = 0;  // s resting on a destination
  bool handed_over = false;  // it rested on the station
  bool slipped = false;    // slipped from a gripper (a fault): resting again is no new arrival or hand-over
};

/// The order board between Meta Control (posts) and Multi Robot Control (takes).
class Orders : public vsd::Node {
  VSD_INSTANCE(Orders, vsd::Node)
  VSD_PROPERTY(vsd::SharedRef<vsd::Node>, part, nullptr)  // σ: the part to pick next
  VSD_PROPERTY(std::int64_t, route, 0)

 public:
  std::ostream* log = nullptr;
  double* clock = nullptr;
  /// γ: posts @p p with @p r (1: A direct, 2: hand-over from A to B, 3: B direct).
  void post(vsd::SharedRef<vsd::Node> p, std::int64_t r) {
    if (part()) throw vsd::Error("orders.post: the board already holds " + part()->name());
    if (log) *log << "t=" << fmt(*clock) << " s  γ " << name() << ".post(" << p->name() << ", route " << r << ")\n";
    set_route(r);
    set_part(p);
  }
  /// γ: takes the order off the board.
  void clear() {
    set_part(nullptr);
    set_route(0);
  }
  static std::string fmt(double t) {
    char s[32];
    std::snprintf(s, sizeof s, "%.2f", t);
    return s;
  }
  VSD_METHOD(post)
  VSD_METHOD(clear)
};

/// The conveyor's end: its frame is the pick position; its sensor reports the part lying there.
class Conveyor : public Node3D {
  VSD_INSTANCE(Conveyor, Node3D)
  VSD_PROPERTY(std::int64_t, arrivals, 0)                      // σ: parts that came to rest at the sensor
  VSD_PROPERTY(vsd::SharedRef<vsd::Node>, last, nullptr)       // the last of them
  VSD_PROPERTY(vsd::SharedRef<vsd::Node>, at_sensor, nullptr)  // σ: the part lying at the sensor now
  VSD_PROPERTY(double, time, 0.0)

 public:
  std::string clock() const { return Orders::fmt(time()); }
  VSD_METHOD(clock)
};

/// The hand-over station: its sensor reports the part resting on it.
class Station : public Node3D {
  VSD_INSTANCE(Station, Node3D)
  VSD_PROPERTY(vsd::SharedRef<vsd::Node>, part, nullptr)  // σ
};

/// The shared zone's presence sensor: which arms are in it, from their geometry (every step).
class ZoneSensor : public Node3D {
  VSD_INSTANCE(ZoneSensor, Node3D)
  VSD_PROPERTY(bool, occupied, false)  // σ: some arm is in the zone
  VSD_PROPERTY(std::string, by, "")    // "robot_a", "robot_b", "robot_a and robot_b" or ""
};

/// The operator's commands (docs/workcell.md, "Two processes"): properties that a user interface writes —
/// in the two-process run the ui owns this node — and the plant reacts to at the start of its sensor step.
class Operator : public vsd::Node {
  VSD_INSTANCE(Operator, vsd::Node)
  VSD_PROPERTY(bool, pause_a, false)                           // robot_a's controller holds while true
  VSD_PROPERTY(bool, pause_b, false)                           // robot_b's
  VSD_PROPERTY(std::int64_t, injections, 0)                    // raised by one per part to inject ...
  VSD_PROPERTY(std::int64_t, inject_kind, 1)                   // ... of this kind (1 or 2)
  VSD_PROPERTY(std::int64_t, moves, 0)                         // raised by one per move of ...
  VSD_PROPERTY(vsd::SharedRef<vsd::Node>, move_part, nullptr)  // ... this part (lying still) ...
  VSD_PROPERTY(double, move_dx, 0.0)                           // ... by (dx, dy), at most 2 cm
  VSD_PROPERTY(double, move_dy, 0.0)
  VSD_PROPERTY(bool, ready, false)  // the ui has joined (the two-process controller waits for it)
  // The ui's digest of its replica's vsd::io binary save; not Savable, so that it is not in the saves
  // it describes.
  VSD_PROPERTY(std::string, replica_digest, "", vsd::Editable | vsd::Distributed)
};

/// What the plant tells the operator: its reply to the last command, and the end of the run.
class Session : public vsd::Node {
  VSD_INSTANCE(Session, vsd::Node)
  VSD_PROPERTY(std::int64_t, replies, 0)
  VSD_PROPERTY(std::string, reply, "")
  VSD_PROPERTY(bool, finished, false)
  VSD_PROPERTY(std::string, verdict, "")  // the controller's comparison of the replica with its state
};

/// A robot's interface to the nets: σ properties, γ methods (as the one-robot cell's Robot, with joint
/// space motions: a Cartesian goal is solved by IK once and cached, the controller plans a trapezoidal
/// joint trajectory to it, rail included).
class Robot : public vsd::Node {
  VSD_INSTANCE(Robot, vsd::Node)
  VSD_PROPERTY(double, time, 0.0)
  VSD_PROPERTY(bool, arrived, true)                          // σ
  VSD_PROPERTY(vsd::SharedRef<vsd::Node>, touched, nullptr)  // σ: collision, pad against a part
  VSD_PROPERTY(vsd::SharedRef<vsd::Node>, holding, nullptr)
  VSD_PROPERTY(bool, faulted, false)  // σ: its hardware adapters do not deliver (--hardware); it holds

 public:
  vsd::robotics::JointController* controller = nullptr;
  vsd::robotics::KinematicTree* tree = nullptr;
  vsd::scene::SpatialView* view = nullptr;
  Node3D* base = nullptr;
  Node3D* pad = nullptr;
  Conveyor* conveyors[2] = {nullptr, nullptr};  // the lanes' stops
  Station* station = nullptr;
  std::ostream* log = nullptr;
  std::uint64_t step = 0;
  std::uint64_t commanded_in_step = 0;
  double moving_time = 0;
  double grasped_at = 0;  // s: the last grasp
  bool paused = false;  // by the operator: the controller holds (mode Idle) until resumed
  std::map<std::array<long, 3>, std::vector<double>> solutions;  // goal in the base frame (µm) -> joints

  /// γ: moves the pad's contact face to @p height above @p where's origin, the tool pointing down.
  void move_to(vsd::SharedRef<vsd::Node> where, double height) {
    auto* n = dynamic_cast<Node3D*>(where.get());
    if (n == nullptr) throw vsd::Error(name() + ".move_to: the target is not a 3D node");
    const Eigen::Vector3d p = n->world_frame().translation() + Eigen::Vector3d(0, 0, height + tool_length);
    if (log)
      *log << "t=" << Orders::fmt(time()) << " s  γ " << name() << ".move_to(" << n->name() << ", "
           << Orders::fmt(height) << ")\n";
    command(solve(p));
  }
  /// γ: closes the gripper on @p part: the arm stops, the part is carried by the pad (no rigid body).
  void grasp(vsd::SharedRef<vsd::Node> part) {
    auto* b = dynamic_cast<Part*>(part.get());
    if (b == nullptr) throw vsd::Error(name() + ".grasp: not a part");
    if (holding()) throw vsd::Error(name() + ".grasp: already holding " + holding()->name());
    if (log) *log << "t=" << Orders::fmt(time()) << " s  γ " << name() << ".grasp(" << b->name() << ")\n";
    command(tree->positions());
    view->relate(*b, *pad, vsd::scene::SpatialRelation::GrabbedBy);
    if (auto* body = b->find_extension<vsd::physics::RigidBody>()) b->remove_extension(*body);
    b->set_resting(false);
    b->slow_for = 0;
    b->set_stage(held);
    b->slipped = false;
    for (Conveyor* c : conveyors)
      if (c->at_sensor().get() == b) c->set_at_sensor(nullptr);
    if (station->part().get() == b) station->set_part(nullptr);
    grasped_at = time();
    set_holding(part);
  }
  /// γ: opens the gripper: the part gets its rigid body back.
  void release() {
    auto* b = dynamic_cast<Part*>(holding().get());
    if (b == nullptr) throw vsd::Error(name() + ".release: holding nothing");
    if (log) *log << "t=" << Orders::fmt(time()) << " s  γ " << name() << ".release(" << b->name() << ")\n";
    view->release(*b);
    b->add_extension(b->state().create<vsd::physics::RigidBody>());
    set_holding(nullptr);
  }
  /// A fault, not a command: the gripper loses its part, which gets its rigid body back and falls.
  void slip() {
    auto* b = dynamic_cast<Part*>(holding().get());
    if (b == nullptr) return;
    view->release(*b);
    b->add_extension(b->state().create<vsd::physics::RigidBody>());
    b->slipped = true;
    set_holding(nullptr);
  }
  std::string clock() const { return Orders::fmt(time()); }
  VSD_METHOD(move_to)
  VSD_METHOD(grasp)
  VSD_METHOD(release)
  VSD_METHOD(clock)

  /// The joints that put the flange at @p flange_at (world) pointing down, from the posture seed.
  std::vector<double> solve(const Eigen::Vector3d& flange_at) {
    const Eigen::Vector3d p = base->world_frame().inverse() * flange_at;
    const std::array<long, 3> key{std::lround(p.x() * 1e6), std::lround(p.y() * 1e6),
                                  std::lround(p.z() * 1e6)};
    if (auto it = solutions.find(key); it != solutions.end()) return it->second;
    Eigen::Isometry3d goal = Eigen::Isometry3d::Identity();
    goal.translation() = p;
    goal.rotate(Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitY()));
    // The rail where the goal is, the arm elbow up with the wrist bent down: every goal is solved from
    // this posture, so consecutive solutions stay in one family and joint-space moves stay short.
    const std::vector<double> seed{p.y(), 0.0, 0.3, 0.0, -1.5, 0.0, 1.2, 0.0};
    // A solver per goal: the tree's model is rebuilt when the tree changes, and solving is rare (cached).
    // A bounded number of restarts rather than a time budget: a run must not depend on how busy the
    // machine is (a budget cut short on a loaded machine would turn "reachable" into "not").
    vsd::robotics::IkOptions options;
    options.time_budget = 60.0;
    options.max_restarts = 50;
    const vsd::robotics::Model& model = tree->model();
    vsd::robotics::IkSolver ik(model, model.find_body("iiwa_link_ee_kuka"), options);
    const auto r = ik.solve(goal, seed);
    if (!r.success) {
      char s[96];
      std::snprintf(s, sizeof s, "(%.3f, %.3f, %.3f)", flange_at.x(), flange_at.y(), flange_at.z());
      throw vsd::Error(name() + ": no IK solution for the flange at " + s);
    }
    solutions.emplace(key, r.q);
    return r.q;
  }
  /// The planned duration (s) of the move between two flange positions (solved as move_to solves them),
  /// with the limits and interpolation the controller plans with.
  vsd::robotics::JointTrajectory plan(const Eigen::Vector3d& from, const Eigen::Vector3d& to) {
    const std::vector<double> a = solve(from), b = solve(to);
    std::vector<double> v, acc;
    for (const vsd::robotics::DofInfo& d : tree->model().layout()) {
      v.push_back(d.velocity_limit > 0 ? d.velocity_limit : controller->default_velocity());
      acc.push_back(d.acceleration_limit > 0 ? d.acceleration_limit : controller->default_acceleration());
    }
    return vsd::robotics::JointTrajectory::plan(controller->interpolation(), a, b, v, acc);
  }
  double move_time(const Eigen::Vector3d& from, const Eigen::Vector3d& to) { return plan(from, to).duration(); }
  /// The time (s, whole steps) from commanding the descent from @p from towards @p to until the pad's
  /// face reaches the height @p contact_z (world): where collision reports the touch and the nets grasp.
  double contact_time(const Eigen::Vector3d& from, const Eigen::Vector3d& to, double contact_z, double step) {
    const vsd::robotics::JointTrajectory t = plan(from, to);
    const vsd::robotics::Model& m = tree->model();
    auto data = m.make_data();
    const int flange = m.find_body("iiwa_link_ee_kuka");
    std::vector<double> q(t.size()), qd(t.size());
    for (int k = 1;; ++k) {
      const double at_time = k * step;
      t.sample(at_time, q.data(), qd.data());
      m.forward(q, data);
      const double z = (base->world_frame() * m.pose(data, flange).translation).z() - tool_length;
      if (z <= contact_z + 1e-6 || at_time >= t.duration()) return at_time;
    }
  }
  bool reaches(const Eigen::Vector3d& flange_at) {
    try {
      solve(flange_at);
      return true;
    } catch (const vsd::Error&) {
      return false;
    }
  }

 private:
  void command(const std::vector<double>& q) {
    controller->set_target(q);
    controller->set_mode(paused ? vsd::robotics::ControlMode::Idle : vsd::robotics::ControlMode::Position);
    set_arrived(false);
    commanded_in_step = step;
  }
};

namespace {

class CellModule : public vsd::Module {
 public:
  std::string_view name() const override { return "two-robot workcell"; }
  void register_types(vsd::Registry& r) override {
    r.add<Part>();
    r.add<Orders>();
    r.add<Conveyor>();
    r.add<Station>();
    r.add<ZoneSensor>();
    r.add<Robot>();
    r.add<Operator>();
    r.add<Session>();
    r.add<Infeed>();
  }
};

// True when a sphere of radius r at c touches the box [lo, hi].
bool sphere_in_box(const Eigen::Vector3d& c, double r, const Eigen::Vector3d& lo, const Eigen::Vector3d& hi) {
  const Eigen::Vector3d nearest = c.cwiseMax(lo).cwiseMin(hi);
  return (c - nearest).norm() <= r;
}

}  // namespace

void add_cell_modules(vsd::Environment& env, double collision_period) {
  env.use<vsd::robotics::Module>();
  env.use<vsd::physics::Module>();
  env.use<vsd::collision::Module>(collision_period);
  env.use<CellModule>();
  env.use<vsd::soml::Module>();
}

struct Cell::promise_type {
  CellReport report;
  std::exception_ptr error;
  Cell get_return_object() { return Cell(std::coroutine_handle<promise_type>::from_promise(*this)); }
  std::suspend_never initial_suspend() noexcept { return {}; }  // building runs in build_cell's call
  std::suspend_always final_suspend() noexcept { return {}; }   // the Cell destroys the frame
  void return_value(CellReport r) { report = std::move(r); }
  void unhandled_exception() { error = std::current_exception(); }  // rethrown by Cell::rethrow
};

Cell::Cell(Cell&& other) noexcept : h_(std::exchange(other.h_, {})) {}

Cell::~Cell() {
  if (h_) h_.destroy();  // the frame's locals (the cell) go in reverse order, as a function's would
}

void Cell::rethrow() {
  if (h_ && h_.promise().error) std::rethrow_exception(std::exchange(h_.promise().error, nullptr));
}

CellReport Cell::run() {
  if (!h_ || h_.done()) throw vsd::Error("Cell::run: the cell has run already");
  h_.resume();
  rethrow();
  return std::move(h_.promise().report);
}

namespace {

void check_options(const CellOptions& o) {
  if (o.parts < 1) throw vsd::Error("parts must be at least 1");
  if (!(o.step > 0) || !(o.physics_step > 0) || o.physics_step > o.step)
    throw vsd::Error("the physics step must be positive and at most the step");
  if (!o.png.empty()) check_writable(o.png);  // before the run, not after it
}

// The whole run as one coroutine: it builds the cell, suspends (build_cell returns), and the loop runs
// when Cell::run resumes it. Its locals — the cell's state, which the scheduler task, the collision
// listeners and the nets' callbacks refer to — live in the coroutine's frame as long as the Cell.
Cell cell_coroutine(vsd::Environment& env, const CellOptions& o) {
  using vsd::scene::GeometryKind;
  std::ostream* tl = o.timeline;
  const double time_limit = o.time_limit > 0 ? o.time_limit : 60.0 * o.parts;

  env.scheduler().set_base_step(o.step);
  add_cell_modules(env, o.step);
  auto& collision = env.use<vsd::collision::Module>(o.step);
  auto& soml = env.use<vsd::soml::Module>();
  vsd::SimState& s = env.main_state();

  // --- The cell: what collision detection watches (the room, the pads, the arm spheres); the room is the
  // physics world (surfaces and parts). The robots' own links stay outside both.
  auto& cell_node = s.create<vsd::scene::Scene>();
  cell_node.set_name("cell");
  s.database().add_child(cell_node);
  auto& room = s.create<vsd::scene::Scene>();
  room.set_name("room");
  cell_node.add_child(room);
  auto& world = s.create<vsd::physics::World>();
  world.set_step(o.physics_step);
  room.add_extension(world);
  auto& outfeed = s.create<vsd::Node>();  // delivered parts, out of both worlds
  outfeed.set_name("outfeed");
  s.database().add_child(outfeed);

  vsd_example::SceneKit kit(s, cell_node);
  auto marker = [&](Node3D& n, std::string name, const Eigen::Vector2d& xy) -> Node3D& {
    n.set_name(std::move(name));
    n.set_frame(at(xy.x(), xy.y(), table_top));
    cell_node.add_child(n);
    return n;
  };
  // The surfaces: the conveyor's belt, the station, the two destinations (static hulls: no rigid body).
  auto surface = [&](std::string name, const Eigen::Vector2d& xy, Eigen::Vector2d size) {
    kit.hull(s.create<vsd::scene::Hull>(), std::move(name),
             kit.geometry(GeometryKind::Box, {size.x(), size.y(), 0.04}),
             at(xy.x(), xy.y(), table_top - 0.02), room);
  };
  for (const Eigen::Vector2d& pick : {pick_xy, pick_b_xy})
    surface(pick.x() < 0 ? "belt" : "belt_b", {pick.x(), (belt_start + pick.y()) / 2},
            {0.16, pick.y() - belt_start + 0.2});
  surface("station table", station_xy, {0.16, 0.16});
  surface("dest_a table", dest_a_xy, {0.2, 0.2});
  surface("dest_b table", dest_b_xy, {0.2, 0.2});
  auto& conveyor = static_cast<Conveyor&>(marker(s.create<Conveyor>(), "conveyor", pick_xy));
  auto& conveyor_b = static_cast<Conveyor&>(marker(s.create<Conveyor>(), "conveyor_b", pick_b_xy));
  auto& infeed = static_cast<Infeed&>(marker(s.create<Infeed>(), "infeed", {0.0, belt_start}));
  auto& station = static_cast<Station&>(marker(s.create<Station>(), "station", station_xy));
  auto& zone = static_cast<ZoneSensor&>(marker(s.create<ZoneSensor>(), "zone", station_xy));
  Node3D& dest_a = marker(s.create<Node3D>(), "dest_a", dest_a_xy);
  Node3D& dest_b = marker(s.create<Node3D>(), "dest_b", dest_b_xy);
  Node3D& gate_a = marker(s.create<Node3D>(), "gate_a", gate_a_xy);
  Node3D& gate_b = marker(s.create<Node3D>(), "gate_b", gate_b_xy);
  auto& orders = s.create<Orders>();  // robot A's jobs
  orders.set_name("orders");
  s.database().add_child(orders);
  auto& orders_b = s.create<Orders>();  // robot B's jobs from lane B
  orders_b.set_name("orders_b");
  s.database().add_child(orders_b);
  auto& op = s.create<Operator>();
  op.set_name("operator");
  s.database().add_child(op);
  auto& session = s.create<Session>();
  session.set_name("session");
  s.database().add_child(session);
  double now = 0;
  for (Orders* b : {&orders, &orders_b}) {
    b->log = tl;
    b->clock = &now;
  }
  infeed.log = tl;
  infeed.clock = &now;
  vsd::scene::SpatialView view(s);

  // --- The robots: the 8-axis URDF twice, each base on its rail, facing the zone.
  const auto urdf = vsd_example::eight_axis_urdf(read_text(o.urdf), "0 1 0", -1.2, 1.2);
  if (!urdf) throw vsd::Error(o.urdf + ": no fixed joint 'world_iiwa_joint' to turn into the linear axis");
  vsd::scene::UrdfOptions urdf_options;
  urdf_options.load_meshes = false;
  Robot* robots[2] = {nullptr, nullptr};
  std::vector<vsd::scene::Hull*> spheres[2];
  // --hardware (hardware.hpp): each robot's joints bound to its adapters once it stands at its gate.
  std::unique_ptr<CellHardware> hardware;
  if (o.hardware.enabled) hardware = std::make_unique<CellHardware>(o.hardware);
  check_faults(o.faults, o.hardware);
  FaultMonitor faults(o.faults);
  faults.timeline = tl;
  const char* arm_links[] = {"iiwa_link_4", "iiwa_link_6"};  // elbow and wrist; the pad stands for the hand
  auto& pad_shape = kit.geometry(GeometryKind::Box, {0.04, 0.04, 0.01});
  auto& sphere_shape = kit.geometry(GeometryKind::Sphere, {}, arm_sphere);
  for (int i = 0; i < 2; ++i) {
    const std::string tag = i == 0 ? "a" : "b";
    auto rep = vsd::scene::load_urdf_text(s.database(), *urdf, "arm_" + tag, ".", urdf_options);
    rep.scene->set_name("arm_" + tag);
    Eigen::Isometry3d base = at(i == 0 ? -rail_x : rail_x, 0, 0);
    if (i == 1) base.rotate(Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitZ()));
    rep.scene->set_frame(base);
    auto& tree = vsd::robotics::build_kinematics(*rep.scene);
    auto& controller = s.create<vsd::robotics::JointController>();
    rep.scene->add_extension(controller);
    controller.set_default_velocity(1.0);
    Node3D* flange = rep.scene->find_link("iiwa_link_ee_kuka");
    if (flange == nullptr) throw vsd::Error(o.urdf + ": no link iiwa_link_ee_kuka");
    auto& robot = s.create<Robot>();
    robot.set_name("robot_" + tag);
    s.database().add_child(robot);
    robot.controller = &controller;
    robot.tree = &tree;
    robot.view = &view;
    robot.base = rep.scene;
    robot.conveyors[0] = &conveyor;
    robot.conveyors[1] = &conveyor_b;
    robot.station = &station;
    robot.log = tl;
    // Start at the gate, above the work height.
    const Node3D& gate = i == 0 ? gate_a : gate_b;
    tree.set_positions(
        robot.solve(gate.world_frame().translation() + Eigen::Vector3d(0, 0, 0.12 + tool_length)));
    auto& pad = s.create<vsd::scene::Hull>();
    kit.hull(pad, "pad_" + tag, pad_shape, flange->world_frame() * at(0, 0, tool_length - 0.005), cell_node);
    view.relate(pad, *flange, vsd::scene::SpatialRelation::AttachedTo);
    robot.pad = &pad;
    if (hardware) hardware->attach(i, *rep.scene, tree);
    spheres[i].push_back(&pad);
    for (const char* link : arm_links) {
      Node3D* l = rep.scene->find_link(link);
      if (l == nullptr) throw vsd::Error(o.urdf + ": no link " + link);
      auto& sp = s.create<vsd::scene::Hull>();
      kit.hull(sp, std::string(link) + "_" + tag, sphere_shape, l->world_frame(), cell_node);
      view.relate(sp, *l, vsd::scene::SpatialRelation::AttachedTo);
      spheres[i].push_back(&sp);
    }
    robots[i] = &robot;
  }
  if (hardware) hardware->connect(o.step);  // both robots Running before the first step
  // Who reaches what (the reason for the hand-over): checked by IK, not assumed.
  for (int i = 0; i < 2; ++i) {
    std::string line;
    const Node3D* points[] = {&conveyor, &conveyor_b, &station, &dest_a, &dest_b};
    for (const Node3D* n : points) {
      const bool r =
          robots[i]->reaches(n->world_frame().translation() + Eigen::Vector3d(0, 0, 0.1 + tool_length));
      line += (line.empty() ? "" : ", ") + n->name() + (r ? " yes" : " no");
    }
    if (tl) *tl << "reach of " << robots[i]->name() << ": " << line << '\n';
  }

  // --- The analytic bound's motion times (cycle_bound.hpp; docs/workcell.md, "The analytic bound"): the
  // moves of each job as the nets command them, planned as the controllers plan them, between the pad
  // heights the nets use (above = 0.12 m travel height, drop = 0.004 m; a small part on route 1, a large
  // one on routes 2 and 3). The descent is counted to the contact (the part's top), where it stops.
  CycleParameters cycle;
  {
    constexpr double above = 0.12, drop = 0.004;
    auto pt = [](const Node3D& n, double height) {
      return Eigen::Vector3d(n.world_frame().translation() + Eigen::Vector3d(0, 0, height + tool_length));
    };
    // A sequence of pad positions: the sum of each move's cycle (move_cycle: the step rounding, the
    // step in which the nets see `arrived`).
    auto path = [&](Robot& r, std::initializer_list<Eigen::Vector3d> stops) {
      double t = 0;
      const Eigen::Vector3d* prev = nullptr;
      for (const Eigen::Vector3d& x : stops) {
        if (prev != nullptr) t += move_cycle(r.move_time(*prev, x), o.step);
        prev = &x;
      }
      return t;
    };
    const double small = 0.04, large = 0.06;
    // The part's centre is at half its height above the surface: its top at `h`, the travel height at
    // h + above (move_to(part, h / 2 + above)), the same as move_to(surface, h + above).
    Robot& a = *robots[0];
    Robot& b = *robots[1];
    // The descent: commanded 1 cm into the part, it ends where the pad touches the part's top.
    auto descent = [&](Robot& r, const Node3D& n, double h) {
      return r.contact_time(pt(n, h + above), pt(n, h - 0.01), table_top + h, o.step);
    };
    cycle.direct_a = path(a, {pt(dest_a, small + above), pt(conveyor, small + above)}) + descent(a, conveyor, small) +
                     path(a, {pt(conveyor, small), pt(conveyor, small + above), pt(dest_a, small + above),
                              pt(dest_a, small + drop), pt(dest_a, small + above)});
    cycle.direct_b = path(b, {pt(dest_b, large + above), pt(conveyor_b, large + above)}) +
                     descent(b, conveyor_b, large) +
                     path(b, {pt(conveyor_b, large), pt(conveyor_b, large + above), pt(dest_b, large + above),
                              pt(dest_b, large + drop), pt(dest_b, large + above)});
    // A's half of a hand-over, from its gate (where the last one ended) back to it; the zone is held from
    // the gate into the station and back to the gate.
    cycle.zone_a = path(a, {pt(gate_a, large + above), pt(station, large + above), pt(station, large + drop),
                            pt(station, large + above), pt(gate_a, above)});
    cycle.give_a = path(a, {pt(gate_a, above), pt(conveyor, large + above)}) + descent(a, conveyor, large) +
                   path(a, {pt(conveyor, large), pt(conveyor, large + above), pt(gate_a, large + above)}) +
                   cycle.zone_a;
    // B's half: from above dest_b into the station (holding the zone), out to its gate, to dest_b.
    cycle.zone_b = path(b, {pt(dest_b, large + above), pt(station, large + above)}) + descent(b, station, large) +
                   path(b, {pt(station, large), pt(station, large + above), pt(gate_b, large + above)});
    cycle.take_b = cycle.zone_b + path(b, {pt(gate_b, large + above), pt(dest_b, large + above),
                                           pt(dest_b, large + drop), pt(dest_b, large + above)});
    cycle.arrival_gap = arrival_min + arrival_spread / 2;  // the mean gap
  }

  // --- Collision: pad against part contacts (σ touched); distances between the arms on request.
  auto is_pad = [&](const vsd::scene::Hull& h) { return &h == robots[0]->pad || &h == robots[1]->pad; };
  vsd::collision::Options copt;
  copt.root = &cell_node;
  copt.pair_filter = [&](const vsd::scene::Hull& a, const vsd::scene::Hull& b) {
    return (is_pad(a) && dynamic_cast<const Part*>(&b) != nullptr) ||
           (is_pad(b) && dynamic_cast<const Part*>(&a) != nullptr);
  };
  auto& contacts = collision.world(s, copt);
  auto robot_of = [&](const vsd::scene::Hull& pad) { return &pad == robots[0]->pad ? robots[0] : robots[1]; };
  auto c_begin = contacts.on_contact_begin().connect([&](vsd::scene::Hull& a, vsd::scene::Hull& b) {
    vsd::scene::Hull& pad = is_pad(a) ? a : b;
    vsd::scene::Hull& part = is_pad(a) ? b : a;
    Robot* r = robot_of(pad);
    if (tl)
      *tl << "t=" << Orders::fmt(now) << " s  σ collision: " << r->name() << "'s pad touches " << part.name()
          << '\n';
    r->set_touched(vsd::SharedRef<vsd::Node>(&part));
  });
  auto c_end = contacts.on_contact_end().connect([&](vsd::scene::Hull& a, vsd::scene::Hull& b) {
    vsd::scene::Hull& pad = is_pad(a) ? a : b;
    vsd::scene::Hull& part = is_pad(a) ? b : a;
    Robot* r = robot_of(pad);
    if (r->touched().get() == &part) r->set_touched(nullptr);
  });

  // --- Parts: two kinds, arriving on the belt at random gaps.
  Random random(o.seed);
  vsd::scene::Geometry* part_shape[2] = {&kit.geometry(GeometryKind::Box, {0.04, 0.04, 0.04}),
                                         &kit.geometry(GeometryKind::Box, {0.06, 0.06, 0.06})};
  // The conveyor's lanes: each a belt of parts, front first (no rigid body: the belt carries them).
  struct Lane {
    Conveyor* stop;
    Eigen::Vector2d pick;
    std::vector<Part*> belt;
  };
  Lane lanes[2] = {{&conveyor, pick_xy, {}}, {&conveyor_b, pick_b_xy, {}}};
  auto room_at_start = [](const Lane& l) { return l.belt.empty() || l.belt.back()->belt_y > belt_start + belt_gap; };
  Part* at_infeed = nullptr;  // waiting for Meta Control's divert
  std::vector<Part*> placed;  // with a rigid body, somewhere in the room
  int spawned = 0;         // parts made (named part1, part2, ...)
  int random_spawned = 0;  // of them, the seed's arrivals (o.parts in all)
  std::vector<std::int64_t> injected;  // kinds the operator asked for, not on the belt yet
  int parts_injected = 0;
  std::int64_t injections_seen = 0, moves_seen = 0;
  auto parts_wanted = [&] { return o.parts + parts_injected; };
  bool in_zone[2] = {false, false};  // this step's zone sensor
  double next_arrival = 0.5;
  CellReport report;
  int handled_by_route[3] = {0, 0, 0};  // routes 1, 2 (hand-over) and 3
  bool zone_sensor_down = false;          // a fault: the zone's presence sensor delivers nothing
  vsd::soml::Place* zone_free = nullptr;  // Multi Robot Control's zone.free (the fault monitor watches it)

  // --- The sensors, after control, physics and collision in each step: only changes reach the nets.
  env.scheduler().add_periodic(
      "cell sensors", o.step,
      [&](const vsd::StepInfo& info) {
        now = info.time;
        conveyor.set_time(info.time);
        conveyor_b.set_time(info.time);
        const double dt = o.step;
        // The operator's commands: the plant's reaction to the properties of `operator` (written by a ui,
        // through vsd::dist in the two-process run). Each is answered on `session`.
        auto reply = [&](const std::string& text) {
          if (tl) *tl << "t=" << Orders::fmt(now) << " s  operator: " << text << '\n';
          session.set_reply(text);
          session.set_replies(session.replies() + 1);
        };
        for (int i = 0; i < 2; ++i) {
          Robot* r = robots[i];
          const bool pause = i == 0 ? op.pause_a() : op.pause_b();
          if (pause == r->paused) continue;
          r->paused = pause;
          if (pause)
            r->controller->set_mode(vsd::robotics::ControlMode::Idle);  // holds where it is
          else if (!r->controller->done())
            r->controller->set_mode(vsd::robotics::ControlMode::Position);  // replans from here
          reply((pause ? "paused " : "resumed ") + r->name());
        }
        for (; injections_seen < op.injections(); ++injections_seen) {
          if (op.inject_kind() != 1 && op.inject_kind() != 2) {
            reply("refused to inject a part of kind " + std::to_string(op.inject_kind()) + ": kinds are 1 and 2");
            continue;
          }
          injected.push_back(op.inject_kind());
          ++parts_injected;
          reply("injects a part of kind " + std::to_string(op.inject_kind()));
        }
        if (moves_seen < op.moves()) {
          moves_seen = op.moves();
          auto* p = dynamic_cast<Part*>(op.move_part().get());
          const Eigen::Vector3d d(op.move_dx(), op.move_dy(), 0);
          if (p == nullptr) {
            reply("refused a move: move_part is not a part");
          } else if (!(d.norm() <= 0.02)) {
            reply("refused to move " + p->name() + ": at most 2 cm at a time");
          } else if (!p->resting() || p->find_extension<vsd::physics::RigidBody>() == nullptr) {
            reply("refused to move " + p->name() + ": only a part lying still can be moved");
          } else {
            Eigen::Isometry3d f = p->frame();
            f.translation() += d;
            p->set_frame(f);  // physics teleports its body (velocities kept: zero, it lies still)
            reply("moved " + p->name() + " by (" + Orders::fmt(d.x()) + ", " + Orders::fmt(d.y()) + ") m");
          }
        }
        for (Robot* r : robots) {
          r->step = info.step;
          r->set_time(info.time);
          if (!r->controller->done() && !r->paused && report.parts_handled < parts_wanted())
            r->moving_time += dt;  // until the last part
          if (!r->arrived() && info.step > r->commanded_in_step && r->controller->done()) {
            r->set_arrived(true);
            if (tl) *tl << "t=" << Orders::fmt(now) << " s  σ " << r->name() << " arrived\n";
          }
          if (!r->controller->fault().empty())
            throw vsd::Error(r->name() + " controller: " + r->controller->fault());
        }
        // The adapters' state (σ Robot.faulted) and the injected faults (faults.hpp): on and off by time,
        // the cell's reaction seen through the views, the report lines written by the monitor.
        if (hardware || !o.faults.empty()) {
          FaultView views[2];
          for (int i = 0; i < 2; ++i) {
            Robot* r = robots[i];
            views[i].name = r->name();
            if (hardware) {
              const auto& b = hardware->binding(i);
              views[i].adapter_fault = b.fault();
              views[i].delivering = b.status() == vsd::robotics::BindingStatus::Running;
              const bool faulted = b.status() == vsd::robotics::BindingStatus::Fault;
              if (faulted != r->faulted() && tl)
                *tl << "t=" << Orders::fmt(now) << " s  σ " << r->name()
                    << (faulted ? " faulted: " + b.fault() : std::string(" delivers again")) << '\n';
              r->set_faulted(faulted);
            }
            if (auto* part = r->holding().get()) views[i].holding = part->name();
            views[i].grasped_at = r->grasped_at;
            const Eigen::Vector3d pad = r->pad->world_frame().translation();
            for (int k = 0; k < 3; ++k) views[i].pad[k] = pad[k];
          }
          const FaultActions act = faults.step(now, views, zone_free != nullptr ? static_cast<int>(zone_free->count()) : 1);
          for (int i = 0; i < 2; ++i)
            if (hardware) hardware->silence(i, act.silent[i]);
          zone_sensor_down = act.zone_sensor_down;
          if (act.slip >= 0) robots[act.slip]->slip();
        }
        // The zone: an arm is in it when one of its spheres touches the zone's box. Both at once is a
        // violation, counted from this geometry, whatever the nets' markings say.
        for (int i = 0; i < 2; ++i) {
          in_zone[i] = false;
          for (const vsd::scene::Hull* h : spheres[i])
            in_zone[i] =
                in_zone[i] || sphere_in_box(h->world_frame().translation(), arm_sphere, zone_min, zone_max);
        }
        // A zone sensor that is down reads as occupied (fail-safe): no net lets a robot in.
        const std::string by = zone_sensor_down            ? "unknown (the sensor is down)"
                               : in_zone[0] && in_zone[1] ? "robot_a and robot_b"
                               : in_zone[0]             ? "robot_a"
                               : in_zone[1]             ? "robot_b"
                                                        : "";
        if (by != zone.by() && tl)
          *tl << "t=" << Orders::fmt(now) << " s  σ zone occupied by " << (by.empty() ? "nobody" : by)
              << '\n';
        zone.set_by(by);
        zone.set_occupied(!by.empty());
        if (in_zone[0] && in_zone[1]) {
          ++report.zone_violations;
          if (tl) *tl << "t=" << Orders::fmt(now) << " s  ZONE VIOLATION: both arms in the shared zone\n";
        }
        // The infeed: the part Meta Control diverted goes onto its lane's start when that has room; a new
        // part comes to the infeed when its gap has passed and the infeed is empty.
        if (at_infeed != nullptr && infeed.chosen != 0 && room_at_start(lanes[infeed.chosen - 1])) {
          Lane& l = lanes[infeed.chosen - 1];
          at_infeed->belt_y = belt_start;
          at_infeed->set_frame(at(l.pick.x(), belt_start, table_top + at_infeed->height() / 2));
          l.belt.push_back(at_infeed);
          at_infeed = nullptr;
          infeed.chosen = 0;
        }
        if (at_infeed == nullptr && (!injected.empty() || (random_spawned < o.parts && info.time >= next_arrival))) {
          auto& p = s.create<Part>();
          const bool inject = !injected.empty();
          // --kinds 1 draws too, so that the arrival times are the seed's either way.
          const std::int64_t drawn = inject ? injected.front() : random.uniform() < 0.5 ? 1 : 2;
          const auto kind = inject || o.kinds == 2 ? drawn : 1;
          if (inject)
            injected.erase(injected.begin());
          else
            ++random_spawned;
          p.set_kind(kind);
          p.set_height(kind == 1 ? 0.04 : 0.06);
          kit.hull(p, "part" + std::to_string(++spawned), *part_shape[kind - 1],
                   at(0.0, belt_start, table_top + p.height() / 2), room);
          at_infeed = &p;
          infeed.set_waiting(vsd::SharedRef<vsd::Node>(&p));
          if (!inject) next_arrival = info.time + arrival_min + arrival_spread * random.uniform();
          if (tl)
            *tl << "t=" << Orders::fmt(now) << " s  conveyor: " << p.name() << " (kind " << kind
                << ") comes in\n";
        }
        for (Lane& l : lanes) {
          // The stop is free when no part lies there (one that slipped from a gripper back onto it included).
          const auto at_stop = [&](Part* p) {
            const double d = (p->world_frame().translation().head<2>() - l.pick).norm();
            return (p->stage() == on_belt && d < 0.05) || (p->slipped && d < 0.1);
          };
          const bool spot_free = !l.stop->at_sensor() && std::none_of(placed.begin(), placed.end(), at_stop);
          for (std::size_t k = 0; k < l.belt.size(); ++k) {
            const double limit =
                k == 0 ? (spot_free ? l.pick.y() : l.pick.y() - belt_gap) : l.belt[k - 1]->belt_y - belt_gap;
            l.belt[k]->belt_y = std::min(limit, l.belt[k]->belt_y + belt_speed * dt);
            l.belt[k]->set_frame(at(l.pick.x(), l.belt[k]->belt_y, table_top + l.belt[k]->height() / 2));
          }
          if (!l.belt.empty() && spot_free && l.belt.front()->belt_y >= l.pick.y() - 1e-9) {
            Part* p = l.belt.front();  // at the stop: physics takes it over until the sensor sees it at rest
            l.belt.erase(l.belt.begin());
            p->add_extension(s.create<vsd::physics::RigidBody>());
            placed.push_back(p);
          }
          const auto queued = static_cast<std::int64_t>(
              l.belt.size() + (l.stop->at_sensor() ? 1 : 0) + std::count_if(placed.begin(), placed.end(), at_stop));
          if (&l == &lanes[0] && queued != infeed.queued_a()) infeed.set_queued_a(queued);
          if (&l == &lanes[1] && queued != infeed.queued_b()) infeed.set_queued_b(queued);
        }
        // Rest: where a part lies still decides what the sensors report. The parts with a rigid body are
        // those in the room that neither the belt carries nor a robot holds.
        placed.clear();
        for (std::size_t k = 0; k < room.children().size(); ++k)
          if (auto* p = dynamic_cast<Part*>(room.children()[k]);
              p && p->find_extension<vsd::physics::RigidBody>())
            placed.push_back(p);
        for (Part* p : placed) {
          const auto* body = p->find_extension<vsd::physics::RigidBody>();
          const Eigen::Vector3d x = p->world_frame().translation();
          if (x.z() < table_top - 0.05) throw vsd::Error(p->name() + " fell off at t=" + Orders::fmt(now));
          const bool slow = body->linear_velocity().norm() < rest_speed &&
                            body->angular_velocity().norm() < rest_speed / 0.02;
          p->slow_for = slow ? p->slow_for + dt : 0;
          const bool rest = p->slow_for >= rest_time;
          if (rest && !p->resting()) {
            p->set_resting(true);
            const Eigen::Vector2d xy = x.head<2>();
            const char* where = nullptr;
            const Lane* lane = (xy - pick_xy).norm() < 0.05     ? &lanes[0]
                               : (xy - pick_b_xy).norm() < 0.05 ? &lanes[1]
                                                                : nullptr;
            if (lane != nullptr) {
              where = lane == &lanes[0] ? "the conveyor's sensor" : "the conveyor's sensor on lane B";
              p->set_stage(at_sensor);
              lane->stop->set_at_sensor(vsd::SharedRef<vsd::Node>(p));
              if (!p->slipped) {  // a part that slipped back is no new arrival (its job goes on)
                lane->stop->set_last(vsd::SharedRef<vsd::Node>(p));
                lane->stop->set_arrivals(lane->stop->arrivals() + 1);
                ++report.parts_arrived;
              }
            } else if ((xy - station_xy).norm() < 0.06) {
              where = "the station";
              p->set_stage(on_station);
              p->handed_over = true;
              station.set_part(vsd::SharedRef<vsd::Node>(p));
              if (!p->slipped) ++report.handovers;
            } else if ((xy - (p->kind() == 1 ? dest_a_xy : dest_b_xy)).norm() < 0.06) {
              where = p->kind() == 1 ? "dest_a" : "dest_b";
              p->set_stage(on_destination);
            } else {
              throw vsd::Error(p->name() + " came to rest at a wrong place (" + Orders::fmt(xy.x()) + ", " +
                               Orders::fmt(xy.y()) + ") at t=" + Orders::fmt(now));
            }
            if (tl) *tl << "t=" << Orders::fmt(now) << " s  σ " << p->name() << " rests on " << where << '\n';
          } else if (!rest) {
            p->set_resting(false);
          }
          if (p->stage() == on_destination && (p->resting_for += dt) >= outfeed_delay) {
            // The outfeed takes it away: out of the physics and collision worlds.
            p->remove_extension(*p->find_extension<vsd::physics::RigidBody>());
            outfeed.add_child(*p);
            p->set_stage(delivered);
            ++report.parts_handled;
            ++handled_by_route[p->kind() == 1 ? 0 : p->handed_over ? 1 : 2];
            if (tl)
              *tl << "t=" << Orders::fmt(now) << " s  part handled: " << p->name() << " ("
                  << report.parts_handled << " of " << parts_wanted() << ")\n";
          }
        }
      },
      vsd::Phase::sensors);

  // --- The nets.
  vsd::soml::RunOptions run;
  run.seed = o.seed;
  std::ostringstream discard;
  run.out = tl != nullptr ? tl : &discard;
  vsd::soml::Program& mrc = soml.load(s, o.robot_script, read_text(o.robot_script), run);
  vsd::soml::Program& meta = soml.load(s, o.meta_script, read_text(o.meta_script), run);
  if (vsd::Node* z = mrc.object("zone"))
    z->visit([&](vsd::Node& c) {
      if (auto* pl = dynamic_cast<vsd::soml::Place*>(&c); pl != nullptr && pl->name() == "free") zone_free = pl;
    });
  for (vsd::soml::Program* p : {&mrc, &meta}) {
    if (tl == nullptr) continue;
    // "token: multi_robot_control a.fetch: a.idle -1, a.approaching +1": net, transition, black tokens moved
    // (places named from the script object down), and where an object token went.
    const std::string root = p->root().path() + "/";
    auto local = [root](const vsd::Node& n) {
      std::string id = n.path();
      if (id.rfind(root, 0) == 0) id.erase(0, root.size());
      std::replace(id.begin(), id.end(), '/', '.');
      return id;
    };
    p->on_firing([tl, &now, local, net = p->root().name()](const vsd::soml::Firing& f) {
      *tl << "t=" << Orders::fmt(now) << " s  token: " << net << ' ' << local(*f.transition);
      const char* sep = ": ";
      for (const auto& m : f.taken) *tl << std::exchange(sep, ", ") << local(*m.place) << " -" << m.count;
      for (const auto& m : f.given) *tl << std::exchange(sep, ", ") << local(*m.place) << " +" << m.count;
      if (f.from != nullptr || f.to != nullptr)
        *tl << std::exchange(sep, ", ") << "job " << (f.from ? local(*f.from) : std::string("(new)"))
            << " -> " << (f.to ? local(*f.to) : std::string("(out)"));
      *tl << '\n';
    });
  }

  co_await std::suspend_always{};  // built: build_cell returns; Cell::run resumes here

  // --- The run, with the geometric checks every step.
  std::ofstream csv;
  if (!o.csv.empty()) {
    csv.open(o.csv);
    if (!csv) throw vsd::Error("cannot write " + o.csv);
    csv << "time,a_x,a_y,a_z,b_x,b_y,b_z,a_in_zone,b_in_zone,arm_distance,parts_handled\n";
  }
  report.min_arm_distance = std::numeric_limits<double>::infinity();
  double quiet_since = 0;
  std::map<Part*, double> belt_y_before;  // to tell a moving belt from a full, stopped one
  // Until every part is handled, then until the robots are back at rest (their nets idle) — at most 20 s.
  double drained_at = -1;
  std::vector<double> step_times;  // s of wall time per env.step()
  TracePlot plot;
  if (o.on_built) o.on_built(env);
  for (;;) {
    if (report.parts_handled == parts_wanted()) {
      if (drained_at < 0) drained_at = env.time();
      const bool still = robots[0]->controller->done() && robots[1]->controller->done() &&
                         robots[0]->arrived() && robots[1]->arrived() && !mrc.enabled_any() &&
                         !meta.enabled_any();
      if (still || env.time() - drained_at > 20.0) break;
    }
    if (env.time() >= time_limit) {
      report.timed_out = true;
      break;
    }
    belt_y_before.clear();
    for (const Lane& l : lanes)
      for (Part* p : l.belt) belt_y_before[p] = p->belt_y;
    if (o.before_step && !o.before_step(env)) {
      report.interrupted = true;
      break;
    }
    const double cpu_start = o.step_cpu ? thread_cpu_seconds() : 0.0;
    const auto step_start = std::chrono::steady_clock::now();
    env.step();
    step_times.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - step_start).count());
    if (o.step_cpu) report.step_cpu_total += thread_cpu_seconds() - cpu_start;
    double d = std::numeric_limits<double>::infinity();
    for (const auto* ha : spheres[0])
      for (const auto* hb : spheres[1]) d = std::min(d, contacts.distance(*ha, *hb).distance);
    report.min_arm_distance = std::min(report.min_arm_distance, d);
    if (!o.png.empty()) {
      TraceSample sample;
      sample.t = env.time();
      const Eigen::Vector3d pa = robots[0]->pad->world_frame().translation();
      const Eigen::Vector3d pb = robots[1]->pad->world_frame().translation();
      std::copy(pa.data(), pa.data() + 3, sample.a);
      std::copy(pb.data(), pb.data() + 3, sample.b);
      sample.a_in_zone = in_zone[0];
      sample.b_in_zone = in_zone[1];
      plot.add(sample);
    }
    if (csv.is_open()) {
      const Eigen::Vector3d pa = robots[0]->pad->world_frame().translation();
      const Eigen::Vector3d pb = robots[1]->pad->world_frame().translation();
      csv << env.time() << ',' << pa.x() << ',' << pa.y() << ',' << pa.z() << ',' << pb.x() << ',' << pb.y()
          << ',' << pb.z() << ',' << in_zone[0] << ',' << in_zone[1] << ',' << d << ','
          << report.parts_handled << '\n';
    }
    // Deadlock: parts left, yet nothing moves and no transition is enabled, for 10 s.
    const bool belt_moves = std::any_of(lanes, lanes + 2, [&](const Lane& l) {
      return std::any_of(l.belt.begin(), l.belt.end(), [&](Part* p) { return p->belt_y != belt_y_before[p]; });
    });
    const bool more_to_come =
        (random_spawned < o.parts || !injected.empty()) && at_infeed == nullptr;
    // A robot the operator paused is waiting for the operator, not deadlocked.
    const bool moving = report.parts_handled == parts_wanted() || belt_moves || more_to_come ||
                        robots[0]->paused || robots[1]->paused || robots[0]->faulted() ||
                        robots[1]->faulted() || zone_sensor_down ||
                        !robots[0]->controller->done() || !robots[1]->controller->done() ||
                        std::any_of(placed.begin(), placed.end(),
                                    [](Part* p) { return !p->resting() || p->stage() == on_destination; });
    if (moving || mrc.enabled_any() || meta.enabled_any()) {
      quiet_since = env.time();
    } else if (env.time() - quiet_since > 10.0) {
      report.deadlocks = 1;
      if (tl) *tl << "t=" << Orders::fmt(now) << " s  DEADLOCK: parts left, nothing moves, nothing enabled\n";
      break;
    }
  }

  if (!step_times.empty()) {
    const auto quantile = [&](double q) {
      const auto k = static_cast<std::ptrdiff_t>(q * static_cast<double>(step_times.size() - 1));
      std::nth_element(step_times.begin(), step_times.begin() + k, step_times.end());
      return step_times[static_cast<std::size_t>(k)];
    };
    for (double t : step_times) report.step_total += t;
    report.step_p50 = quantile(0.5);
    report.step_p99 = quantile(0.99);
  }
  report.time = drained_at >= 0 ? drained_at : env.time();
  report.parts_injected = parts_injected;
  report.steps = env.scheduler().steps();
  report.parts_per_hour = report.time > 0 ? report.parts_handled * 3600.0 / report.time : 0;
  for (int i = 0; i < 2; ++i)
    report.utilisation[i] = report.time > 0 ? robots[i]->moving_time / report.time : 0;
  if (report.parts_handled > 0) {
    const double n = report.parts_handled;
    cycle.share_direct_a = handled_by_route[0] / n;
    cycle.share_handover = handled_by_route[1] / n;
    cycle.share_direct_b = 1.0 - cycle.share_direct_a - cycle.share_handover;
  }
  report.cycle = cycle;
  report.bound = cycle_bound(cycle);
  report.firings = mrc.firings() + meta.firings();
  report.condition_tests = mrc.condition_tests() + meta.condition_tests();
  for (vsd::soml::Program* p : {&mrc, &meta})
    for (const std::string& e : p->condition_errors()) report.condition_errors.push_back(e);
  std::string marking;
  for (const char* obj : {"a", "b", "zone", "station"}) {
    vsd::Node* n = mrc.object(obj);
    n->visit([&](vsd::Node& c) {
      if (auto* pl = dynamic_cast<vsd::soml::Place*>(&c); pl != nullptr && pl->count() > 0)
        marking += (marking.empty() ? "" : ", ") + std::string(obj) + "." + pl->name() + " " +
                   std::to_string(pl->count());
    });
  }
  report.final_marking = marking;
  if (!o.png.empty()) {
    try {
      plot.write(o.png);
    } catch (const vsd::Error& e) {
      report.png_error = e.what();  // the run's figures are not lost with the picture
    }
  }
  faults.finish(env.time());
  report.faults = faults.records();
  report.fault_lines = faults.lines();
  for (int i = 0; hardware && i < 2; ++i) report.hardware.push_back(robots[i]->name() + ": " + hardware->summary(i));
  co_return report;
}

}  // namespace

Cell build_cell(vsd::Environment& env, const CellOptions& o) {
  check_options(o);
  Cell cell = cell_coroutine(env, o);
  cell.rethrow();
  return cell;
}

CellReport run_cell(const CellOptions& o) {
  check_options(o);
  vsd::Environment env;
  // on_finished runs before the Environment goes, however the run ends.
  bool completed = false;
  struct Finish {
    const CellOptions& o;
    vsd::Environment& env;
    const bool& completed;
    ~Finish() {
      if (o.on_finished) o.on_finished(env, completed);
    }
  } finish{o, env, completed};
  Cell cell = cell_coroutine(env, o);
  cell.rethrow();
  CellReport report = cell.run();
  completed = true;
  return report;
}

void define_net_classes(vsd::Environment& env, const CellOptions& o) {
  auto& soml = env.use<vsd::soml::Module>();
  vsd::SimState& s = env.create_state("net classes");
  auto add = [&](vsd::Node& parent, vsd::Node& n, const char* name) -> vsd::Node& {
    n.set_name(name);
    parent.add_child(n);
    return n;
  };
  vsd::Node& cell = add(s.database(), s.create<vsd::scene::Scene>(), "cell");
  add(cell, s.create<Conveyor>(), "conveyor");
  add(cell, s.create<Conveyor>(), "conveyor_b");
  add(cell, s.create<Infeed>(), "infeed");
  add(cell, s.create<Station>(), "station");
  add(cell, s.create<ZoneSensor>(), "zone");
  for (const char* n : {"dest_a", "dest_b", "gate_a", "gate_b"}) add(cell, s.create<Node3D>(), n);
  add(s.database(), s.create<Orders>(), "orders");
  add(s.database(), s.create<Orders>(), "orders_b");
  add(s.database(), s.create<Robot>(), "robot_a");
  add(s.database(), s.create<Robot>(), "robot_b");
  static std::ostringstream discard;  // the programs never run here: nothing is printed
  vsd::soml::RunOptions run;
  run.out = &discard;
  for (const std::string* f : {&o.robot_script, &o.meta_script}) soml.load(s, *f, read_text(*f), run);
}

void print_summary(std::ostream& out, const CellReport& r) {
  char line[160];
  auto put = [&](const char* fmt, auto... v) {
    std::snprintf(line, sizeof line, fmt, v...);
    out << line << '\n';
  };
  put("simulated: %.1f s in %llu steps", r.time, static_cast<unsigned long long>(r.steps));
  put("parts arrived: %d", r.parts_arrived);
  put("parts handled: %d", r.parts_handled);
  if (r.parts_injected > 0) put("parts injected by the operator: %d", r.parts_injected);
  put("hand-overs: %d", r.handovers);
  put("parts/hour: %.1f", r.parts_per_hour);
  put("parts/hour bound: %.1f (%s; cycle %.2f s per part: robot A %.2f s, robot B %.2f s, zone %.2f s, "
      "arrivals %.2f s)",
      r.bound.parts_per_hour, r.bound.limit.c_str(), r.bound.cycle, r.bound.load_a, r.bound.load_b,
      r.bound.load_zone, r.cycle.arrival_gap);
  put("job cycles: A direct %.2f s, B direct %.2f s, hand-over A %.2f s (zone %.2f s), B %.2f s (zone %.2f s)",
      r.cycle.direct_a, r.cycle.direct_b, r.cycle.give_a, r.cycle.zone_a, r.cycle.take_b, r.cycle.zone_b);
  put("parts/hour of the bound: %.0f %%", r.bound.parts_per_hour > 0 ? 100 * r.parts_per_hour / r.bound.parts_per_hour : 0.0);
  put("zone violations: %d", r.zone_violations);
  put("deadlocks: %d", r.deadlocks);
  put("min arm distance: %.3f m", r.min_arm_distance);
  put("utilisation: robot A %.0f %%, robot B %.0f %%", 100 * r.utilisation[0], 100 * r.utilisation[1]);
  put("firings: %llu", static_cast<unsigned long long>(r.firings));
  put("condition tests: %llu", static_cast<unsigned long long>(r.condition_tests));
  out << "final marking (multi robot control): " << r.final_marking << '\n';
  for (const std::string& e : r.condition_errors) out << "condition error: " << e << '\n';
  put("step time: p50 %.3f ms, p99 %.3f ms (wall, both robots and both nets)", 1e3 * r.step_p50, 1e3 * r.step_p99);
  if (!r.png_error.empty()) out << "png: " << r.png_error << '\n';
  for (const std::string& h : r.hardware) out << "hardware " << h << '\n';
  if (!r.faults.empty()) {
    int recovered = 0;
    for (const FaultRecord& f : r.faults) recovered += f.recovered >= 0 ? 1 : 0;
    put("faults injected: %d, recovered: %d", static_cast<int>(r.faults.size()), recovered);
    for (const std::string& l : r.fault_lines) out << l << '\n';
  }
  if (r.timed_out) out << "stopped: time limit reached\n";
  if (r.interrupted) out << "stopped: interrupted\n";
}

}  // namespace vsd_workcell

namespace vsd_workcell {

void parse_options(const std::vector<std::string>& args, CellOptions& o) {
  auto value = [&](std::size_t& i) -> const std::string& {
    if (i + 1 >= args.size()) throw vsd::Error(args[i] + ": needs a value");
    return args[++i];
  };
  auto number = [&](std::size_t& i, double lo, double hi) {
    const std::string& flag = args[i];
    const std::string& v = value(i);
    std::size_t used = 0;
    double x = 0;
    try {
      x = std::stod(v, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (used != v.size() || v.empty() || !(x >= lo && x <= hi)) {
      std::ostringstream m;
      m << flag << ": '" << v << "' is not a number in [" << lo << ", " << hi << "]";
      throw vsd::Error(m.str());
    }
    return x;
  };
  auto whole = [&](std::size_t& i, double lo, double hi) {
    const std::string& flag = args[i];
    const std::string& v = value(i);
    if (v.empty() || v.find_first_not_of("0123456789") != std::string::npos || v.size() > 15 ||
        std::stod(v) < lo || std::stod(v) > hi) {
      std::ostringstream m;
      m << flag << ": '" << v << "' is not a whole number in [" << lo << ", " << hi << "]";
      throw vsd::Error(m.str());
    }
    return std::stoll(v);
  };
  for (std::size_t i = 0; i < args.size(); ++i) {
    const std::string& a = args[i];
    if (take_hardware_option(args, i, o.hardware)) continue;
    if (a == "--seed")
      o.seed = static_cast<std::uint64_t>(whole(i, 0, 1e15));
    else if (a == "--parts")
      o.parts = static_cast<int>(whole(i, 1, 1e6));
    else if (a == "--step")
      o.step = number(i, 1e-4, 0.05);
    else if (a == "--physics-step")
      o.physics_step = number(i, 1e-4, 0.05);
    else if (a == "--time-limit")
      o.time_limit = number(i, 1, 1e9);
    else if (a == "--kinds")
      o.kinds = static_cast<int>(whole(i, 1, 2));
    else if (a == "--csv")
      o.csv = value(i);
    else if (a == "--png")
      o.png = value(i);
    else if (a == "--urdf")
      o.urdf = value(i);
    else if (a == "--meta")
      o.meta_script = value(i);
    else if (a == "--robots")
      o.robot_script = value(i);
    else if (a == "--fault")
      o.faults.push_back(parse_fault(value(i)));
    else
      throw vsd::Error("unknown option '" + a + "'");
  }
  if (o.physics_step > o.step) throw vsd::Error("--physics-step must not exceed --step");
  for (const std::string& e : {o.hardware.arm[0], o.hardware.arm[1], o.hardware.simulator})
    if (!e.empty() && !o.hardware.enabled)
      throw vsd::Error("--arm-a, --arm-b and --simulator go with --hardware");
  check_faults(o.faults, o.hardware);
}

}  // namespace vsd_workcell
