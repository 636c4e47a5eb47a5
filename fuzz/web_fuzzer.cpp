// Fuzzes what the inspector does with a request (vsd::web, docs/web.md) once HTTP delivered it: any path,
// query and body must get an answer (2xx or 4xx with a JSON error), never a crash, a hang or a sanitizer
// report; and a refused write must change nothing (the state is compared with a copy made before).
//
// Input: the first byte picks the endpoint, the rest up to the first '\n' is the query ("k=v&k=v") or is
// ignored for writes, and what follows is the body.
#include <cstdint>
#include <cstdlib>
#include <string>
#include <string_view>

#include "vsd/scene.hpp"
#include "vsd/soml.hpp"
#include "vsd/web.hpp"
#include "web/feed.hpp"
#include "web/inspector.hpp"

namespace {

constexpr const char* script = R"(
object cell {
  int done = 0;
  place ready = 2;
  place finished;
  transition work { do { done += 1; } }
  arrow ready -> work;
  arrow work -> finished;
}
)";

constexpr std::string_view endpoints[] = {
    "GET /api/info",     "GET /api/classes",   "GET /api/children", "GET /api/table",  "GET /api/instance",
    "GET /api/scene",    "GET /api/mesh",      "GET /api/nets",     "GET /api/timeline", "POST /api/set",
    "POST /api/call",    "POST /api/fire",     "POST /api/pause",   "GET /api/nothing", "POST /api/nothing",
    // The SOML++ debugger (a stop continues at once: nobody serves it here).
    "GET /api/debug", "GET /api/debug/source", "GET /api/debug/locals", "GET /api/debug/print", "GET /api/trace",
    "POST /api/debug/break", "POST /api/debug/remove", "POST /api/debug/resume", "POST /api/debug/pause"};

std::vector<std::pair<std::string, std::string>> parse_query(std::string_view q) {
  std::vector<std::pair<std::string, std::string>> out;
  while (!q.empty()) {
    const std::size_t amp = q.find('&');
    const std::string_view kv = q.substr(0, amp);
    const std::size_t eq = kv.find('=');
    out.emplace_back(std::string(kv.substr(0, eq)), eq == std::string_view::npos ? "" : std::string(kv.substr(eq + 1)));
    if (amp == std::string_view::npos) break;
    q.remove_prefix(amp + 1);
  }
  return out;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  vsd::Environment env;
  env.use<vsd::scene::Module>();
  auto& soml = env.use<vsd::soml::Module>();
  vsd::SimState& s = env.main_state();
  auto& node = s.create<vsd::scene::Node3D>();
  node.set_name("box");
  s.database().add_child(node);
  auto& hull = s.create<vsd::scene::Hull>();
  auto& g = s.create<vsd::scene::Geometry>();
  g.set_kind(vsd::scene::GeometryKind::Mesh);
  g.set_vertices({Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(1, 0, 0), Eigen::Vector3d(0, 1, 0)});
  g.set_facets({0, 1, 2, 7, -1, 0});  // one sound triangle, one damaged
  hull.set_geometry(&g);
  node.add_child(hull);
  auto& link = s.create<vsd::scene::Link>();
  s.database().add_child(link);
  soml.load(s, "web_fuzz.soml", script);

  vsd::web::Options options;
  options.timeline_bytes = 0;  // the fuzzer compares states; the timeline's seeks are tested in ctest
  vsd::web::detail::Feed feed(4);
  vsd::web::detail::Inspector inspector(env, s, options, feed);
  vsd::SimState& before = env.create_state("before");
  before.copy_from(s);

  const std::string_view endpoint = endpoints[(data[0] & 0x7f) % std::size(endpoints)];
  const std::string_view rest(reinterpret_cast<const char*>(data + 1), size - 1);
  const std::size_t nl = rest.find('\n');
  vsd::web::detail::Request r;
  r.method = std::string(endpoint.substr(0, endpoint.find(' ')));
  r.path = std::string(endpoint.substr(endpoint.find(' ') + 1));
  r.query = parse_query(rest.substr(0, nl));
  r.body = nl == std::string_view::npos ? std::string() : std::string(rest.substr(nl + 1));
  r.writable = (data[0] & 0x80) != 0;
  const vsd::web::detail::Reply reply = inspector.handle(r);
  if (reply.status < 200 || reply.status >= 500 || reply.body.empty()) std::abort();
  if (reply.status >= 400 && r.method == "POST" && !s.equals(before)) std::abort();  // refused: no change
  return 0;
}
