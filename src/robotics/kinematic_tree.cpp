// KinematicTree, the per-SimState listeners that make joint values move link frames, and the builders.
#include "vsd/robotics/kinematic_tree.hpp"

#include <unordered_map>

#include "vsd/core/error.hpp"
#include "vsd/core/sim_state.hpp"
#include "vsd/core/watch.hpp"
#include "vsd/robotics/controller.hpp"
#include "vsd/scene/joint.hpp"
#include "vsd/scene/link.hpp"
#include "vsd/scene/scene.hpp"

namespace vsd::robotics {

// Clears a JointController's `done` when it gets a new target (defined in controller.cpp).
void on_controller_changed(SimStateInstance& inst, const MetaProperty& p);

namespace {

// What vsd::robotics keeps per SimState, in the state's context: an at-once Watch that derives link frames
// and mimic values from joint values, and the topology version that compiled models compare with.
//
// A joint value is the one recorded property of a joint set. The owner's `frame` and a mimic follower's
// value are derived (SimState::Deriving): signalled, so world frames, collision and carried objects follow,
// but not recorded — every state that this module serves derives them itself from the recorded value.
// The other way round, when someone else moves a jointed link (physics writes the poses of a robot's
// bodies), the joint values follow the link's frame (KinematicJoint::values_of), derived as well: FK,
// Jacobians and controllers see the joints where the bodies are.
struct Tracker {
  explicit Tracker(SimState& s);
  void heard(SimStateInstance& inst, const MetaProperty* p, Changes what);
  void joint_changed(KinematicJoint& j, const MetaProperty& p);
  void node_changed(scene::Node3D& node, const MetaProperty& p);
  void sync_owner_frame(KinematicJoint& j);
  void sync_mimic(KinematicJoint& f);
  void follow_frame(const scene::Node3D& node, KinematicJoint& j);
  const std::vector<KinematicJoint*>& followers_of(const KinematicJoint& j);

  SimState& state;
  std::uint64_t version = 1;
  std::uint64_t followers_version = 0;
  std::unordered_map<const KinematicJoint*, std::vector<KinematicJoint*>> followers;
  int depth = 0;            // nested updates (mimic chains); a cycle stops here instead of recursing forever
  int syncing = 0;          // > 0 while the tracker sets a link frame itself
  bool from_frame = false;  // the joint values being set follow a frame someone else set
  Watch watch;              // last: goes first
};

// Sets a flag for the length of a scope.
struct Raise {
  explicit Raise(int& c) : counter(&c) { ++*counter; }
  ~Raise() { --*counter; }
  Raise(const Raise&) = delete;
  Raise& operator=(const Raise&) = delete;
  int* counter;
};

void Tracker::sync_owner_frame(KinematicJoint& j) {
  if (auto* owner = j.owner(); owner != nullptr)
    if (auto* node = owner->as<scene::Node3D>()) {
      Raise own(syncing);
      SimState::Deriving derived(state);
      node->set_frame(j.motion_frame());
    }
}

void Tracker::sync_mimic(KinematicJoint& f) {
  if (f.mimic().get() == nullptr) return;
  SimState::Deriving derived(state);
  f.set_position(f.mimic_multiplier() * f.mimic()->position() + f.mimic_offset());
}

void Tracker::follow_frame(const scene::Node3D& node, KinematicJoint& j) {
  const Eigen::Isometry3d& f = node.frame();
  if (!f.matrix().allFinite() || f.matrix() == j.motion_frame().matrix()) return;  // nothing to follow
  const auto [q1, q2] = j.values_of(f);
  SimState::Deriving derived(state);
  from_frame = true;
  struct Reset {
    bool& b;
    ~Reset() { b = false; }
  } reset{from_frame};
  j.set_position(q1);
  if (j.dof() == 2) j.set_position2(q2);
}

Tracker::Tracker(SimState& s)
    : state(s), watch(s, [this](SimStateInstance& i, const MetaProperty* p, Changes what) { heard(i, p, what); }) {
  // Every property of a joint but its velocity, name and description; of a node its frame (part of the
  // model unless a joint derives it) and extensions (a joint attached or removed); of a controller what
  // makes it start anew; and every node that changes parent (the tree's shape).
  std::vector<const MetaProperty*> joint_props;
  for (const MetaProperty* p : KinematicJoint::static_meta().properties())
    if (p != &KinematicJoint::vsd_prop_velocity() && p != &KinematicJoint::vsd_prop_name() &&
        p != &KinematicJoint::vsd_prop_description())
      joint_props.push_back(p);
  watch.properties(KinematicJoint::static_meta(), joint_props)
      .properties(scene::Node3D::static_meta(),
                  {&scene::Node3D::vsd_prop_frame(), &vsd::NamedModelInstance::vsd_prop_extensions()})
      .properties(JointController::static_meta(),
                  {&JointController::vsd_prop_target(), &JointController::vsd_prop_target_pose(),
                   &JointController::vsd_prop_tip(), &JointController::vsd_prop_mode()})
      .reparented(vsd::Node::static_meta());
}

void Tracker::heard(SimStateInstance& inst, const MetaProperty* p, Changes what) {
  if (what.has(Changes::parent)) {
    ++version;
  } else if (auto* j = inst.as<KinematicJoint>()) {
    joint_changed(*j, *p);
  } else if (auto* c = inst.as<JointController>()) {
    on_controller_changed(*c, *p);
  } else {
    node_changed(static_cast<scene::Node3D&>(inst), *p);
  }
}

const std::vector<KinematicJoint*>& Tracker::followers_of(const KinematicJoint& j) {
  if (followers_version != version) {
    followers.clear();
    for (KinematicJoint* f : state.index().of<KinematicJoint>())
      if (f->mimic().get() != nullptr) followers[f->mimic().get()].push_back(f);
    followers_version = version;
  }
  static const std::vector<KinematicJoint*> none;
  auto it = followers.find(&j);
  return it == followers.end() ? none : it->second;
}

// Whether @p node is part of some kinematic tree: it or one of its ancestors holds a KinematicTree. Only
// such nodes are in a compiled model; a part on a conveyor, a gripper pad or a marker can move or gain
// extensions without any model having to be compiled again.
bool in_a_tree(const vsd::Node& node) {
  for (const vsd::Node* n = &node; n != nullptr; n = n->parent())
    if (n->find_extension<KinematicTree>() != nullptr) return true;
  return false;
}

void Tracker::joint_changed(KinematicJoint& j, const MetaProperty& p) {
  if (from_frame) return;  // the values follow the link's frame: nothing to derive from them
  if (depth > 64) return;  // a mimic cycle (compile() rejects it); do not recurse without end
  ++depth;
  struct Leave {
    int& d;
    ~Leave() { --d; }
  } leave{depth};
  const bool position = &p == &KinematicJoint::vsd_prop_position();
  const bool value = position || &p == &KinematicJoint::vsd_prop_position2();
  if (!value) {  // a limit, an axis, a mimic...: part of the model of the tree the joint is in, if any
    const auto* owner = j.owner() != nullptr ? j.owner()->as<vsd::Node>() : nullptr;
    if (owner != nullptr && in_a_tree(*owner)) ++version;
  }
  if (&p == &KinematicJoint::vsd_prop_mimic() || &p == &KinematicJoint::vsd_prop_mimic_multiplier() ||
      &p == &KinematicJoint::vsd_prop_mimic_offset()) {
    sync_mimic(j);  // never dropped: the follower takes its master's value at once
    return;
  }
  if (position && j.mimic().get() != nullptr) {
    // A follower's value is its master's, whoever wrote it.
    const double want = j.mimic_multiplier() * j.mimic()->position() + j.mimic_offset();
    if (j.position() != want) {
      SimState::Deriving derived(state);
      j.set_position(want);
      return;
    }
  }
  sync_owner_frame(j);
  if (position) {
    // Copy: a follower's update may rebuild the table.
    const std::vector<KinematicJoint*> fs = followers_of(j);
    for (KinematicJoint* f : fs) sync_mimic(*f);
  }
}

void Tracker::node_changed(scene::Node3D& node, const MetaProperty& p) {
  KinematicJoint* j = node.find_extension<KinematicJoint>();
  if (&p == &vsd::NamedModelInstance::vsd_prop_extensions()) {
    if (in_a_tree(node)) ++version;  // a joint or a tree attached or removed inside a tree
    if (j != nullptr) sync_owner_frame(*j);
  } else if (j == nullptr) {
    if (in_a_tree(node)) ++version;  // the frame of a fixed link is part of the model
  } else if (syncing == 0) {
    follow_frame(node, *j);  // someone else moved a jointed link: its values follow
  }
}

Tracker& tracker(SimState& state) { return state.context().get_or_emplace<Tracker>(state); }

}  // namespace

void track(SimState& state) { (void)tracker(state); }

void untrack(SimState& state) noexcept { state.context().erase<Tracker>(); }

std::uint64_t topology_version(SimState& state) { return tracker(state).version; }

namespace {

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
