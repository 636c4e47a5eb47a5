#include "vsd/robotics/module.hpp"

#include "vsd/core/environment.hpp"
#include "vsd/core/registry.hpp"
#include "vsd/robotics/joint.hpp"
#include "vsd/robotics/kinematic_tree.hpp"
#include "vsd/scene/module.hpp"

namespace vsd::robotics {

void Module::register_types(vsd::Registry& registry) {
  registry.add_type<KinematicJointType>();
  registry.add_type<DhConvention>();
  registry.add<KinematicJoint>();
  registry.add<KinematicTree>();
}

void Module::attach(vsd::Environment& env) {
  env.use<scene::Module>();
  for (SimState* s : env.states()) track(*s);
}

}  // namespace vsd::robotics
