// The classes and the small model the fuzzers and the seed generator share.
#pragma once

#include <string>
#include <vector>
#include <vsd/vsd.hpp>

namespace fuzz {

class FzRobot : public vsd::Node {
  VSD_INSTANCE(FzRobot, vsd::Node)
  VSD_PROPERTY(double, speed, 1.0)
  VSD_PROPERTY(std::vector<double>, joints, {})
  VSD_PROPERTY(Eigen::Isometry3d, frame, Eigen::Isometry3d::Identity())
  VSD_PROPERTY(vsd::SharedRef<vsd::Node>, target, nullptr)
  VSD_PROPERTY(vsd::Ref<vsd::Node>, tool, nullptr)
  VSD_PROPERTY(vsd::SharedRefList<vsd::Node>, watched, {})
};

/// A few nodes, robots and references of every kind.
inline void build(vsd::SimState& s) {
  s.environment().registry().add<FzRobot>();
  auto& cell = s.create<vsd::Node>();
  cell.set_name("cell");
  s.database().add_child(cell);
  for (int i = 0; i < 3; ++i) {
    auto& r = s.create<FzRobot>();
    r.set_name("r" + std::to_string(i));
    r.set_speed(i);
    r.set_joints({0.5 * i, 1.0});
    cell.add_child(r);
    auto& tool = s.create<vsd::Node>();
    r.set_tool(&tool);
    r.set_target(&cell);
    r.list_insert(FzRobot::vsd_prop_watched(), 0, tool);
    r.add_extension(s.create<vsd::Extension>());
  }
}

/// Checks what every accepted input must leave behind: reference counts that match the references.
inline bool counts_consistent(const vsd::SimState& s) {
  for (vsd::SimStateInstance* x : s.instances()) {
    std::uint32_t n = 0;
    for (vsd::SimStateInstance* y : s.instances())
      for (const vsd::MetaProperty* p : y->meta().reference_properties()) {
        if (!p->type().is_composite()) continue;
        if (p->type().is_ref_list()) {
          const auto& l = *static_cast<const vsd::RefListBase*>(p->address(*y));
          for (std::size_t i = 0; i < l.size(); ++i) n += l.at(i) == x ? 1 : 0;
        } else {
          n += static_cast<const vsd::RefBase*>(p->address(*y))->get() == x ? 1 : 0;
        }
      }
    if (n != x->composite_count()) return false;
  }
  return true;
}

}  // namespace fuzz
