// The program each consumer project builds (find_package/, add_subdirectory/, fetch_content/): vsd's
// public headers, an Environment with a Node, and a snapshot round trip through vsd::io.
#include <vsd/io.hpp>
#include <vsd/vsd.hpp>

int main() {
  vsd::Environment env;
  auto& state = env.main_state();
  auto& n = state.create<vsd::Node>();
  n.set_name("hello");
  state.database().add_child(n);
  auto& copy = env.create_state("copy");
  vsd::io::load_bytes(copy, vsd::io::save_bytes(state));
  return n.name() == "hello" && copy.equals(state) ? 0 : 1;
}
