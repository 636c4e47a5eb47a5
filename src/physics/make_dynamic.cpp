// make_dynamic(): a loaded URDF scene becomes rigid bodies and dynamic joints.
#include <cmath>
#include <string>

#include "vsd/core/error.hpp"
#include "vsd/core/sim_state.hpp"
#include "vsd/physics/simulation.hpp"
#include "vsd/scene/joint.hpp"
#include "vsd/scene/link.hpp"
#include "vsd/scene/scene.hpp"

namespace vsd::physics {

namespace {
bool below_world(const vsd::Node& n) {
  for (const vsd::Node* p = &n; p != nullptr; p = p->parent())
    if (p->find_extension<World>() != nullptr) return true;
  return false;
}
}  // namespace

std::size_t make_dynamic(scene::Scene& scene, bool fix_base) {
  vsd::SimState& state = scene.state();
  // Check every joint and link first, so that an unsupported one changes nothing.
  for (scene::Joint* j : scene.joints())
    if (j->type() == scene::JointType::Planar || j->type() == scene::JointType::Unknown)
      throw vsd::Error("vsd::physics: joint '" + j->name() + "' of scene '" + scene.name() +
                       "' is planar or of unknown type, which ODE cannot simulate between two bodies");
  // A negative mass is not "no body": silently leaving such a link out would move it with its parent
  // as if it were a massless frame.
  for (scene::Link* l : scene.links())
    if (l->mass() < 0.0 || !std::isfinite(l->mass()))
      throw vsd::Error("vsd::physics: link '" + l->name() + "' of scene '" + scene.name() + "' has a mass of " +
                       std::to_string(l->mass()) + " kg; a link is a body with a positive mass or a massless "
                       "frame with mass 0");
  std::size_t made = 0;
  for (scene::Link* l : scene.links()) {
    if (!(l->mass() > 0.0) || l->find_extension<RigidBody>() != nullptr) continue;
    auto& rb = state.create<RigidBody>();
    l->add_extension(rb);
    ++made;
  }
  auto body_of = [](scene::Link* l) { return l != nullptr && l->find_extension<RigidBody>() != nullptr; };
  for (scene::Joint* j : scene.joints()) {
    scene::Link* child = j->child_link().get();
    scene::Link* parent = j->parent_link().get();
    if (!body_of(child) || j->type() == scene::JointType::Floating) continue;  // massless frame, or free
    auto& pj = state.create<Joint>();
    pj.set_name(j->name());
    switch (j->type()) {
      case scene::JointType::Revolute:
      case scene::JointType::Continuous:
        pj.set_kind(JointKind::Hinge);
        break;
      case scene::JointType::Prismatic:
        pj.set_kind(JointKind::Slider);
        break;
      default:
        pj.set_kind(JointKind::Fixed);
        break;
    }
    // The child link's frame is the joint frame at position 0: anchor at its origin, axis as given.
    pj.set_axis(j->axis());
    if (j->has_limits() && j->type() != scene::JointType::Continuous &&
        j->type() != scene::JointType::Fixed && j->lower() <= j->upper()) {
      pj.set_has_limits(true);
      pj.set_lower(j->lower());
      pj.set_upper(j->upper());
    }
    if (body_of(parent)) pj.set_other(parent);
    child->add_extension(pj);
  }
  if (fix_base) {
    for (scene::Link* l : scene.links()) {
      if (!body_of(l)) continue;
      bool is_child = false;
      for (scene::Joint* j : scene.joints()) is_child = is_child || j->child_link().get() == l;
      if (is_child) continue;
      auto& pj = state.create<Joint>();
      pj.set_name(l->name() + "_to_world");
      pj.set_kind(JointKind::Fixed);
      l->add_extension(pj);
    }
  }
  if (!below_world(scene)) scene.add_extension(state.create<World>());
  return made;
}

}  // namespace vsd::physics
