// vsd_soml_set_count: N typed sets of one property, for instruction counts under
// `valgrind --tool=callgrind` (repeatable on a loaded machine, where wall-clock figures are not).
//
//   vsd_soml_set_count N watched     a SOML++ condition reads the property (the executor hears each set)
//   vsd_soml_set_count N unwatched   a SOML++ program is loaded; its condition reads another class
//   vsd_soml_set_count N none        no program
//
// Instructions per set = (count for 2N - count for N) / N; benchmarks/README.md ("What a loaded program
// costs the setters") shows how. The source builds against older trees too (no API newer than issue 8),
// so the same count can be taken before and after a change.
#include <cstdlib>
#include <cstring>
#include <iostream>

#include "vsd/core.hpp"
#include "vsd/soml.hpp"

namespace {

class CountTank : public vsd::Node {
  VSD_INSTANCE(CountTank, vsd::Node)
  VSD_PROPERTY(double, level, 0.0)
};

}  // namespace

int main(int argc, char** argv) {
  if (argc != 3) {
    std::cerr << "usage: vsd_soml_set_count N watched|unwatched|none\n";
    return 2;
  }
  const long n = std::atol(argv[1]);
  const std::string_view mode = argv[2];
  vsd::Registry reg;
  reg.add<CountTank>();
  vsd::Environment env{0, reg};
  auto* tank = &env.main_state().create<CountTank>();
  env.main_state().database().add_child(*tank);
  if (mode != "none") {
    const bool watched = mode == "watched";
    auto& p = env.use<vsd::soml::Module>().load(
        env.main_state(), "count.soml",
        watched ? "shared<CountTank> tank; place a = 1; place b;\n"
                  "transition t { when tank != null && tank.level > 1000000000000.0; }\n"
                  "arrow a -> t; arrow t -> b;\n"
                : "object c { int n = 0; place a = 1; place b; transition t { when n > 1000000; }\n"
                  "  arrow a -> t; arrow t -> b; }\n");
    if (watched) p.root().set("tank", vsd::Value(vsd::SharedRef<vsd::Node>(tank)));
    p.run_until_quiet();  // the condition has read what it reads
  }
  double x = 1;
  for (long i = 0; i < n; ++i) {
    x += 1.0;
    tank->set_level(x);
  }
  std::cout << tank->level() << "\n";  // the sets are observable: nothing folds them away
  return 0;
}
