// KinematicTree, the per-SimState listeners that make joint values move link frames, and the builders.
#include "vsd/robotics/kinematic_tree.hpp"

#include <mutex>
#include <unordered_map>

#include "vsd/core/error.hpp"
#include "vsd/core/sim_state.hpp"
#include "vsd/robotics/controller.hpp"
#include "vsd/scene/joint.hpp"
#include "vsd/scene/link.hpp"
#include "vsd/scene/scene.hpp"

namespace vsd::robotics {

// Clears a JointController's `done` when it gets a new target (defined in controller.cpp).
void on_controller_changed(SimStateInstance& inst, const MetaProperty& p);

namespace {

// What vsd::robotics keeps per SimState: its listeners, the topology version and the mimic followers.
struct Tracker {
  std::vector<Connection> connections;
  std::uint64_t version = 1;
  std::uint64_t followers_version = 0;
  std::unordered_map<const KinematicJoint*, std::vector<KinematicJoint*>> followers;
  int depth = 0;  // nested updates (mimic chains); a cycle stops here instead of recursing forever
};

// Keyed by address; an entry whose SimState died is recognised by its dead connection (as vsd::scene does).
std::mutex trackers_mutex;
std::unordered_map<const SimState*, std::unique_ptr<Tracker>>& trackers() {
  static auto* map = new std::unordered_map<const SimState*, std::unique_ptr<Tracker>>();
  return *map;
}

Tracker* find_tracker(const SimState& state) {
  std::lock_guard lock(trackers_mutex);
  auto it = trackers().find(&state);
  if (it == trackers().end() || it->second->connections.empty() ||
      !it->second->connections.front().connected())
    return nullptr;
  return it->second.get();
}

void sync_owner_frame(KinematicJoint& j) {
  if (auto* owner = j.owner(); owner != nullptr)
    if (auto* node = owner->as<scene::Node3D>()) node->set_frame(j.motion_frame());
}

const std::vector<KinematicJoint*>& followers_of(Tracker& t, SimState& state, const KinematicJoint& j) {
  if (t.followers_version != t.version) {
    t.followers.clear();
    for (KinematicJoint* f : state.index().of<KinematicJoint>())
      if (f->mimic().get() != nullptr) t.followers[f->mimic().get()].push_back(f);
    t.followers_version = t.version;
  }
  static const std::vector<KinematicJoint*> none;
  auto it = t.followers.find(&j);
  return it == t.followers.end() ? none : it->second;
}

void sync_mimic(KinematicJoint& f) {
  if (f.mimic().get() == nullptr) return;
  f.set_position(f.mimic_multiplier() * f.mimic()->position() + f.mimic_offset());
}

void on_joint_changed(Tracker& t, SimStateInstance& inst, const MetaProperty& p) {
  auto& j = static_cast<KinematicJoint&>(inst);
  const std::string_view name = p.name();
  if (name == "velocity" || name == "name") return;
  if (t.depth > 64) return;  // a mimic cycle (compile() rejects it); do not recurse without end
  ++t.depth;
  struct Leave {
    int& d;
    ~Leave() { --d; }
  } leave{t.depth};
  const bool value = name == "position" || name == "position2";
  if (!value && name != "description") ++t.version;
  if (name == "mimic" || name == "mimic_multiplier" || name == "mimic_offset") {
    sync_mimic(j);  // never dropped: the follower takes its master's value at once
    return;
  }
  if (name == "position" && j.mimic().get() != nullptr) {
    // A follower's value is its master's, whoever wrote it.
    const double want = j.mimic_multiplier() * j.mimic()->position() + j.mimic_offset();
    if (j.position() != want) {
      j.set_position(want);
      return;
    }
  }
  sync_owner_frame(j);
  if (name == "position") {
    if (scene::Joint* d = j.description().get(); d != nullptr) d->set_position(j.position());
    // Copy: a follower's update may rebuild the table.
    const std::vector<KinematicJoint*> fs = followers_of(t, inst.state(), j);
    for (KinematicJoint* f : fs) sync_mimic(*f);
  }
}

void on_node_changed(Tracker& t, SimStateInstance& inst, const MetaProperty& p) {
  const std::string_view name = p.name();
  if (name == "extensions") {
    ++t.version;
    auto& node = static_cast<scene::Node3D&>(inst);
    if (auto* j = node.find_extension<KinematicJoint>()) sync_owner_frame(*j);
  } else if (name == "frame") {
    // The frame of a node moved by a joint is derived; any other node's frame is part of the model.
    if (static_cast<scene::Node3D&>(inst).find_extension<KinematicJoint>() == nullptr) ++t.version;
  }
}

void on_scene_joint_changed(SimStateInstance& inst, const MetaProperty& p) {
  if (p.name() != "position") return;
  auto& d = static_cast<scene::Joint&>(inst);
  if (scene::Link* child = d.child_link().get())
    if (auto* j = child->find_extension<KinematicJoint>(); j != nullptr && j->description().get() == &d)
      j->set_position(d.position());
}

Tracker& tracker(SimState& state) {
  if (Tracker* t = find_tracker(state)) return *t;
  auto t = std::make_unique<Tracker>();
  Tracker* raw = t.get();
  t->connections.push_back(
      state.on_property_changed(KinematicJoint::static_meta(), true)
          .connect([raw](SimStateInstance& i, const MetaProperty& p) { on_joint_changed(*raw, i, p); }));
  t->connections.push_back(
      state.on_property_changed(scene::Node3D::static_meta(), true)
          .connect([raw](SimStateInstance& i, const MetaProperty& p) { on_node_changed(*raw, i, p); }));
  t->connections.push_back(
      state.on_property_changed(scene::Joint::static_meta(), true).connect(&on_scene_joint_changed));
  t->connections.push_back(
      state.on_property_changed(JointController::static_meta(), true).connect(&on_controller_changed));
  t->connections.push_back(state.on_child_added().connect([raw](vsd::Node&, vsd::Node&) { ++raw->version; }));
  t->connections.push_back(
      state.on_child_removed().connect([raw](vsd::Node&, vsd::Node&) { ++raw->version; }));
  std::lock_guard lock(trackers_mutex);
  auto& slot = trackers()[&state];
  // A dead entry (its SimState is gone and the address reused) is replaced; its connections are inert.
  slot = std::move(t);
  return *raw;
}

KinematicJointType type_of(scene::JointType t, std::string_view name, std::vector<std::string>* warnings) {
  switch (t) {
    case scene::JointType::Revolute:
    case scene::JointType::Continuous:
      return KinematicJointType::Rotary;
    case scene::JointType::Prismatic:
      return KinematicJointType::Prismatic;
    case scene::JointType::Fixed:
      return KinematicJointType::Fixed;
    default:
      if (warnings != nullptr) {
        const char* what = t == scene::JointType::Floating ? "a floating joint"
                           : t == scene::JointType::Planar ? "a planar joint"
                                                           : "a joint of unknown type";
        warnings->push_back("joint '" + std::string(name) + "': " + what +
                            " is kept fixed (vsd::robotics has rotary, prismatic, universal and fixed joints)");
      }
      return KinematicJointType::Fixed;
  }
}

}  // namespace

void track(SimState& state) { (void)tracker(state); }

std::uint64_t topology_version(SimState& state) { return tracker(state).version; }

// ---- KinematicTree --------------------------------------------------------------------------------------

scene::Node3D* KinematicTree::base() const noexcept {
  NamedModelInstance* o = owner();
  return o != nullptr ? o->as<scene::Node3D>() : nullptr;
}

std::vector<KinematicJoint*> KinematicTree::joints() const {
  std::vector<KinematicJoint*> out;
  scene::Node3D* b = base();
  if (b == nullptr) return out;
  for (vsd::Node* c : b->children())
    c->visit([&](vsd::Node& n) {
      if (auto* j = n.find_extension<KinematicJoint>()) out.push_back(j);
    });
  return out;
}

KinematicJoint* KinematicTree::find_joint(std::string_view name) const {
  for (KinematicJoint* j : joints())
    if (j->name() == name) return j;
  return nullptr;
}

const Model& KinematicTree::model() const {
  scene::Node3D* b = base();
  if (b == nullptr) throw vsd::Error("KinematicTree '" + name() + "' is not attached to a 3D node");
  const std::uint64_t v = topology_version(state());
  if (model_ == nullptr || model_version_ != v) {
    model_ = std::make_shared<const Model>(Model::compile(*b));
    model_version_ = v;
    ++compilations_;
  }
  return *model_;
}

std::vector<double> KinematicTree::positions() const {
  const Model& m = model();
  std::vector<double> q;
  q.reserve(static_cast<std::size_t>(m.dof()));
  for (const DofInfo& d : m.layout())
    q.push_back(d.axis_index == 0 ? d.joint->position() : d.joint->position2());
  return q;
}

void KinematicTree::set_positions(std::span<const double> q) {
  const Model& m = model();
  if (q.size() != static_cast<std::size_t>(m.dof()))
    throw vsd::Error("KinematicTree '" + name() + "': " + std::to_string(q.size()) + " joint values given, " +
                     std::to_string(m.dof()) + " expected");
  // The layout refers to joints of the compiled model; copy it, since a set may trigger a recompile.
  std::vector<DofInfo> layout(m.layout().begin(), m.layout().end());
  for (std::size_t i = 0; i < layout.size(); ++i) {
    auto* j = const_cast<KinematicJoint*>(layout[i].joint);
    if (layout[i].axis_index == 0) {
      j->set_position(q[i]);
    } else {
      j->set_position2(q[i]);
    }
  }
}

// ---- builders -------------------------------------------------------------------------------------------

KinematicTree& build_kinematics(scene::Scene& scene, std::vector<std::string>* warnings) {
  track(scene.state());
  if (auto* t = scene.find_extension<KinematicTree>()) return *t;
  SimState& state = scene.state();
  std::vector<std::pair<scene::Joint*, KinematicJoint*>> made;
  for (scene::Joint* d : scene.joints()) {
    scene::Link* child = d->child_link().get();
    if (child == nullptr) throw vsd::Error("joint '" + d->name() + "' has no child link");
    if (child->find_extension<KinematicJoint>() != nullptr) continue;
    auto& j = state.create<KinematicJoint>();
    j.set_name(d->name());
    j.set_type(type_of(d->type(), d->name(), warnings));
    j.set_origin(d->origin());
    j.set_axis(d->axis());
    j.set_has_limits(d->has_limits() && d->type() != scene::JointType::Continuous);
    j.set_lower(d->lower());
    j.set_upper(d->upper());
    j.set_velocity_limit(d->velocity());
    j.set_effort_limit(d->effort());
    j.set_position(d->position());
    j.set_description(d);
    made.emplace_back(d, &j);
  }
  // Mimics after every joint exists (a mimic may name a later joint).
  for (auto& [d, j] : made) {
    if (d->mimic().get() == nullptr) continue;
    scene::Link* master_link = d->mimic()->child_link().get();
    KinematicJoint* master = master_link != nullptr ? master_link->find_extension<KinematicJoint>() : nullptr;
    if (master == nullptr) {
      for (auto& [d2, j2] : made)
        if (d2 == d->mimic().get()) master = j2;
    }
    if (master == nullptr)
      throw vsd::Error("joint '" + d->name() + "': mimics '" + d->mimic()->name() +
                       "', which has no child link");
    j->set_mimic_multiplier(d->mimic_multiplier());
    j->set_mimic_offset(d->mimic_offset());
    j->set_mimic(master);
  }
  for (auto& [d, j] : made) d->child_link()->add_extension(*j);
  auto& tree = state.create<KinematicTree>();
  tree.set_name(scene.name());
  scene.add_extension(tree);
  return tree;
}

KinematicTree& build_dh_chain(scene::Node3D& base, DhConvention convention, std::span<const DhJoint> rows) {
  if (rows.empty()) throw vsd::Error("build_dh_chain: the DH table is empty");
  if (convention == DhConvention::None) throw vsd::Error("build_dh_chain: no DH convention given");
  for (const DhJoint& r : rows)
    if (r.type != KinematicJointType::Rotary && r.type != KinematicJointType::Prismatic)
      throw vsd::Error("build_dh_chain: joint '" + r.name + "' must be rotary or prismatic");
  SimState& state = base.state();
  track(state);
  scene::Node3D* parent = &base;
  for (const DhJoint& r : rows) {
    auto& link = state.create<scene::Link>();
    link.set_name(r.name + "_link");
    auto& j = state.create<KinematicJoint>();
    j.set_name(r.name);
    j.set_type(r.type);
    j.set_dh_parameters(convention, r.parameters);
    j.set_has_limits(r.has_limits);
    j.set_lower(r.lower);
    j.set_upper(r.upper);
    j.set_velocity_limit(r.velocity_limit);
    link.add_extension(j);
    parent->add_child(link);
    parent = &link;
  }
  auto& tree = state.create<KinematicTree>();
  tree.set_name(base.name());
  base.add_extension(tree);
  return tree;
}

}  // namespace vsd::robotics
