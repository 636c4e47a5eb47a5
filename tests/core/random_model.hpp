// RandomModel: random create/delete/move/set/reference operations on a SimState, for model-based tests
// of replication (transactions) and persistence.
#pragma once

#include <random>
#include <string>
#include <vector>

#include "test_classes.hpp"

namespace vsd_test {

class RandomModel {
 public:
  RandomModel(vsd::SimState& s, std::uint32_t seed) : s_(s), rng_(seed) {}

  // One random operation. Operations that the rules reject (cycles, ...) must throw vsd::Error and
  // leave the state consistent; they are counted.
  void step() {
    const auto all = s_.instances();
    auto pick = [&]() -> vsd::SimStateInstance* { return all[uniform(all.size())]; };
    auto pick_node = [&]() -> vsd::Node* {
      for (int tries = 0; tries < 8; ++tries)
        if (auto* n = pick()->as<vsd::Node>()) return n;
      return &s_.database();
    };
    try {
      switch (uniform(10)) {
        case 0:
        case 1: {  // create, usually attached somewhere
          const unsigned kind = uniform(3);
          vsd::Node& n = kind == 0   ? static_cast<vsd::Node&>(s_.create<TRobot>())
                         : kind == 1 ? static_cast<vsd::Node&>(s_.create<TTool>())
                                     : s_.create<vsd::Node>();
          n.set_name("n" + std::to_string(n.id()));
          if (uniform(5) != 0) pick_node()->add_child(n);
          break;
        }
        case 2: {  // delete
          auto* x = pick();
          if (x != &s_.database()) s_.destroy(*x);
          break;
        }
        case 3: {  // move a node under another
          auto* a = pick_node();
          auto* b = pick_node();
          if (b != &s_.database()) a->add_child(*b);
          break;
        }
        case 4: {  // remove a child (deletes it unless held elsewhere)
          auto* a = pick_node();
          if (!a->children().empty()) a->remove_child(*a->children()[uniform(a->children().size())]);
          break;
        }
        case 5: {  // scalar properties
          if (auto* r = pick()->as<TRobot>()) {
            r->set_speed(static_cast<double>(uniform(1000)) / 8.0);
            r->set_joints(std::vector<double>(uniform(4), 0.5 * uniform(10)));
            r->set_axes(static_cast<int>(uniform(12)));
          }
          break;
        }
        case 6: {  // shared references
          if (auto* r = pick()->as<TRobot>()) r->set_target(uniform(4) == 0 ? nullptr : pick_node());
          break;
        }
        case 7: {  // composite reference
          if (auto* r = pick()->as<TRobot>()) {
            auto* t = pick()->as<TTool>();
            r->set_tool(uniform(3) == 0 ? nullptr : t);
          }
          break;
        }
        case 8: {  // shared list
          if (auto* r = pick()->as<TRobot>()) {
            const auto& p = TRobot::vsd_prop_watched();
            if (r->watched().size() < 4 || uniform(2) == 0) {
              r->list_insert(p, uniform(r->watched().size() + 1), *pick_node());
            } else {
              r->list_erase(p, uniform(r->watched().size()));
            }
          }
          break;
        }
        case 9: {  // generic path by name
          if (auto* x = pick()->as<vsd::NamedModelInstance>())
            x->set("name", vsd::Value("g" + std::to_string(uniform(50))));
          break;
        }
      }
    } catch (const vsd::Error&) {
      ++rejected_;
    }
  }

  [[nodiscard]] int rejected() const { return rejected_; }

 private:
  unsigned uniform(std::size_t n) {
    return static_cast<unsigned>(std::uniform_int_distribution<std::size_t>(0, n - 1)(rng_));
  }
  vsd::SimState& s_;
  std::mt19937 rng_;
  int rejected_ = 0;
};

}  // namespace vsd_test
