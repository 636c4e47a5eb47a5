// vsd_lifecycle_count: a fixed amount of life-cycle work, for instruction counts under
// `valgrind --tool=callgrind` (repeatable on a loaded machine, where wall-clock figures are not).
//
//   vsd_lifecycle_count create N     N x (create + destroy) of the built-in Robot
//   vsd_lifecycle_count runtime N    the same with the run-time twin RtRobot
//   vsd_lifecycle_count emit N K     N emits of a void(int) signal with K listeners
//   vsd_lifecycle_count record N K   N recorded sets (a frame and a double, alternating) taken as
//                                    bundles of K sets (K >= 1), the way a stepped state records
//   vsd_lifecycle_count load N [build-only]
//                                    builds and saves a model of N instances (binary), then loads it
//                                    (not with build-only)
//
// Instructions per operation = (count for N - count for 0) / N, and per loaded instance
// (count of "load N" - count of "load N build-only") / N; benchmarks/README.md shows how.
#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <string_view>
#include <vector>

#include "fixture.hpp"
#include "vsd/core/meta_type_eigen.hpp"
#include "vsd/io.hpp"

/// What a moving body's recording writes most: its frame, and a scalar beside it.
class Framed : public vsd::Node {
  VSD_INSTANCE(Framed, vsd::Node)
  VSD_PROPERTY(Eigen::Isometry3d, frame, Eigen::Isometry3d::Identity())
  VSD_PROPERTY(double, speed, 0.0)
};

namespace {

int usage() {
  std::fprintf(stderr, "usage: vsd_lifecycle_count create|runtime|load N, or emit|record N K\n");
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
  } else if (mode == "record" && argc > 3) {
    const long k = std::max(1L, std::atol(argv[3]));
    Framed& f = st.create<Framed>();
    st.start_recording();
    std::size_t ops = 0;
    Eigen::Isometry3d x = Eigen::Isometry3d::Identity();
    for (long i = 0; i < n; ++i) {
      if (i % 2 == 0) {
        x.translation().x() = bench::value(static_cast<std::size_t>(i));
        f.set_frame(x);
      } else {
        f.set_speed(bench::value(static_cast<std::size_t>(i)));
      }
      if ((i + 1) % k == 0) ops += st.take_recording().size();
    }
    ops += st.stop_recording().size();
    if (ops != static_cast<std::size_t>(n)) return std::fprintf(stderr, "sets missing\n"), 1;
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
