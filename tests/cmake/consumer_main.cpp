// The program each consumer project builds (find_package/, add_subdirectory/, fetch_content/): vsd's
// public headers, an Environment with a Node, a snapshot round trip through vsd::io, and a SOML++ script
// checked by vsd::soml.
#include <vsd/io.hpp>
#include <vsd/soml.hpp>
#include <vsd/vsd.hpp>

int main() {
  vsd::Environment env;
  auto& state = env.main_state();
  auto& n = state.create<vsd::Node>();
  n.set_name("hello");
  state.database().add_child(n);
  auto& copy = env.create_state("copy");
  vsd::io::load_bytes(copy, vsd::io::save_bytes(state));
  const auto script = vsd::soml::check_source("consumer.soml", "class A : Node { int x = 1; }");
  return n.name() == "hello" && copy.equals(state) && script->ok() ? 0 : 1;
}
