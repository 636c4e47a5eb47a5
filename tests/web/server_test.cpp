// vsd::web::Server over real sockets: reads generated from the meta-information, edits through the
// setters (and refused ones that change nothing), the security rules, the timeline, the nets' fire
// button and the event stream.
#include <filesystem>
#include <fstream>
#include <thread>

#include "web_fixture.hpp"

namespace {

using namespace vsd_web_test;
using vsd::scene::Geometry;
using vsd::scene::GeometryKind;
using vsd::scene::Hull;
using vsd::scene::Link;
using vsd::scene::Material;
using vsd::scene::Node3D;

class Server : public WebTest {
 protected:
  Node3D* box = nullptr;
  Hull* hull = nullptr;
  Link* link = nullptr;

  void build_scene() {
    box = &state.create<Node3D>();
    box->set_name("box");
    state.database().add_child(*box);
    hull = &state.create<Hull>();
    hull->set_name("box hull");
    auto& g = state.create<Geometry>();
    g.set_kind(GeometryKind::Box);
    g.set_size(Eigen::Vector3d(1, 2, 3));
    auto& m = state.create<Material>();
    m.set_color(Eigen::Vector4d(1, 0, 0, 1));
    hull->set_geometry(&g);
    hull->set_material(&m);
    box->add_child(*hull);
    link = &state.create<Link>();
    link->set_name("link");
    link->set_mass(2.5);
    state.database().add_child(*link);
  }
};

TEST_F(Server, InfoSaysWhetherTheRequestMayWrite) {
  start();
  const HttpReply r = get("/api/info");
  ASSERT_EQ(r.status, 200) << r.body;
  EXPECT_EQ(member(r.body, "writable"), "false");
  EXPECT_EQ(member(r.body, "state"), "\"main\"");
  const HttpReply w = send(http_text("GET", "/api/info", host(), "", {"X-VSD-Token: " + server->token()}));
  EXPECT_EQ(member(w.body, "writable"), "true");
  EXPECT_EQ(server->token().size(), 32U);
}

TEST_F(Server, TreeAndInstanceComeFromTheMetaInformation) {
  build_scene();
  start();
  const HttpReply c = get("/api/children");
  ASSERT_EQ(c.status, 200) << c.body;
  const auto kids = items(c.body, "children");
  ASSERT_EQ(kids.size(), 2U);
  EXPECT_EQ(member(kids[0], "name"), "\"box\"");
  EXPECT_EQ(member(kids[0], "class"), "\"scene::Node3D\"");
  EXPECT_EQ(member(kids[0], "children"), "1");

  const HttpReply i = get("/api/instance?id=" + std::to_string(link->id()));
  ASSERT_EQ(i.status, 200) << i.body;
  bool saw_mass = false;
  for (const auto& p : items(i.body, "properties")) {
    if (member(p, "name") != "\"mass\"") continue;
    saw_mass = true;
    EXPECT_EQ(member(p, "type"), "\"double\"");
    EXPECT_EQ(member(p, "value"), "2.5");
    EXPECT_EQ(member(p, "editable"), "true");
  }
  EXPECT_TRUE(saw_mass);

  const HttpReply classes = get("/api/classes");
  ASSERT_EQ(classes.status, 200);
  bool saw_link = false;
  for (const auto& cls : elements(classes.body))
    if (member(cls, "name") == "\"scene::Link\"") {
      saw_link = true;
      EXPECT_EQ(member(cls, "base"), "\"scene::Node3D\"");
      EXPECT_EQ(member(cls, "count"), "1");
    }
  EXPECT_TRUE(saw_link);
}

TEST_F(Server, AnEditGoesThroughTheSetterAndIsRecorded) {
  build_scene();
  start();
  const HttpReply r = post("/api/set", R"({"id": )" + std::to_string(link->id()) + R"(, "property": "mass", "value": 4})");
  ASSERT_EQ(r.status, 200) << r.body;
  EXPECT_EQ(member(r.body, "value"), "4");
  EXPECT_DOUBLE_EQ(link->mass(), 4.0);
  // The edit is an entry of the timeline, like a step.
  const HttpReply t = get("/api/timeline");
  ASSERT_FALSE(items(t.body, "entries").empty());
}

TEST_F(Server, ABadValueIsRefusedWithPropertyAndTypeAndChangesNothing) {
  build_scene();
  start();
  const std::string id = std::to_string(link->id());
  const HttpReply r = post("/api/set", R"({"id": )" + id + R"(, "property": "mass", "value": "heavy"})");
  EXPECT_EQ(r.status, 400);
  const std::string error = member(r.body, "error");
  EXPECT_NE(error.find("mass"), std::string::npos) << error;
  EXPECT_NE(error.find("double"), std::string::npos) << error;
  EXPECT_DOUBLE_EQ(link->mass(), 2.5);

  // A frame with a wrong shape, a property that is not there, one that is not editable, an unknown id.
  EXPECT_EQ(post("/api/set", R"({"id": )" + std::to_string(box->id()) + R"(, "property": "frame", "value": [1, 2]})").status, 400);
  const HttpReply none = post("/api/set", R"({"id": )" + id + R"(, "property": "colour", "value": 1})");
  EXPECT_EQ(none.status, 400);
  EXPECT_NE(member(none.body, "error").find("no property 'colour'"), std::string::npos);
  const HttpReply ro = post("/api/set", R"({"id": )" + id + R"(, "property": "children", "value": []})");
  EXPECT_EQ(ro.status, 400);
  EXPECT_NE(member(ro.body, "error").find("not editable"), std::string::npos);
  EXPECT_EQ(post("/api/set", R"({"id": 999999, "property": "mass", "value": 1})").status, 400);
  EXPECT_DOUBLE_EQ(link->mass(), 2.5);
}

TEST_F(Server, MalformedRequestsGet4xxAndChangeNothing) {
  build_scene();
  start();
  const std::string id = std::to_string(link->id());
  for (const std::string& body : {std::string("{"), std::string("[1]"), std::string("{\"id\": 1, \"id\": 2}"),
                                 std::string(100000, '['), std::string("{\"id\": -3, \"property\": \"mass\", \"value\": 1}"),
                                 std::string("{\"id\": \"x\", \"property\": \"mass\", \"value\": 1}"),
                                 std::string("{\"id\": " + id + ", \"property\": 5, \"value\": 1}"),
                                 std::string("{\"id\": " + id + ", \"property\": \"mass\"}"),
                                 std::string("{\"id\": " + id + ", \"property\": \"mass\", \"value\": 1} trailing")}) {
    const HttpReply r = post("/api/set", body);
    EXPECT_EQ(r.status, 400) << body.substr(0, 60) << " -> " << r.body;
    EXPECT_FALSE(member(r.body, "error").empty());
  }
  EXPECT_DOUBLE_EQ(link->mass(), 2.5);
  EXPECT_EQ(get("/api/instance?id=abc").status, 400);
  EXPECT_EQ(get("/api/instance").status, 400);
  EXPECT_EQ(get("/api/nothing").status, 404);
  EXPECT_EQ(get("/api/children?id=" + std::to_string(hull->geometry()->id())).status, 400);  // no Node
}

TEST_F(Server, OversizedBodiesAreRefused) {
  vsd::web::Options o;
  o.max_body = 1000;
  start(o);
  const HttpReply r = post("/api/pause", "{\"paused\": true, \"pad\": \"" + std::string(5000, 'x') + "\"}");
  EXPECT_EQ(r.status, 413);
  EXPECT_FALSE(server->paused());
}

TEST_F(Server, WritesNeedTheToken) {
  build_scene();
  start();
  const std::string body = R"({"id": )" + std::to_string(link->id()) + R"(, "property": "mass", "value": 9})";
  EXPECT_EQ(post("/api/set", body, false).status, 403);
  EXPECT_EQ(post("/api/set", body, false, {"X-VSD-Token: " + std::string(32, '0')}).status, 403);
  EXPECT_EQ(post("/api/set", body, false, {"X-VSD-Token: " + server->token().substr(0, 31)}).status, 403);
  // The token in the URL is no token.
  EXPECT_EQ(send(http_text("POST", "/api/set?token=" + server->token(), host(), body, {})).status, 403);
  EXPECT_DOUBLE_EQ(link->mass(), 2.5);
}

TEST_F(Server, ForeignHostsAndOriginsAreRefused) {
  build_scene();
  start();
  const std::string port = std::to_string(server->port());
  EXPECT_EQ(send(http_text("GET", "/api/info", "evil.example:" + port, "", {})).status, 403);
  EXPECT_EQ(send(http_text("GET", "/api/info", "evil.example", "", {})).status, 403);
  EXPECT_EQ(send(http_text("GET", "/api/info", "10.0.0.1:" + port, "", {})).status, 403);  // not loopback
  EXPECT_EQ(send(http_text("GET", "/api/info", "localhost:" + port, "", {})).status, 200);
  EXPECT_EQ(send("GET /api/info HTTP/1.0\r\n\r\n").status, 403);  // no Host at all
  const std::string body = R"({"id": )" + std::to_string(link->id()) + R"(, "property": "mass", "value": 9})";
  EXPECT_EQ(post("/api/set", body, true, {"Origin: http://evil.example"}).status, 403);
  EXPECT_DOUBLE_EQ(link->mass(), 2.5);
  EXPECT_EQ(post("/api/set", body, true, {"Origin: http://" + host()}).status, 200);
  EXPECT_DOUBLE_EQ(link->mass(), 9.0);
}

TEST_F(Server, ANonLoopbackAddressNeedsAToken) {
  vsd::web::Options o;
  o.bind = "0.0.0.0";
  o.port = 0;
  vsd::web::Server s(env, state, o);
  EXPECT_THROW(s.start(), vsd::Error);
  o.token = "a-long-enough-token";
  vsd::web::Server t(env, state, o);
  EXPECT_NO_THROW(t.start());
  EXPECT_TRUE(t.listening());
}

TEST_F(Server, ABusyPortIsAnError) {
  start();
  vsd::web::Options o;
  o.port = server->port();
  vsd::web::Server second(env, state, o);
  EXPECT_THROW(second.start(), vsd::Error);
}

TEST_F(Server, ARequestNobodyServesTimesOut) {
  vsd::web::Options o;
  o.request_timeout = std::chrono::milliseconds(100);
  start(o);
  const HttpReply r = raw_http(server->port(), http_text("GET", "/api/info", host(), "", {}));  // nobody serves
  EXPECT_EQ(r.status, 503);
  server->serve_for(std::chrono::milliseconds(1));  // the cancelled job does not run late
}

TEST_F(Server, TheSceneHasFramesShapesAndColours) {
  build_scene();
  box->set_frame(Eigen::Isometry3d(Eigen::Translation3d(1, 2, 3)));
  start();
  const HttpReply r = get("/api/scene");
  ASSERT_EQ(r.status, 200) << r.body;
  const auto hulls = items(r.body, "hulls");
  ASSERT_EQ(hulls.size(), 1U);
  EXPECT_EQ(member(hulls[0], "node"), std::to_string(box->id()));
  EXPECT_EQ(member(member(hulls[0], "shape"), "kind"), "\"Box\"");
  EXPECT_EQ(member(member(hulls[0], "shape"), "size"), "[1,2,3]");
  EXPECT_EQ(member(hulls[0], "color"), "[1,0,0,1]");
  const auto world = items(hulls[0], "world");
  ASSERT_EQ(world.size(), 16U);
  EXPECT_EQ(world[12], "1");  // column-major: the translation is the last column
  EXPECT_EQ(world[13], "2");
  EXPECT_EQ(world[14], "3");
  EXPECT_EQ(get("/api/mesh?id=" + std::to_string(box->id())).status, 400);  // not a Geometry
}

TEST_F(Server, TablesFilterAndPageByIdOverManyInstances) {
  for (int i = 0; i < 5000; ++i) {
    auto& l = state.create<Link>();
    l.set_name("l" + std::to_string(i));
    l.set_mass(i % 10);
    state.database().add_child(l);
  }
  start();
  const HttpReply r = get("/api/table?class=scene::Link&where=mass%20%3E%3D%208&offset=10&limit=5");
  ASSERT_EQ(r.status, 200) << r.body;
  EXPECT_EQ(member(r.body, "total"), "1000");
  const auto rows = items(r.body, "rows");
  ASSERT_EQ(rows.size(), 5U);
  EXPECT_LT(std::stoull(member(rows[0], "id")), std::stoull(member(rows[1], "id")));
  EXPECT_EQ(member(member(rows[0], "values"), "mass"), "8");
  const HttpReply named = get("/api/table?class=scene::Link&where=name%20~%20l499&limit=100");
  EXPECT_EQ(member(named.body, "total"), "11");  // l499, l4990..l4999
  EXPECT_EQ(get("/api/table?class=scene::Link&where=mass%20%3E%20heavy").status, 400);
  EXPECT_EQ(get("/api/table?class=scene::Link&where=weight%20%3E%201").status, 400);
  EXPECT_EQ(get("/api/table?class=NoSuchClass").status, 400);
  EXPECT_EQ(get("/api/table?class=scene::Link&limit=-1").status, 400);
  EXPECT_EQ(items(get("/api/table?class=scene::Link&limit=999999").body, "rows").size(), 1000U);  // capped
}

TEST_F(Server, MethodsAreCalledThroughTheirMetaMethods) {
  start();
  const std::string env_id = std::to_string(state.database().id());
  // The Database has no method "frobnicate"; a call is refused by name.
  const HttpReply r = post("/api/call", R"({"id": )" + env_id + R"(, "method": "frobnicate", "args": []})");
  EXPECT_EQ(r.status, 400);
  EXPECT_NE(member(r.body, "error").find("frobnicate"), std::string::npos);
}

TEST_F(Server, TheTimelineScrubsBackAndForwardAndForksOnAnEdit) {
  build_scene();
  start();
  const std::string id = std::to_string(link->id());
  server->serve_for(std::chrono::milliseconds(1));  // the construction is entry 0
  for (int m = 10; m <= 30; m += 10) {
    link->set_mass(m);
    env.step();  // the outputs task cuts an entry per step
  }
  const HttpReply t = get("/api/timeline");
  const std::uint64_t end = std::stoull(member(t.body, "end"));
  ASSERT_GE(end, 3U);
  EXPECT_EQ(member(t.body, "live"), "true");
  ASSERT_EQ(post("/api/timeline/seek", "{\"index\": " + std::to_string(end - 2) + "}").status, 200);
  EXPECT_DOUBLE_EQ(link->mass(), 10.0);
  EXPECT_TRUE(server->paused());
  ASSERT_EQ(post("/api/timeline/seek", "{\"index\": " + std::to_string(end - 1) + "}").status, 200);
  EXPECT_DOUBLE_EQ(link->mass(), 20.0);
  EXPECT_EQ(post("/api/timeline/seek", "{\"index\": " + std::to_string(end + 5) + "}").status, 400);
  EXPECT_DOUBLE_EQ(link->mass(), 20.0);
  // An edit in the past forks: the entry with 30 is gone, and the edit is the newest entry.
  ASSERT_EQ(post("/api/set", R"({"id": )" + id + R"(, "property": "mass", "value": 25})").status, 200);
  const HttpReply after = get("/api/timeline");
  EXPECT_EQ(member(after.body, "live"), "true");
  EXPECT_EQ(std::stoull(member(after.body, "end")), end);
  ASSERT_EQ(post("/api/timeline/seek", "{\"index\": " + std::to_string(end - 1) + "}").status, 200);
  EXPECT_DOUBLE_EQ(link->mass(), 20.0);
  ASSERT_EQ(post("/api/timeline/live", "{}").status, 200);
  EXPECT_DOUBLE_EQ(link->mass(), 25.0);
  EXPECT_FALSE(server->paused());
}

TEST_F(Server, WithTheTimelineOffNothingIsRecordedAndSeekIsRefused) {
  build_scene();
  vsd::web::Options o;
  o.timeline_bytes = 0;
  start(o);
  EXPECT_FALSE(state.recording());
  link->set_mass(3);
  env.step();
  const HttpReply t = get("/api/timeline");
  EXPECT_EQ(member(t.body, "enabled"), "false");
  EXPECT_TRUE(items(t.body, "entries").empty());
  const HttpReply seek = post("/api/timeline/seek", "{\"index\": 0}");
  EXPECT_EQ(seek.status, 400);
  EXPECT_NE(member(seek.body, "error").find("off"), std::string::npos);
  EXPECT_DOUBLE_EQ(link->mass(), 3.0);
}

constexpr const char* cell_script = R"(
object webcell {
  int done = 0;
  place ready = 2;
  place finished;
  transition work { do { done += 1; } }
  arrow ready -> work;
  arrow work -> finished;
}
)";

TEST_F(Server, TheFireButtonFiresAnEnabledTransitionOnly) {
  auto& soml = env.use<vsd::soml::Module>();
  vsd::soml::Program& p = soml.load(state, "cell.soml", cell_script);
  start();
  HttpReply nets = get("/api/nets");
  ASSERT_EQ(nets.status, 200) << nets.body;
  const auto list = items(nets.body, "nets");
  ASSERT_EQ(list.size(), 1U);
  const auto transitions = items(list[0], "transitions");
  ASSERT_EQ(transitions.size(), 1U);
  EXPECT_EQ(member(transitions[0], "enabled"), "true");
  const std::string work = member(transitions[0], "id");
  EXPECT_EQ(items(list[0], "arrows").size(), 2U);

  ASSERT_EQ(post("/api/fire", "{\"transition\": " + work + "}").status, 200);
  ASSERT_EQ(post("/api/fire", "{\"transition\": " + work + "}").status, 200);
  ASSERT_NE(p.object("webcell"), nullptr);
  EXPECT_EQ(p.place("finished", p.object("webcell"))->count(), 2);
  const HttpReply refused = post("/api/fire", "{\"transition\": " + work + "}");
  EXPECT_EQ(refused.status, 400);
  EXPECT_NE(member(refused.body, "error").find("not enabled"), std::string::npos);
  EXPECT_EQ(p.firings(), 2U);
  nets = get("/api/nets");
  const auto places = items(items(nets.body, "nets")[0], "places");
  EXPECT_EQ(member(places[0], "tokens"), "0");  // ready
  EXPECT_EQ(post("/api/fire", "{\"transition\": " + std::to_string(state.database().id()) + "}").status, 400);
}

TEST_F(Server, ChangesArePushedToTheEventStreamWithWorldFrames) {
  build_scene();
  start();
  std::atomic<bool> connected{false};
  auto events = std::async(std::launch::async, [&, port = server->port(), h = host()] {
    return read_events(port, h, "\"frames\":[{", connected);
  });
  while (!connected) server->serve_for(std::chrono::milliseconds(2));
  box->set_frame(Eigen::Isometry3d(Eigen::Translation3d(0, 0, 7)));
  while (events.wait_for(std::chrono::milliseconds(0)) != std::future_status::ready)
    server->serve_for(std::chrono::milliseconds(5));
  const std::string all = events.get();
  EXPECT_NE(all.find("text/event-stream"), std::string::npos);
  EXPECT_NE(all.find("event: hello"), std::string::npos);
  EXPECT_NE(all.find("event: changes"), std::string::npos);
  EXPECT_NE(all.find("\"property\":\"frame\""), std::string::npos);
  // The hull below the box moved too: its world frame travels although its own frame did not change.
  EXPECT_NE(all.find("{\"id\":" + std::to_string(hull->id()) + ",\"world\":"), std::string::npos) << all;
}

TEST_F(Server, OnlyThePagesOwnFilesAreServed) {
  namespace fs = std::filesystem;
  const fs::path dir = fs::temp_directory_path() / ("vsd_web_assets_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir / "app");
  std::ofstream(dir / "index.html") << "<!doctype html><title>vsd</title>";
  std::ofstream(dir / "app" / "main.js") << "export {};";
  std::ofstream(dir / ".hidden") << "secret";
  fs::create_symlink("/etc/passwd", dir / "app" / "passwd.js");  // a link that leads out of the folder
  vsd::web::Options o;
  o.port = 0;
  o.assets = dir.string();
  server = std::make_unique<vsd::web::Server>(env, state, o);
  server->start();
  const HttpReply index = get("/");
  EXPECT_EQ(index.status, 200);
  EXPECT_NE(index.body.find("<title>vsd</title>"), std::string::npos);
  EXPECT_NE(index.head.find("text/html"), std::string::npos);
  EXPECT_EQ(get("/app/main.js").status, 200);
  for (const char* path : {"/app/passwd.js", "/.hidden", "/../../../../etc/passwd", "/app/../../etc/passwd",
                           "/%2e%2e/%2e%2e/etc/passwd", "/app", "/nothing.html"}) {
    const HttpReply r = get(path);
    EXPECT_NE(r.status, 200) << path;
    EXPECT_EQ(r.body.find("root:"), std::string::npos) << path;
  }
  server.reset();
  fs::remove_all(dir);
}

TEST_F(Server, StopEndsRunFromAnotherThread) {
  start();
  std::thread stopper([&] {
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
    server->stop();
  });
  server->pause(false);
  server->run();  // steps in real time until stop()
  stopper.join();
  EXPECT_FALSE(server->listening());
  EXPECT_GT(env.scheduler().steps(), 0U);
}

}  // namespace
