// Consumer smoke test (find_package): vsd's public header, an Environment, and one Node.
#include <vsd/vsd.hpp>

int main() {
  vsd::Environment env;
  auto& state = env.main_state();
  auto& n = state.create<vsd::Node>();
  n.set_name("hello");
  return n.name() == "hello" ? 0 : 1;
}
