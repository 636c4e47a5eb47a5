// vsd demo: the active simulation database at work.
//
//  1. declares C++ classes with properties and methods, and defines a class at run time;
//  2. builds a small work cell and listens to what happens in it;
//  3. plugs a module into the step loop (a conveyor "kinematics" algorithm);
//  4. records the changes as a transaction, sends it as bytes to a second SimState, and undoes it.
#include <cstdio>
#include <string>
#include <vsd/vsd.hpp>

#if VSD_DEMO_WITH_IO
#include <filesystem>
#include <vsd/io.hpp>
#endif

namespace cell {

class Robot : public vsd::Node {
  VSD_INSTANCE(Robot, vsd::Node)
  VSD_PROPERTY(double, speed, 0.5, vsd::Editable | vsd::Savable)
  VSD_PROPERTY(Eigen::Isometry3d, base, Eigen::Isometry3d::Identity())
  VSD_PROPERTY(vsd::SharedRef<vsd::Node>, target, nullptr)

 public:
  /// Moves the robot to its home position: a method callable through the meta-information system.
  void home() { set_speed(0.0); }
  VSD_METHOD(home)
};

class Camera : public vsd::Extension {
  VSD_INSTANCE(Camera, vsd::Extension)
  VSD_PROPERTY(double, fov_deg, 60.0)
};

/// A module: registers its classes and an algorithm that runs every 50 ms of simulated time.
class ConveyorModule : public vsd::Module {
 public:
  explicit ConveyorModule(const vsd::MetaInstance& conveyor) : conveyor_(&conveyor) {}
  std::string_view name() const override { return "conveyor"; }
  void register_types(vsd::Registry& r) override {
    r.add<Robot>();
    r.add<Camera>();
  }
  void attach(vsd::Environment& env) override {
    const vsd::MetaProperty& pos = conveyor_->property("position");
    const vsd::MetaProperty& belt = conveyor_->property("belt_speed");
    env.scheduler().add_periodic(
        "conveyor kinematics", 0.05, [&env, &pos, &belt, this](const vsd::StepInfo& step) {
          env.main_state().index().for_each(*conveyor_, true, [&](vsd::SimStateInstance& c) {
            pos.set<double>(c, pos.get<double>(c) + belt.get<double>(c) * step.dt);
          });
        });
  }

 private:
  const vsd::MetaInstance* conveyor_;
};

}  // namespace cell

namespace {

std::string describe(const vsd::SimStateInstance& i) {
  const auto* n = i.as<vsd::NamedModelInstance>();
  return i.meta().name() + " #" + std::to_string(i.id()) +
         (n != nullptr && !n->name().empty() ? " '" + n->name() + "'" : "");
}

void print_tree(const vsd::Node& n, int depth) {
  std::printf("%*s- %s", depth * 2, "", describe(n).c_str());
  for (const vsd::MetaProperty* p : n.meta().own_properties())
    if (!p->type().is_ref_list())
      std::printf("  %s=%s", p->name().c_str(), p->get_value(n).to_text().c_str());
  for (const vsd::Extension* e : n.extensions()) std::printf("  [+%s]", describe(*e).c_str());
  std::printf("\n");
  for (const vsd::Node* c : n.children()) print_tree(*c, depth + 1);
}

}  // namespace

int main() {
  vsd::Environment env;
  vsd::SimState& state = env.main_state();

  std::printf("== 1. Classes\n");
  // A class made at run time, deriving from a built-in one, with a method bound to a lambda.
  const vsd::MetaInstance& conveyor =
      vsd::ClassBuilder("Conveyor", vsd::Node::static_meta())
          .property<double>("belt_speed", 0.2)
          .property<double>("position", 0.0)
          .method("stop", {}, nullptr,
                  [](vsd::SimStateInstance& self, std::span<const vsd::Value>) {
                    self.set("belt_speed", vsd::Value(0.0));
                    return vsd::Value();
                  })
          .define();
  env.use<cell::ConveyorModule>(conveyor);
  for (const char* name : {"Robot", "Camera", "Conveyor"}) {
    const vsd::MetaInstance& cls = env.registry().get_class(name);
    std::printf("%-9s (%s, base %s):", cls.name().c_str(), cls.is_runtime() ? "run-time" : "built-in",
                cls.base()->name().c_str());
    for (const vsd::MetaProperty* p : cls.own_properties())
      std::printf(" %s:%s", p->name().c_str(), p->type().name().c_str());
    for (const vsd::MetaMethod* m : cls.methods()) std::printf(" %s", m->signature().c_str());
    std::printf("\n");
  }

  std::printf("\n== 2. Listening\n");
  auto on_create = state.on_created().connect(
      [](vsd::SimStateInstance& i) { std::printf("  created  %s\n", describe(i).c_str()); });
  auto on_delete = state.on_deleted().connect(
      [](vsd::SimStateInstance& i) { std::printf("  deleted  %s\n", describe(i).c_str()); });
  auto on_robot = state.on_property_changed(cell::Robot::static_meta())
                      .connect([](vsd::SimStateInstance& i, const vsd::MetaProperty& p) {
                        std::printf("  changed  %s.%s = %s\n", describe(i).c_str(), p.name().c_str(),
                                    p.get_value(i).to_text().c_str());
                      });
  std::printf(
      "listening to creations and deletions in the main state, and to property changes of every Robot\n");

  std::printf("\n== 3. Building a work cell\n");
  auto& cell = state.create<vsd::Node>();
  cell.set_name("cell");
  state.database().add_child(cell);
  auto& robot = state.create<cell::Robot>();
  robot.set_name("kuka");
  cell.add_child(robot);
  auto& camera = state.create<cell::Camera>();
  robot.add_extension(camera);
  auto& belt = static_cast<vsd::Node&>(state.create("Conveyor"));
  belt.set_name("belt");
  cell.add_child(belt);
  robot.set_target(&belt);
  print_tree(state.database(), 1);

  std::printf("\n== 4. Recording, stepping, replaying\n");
  vsd::SimState& replica = env.create_state("replica");
  replica.copy_from(state);
  state.start_recording();
  robot.set_speed(1.5);               // typed setter
  robot.set("speed", vsd::Value(2));  // generic, by name: the int converts to double
  env.run_for(0.2);                   // the conveyor module moves the belt
  belt.call("stop");                  // vsdMetaCall on a run-time method
  robot.call("home");                 // ... and on a built-in one
  state.destroy(belt);                // the robot's shared target becomes null
  const vsd::Transaction bundle = state.stop_recording();
  std::printf("recorded %zu operations (%zu bytes):\n%s", bundle.size(), bundle.bytes().size(),
              bundle.describe().c_str());

  // The bundle travels as bytes, as it would to another thread or machine.
  replica.apply(vsd::Transaction::from_bytes(bundle.bytes()));
  std::string difference;
  std::printf("replica equals the source: %s\n",
              replica.equals(state, &difference) ? "yes" : ("no: " + difference).c_str());
  print_tree(replica.database(), 1);

  std::printf("\n== 5. Undo on the replica\n");
  on_robot.disconnect();
  replica.apply(bundle.inverted());
  print_tree(replica.database(), 1);
  std::printf("robots: %zu, conveyors: %zu, nodes in the main database: %zu\n",
              replica.index().count(cell::Robot::static_meta()), replica.index().count(conveyor),
              state.database().size());

#if VSD_DEMO_WITH_IO
  std::printf("\n== 6. Saving and loading\n");
  // Text (JSON, one property per line) for people and version control; binary for speed. The file
  // carries the run-time class Conveyor's definition with it.
  const auto path = std::filesystem::temp_directory_path() / "vsd_demo_cell.json";
  vsd::io::save(replica, path);  // ".json": the text format; saved atomically
  const auto text = vsd::io::read_file(path);
  std::printf("%s", std::string(text.begin(), text.end()).c_str());
  vsd::SimState& reloaded = env.create_state("reloaded");
  const vsd::io::LoadReport report = vsd::io::load(reloaded, path);  // all or nothing
  std::printf("loaded %zu instances; binary would take %zu bytes instead of %zu\n", report.instances,
              vsd::io::save_bytes(replica, vsd::io::Format::Binary).size(), text.size());
  std::printf("reloaded from text equals the replica: %s\n", reloaded.equals(replica) ? "yes" : "no");
  std::filesystem::remove(path);
#endif
  return 0;
}
