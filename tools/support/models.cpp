// The classes every tool knows, and vsd files loaded with stand-ins (see vsd_tool/models.hpp).
#include "vsd_tool/models.hpp"

#include "vsd/core/environment.hpp"
#include "vsd/core/registry.hpp"
#include "vsd/core/sim_state.hpp"
#include "vsd_tool/input.hpp"
#ifdef VSD_TOOL_WITH_SOML
#include "vsd/soml/module.hpp"
#endif
#ifdef VSD_TOOL_WITH_SCENE
#include "vsd/scene/module.hpp"
#endif
#ifdef VSD_TOOL_WITH_ROBOTICS
#include "vsd/robotics/module.hpp"
#endif
#ifdef VSD_TOOL_WITH_PHYSICS
#include "vsd/physics/module.hpp"
#endif

namespace vsd::tool {

void register_classes(Registry& registry) {
  // Every C++ class and type linked into the program (a tool built with your classes knows them) ...
  if (&registry != &Registry::global()) {
    for (const MetaType* t : Registry::global().types())
      if (t->cpp_tag() != nullptr && !t->is_reference() && registry.find_type(t->name()) == nullptr) registry.add(*t);
    for (const MetaInstance* c : Registry::global().classes())
      if (!c->is_runtime() && registry.find_class_exact(c->name()) == nullptr) registry.add(*c);
  }
  // ... and those of every module, explicitly: static linking may drop the automatic registration, never
  // this. Modules register their classes without being attached: nothing runs, nothing is scheduled.
#ifdef VSD_TOOL_WITH_SOML
  soml::Module().register_types(registry);
#endif
#ifdef VSD_TOOL_WITH_SCENE
  scene::Module().register_types(registry);
#endif
#ifdef VSD_TOOL_WITH_ROBOTICS
  robotics::Module().register_types(registry);
#endif
#ifdef VSD_TOOL_WITH_PHYSICS
  physics::Module().register_types(registry);
#endif
}

Workspace::Workspace() : registry_(std::make_unique<Registry>()) {
  register_classes(*registry_);
  env_ = std::make_unique<Environment>(0, *registry_);
}

Workspace::~Workspace() { env_.reset(); }

SimState& Workspace::state() noexcept { return env_->main_state(); }

io::LoadReport load_vsd_bytes(SimState& state, std::span<const std::uint8_t> bytes, std::string_view origin) {
  register_classes(state.environment().registry());
  io::LoadOptions options;
  options.unknown_classes = io::UnknownClasses::Placeholder;
  return io::load_bytes(state, bytes, origin, options);
}

io::LoadReport load_vsd(SimState& state, std::string_view path) {
  return load_vsd_bytes(state, read_input(path), input_name(path));
}

}  // namespace vsd::tool
