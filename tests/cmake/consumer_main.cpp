// The program each consumer project builds (find_package/, add_subdirectory/, fetch_content/): vsd's
// public headers and an Environment with a Node; with vsd::io a snapshot round trip; with vsd::scene a
// URDF loaded; with vsd::soml a SOML++ script checked; with vsd::analysis a net through PNML and the
// explorer.
#include <vsd/vsd.hpp>
#ifdef CONSUMER_HAS_IO
#include <vsd/io.hpp>
#endif
#ifdef CONSUMER_HAS_SCENE
#include <vsd/scene.hpp>
#endif
#ifdef CONSUMER_HAS_SOML
#include <vsd/soml.hpp>
#endif
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
  copy.copy_from(state);
#ifdef CONSUMER_HAS_IO
  auto& loaded = env.create_state("loaded");
  vsd::io::load_bytes(loaded, vsd::io::save_bytes(state));
  if (!loaded.equals(state)) return 1;
#endif
#ifdef CONSUMER_HAS_SCENE
  const auto report = vsd::scene::load_urdf_text(
      state.database(), "<robot name=\"r\"><link name=\"a\"/><link name=\"b\"/>"
                        "<joint name=\"j\" type=\"revolute\"><parent link=\"a\"/><child link=\"b\"/>"
                        "<limit lower=\"-1\" upper=\"1\" effort=\"1\" velocity=\"1\"/></joint></robot>",
      "consumer.urdf", ".");
  if (report.links != 2 || report.joints != 1) return 1;
#endif
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
  return n.name() == "hello" && copy.database().children().size() == 1 ? 0 : 1;
}
