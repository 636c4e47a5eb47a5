#include "vsd/analysis/pt_net.hpp"

#include <gtest/gtest.h>

#include "vsd/core/error.hpp"

namespace an = vsd::analysis;
using an::PtNet;

namespace {

TEST(PtNet, BuildsPlacesTransitionsAndArcs) {
  PtNet net("n", "Net");
  EXPECT_EQ(net.add_place("p", "P", 2), 0u);
  EXPECT_EQ(net.add_place("q"), 1u);
  EXPECT_EQ(net.add_transition("t"), 0u);
  net.add_input(0, 0, 2, "a1");
  net.add_output(0, 1);
  net.add_inhibitor(0, 1, 3);
  EXPECT_EQ(net.places()[1].name, "q");  // the id when no name is given
  EXPECT_EQ(net.arc_count(), 3u);
  EXPECT_TRUE(net.has_inhibitors());
  EXPECT_EQ(net.find_place("q"), 1u);
  EXPECT_EQ(net.find_transition("t"), 0u);
  EXPECT_FALSE(net.find_place("t").has_value());
  EXPECT_EQ(net.initial_marking(), (std::vector<std::uint32_t>{2, 0}));
}

TEST(PtNet, ParallelArcsMerge) {
  PtNet net("n");
  net.add_place("p", {}, 5);
  net.add_transition("t");
  net.add_input(0, 0, 1, "a");
  net.add_input(0, 0, 2, "b");
  net.add_inhibitor(0, 0, 9);
  net.add_inhibitor(0, 0, 7);
  ASSERT_EQ(net.transitions()[0].inputs.size(), 1u);
  EXPECT_EQ(net.transitions()[0].inputs[0].weight, 3u);
  EXPECT_EQ(net.transitions()[0].inputs[0].id, "a");
  EXPECT_EQ(net.transitions()[0].inhibitors[0].weight, 7u);
  // Weights that would wrap around when summed are refused, and the arc keeps its weight.
  net.add_output(0, 0, 4'000'000'000u);
  EXPECT_THROW(net.add_output(0, 0, 400'000'000u), vsd::Error);
  EXPECT_EQ(net.transitions()[0].outputs[0].weight, 4'000'000'000u);
}

TEST(PtNet, FiringRule) {
  PtNet net("n");
  const auto p = net.add_place("p", {}, 2);
  const auto q = net.add_place("q");
  const auto t = net.add_transition("t");
  net.add_input(t, p, 2);
  net.add_output(t, q, 5);
  net.add_inhibitor(t, q, 1);
  auto m = net.initial_marking();
  EXPECT_TRUE(net.enabled(t, m));
  net.fire(t, m);
  EXPECT_EQ(m, (std::vector<std::uint32_t>{0, 5}));
  EXPECT_FALSE(net.enabled(t, m));
  EXPECT_THROW(net.fire(t, m), vsd::Error);
  std::vector<std::uint32_t> inhibited{2, 1};
  EXPECT_FALSE(net.enabled(t, inhibited));  // q holds 1 >= the inhibitor's weight
}

TEST(PtNet, BadInputThrowsWithTheNames) {
  PtNet net("n");
  net.add_place("p");
  net.add_transition("t");
  auto message = [](auto&& f) {
    try {
      f();
    } catch (const vsd::Error& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_NE(message([&] { net.add_place("t"); }).find("id 't' of a place is already used"),
            std::string::npos);
  EXPECT_NE(message([&] { net.add_transition(""); }).find("non-empty id"), std::string::npos);
  EXPECT_NE(message([&] { net.add_input(0, 7); }).find("names place index 7"), std::string::npos);
  EXPECT_NE(message([&] { net.add_output(3, 0); }).find("transition index 3"), std::string::npos);
  EXPECT_NE(message([&] { net.add_inhibitor(0, 0, 0); }).find("weight 0"), std::string::npos);
  EXPECT_THROW(net.set_initial(4, 1), vsd::Error);
  EXPECT_THROW((void)net.enabled(0, std::vector<std::uint32_t>{}), vsd::Error);
  net.set_initial(0, 3);
  EXPECT_EQ(net.places()[0].initial, 3u);
}

TEST(PtNet, EqualityComparesEverything) {
  PtNet a("n");
  a.add_place("p", {}, 1);
  PtNet b = a;
  EXPECT_EQ(a, b);
  b.set_initial(0, 2);
  EXPECT_NE(a, b);
}

}  // namespace
