// Randomised model-based test: thousands of random operations on a recording SimState, replayed on a
// replica that must stay equal, with every reference count consistent and undo restoring the start.
#include <gtest/gtest.h>

#include <random>

#include "test_classes.hpp"

using vsd_test::TRobot;
using vsd_test::TTool;

namespace {

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

class ModelBased : public testing::TestWithParam<std::uint32_t> {};

TEST_P(ModelBased, ReplicaStaysEqualAndCountsStayConsistent) {
  vsd::Environment env;
  vsd::SimState& source = env.main_state();
  vsd::SimState& replica = env.create_state("replica");
  vsd::SimState& initial = env.create_state("initial");
  RandomModel model(source, GetParam());
  for (int i = 0; i < 200; ++i) model.step();  // some history before recording starts
  replica.copy_from(source);
  initial.copy_from(source);
  source.start_recording();
  std::vector<vsd::Transaction> bundles;
  for (int batch = 0; batch < 40; ++batch) {
    for (int i = 0; i < 100; ++i) model.step();
    bundles.push_back(source.take_recording());
    // Half of the bundles travel through bytes, as they would between machines.
    replica.apply(batch % 2 == 0 ? bundles.back() : vsd::Transaction::from_bytes(bundles.back().bytes()));
    std::string diff;
    ASSERT_TRUE(source.equals(replica, &diff)) << "batch " << batch << ": " << diff;
    ASSERT_EQ(vsd_test::check_reference_counts(source), "") << "batch " << batch;
    ASSERT_EQ(vsd_test::check_reference_counts(replica), "") << "batch " << batch;
  }
  // Undo everything, newest first: the replica returns to the state recording started from.
  for (auto it = bundles.rbegin(); it != bundles.rend(); ++it) replica.apply(it->inverted());
  std::string diff;
  EXPECT_TRUE(replica.equals(initial, &diff)) << diff;
  EXPECT_EQ(vsd_test::check_reference_counts(replica), "");
  EXPECT_LT(model.rejected(), 4000 / 2) << "most random operations should be legal";
}

INSTANTIATE_TEST_SUITE_P(Seeds, ModelBased, testing::Values(1u, 2u, 3u, 20261121u));

}  // namespace
