// vsd::web: what the inspector costs the simulation and how fast it answers (benchmarks/README.md,
// "The inspector in the browser"). Clients are raw sockets in threads of their own, as a browser's
// connections would be; the simulation runs where a program runs it (the benchmark's thread, or a thread
// of its own calling Server::run()).
#include <benchmark/benchmark.h>

#include <algorithm>
#include <atomic>
#include <condition_variable>
#include <fstream>
#include <mutex>
#include <thread>
#include <vector>

#include "../tests/web/http_client.hpp"
#include "vsd/core.hpp"
#include "vsd/scene.hpp"
#include "vsd/web.hpp"
#include "web_inspected.hpp"
#ifdef VSD_BENCH_WEB_PHYSICS
#include "physics_scene.hpp"
#endif

namespace {

using vsd_bench::host_of;
using vsd_bench::Inspected;
using vsd_bench::StreamReader;
using vsd_web_test::http_text;
using vsd_web_test::raw_http;


/// A cell-sized scene: @p n boxes (a Node3D with a box hull each) that move every step.
std::vector<vsd::scene::Node3D*> boxes(vsd::SimState& s, int n) {
  std::vector<vsd::scene::Node3D*> out;
  auto& g = s.create<vsd::scene::Geometry>();
  g.set_kind(vsd::scene::GeometryKind::Box);
  g.set_size(Eigen::Vector3d(0.1, 0.1, 0.1));
  for (int i = 0; i < n; ++i) {
    auto& node = s.create<vsd::scene::Node3D>();
    auto& hull = s.create<vsd::scene::Hull>();
    hull.set_geometry(&g);
    node.add_child(hull);
    s.database().add_child(node);
    out.push_back(&node);
  }
  return out;
}

std::size_t resident_bytes() {
  std::ifstream statm("/proc/self/statm");
  std::size_t pages = 0, resident = 0;
  statm >> pages >> resident;
  return resident * static_cast<std::size_t>(::sysconf(_SC_PAGESIZE));
}

// One step of a cell of 200 moving boxes: without a server (arg 0), with a server and one page connected
// to its event stream (arg 1), and the same with the timeline off (arg 2: Options::timeline_bytes = 0).
// The ratio is the inspector's overhead per step: recording the changes (for the timeline), the Watch of
// every class, and a pushed batch 30 times a second.
void BM_WebStep(benchmark::State& st) {
  vsd::Environment env;
  env.use<vsd::scene::Module>();
  auto& s = env.main_state();
  const auto nodes = boxes(s, 200);
  Inspected inspected(env, s, st.range(0));
  auto& server = inspected.server;
  auto& page = inspected.page;
  double z = 0;
  for (auto _ : st) {
    z += 0.001;
    for (std::size_t i = 0; i < nodes.size(); ++i)
      nodes[i]->set_frame(Eigen::Isometry3d(Eigen::Translation3d(static_cast<double>(i), 0, z)));
    env.step();
    benchmark::DoNotOptimize(nodes.back()->world_frame());
  }
  if (server) {
    st.counters["batches"] = static_cast<double>(server->stats().batches);
    st.counters["page_MB"] = static_cast<double>(page->bytes()) / 1e6;
  }
}
BENCHMARK(BM_WebStep)->Arg(0)->Arg(1)->Arg(2)->Unit(benchmark::kMicrosecond);

#ifdef VSD_BENCH_WEB_PHYSICS
// The same three cases on a step that does real work: the physics benchmark's 200 bodies resting on a
// plane (bench_physics.cpp, about 500 contacts; every pose and velocity written back through the setters).
void BM_WebPhysicsStep(benchmark::State& st) {
  vsd_bench_physics::VsdScene scene;
  auto& s = scene.env.main_state();
  Inspected inspected(scene.env, s, st.range(0));
  auto& server = inspected.server;
  for (auto _ : st) {
    scene.env.step();
    benchmark::DoNotOptimize(scene.hulls.back()->frame());
  }
  if (scene.sim->stats().bodies != vsd_bench_physics::body_count) st.SkipWithError("not all bodies simulated");
  if (server) st.counters["batches"] = static_cast<double>(server->stats().batches);
}
BENCHMARK(BM_WebPhysicsStep)->Arg(0)->Arg(1)->Arg(2)->Unit(benchmark::kMicrosecond);
#endif

// Edit -> database -> page: a POST /api/set from one thread until the page's event stream shows the new
// value, while the simulation steps at 1 kHz in real time on its own thread. Manual time; p50 and p95 of
// the iterations as counters (milliseconds).
void BM_WebEditToPage(benchmark::State& st) {
  vsd::Environment env;
  env.use<vsd::scene::Module>();
  env.scheduler().set_base_step(0.001);
  auto& s = env.main_state();
  auto& link = s.create<vsd::scene::Link>();
  s.database().add_child(link);
  (void)boxes(s, 50);
  vsd::web::Options o;
  o.port = 0;
  vsd::web::Server server(env, s, o);
  server.start();
  std::mutex m;
  std::condition_variable seen;
  std::string tail;  // what the page received lately
  StreamReader page(server, [&](std::string_view data) {
    std::lock_guard lock(m);
    tail.append(data);
    if (tail.size() > (1U << 16)) tail.erase(0, tail.size() - (1U << 15));
    seen.notify_all();
  });
  server.pause(false);
  std::thread sim([&] { server.run(); });
  const std::string id = std::to_string(link.id());
  std::vector<double> ms;
  int k = 0;
  for (auto _ : st) {
    ++k;
    const std::string value = std::to_string(1000 + k) + ".5";
    const std::string body = R"({"id": )" + id + R"(, "property": "mass", "value": )" + value + "}";
    const std::string marker = "\"property\":\"mass\",\"value\":" + value;
    const auto t0 = std::chrono::steady_clock::now();
    const auto reply = raw_http(server.port(), http_text("POST", "/api/set", host_of(server), body,
                                                         {"X-VSD-Token: " + server.token()}));
    std::unique_lock lock(m);
    const bool ok = seen.wait_for(lock, std::chrono::seconds(5), [&] { return tail.find(marker) != std::string::npos; });
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    lock.unlock();
    if (reply.status != 200 || !ok) {
      st.SkipWithError("the edit did not reach the page");
      break;
    }
    ms.push_back(seconds * 1e3);
    st.SetIterationTime(seconds);
  }
  server.stop();
  sim.join();
  if (!ms.empty()) {
    std::sort(ms.begin(), ms.end());
    st.counters["p50_ms"] = ms[ms.size() / 2];
    st.counters["p95_ms"] = ms[std::min(ms.size() - 1, ms.size() * 95 / 100)];
  }
}
BENCHMARK(BM_WebEditToPage)->UseManualTime()->Unit(benchmark::kMillisecond)->Iterations(200);

// What the page fetches before its first paint of a state of 100,000 nodes: the classes, the first 200
// children of the Database and the first 100 rows of the nodes' table (only visible rows travel).
void BM_WebFirstPaintRequests(benchmark::State& st) {
  vsd::Environment env;
  auto& s = env.main_state();
  for (int i = 0; i < 100'000; ++i) {
    auto& n = s.create<vsd::Node>();
    n.set_name("n" + std::to_string(i));
    s.database().add_child(n);
  }
  vsd::web::Options o;
  o.port = 0;
  vsd::web::Server server(env, s, o);
  server.start();
  std::thread sim([&] { server.run(); });  // paused: serves
  std::size_t bytes = 0;
  for (auto _ : st) {
    for (const char* path : {"/api/info", "/api/classes", "/api/children?limit=200", "/api/table?class=Node&limit=100"}) {
      const auto r = raw_http(server.port(), http_text("GET", path, host_of(server), "", {}));
      if (r.status != 200) st.SkipWithError(path);
      bytes += r.body.size();
    }
  }
  server.stop();
  sim.join();
  st.counters["KB_per_paint"] = static_cast<double>(bytes) / 1e3 / static_cast<double>(st.iterations());
}
BENCHMARK(BM_WebFirstPaintRequests)->Unit(benchmark::kMillisecond);

// 10,000 properties changed per step, pushed to four pages at (at most) 30 batches a second, with the
// simulation stepping as fast as it can: bytes pushed, batches dropped for slow pages, and the growth of
// the process's resident memory over the run (it must stay flat: the feed drops rather than queues).
void BM_WebPush10kToFourPages(benchmark::State& st) {
  vsd::Environment env;
  auto& s = env.main_state();
  std::vector<vsd::scene::Link*> links;
  for (int i = 0; i < 10'000; ++i) {
    auto& l = s.create<vsd::scene::Link>();
    s.database().add_child(l);
    links.push_back(&l);
  }
  double mass = 0;
  env.scheduler().add_periodic("change 10k", env.scheduler().base_step(), [&](const vsd::StepInfo&) {
    mass += 1;
    for (auto* l : links) l->set_mass(mass);
  });
  vsd::web::Options o;
  o.port = 0;
  o.real_time_factor = 0;  // as fast as it goes
  o.timeline_bytes = std::size_t{16} << 20;
  vsd::web::Server server(env, s, o);
  server.start();
  std::vector<std::unique_ptr<StreamReader>> pages;
  for (int i = 0; i < 4; ++i) pages.push_back(std::make_unique<StreamReader>(server, [](std::string_view) {}));
  while (server.stats().clients < 4) server.serve_for(std::chrono::milliseconds(1));
  for (int i = 0; i < 50; ++i) env.step();  // the timeline fills up to its cap first
  const std::size_t rss0 = resident_bytes();
  std::uint64_t steps = 0;
  for (auto _ : st) {
    for (int i = 0; i < 100; ++i) env.step();
    steps += 100;
  }
  const std::size_t rss1 = resident_bytes();
  std::size_t bytes = 0;
  for (const auto& p : pages) bytes += p->bytes();
  st.counters["steps_per_s"] = benchmark::Counter(static_cast<double>(steps), benchmark::Counter::kIsRate);
  st.counters["pushed_MB"] = static_cast<double>(bytes) / 1e6;
  st.counters["batches"] = static_cast<double>(server.stats().batches);
  st.counters["dropped"] = static_cast<double>(server.stats().dropped);
  st.counters["rss_growth_MB"] = (static_cast<double>(rss1) - static_cast<double>(rss0)) / 1e6;
  pages.clear();
}
BENCHMARK(BM_WebPush10kToFourPages)->Unit(benchmark::kMillisecond)->Iterations(20);

}  // namespace

BENCHMARK_MAIN();
