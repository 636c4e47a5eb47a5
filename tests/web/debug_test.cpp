// The SOML++ debugger and the token trace through the inspector's API (src/web/debug_view.hpp): a stop
// blocks the simulation thread inside the program's run while the page reads the stack and the locals
// and resumes it; writes are refused while stopped; the trace lists every firing; bad requests get 4xx.
#include <future>
#include <thread>

#include "web_fixture.hpp"

namespace vsd_web_test {
namespace {

// Line numbers matter: the tests set breakpoints on them.
constexpr const char* debug_script = R"(int twice(int n) {
  int r = n * 2;
  return r;
}

object debugcell {
  int done = 0;
  place ready = 2;
  place finished;
  transition work {
    do {
      done += twice(1);
    }
  }
  arrow ready -> work;
  arrow work -> finished;
}
)";

class Debug : public WebTest {
 protected:
  vsd::soml::Program* program = nullptr;

  void load(vsd::SimState& into) {
    program = &env.use<vsd::soml::Module>().load(into, "webcell.soml", debug_script);
  }
  [[nodiscard]] vsd::Node* cell() const { return program->object("debugcell"); }
  [[nodiscard]] std::int64_t done() const { return cell()->get("done").as<std::int64_t>(); }

  // The page's side, from a thread of its own (the test thread is stopped inside the program then).
  HttpReply page_get(const std::string& path) { return raw_http(server->port(), http_text("GET", path, host(), "", {})); }
  HttpReply page_post(const std::string& path, const std::string& body) {
    return raw_http(server->port(), http_text("POST", path, host(), body, {"X-VSD-Token: " + server->token()}));
  }
  /// Asks /api/debug until a program is stopped; returns the stop (JSON), or "null" after 5 s.
  std::string wait_for_stop() {
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(5);
    while (std::chrono::steady_clock::now() < deadline) {
      const HttpReply r = page_get("/api/debug");
      if (r.status == 200 && member(r.body, "stopped") != "null") return member(r.body, "stopped");
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
    }
    return "null";
  }

  /// Steps the environment here, the simulation thread, while @p page plays the page on another thread.
  /// A page that fails or leaves the program stopped gets the server stopped (the step then ends).
  void step_with_page(const std::function<void()>& page) {
    std::atomic<bool> stepped{false};
    auto f = std::async(std::launch::async, [&] {
      try {
        page();
      } catch (...) {
        server->stop();
        throw;
      }
      for (int i = 0; i < 400 && !stepped; ++i) std::this_thread::sleep_for(std::chrono::milliseconds(5));
      if (!stepped) {
        ADD_FAILURE() << "the page left the program stopped";
        server->stop();
      }
    });
    env.step();
    stepped = true;
    f.get();
  }
};

TEST_F(Debug, ABreakpointStopsTheProgramUntilThePageResumesIt) {
  load(state);
  start();
  const HttpReply dbg = get("/api/debug");
  ASSERT_EQ(dbg.status, 200) << dbg.body;
  const auto programs = items(dbg.body, "programs");
  ASSERT_EQ(programs.size(), 1U);
  EXPECT_EQ(member(programs[0], "program"), "1");
  EXPECT_EQ(member(programs[0], "file"), "\"webcell.soml\"");
  EXPECT_EQ(member(dbg.body, "stopped"), "null");
  const HttpReply source = get("/api/debug/source?program=1");
  ASSERT_EQ(source.status, 200) << source.body;
  EXPECT_NE(source.body.find("done += twice(1);"), std::string::npos);
  EXPECT_NE(member(source.body, "lines").find("12"), std::string::npos);

  const HttpReply bp = post("/api/debug/break", R"({"line": 2})");
  ASSERT_EQ(bp.status, 200) << bp.body;
  const std::string bp_id = member(bp.body, "id");

  std::atomic<bool> connected{false};
  auto events = std::async(std::launch::async, [&, port = server->port(), h = host()] {
    return read_events(port, h, "\"stopped\":null", connected);
  });
  while (!connected) server->serve_for(std::chrono::milliseconds(2));

  std::string first_stop, second_stop;
  step_with_page([&] {
    first_stop = wait_for_stop();
    // While stopped: reads work, everything that would change the state mid-firing is refused.
    EXPECT_EQ(page_get("/api/nets").status, 200);
    const HttpReply locals = page_get("/api/debug/locals?frame=1");
    EXPECT_EQ(locals.status, 200) << locals.body;
    EXPECT_EQ(page_get("/api/debug/locals?frame=9").status, 400);
    const HttpReply n = page_get("/api/debug/print?path=n");
    EXPECT_EQ(member(n.body, "text"), "\"n = 1\"") << n.body;
    const std::string set = R"({"id": )" + std::to_string(cell()->id()) + R"(, "property": "done", "value": 7})";
    const HttpReply refused = page_post("/api/set", set);
    EXPECT_EQ(refused.status, 409) << refused.body;
    EXPECT_NE(member(refused.body, "error").find("stopped at a breakpoint"), std::string::npos);
    EXPECT_EQ(page_post("/api/timeline/seek", R"({"index": 0})").status, 409);
    ASSERT_EQ(page_post("/api/debug/resume", R"({"how": "continue"})").status, 200);
    // The second firing stops again; the page removes the breakpoint and lets it run.
    second_stop = wait_for_stop();
    EXPECT_EQ(page_post("/api/debug/remove", R"({"id": )" + bp_id + "}").status, 200);
    EXPECT_EQ(page_post("/api/debug/resume", R"({"how": "continue"})").status, 200);
  });
  ASSERT_NE(first_stop, "null");
  EXPECT_EQ(member(first_stop, "reason"), "\"breakpoint\"");
  EXPECT_EQ(member(first_stop, "line"), "2");
  EXPECT_EQ(member(first_stop, "function"), "\"twice\"");
  const auto stack = items(first_stop, "stack");
  ASSERT_EQ(stack.size(), 2U);
  EXPECT_EQ(member(stack[0], "line"), "2");
  EXPECT_EQ(member(stack[1], "line"), "12");
  const auto locals = items(first_stop, "locals");
  ASSERT_FALSE(locals.empty());
  EXPECT_EQ(member(locals[0], "name"), "\"n\"");
  EXPECT_EQ(member(locals[0], "value"), "\"1\"");
  EXPECT_NE(second_stop, "null");
  EXPECT_EQ(done(), 4);  // both firings ran to the end, and the refused edit changed nothing
  EXPECT_EQ(program->firings(), 2U);
  EXPECT_TRUE(items(get("/api/debug").body, "programs")[0].find("\"breakpoints\":[]") != std::string::npos);

  const std::string all = events.get();
  EXPECT_NE(all.find("event: debug"), std::string::npos) << all;
  EXPECT_NE(all.find("\"reason\":\"breakpoint\""), std::string::npos);
  EXPECT_NE(all.find("\"stopped\":null"), std::string::npos);
}

TEST_F(Debug, ATransitionBreakpointByIdThenStepsIntoTheAction) {
  load(state);
  start();
  const auto* work = program->object("debugcell")->find_child("work");
  ASSERT_NE(work, nullptr);
  const HttpReply bp = post("/api/debug/break", R"({"transition": )" + std::to_string(work->id()) + "}");
  ASSERT_EQ(bp.status, 200) << bp.body;
  EXPECT_EQ(member(bp.body, "transition"), "\"debugcell.work\"");
  std::string at_transition, after_step;
  step_with_page([&] {
    at_transition = wait_for_stop();
    EXPECT_EQ(page_post("/api/debug/resume", R"({"how": "step"})").status, 200);
    for (int i = 0; i < 200 && (after_step.empty() || after_step == at_transition); ++i) after_step = wait_for_stop();
    // Stop at every firing from now on: remove the breakpoint first.
    EXPECT_EQ(page_post("/api/debug/remove", R"({"id": 1})").status, 200);
    EXPECT_EQ(page_post("/api/debug/resume", R"({"how": "continue"})").status, 200);
  });
  EXPECT_EQ(member(at_transition, "reason"), "\"transition\"");
  EXPECT_EQ(member(member(at_transition, "transition"), "id"), std::to_string(work->id()));
  EXPECT_EQ(member(after_step, "reason"), "\"step\"");
  EXPECT_EQ(member(after_step, "line"), "12");
  EXPECT_EQ(done(), 4);
}

TEST_F(Debug, PauseStopsAtTheNextLineTheProgramRuns) {
  load(state);
  start();
  ASSERT_EQ(post("/api/debug/pause", "{}").status, 200);
  std::string stop;
  step_with_page([&] {
    stop = wait_for_stop();
    EXPECT_EQ(page_post("/api/debug/pause", "{}").status, 400);  // stopped already
    EXPECT_EQ(page_post("/api/debug/resume", R"({"how": "continue"})").status, 200);
  });
  EXPECT_EQ(member(stop, "reason"), "\"step\"");
  EXPECT_EQ(done(), 4);
}

TEST_F(Debug, StoppingTheServerLetsAStoppedProgramGoOn) {
  load(state);
  start();
  ASSERT_EQ(post("/api/debug/break", R"({"line": 12})").status, 200);
  auto f = std::async(std::launch::async, [&] {
    EXPECT_NE(wait_for_stop(), "null");
    server->stop();
  });
  env.step();  // ends: the server stopped, nobody can resume
  f.get();
  EXPECT_EQ(done(), 4);
}

TEST_F(Debug, TheTokenTraceListsEveryFiringAndIsPushed) {
  load(state);
  start();
  std::atomic<bool> connected{false};
  auto events = std::async(std::launch::async, [&, port = server->port(), h = host()] {
    return read_events(port, h, "event: trace", connected);
  });
  while (!connected) server->serve_for(std::chrono::milliseconds(2));
  env.step();
  while (events.wait_for(std::chrono::milliseconds(0)) != std::future_status::ready)
    server->serve_for(std::chrono::milliseconds(5));
  EXPECT_NE(events.get().find("\"label\":\"debugcell.work\""), std::string::npos);

  const HttpReply trace = get("/api/trace");
  ASSERT_EQ(trace.status, 200) << trace.body;
  const auto entries = items(trace.body, "entries");
  ASSERT_EQ(entries.size(), 2U);
  EXPECT_EQ(member(entries[0], "seq"), "1");
  EXPECT_EQ(member(entries[0], "label"), "\"debugcell.work\"");
  EXPECT_EQ(member(entries[0], "kind"), "\"plain\"");
  EXPECT_EQ(member(entries[0], "from"), "null");  // black tokens: no mark moved
  const auto taken = items(entries[0], "taken");
  ASSERT_EQ(taken.size(), 1U);
  EXPECT_EQ(member(taken[0], "label"), "\"debugcell.ready\"");
  EXPECT_EQ(member(taken[0], "tokens"), "1");
  EXPECT_EQ(member(items(entries[1], "given")[0], "label"), "\"debugcell.finished\"");
  EXPECT_EQ(items(get("/api/trace?after=1").body, "entries").size(), 1U);
  EXPECT_EQ(items(get("/api/trace?after=2").body, "entries").size(), 0U);
  EXPECT_EQ(items(get("/api/trace?limit=1").body, "entries").size(), 1U);
}

TEST_F(Debug, TheTraceKeepsOnlyItsNewestEntries) {
  load(state);
  vsd::web::Options o;
  o.trace_entries = 1;
  start(o);
  env.step();
  const HttpReply trace = get("/api/trace");
  EXPECT_EQ(member(trace.body, "newest"), "2");
  EXPECT_EQ(member(trace.body, "oldest"), "2");
  EXPECT_EQ(items(trace.body, "entries").size(), 1U);
}

TEST_F(Debug, BadRequestsAreRefusedWithAMessage) {
  load(state);
  start();
  const auto error = [](const HttpReply& r) { return member(r.body, "error"); };
  HttpReply r = post("/api/debug/break", R"({"line": 5})");
  EXPECT_EQ(r.status, 400);
  EXPECT_NE(error(r).find("no code on webcell.soml:5"), std::string::npos) << r.body;
  r = post("/api/debug/break", R"({"line": 0})");
  EXPECT_EQ(r.status, 400);
  r = post("/api/debug/break", R"({"line": 2, "program": 9})");
  EXPECT_EQ(r.status, 400);
  EXPECT_NE(error(r).find("no program 9"), std::string::npos);
  r = post("/api/debug/break", R"({"transition": )" + std::to_string(state.database().id()) + "}");
  EXPECT_EQ(r.status, 400);
  EXPECT_NE(error(r).find("is not a transition"), std::string::npos);
  EXPECT_EQ(post("/api/debug/break", "{}").status, 400);
  EXPECT_EQ(post("/api/debug/break", "[1]").status, 400);
  r = post("/api/debug/resume", R"({"how": "continue"})");
  EXPECT_EQ(r.status, 400);
  EXPECT_NE(error(r).find("no program is stopped"), std::string::npos);
  EXPECT_EQ(post("/api/debug/remove", R"({"id": 3})").status, 400);
  EXPECT_EQ(post("/api/debug/break", R"({"line": 2})", /*with_token=*/false).status, 403);
  EXPECT_EQ(post("/api/debug/nothing", "{}").status, 404);
  EXPECT_EQ(get("/api/debug/locals").status, 400);
  EXPECT_EQ(get("/api/debug/source").status, 400);
  EXPECT_EQ(get("/api/debug/source?program=x").status, 400);
  EXPECT_EQ(get("/api/debug/print?path=no.such.thing").status, 400);
  EXPECT_EQ(get("/api/trace?after=-1").status, 400);
  EXPECT_TRUE(items(get("/api/debug").body, "programs")[0].find("\"breakpoints\":[]") != std::string::npos);
}

TEST_F(Debug, AProgramWithADebuggerOfItsOwnIsShownWithoutAndTakenWhenFree) {
  load(state);
  auto own = std::make_unique<vsd::soml::Debugger>(*program);
  start();
  auto programs = items(get("/api/debug").body, "programs");
  ASSERT_EQ(programs.size(), 1U);
  EXPECT_EQ(member(programs[0], "debuggable"), "false");
  EXPECT_NE(member(programs[0], "error").find("another debugger"), std::string::npos);
  EXPECT_EQ(post("/api/debug/break", R"({"line": 2})").status, 400);
  own.reset();
  programs = items(get("/api/debug").body, "programs");
  EXPECT_EQ(member(programs[0], "debuggable"), "true");
}

TEST_F(Debug, ProgramsThatGoAreForgottenAndNewOnesAttached) {
  vsd::SimState& other = env.create_state("other");
  auto& soml = env.use<vsd::soml::Module>();
  vsd::web::Options o;
  o.port = 0;
  o.assets = "/nonexistent-vsd-web-assets";
  server = std::make_unique<vsd::web::Server>(env, other, o);
  server->start();
  program = &soml.load(other, "webcell.soml", debug_script);
  EXPECT_EQ(items(get("/api/debug").body, "programs").size(), 1U);
  ASSERT_EQ(post("/api/debug/break", R"({"line": 2})").status, 200);
  env.set_service(soml, other, vsd::Service::none);  // the program goes; its content stays
  EXPECT_TRUE(items(get("/api/debug").body, "programs").empty());
  EXPECT_EQ(post("/api/debug/break", R"({"line": 2})").status, 400);
  env.set_service(soml, other, vsd::Service::derived);
  program = &soml.adopt(other, "webcell.soml", debug_script);
  const auto programs = items(get("/api/debug").body, "programs");
  ASSERT_EQ(programs.size(), 1U);
  EXPECT_EQ(member(programs[0], "program"), "2");  // a new program, a new number
}

TEST_F(Debug, OffLeavesTheProgramsAlone) {
  load(state);
  vsd::web::Options o;
  o.debug = false;
  start(o);
  EXPECT_EQ(get("/api/debug").status, 404);
  EXPECT_EQ(get("/api/trace").status, 404);
  EXPECT_EQ(post("/api/debug/break", R"({"line": 2})").status, 404);
  vsd::soml::Debugger own(*program);  // free for the application
  EXPECT_TRUE(own.attached());
}

}  // namespace
}  // namespace vsd_web_test
