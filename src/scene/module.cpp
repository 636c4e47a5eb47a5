#include "vsd/scene/module.hpp"

#include "vsd/core/registry.hpp"
#include "vsd/core/sim_state.hpp"
#include "vsd/scene/geometry.hpp"
#include "vsd/scene/hull.hpp"
#include "vsd/scene/joint.hpp"
#include "vsd/scene/link.hpp"
#include "vsd/scene/material.hpp"
#include "vsd/scene/node3d.hpp"
#include "vsd/scene/scene.hpp"
#include "vsd/scene/support.hpp"
#include "vsd/scene/texture_map.hpp"
#include "world_frames.hpp"

namespace vsd::scene {

void Module::register_types(vsd::Registry& registry) {
  registry.add_type<GeometryKind>();
  registry.add_type<MapFunction>();
  registry.add_type<HullRole>();
  registry.add_type<JointType>();
  registry.add_type<std::vector<Eigen::Vector2d>>();
  registry.add<Node3D>();
  registry.add<Geometry>();
  registry.add<TextureMap>();
  registry.add<Material>();
  registry.add<Hull>();
  registry.add<Link>();
  registry.add<Joint>();
  registry.add<Scene>();
  registry.add_type<SpatialRelation>();
  registry.add<Support>();
}

void Module::serve(vsd::SimState& state, vsd::Service /*from*/, vsd::Service to) {
  if (to == vsd::Service::none) {
    state.context().erase<WorldFrameWatch>();
  } else {
    state.context().get_or_emplace<WorldFrameWatch>(state);
  }
}

}  // namespace vsd::scene
