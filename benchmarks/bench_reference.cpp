// Composite references over depth: the cycle check that every composite link runs (is the target already
// an ancestor of the holder?), and the release cascade of a deep tree. The argument is the depth of the
// chain of nodes the operation works at; the time per operation should not grow with it (attach, move of
// a small subtree) or grow at most linearly (moving a deep subtree, building and deleting a whole chain).
#include <cstddef>
#include <cstdint>
#include <vector>

#include "fixture.hpp"

namespace {

// A chain of @p depth nodes under the Database of @p s; returns its nodes, top first.
std::vector<vsd::Node*> chain(vsd::SimState& s, std::size_t depth, vsd::Node* under = nullptr) {
  std::vector<vsd::Node*> nodes;
  nodes.reserve(depth);
  vsd::Node* at = under != nullptr ? under : &s.database();
  for (std::size_t i = 0; i < depth; ++i) nodes.push_back(at = &at->add_child(s.create<vsd::Node>()));
  return nodes;
}

void depths(benchmark::internal::Benchmark* b) {
  for (const int d : {16, 256, 4096, 65536}) b->Arg(d);
}

// A new leaf attached at the bottom of a chain, then deleted: the common edit, at any depth.
void BM_Composite_AttachLeaf(benchmark::State& state) {
  bench::World w;
  const auto nodes = chain(w.st, static_cast<std::size_t>(state.range(0)));
  vsd::Node& bottom = *nodes.back();
  for (auto _ : state) {
    vsd::Node& leaf = bottom.add_child(w.st.create<vsd::Node>());
    benchmark::DoNotOptimize(&leaf);
    bottom.remove_child(leaf);  // its last reference: deleted
  }
  if (w.st.size() != nodes.size() + 1 || !bottom.children().empty()) state.SkipWithError("wrong tree");
}
BENCHMARK(BM_Composite_AttachLeaf)->Apply(depths);

// A subtree moved to and fro between the bottoms of two chains of the argument's depth: the search up from
// the new parent is as long as the chains, the one down from the subtree as big as the subtree. A small
// subtree (3 nodes) costs the same at any depth; the worst case, a subtree as deep as the chains, costs
// time linear in the depth.
void BM_Composite_Move(benchmark::State& state, bool deep_subtree) {
  bench::World w;
  const auto depth = static_cast<std::size_t>(state.range(0));
  const auto left = chain(w.st, depth);
  const auto right = chain(w.st, depth);
  const auto moved = chain(w.st, deep_subtree ? depth : 3, left.back());
  std::size_t i = 0;
  for (auto _ : state) {
    vsd::Node& to = ++i % 2 == 0 ? *left.back() : *right.back();
    benchmark::DoNotOptimize(&to.add_child(*moved.front()));
  }
  if (moved.front()->parent() != (i % 2 == 0 ? left.back() : right.back())) state.SkipWithError("not moved");
}
BENCHMARK_CAPTURE(BM_Composite_Move, small_subtree, false)->Apply(depths);
BENCHMARK_CAPTURE(BM_Composite_Move, deep_subtree, true)->Apply(depths);

// A whole chain built by appending at the bottom, then deleted from the top (one release cascade through
// all of it). Reported per node: flat when both are linear in the depth.
void BM_Composite_BuildAndDeleteChain(benchmark::State& state) {
  bench::World w;
  const auto depth = static_cast<std::size_t>(state.range(0));
  for (auto _ : state) {
    const auto nodes = chain(w.st, depth);
    benchmark::DoNotOptimize(nodes.back());
    w.st.destroy(*nodes.front());
  }
  if (w.st.size() != 1) state.SkipWithError("instances left behind");
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations()) * state.range(0));
}
BENCHMARK(BM_Composite_BuildAndDeleteChain)->Apply(depths)->Unit(benchmark::kMillisecond);

}  // namespace
