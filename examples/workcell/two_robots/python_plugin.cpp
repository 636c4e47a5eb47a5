// The two-robot work cell as a plugin of the Python module (include/vsd/python/plugin.hpp):
//
//   info = vsd.load_plugin("build/examples/vsd_two_robot_cell_plugin.so", env, ["--seed", "1"])
//
// builds the cell into env (build_cell: modules, nodes, the plant's scheduler task, both SOML++ nets) and
// returns; whoever steps env runs the cell. Arguments: the cell's options of vsd_two_robot_cell
// (--seed, --parts, --kinds, --step, --physics-step, --urdf, --meta, --robots, --fault); the demo loop's
// (--csv, --png, --time-limit) are refused, since Python runs its own loop. The figures returned:
// robots, arms (the scenes whose KinematicTree moves), step, parts.
#include <memory>
#include <sstream>
#include <string>

#include "cell.hpp"
#include "vsd/core/error.hpp"
#include "vsd/python/plugin.hpp"

namespace {

std::string number(double x) {
  std::ostringstream s;
  s << x;
  return s.str();
}

// What the Environment's tasks refer to: the options (build_cell keeps a reference) and the cell.
struct LoadedCell {
  vsd_workcell::CellOptions options;
  std::unique_ptr<vsd_workcell::Cell> cell;
};

void build(vsd::python::PluginContext& c) {
  auto loaded = std::make_shared<LoadedCell>();
  vsd_workcell::CellOptions& o = loaded->options;
  o.urdf = VSD_CELL_URDF;
  o.meta_script = VSD_CELL_META;
  o.robot_script = VSD_CELL_ROBOTS;
  vsd_workcell::parse_options(c.args, o);
  if (!o.csv.empty() || !o.png.empty() || o.time_limit > 0)
    throw vsd::Error("--csv, --png and --time-limit belong to vsd_two_robot_cell's loop; from Python, step the "
                     "environment and record what you need");
  if (o.hardware.enabled) throw vsd::Error("--hardware: not from Python (run vsd_two_robot_cell --hardware)");
  loaded->cell = std::make_unique<vsd_workcell::Cell>(vsd_workcell::build_cell(c.env, o));
  c.keep = loaded;
  c.info = {{"robots", "robot_a robot_b"}, {"arms", "arm_a arm_b"}, {"step", number(o.step)},
            {"parts", std::to_string(o.parts)}};
}

}  // namespace

VSD_PYTHON_PLUGIN(build)
