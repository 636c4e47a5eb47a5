// Classes shared by the core tests. Names carry a "T" prefix: class names are global in the Registry.
#pragma once

#include <string>
#include <vector>
#include <vsd/vsd.hpp>

namespace vsd_test {

class TTool : public vsd::Node {
  VSD_INSTANCE(TTool, vsd::Node)
  VSD_PROPERTY(double, length, 0.1)
};

class TRobot : public vsd::Node {
  VSD_INSTANCE(TRobot, vsd::Node)
  VSD_PROPERTY(double, speed, 1.0, vsd::Editable | vsd::Savable)
  VSD_PROPERTY(int, axes, 6)
  VSD_PROPERTY(std::vector<double>, joints, {})
  VSD_PROPERTY(Eigen::Isometry3d, frame, Eigen::Isometry3d::Identity())
  VSD_PROPERTY(std::string, cache, "", vsd::Transient)
  /// The node the robot is heading for (shared: the robot does not own it).
  VSD_PROPERTY(vsd::SharedRef<vsd::Node>, target, nullptr)
  /// The tool the robot owns (composite).
  VSD_PROPERTY(vsd::Ref<TTool>, tool, nullptr)
  /// Nodes the robot watches (shared list).
  VSD_PROPERTY(vsd::SharedRefList<vsd::Node>, watched, {})

 public:
  void home() { set_speed(0.0); }
  VSD_METHOD(home)
};

class TGripper : public TRobot {
  VSD_INSTANCE(TGripper, TRobot)
  VSD_PROPERTY(bool, closed, false)
};

class TSensor : public vsd::Extension {
  VSD_INSTANCE(TSensor, vsd::Extension)
  VSD_PROPERTY(double, range, 5.0)
};

/// Counts the composite references to every instance of @p state by walking all reference properties,
/// and compares with each instance's own count. Returns an empty string when consistent.
inline std::string check_reference_counts(const vsd::SimState& state) {
  std::unordered_map<const vsd::SimStateInstance*, std::uint32_t> counted;
  for (vsd::SimStateInstance* x : state.instances()) {
    for (const vsd::MetaProperty* p : x->meta().reference_properties()) {
      if (!p->type().is_composite()) continue;
      if (p->type().is_ref_list()) {
        const auto& list = *static_cast<const vsd::RefListBase*>(p->address(*x));
        for (std::size_t i = 0; i < list.size(); ++i) ++counted[list.at(i)];
      } else if (auto* t = static_cast<const vsd::RefBase*>(p->address(*x))->get()) {
        ++counted[t];
      }
    }
  }
  for (vsd::SimStateInstance* x : state.instances())
    if (x->composite_count() != counted[x])
      return "#" + std::to_string(x->id()) + " counts " + std::to_string(x->composite_count()) + " but " +
             std::to_string(counted[x]) + " composite references exist";
  return {};
}

}  // namespace vsd_test
