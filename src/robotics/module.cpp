#include "vsd/robotics/module.hpp"

#include "vsd/core/environment.hpp"
#include "vsd/core/registry.hpp"
#include "vsd/core/sim_state.hpp"
#include "vsd/robotics/controller.hpp"
#include "vsd/robotics/hardware_binding.hpp"
#include "vsd/robotics/joint.hpp"
#include "vsd/robotics/kinematic_tree.hpp"
#include "vsd/scene/module.hpp"

namespace vsd::robotics {

void Module::register_types(vsd::Registry& registry) {
  registry.add_type<KinematicJointType>();
  registry.add_type<DhConvention>();
  registry.add<KinematicJoint>();
  registry.add<KinematicTree>();
  registry.add_type<ControlMode>();
  registry.add_type<Interpolation>();
  registry.add<JointController>();
  registry.add_type<BindingStatus>();
  registry.add<HardwareBinding>();
}

void Module::attach(vsd::Environment& env) {
  env.use<scene::Module>();
  vsd::Environment* e = &env;
  control_task_ = env.scheduler().add_periodic(
      "robotics control", env.scheduler().base_step(),
      [this, e](const vsd::StepInfo& info) {
        // Controllers compute the commands, then the bindings send them and read the robots back.
        for (SimState* s : e->states_served(*this, Service::stepped)) {
          for (JointController* c : s->index().of<JointController>()) c->step(info.dt);
          for (HardwareBinding* b : s->index().of<HardwareBinding>()) b->cycle(info.dt);
        }
      },
      Phase::controllers);
}

void Module::detach(vsd::Environment& env) {
  if (control_task_ != 0) env.scheduler().remove(control_task_);
  control_task_ = 0;
}

void Module::serve(SimState& state, Service /*from*/, Service to) {
  if (to == Service::none) {
    untrack(state);
  } else {
    track(state);
  }
}

}  // namespace vsd::robotics
