// vsd_lifecycle_count: a fixed amount of life-cycle work, for instruction counts under
// `valgrind --tool=callgrind` (repeatable on a loaded machine, where wall-clock figures are not).
//
//   vsd_lifecycle_count create N     N x (create + destroy) of the built-in Robot
//   vsd_lifecycle_count runtime N    the same with the run-time twin RtRobot
//   vsd_lifecycle_count emit N K     N emits of a void(int) signal with K listeners
//   vsd_lifecycle_count load N [build-only]
//                                    builds and saves a model of N instances (binary), then loads it
//                                    (not with build-only)
//
// Instructions per operation = (count for N - count for 0) / N, and per loaded instance
// (count of "load N" - count of "load N build-only") / N; benchmarks/README.md shows how.
#include <cstdio>
#include <cstdlib>
#include <string>
#include <string_view>
#include <vector>

#include "fixture.hpp"
#include "vsd/io.hpp"

namespace {

int usage() {
  std::fprintf(stderr, "usage: vsd_lifecycle_count create|runtime|load N, or emit N K\n");
  return 2;
}

void build(vsd::SimState& s, long n) {
  for (long g = 0; g < n / 1000; ++g) {
    auto& group = s.create<vsd::Node>();
    group.set_name("group" + std::to_string(g));
    s.database().add_child(group);
    for (int i = 0; i < 999; ++i) {
      auto& r = s.create<Robot>();
      r.set_name("robot" + std::to_string(i));
      r.set_speed(i * 0.5);
      r.set_battery(i % 100);
      group.add_child(r);
    }
  }
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 3) return usage();
  const std::string_view mode = argv[1];
  const long n = std::atol(argv[2]);
  vsd::Environment env;
  vsd::SimState& st = env.main_state();
  if (mode == "create" || mode == "runtime") {
    const vsd::MetaInstance& cls = mode == "create" ? Robot::static_meta() : bench::runtime_robot_class();
    (void)st.create(cls);  // the first instance of a class sets up its bookkeeping: not counted per op
    for (long i = 0; i < n; ++i) {
      vsd::SimStateInstance& r = st.create(cls);
      benchmark::DoNotOptimize(&r);
      st.destroy(r);
    }
  } else if (mode == "emit" && argc > 3) {
    std::vector<bench::Listener> ls(static_cast<std::size_t>(std::atoi(argv[3])));
    vsd::Signal<void(int)> sig;
    std::vector<vsd::Connection> cs;
    for (auto& l : ls) cs.push_back(sig.connect([p = &l](int v) { p->on(v); }));
    for (long i = 0; i < n; ++i) {
      sig.emit(static_cast<int>(i));
      benchmark::ClobberMemory();
    }
  } else if (mode == "load") {
    std::vector<std::uint8_t> bytes;
    {
      vsd::Environment source;
      build(source.main_state(), n);
      bytes = vsd::io::save_bytes(source.main_state(), vsd::io::Format::Binary);
    }
    if (argc > 3 && std::string_view(argv[3]) == "build-only") return 0;
    vsd::io::load_bytes(st, bytes);
    std::printf("%zu instances\n", st.size());
  } else {
    return usage();
  }
  return 0;
}
