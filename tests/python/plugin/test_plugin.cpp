// The plugins of tests/python/test_plugins.py (vsd.load_plugin). Built twice: vsd_test_plugin, a plugin
// that makes a Node (named by its first argument) and a task counting the steps on it, through an
// object it leaves to the environment (PluginContext::keep), and a PluginGauge (a class of its own, with
// a ReadOnly property); and, with VSD_TEST_WRONG_ABI, a library that claims another ABI.
#include <memory>
#include <string>

#include "vsd/core/environment.hpp"
#include "vsd/core/error.hpp"
#include "vsd/core/database.hpp"
#include "vsd/core/flags.hpp"
#include "vsd/core/node.hpp"
#include "vsd/python/plugin.hpp"

#ifdef VSD_TEST_WRONG_ABI
extern "C" __attribute__((visibility("default"))) const char* vsd_python_plugin_abi() {
  return "vsd-python-plugin 0; another compiler";
}
#else
/// A class the plugin registers (when it is loaded): `serial` is ReadOnly — Python must refuse to set it.
class PluginGauge : public vsd::Node {
  VSD_INSTANCE(PluginGauge, vsd::Node)
  VSD_PROPERTY(std::int64_t, serial, 7, vsd::ReadOnly)
  VSD_PROPERTY(double, reading, 0.0)
};

namespace {

struct Counter {
  vsd::Node* node = nullptr;
  int steps = 0;
};

void build(vsd::python::PluginContext& c) {
  if (c.args.size() != 1) throw vsd::Error("expects one argument, the node's name");
  if (c.args[0] == "fail") throw vsd::Error("asked to fail");
  vsd::SimState& s = c.env.main_state();
  auto& n = s.create<vsd::Node>();
  n.set_name(c.args[0]);
  s.database().add_child(n);
  auto& gauge = s.create<PluginGauge>();
  gauge.set_name("gauge");
  s.database().add_child(gauge);
  auto counter = std::make_shared<Counter>();
  counter->node = &n;
  c.env.scheduler().add_periodic("count steps", c.env.scheduler().base_step(), [k = counter.get()](const vsd::StepInfo&) {
    k->node->set_name("steps " + std::to_string(++k->steps));
  });
  c.keep = counter;
  c.info = {{"node", c.args[0]}};
}

}  // namespace

VSD_PYTHON_PLUGIN(build)
#endif
