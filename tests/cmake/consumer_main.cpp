// The program each consumer project builds (find_package/, add_subdirectory/, fetch_content/): vsd's
// public headers, an Environment with a Node, and a snapshot round trip through vsd::io; with
// vsd::soml, a SOML++ script checked; with vsd::analysis, a net through PNML and the explorer.
#include <vsd/io.hpp>
#ifdef CONSUMER_HAS_SOML
#include <vsd/soml.hpp>
#endif
#include <vsd/vsd.hpp>
#ifdef CONSUMER_HAS_ANALYSIS
#include <vsd/analysis.hpp>
#endif

int main() {
  vsd::Environment env;
  auto& state = env.main_state();
  auto& n = state.create<vsd::Node>();
  n.set_name("hello");
  state.database().add_child(n);
  auto& copy = env.create_state("copy");
  vsd::io::load_bytes(copy, vsd::io::save_bytes(state));
#ifdef CONSUMER_HAS_ANALYSIS
  vsd::analysis::PtNet net("n");
  const auto p = net.add_place("p", {}, 2);
  const auto t = net.add_transition("t");
  net.add_input(t, p);
  const auto back = vsd::analysis::read_pnml(vsd::analysis::write_pnml(net));
  if (vsd::analysis::explore(back.net).states != 3) return 1;
#endif
#ifdef CONSUMER_HAS_SOML
  const auto script = vsd::soml::check_source("consumer.soml", "class A : Node { int x = 1; }");
  if (!script->ok()) return 1;
#endif
  return n.name() == "hello" && copy.equals(state) ? 0 : 1;
}
