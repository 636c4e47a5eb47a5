// The paper's streaming example: loader threads build subtrees in SimStates of their own while the
// main thread simulates; each hands its result over as a transaction bundle that the main state applies.
// A SimState belongs to one thread at a time, so no locks are needed around the database.
#include <cstdio>
#include <future>
#include <string>
#include <thread>
#include <vector>
#include <vsd/vsd.hpp>

namespace {

class Building : public vsd::Node {
  VSD_INSTANCE(Building, vsd::Node)
  VSD_PROPERTY(double, height, 10.0)
  VSD_PROPERTY(Eigen::Vector3d, position, Eigen::Vector3d::Zero())
};

// What a loader thread does: "read" a site from an external database into its own SimState.
std::vector<std::uint8_t> load_site(vsd::SimState& loader, int site, int buildings) {
  loader.start_recording();
  auto& root = loader.create<vsd::Node>();
  root.set_name("site" + std::to_string(site));
  loader.database().add_child(root);
  for (int i = 0; i < buildings; ++i) {
    auto& b = loader.create<Building>();
    b.set_name("building" + std::to_string(i));
    b.set_height(5.0 + i % 7);
    b.set_position(Eigen::Vector3d(100.0 * site + i, i * 2.0, 0.0));
    root.add_child(b);
  }
  return loader.stop_recording().bytes();
}

}  // namespace

int main() {
  vsd::Environment env;
  vsd::SimState& main_state = env.main_state();
  auto created =
      main_state.index().on_created(Building::static_meta()).connect([n = 0](vsd::SimStateInstance&) mutable {
        if (++n % 250 == 0) std::printf("  main state: %d buildings arrived\n", n);
      });

  std::vector<std::future<std::vector<std::uint8_t>>> pending;
  for (int site = 0; site < 3; ++site) {
    vsd::SimState& loader = env.create_state("loader" + std::to_string(site));  // made here, used there
    pending.push_back(std::async(std::launch::async, load_site, std::ref(loader), site, 250));
  }
  for (auto& p : pending) {
    const auto bytes = p.get();
    main_state.apply(vsd::Transaction::from_bytes(bytes));
    std::printf("applied a bundle of %zu bytes\n", bytes.size());
  }
  std::printf("main state now holds %zu sites and %zu buildings\n", main_state.database().children().size(),
              main_state.index().count(Building::static_meta()));
  for (vsd::SimState* s : env.states())
    if (s != &main_state) env.remove_state(*s);
  return 0;
}
