// vsd::web::Server: the HTTP side (cpp-httplib) — security checks, the job queue that hands requests to
// the simulation thread, the event streams and the page's files. What a request does is inspector.cpp.
#include "vsd/web/server.hpp"

#include <algorithm>
#include <atomic>
#include <condition_variable>
#include <cstdio>
#include <deque>
#include <filesystem>
#include <fstream>
#include <map>
#include <mutex>
#include <random>
#include <sstream>
#include <thread>

#include "inspector.hpp"
#include "vsd/core/environment.hpp"
#include "vsd/core/error.hpp"
#include "vsd/core/scheduler.hpp"
#include "vsd/core/sim_state.hpp"

// Last: httplib.h brings <resolv.h>, whose `_res` macro breaks Eigen headers included after it.
#include <httplib.h>

namespace vsd::web {
namespace {

namespace fs = std::filesystem;
using detail::Reply;
using detail::Request;

std::string random_token() {
  std::random_device rd;
  std::string t;
  static constexpr char hex[] = "0123456789abcdef";
  for (int i = 0; i < 32; ++i) t += hex[rd() % 16];
  return t;
}

bool loopback(const std::string& address) {
  return address == "127.0.0.1" || address == "::1" || address == "localhost" ||
         address.rfind("127.", 0) == 0;
}

/// Equal without an early exit: the time a refused token takes says nothing about how much of it matched.
bool same_secret(const std::string& given, const std::string& token) {
  if (token.empty() || given.size() != token.size()) return false;
  unsigned diff = 0;
  for (std::size_t i = 0; i < token.size(); ++i) diff |= static_cast<unsigned char>(given[i] ^ token[i]);
  return diff == 0;
}

/// The host part of a Host header value ("127.0.0.1:8080" -> "127.0.0.1", "[::1]:80" -> "::1").
std::string host_name(const std::string& host) {
  if (!host.empty() && host.front() == '[') {
    const std::size_t close = host.find(']');
    return close == std::string::npos ? host : host.substr(1, close - 1);
  }
  const std::size_t colon = host.rfind(':');
  return colon == std::string::npos ? host : host.substr(0, colon);
}

bool ip_literal(const std::string& name) {
  if (name.find(':') != std::string::npos) return true;  // IPv6 (brackets already removed)
  return !name.empty() && std::all_of(name.begin(), name.end(), [](char c) { return (c >= '0' && c <= '9') || c == '.'; });
}

const char* content_type(const fs::path& p) {
  const std::string e = p.extension().string();
  if (e == ".html") return "text/html; charset=utf-8";
  if (e == ".js" || e == ".mjs") return "text/javascript; charset=utf-8";
  if (e == ".css") return "text/css; charset=utf-8";
  if (e == ".json" || e == ".map") return "application/json";
  if (e == ".svg") return "image/svg+xml";
  if (e == ".png") return "image/png";
  if (e == ".wasm") return "application/wasm";
  return "text/plain; charset=utf-8";
}

std::string default_assets() {
#ifdef VSD_WEB_ASSETS_BUILD_DIR
  if (fs::exists(fs::path(VSD_WEB_ASSETS_BUILD_DIR) / "index.html")) return VSD_WEB_ASSETS_BUILD_DIR;
#endif
#ifdef VSD_WEB_ASSETS_INSTALL_DIR
  if (fs::exists(fs::path(VSD_WEB_ASSETS_INSTALL_DIR) / "index.html")) return VSD_WEB_ASSETS_INSTALL_DIR;
#endif
  return {};
}

}  // namespace

/// One request handed to the simulation thread.
struct Job {
  enum class Stage { pending, running, done, cancelled };
  std::function<void(detail::Inspector&)> work;
  Stage stage = Stage::pending;
};

struct Server::Impl {
  Environment& env;
  SimState& state;
  Options options;
  detail::Feed feed;
  detail::Inspector inspector;
  httplib::Server http;
  std::thread listener;
  std::atomic<bool> listening{false};
  std::atomic<bool> stopping{false};
  std::atomic<bool> paused{false};
  int port = 0;
  std::map<std::string, fs::path> files;  // URL path -> file: the page's files, found at start()
  Scheduler::TaskId inputs_task = 0, outputs_task = 0;
  std::atomic<std::uint64_t> requests{0}, refused{0};

  std::mutex jobs_mutex;
  std::condition_variable job_arrived;  // wakes serve_for()
  std::condition_variable job_done;     // wakes the HTTP threads
  std::deque<std::shared_ptr<Job>> jobs;

  Impl(Environment& e, SimState& s, Options o)
      : env(e), state(s), options(std::move(o)), feed(options.client_backlog), inspector(e, s, options, feed) {
    if (detail::Debugging* d = inspector.debugging()) d->wait = [this] { serve_stopped(); };
  }

  /// A SOML++ program stopped at a breakpoint, inside its run on this thread: answer requests (the
  /// inspector refuses all but reads and debugger commands now) until the page resumes it or the server
  /// stops. Not listening: nobody can resume, so it goes on at once.
  void serve_stopped() {
    detail::Debugging& d = *inspector.debugging();
    while (listening && !stopping && !d.resuming()) {
      run_jobs();
      if (d.resuming()) break;
      std::unique_lock lock(jobs_mutex);
      job_arrived.wait_for(lock, std::chrono::milliseconds(200), [&] { return !jobs.empty() || stopping; });
    }
  }

  /// Runs @p work on the simulation thread and waits for it. False when it timed out (it then never runs).
  bool submit(std::function<void(detail::Inspector&)> work) {
    auto job = std::make_shared<Job>();
    job->work = std::move(work);
    std::unique_lock lock(jobs_mutex);
    if (stopping) return false;
    jobs.push_back(job);
    job_arrived.notify_one();
    if (job_done.wait_for(lock, options.request_timeout, [&] { return job->stage == Job::Stage::done; })) return true;
    if (job->stage == Job::Stage::pending) {
      job->stage = Job::Stage::cancelled;  // the simulation thread skips it
      return false;
    }
    job_done.wait(lock, [&] { return job->stage == Job::Stage::done; });  // running: it finishes soon
    return true;
  }

  /// The simulation thread: runs every job that waits.
  void run_jobs() {
    for (;;) {
      std::shared_ptr<Job> job;
      {
        std::lock_guard lock(jobs_mutex);
        while (!jobs.empty() && jobs.front()->stage == Job::Stage::cancelled) jobs.pop_front();
        if (jobs.empty()) return;
        job = jobs.front();
        jobs.pop_front();
        job->stage = Job::Stage::running;
      }
      job->work(inspector);
      {
        std::lock_guard lock(jobs_mutex);
        job->stage = Job::Stage::done;
      }
      job_done.notify_all();
    }
  }

  [[nodiscard]] bool host_allowed(const httplib::Request& req) const {
    const std::string host = req.get_header_value("Host");
    if (host.empty()) return false;
    const std::string name = host_name(host);
    // A DNS name other than localhost could be rebound to 127.0.0.1 by a foreign page: only IP literals,
    // localhost and the bound name itself are accepted.
    return name == "localhost" || name == options.bind || (ip_literal(name) && (!loopback(options.bind) || loopback(name)));
  }

  [[nodiscard]] bool origin_allowed(const httplib::Request& req) const {
    if (!req.has_header("Origin")) return true;  // not a browser's cross-site request
    return req.get_header_value("Origin") == "http://" + req.get_header_value("Host");
  }

  void answer(httplib::Response& res, const Reply& r) {
    ++requests;
    if (r.status >= 400) ++refused;
    res.status = r.status;
    res.set_header("Cache-Control", "no-store");
    res.set_content(r.body, "application/json");
  }

  void api(const httplib::Request& req, httplib::Response& res) {
    Request r;
    r.method = req.method;
    r.path = req.path;
    for (const auto& [k, v] : req.params) r.query.emplace_back(k, v);
    r.body = req.body;
    r.writable = same_secret(req.get_header_value("X-VSD-Token"), options.token);
    if (req.method == "POST" && !origin_allowed(req)) {
      answer(res, Reply::error(403, "writes from another origin are refused"));
      return;
    }
    Reply reply;
    if (!submit([&](detail::Inspector& i) { reply = i.handle(r); }))
      reply = Reply::error(503, "the simulation did not answer in time (it is not stepping or serving)");
    answer(res, reply);
  }

  void events(httplib::Response& res) {
    if (feed.clients() >= max_streams) {
      answer(res, Reply::error(503, "too many event streams are open"));
      return;
    }
    std::shared_ptr<detail::Feed::Client> client;
    // Opened on the simulation thread, between two batches: the hello event and the first batch the
    // client gets follow each other without a gap.
    if (!submit([&](detail::Inspector& i) { client = feed.open(i.hello()); })) {
      answer(res, Reply::error(503, "the simulation did not answer in time (it is not stepping or serving)"));
      return;
    }
    ++requests;
    res.set_header("Cache-Control", "no-store");
    res.set_header("X-Accel-Buffering", "no");
    res.set_chunked_content_provider(
        "text/event-stream",
        [this, client](std::size_t, httplib::DataSink& sink) {
          std::vector<detail::Event> batch;
          if (!feed.wait(*client, batch, std::chrono::seconds(10))) {
            sink.done();
            return true;
          }
          if (batch.empty()) {  // a comment now and then: a dead connection is noticed by the write
            static constexpr std::string_view ping = ": ping\n\n";
            return sink.write(ping.data(), ping.size());
          }
          for (const auto& e : batch)
            if (!sink.write(e->data(), e->size())) return false;
          return true;
        },
        [this, client](bool) { feed.close(client); });
  }

  void page(const httplib::Request& req, httplib::Response& res) {
    const std::string path = req.path == "/" ? "/index.html" : req.path;
    const auto it = files.find(path);
    if (it == files.end()) {
      answer(res, Reply::error(404, files.empty() ? "the page is not installed (run scripts/web-assets.sh, or see docs/web.md); the API under /api/ works"
                                                  : "no such file: " + path.substr(0, 200)));
      return;
    }
    std::ifstream in(it->second, std::ios::binary);
    std::ostringstream data;
    data << in.rdbuf();
    if (!in && !in.eof()) {
      answer(res, Reply::error(500, "cannot read " + path));
      return;
    }
    ++requests;
    // The libraries under /lib are pinned by the lockfile: a day in the browser's cache. The page's own
    // files are asked again each time (edits show up at once).
    res.set_header("Cache-Control", path.rfind("/lib/", 0) == 0 ? "max-age=86400" : "no-cache");
    res.set_content(data.str(), content_type(it->second));
  }

  /// Lists the page's files once: only those are served, whatever path a request names.
  void find_files() {
    files.clear();
    const std::string dir = options.assets.empty() ? default_assets() : options.assets;
    if (dir.empty()) return;
    const fs::path root = fs::weakly_canonical(dir);
    std::error_code ec;
    for (auto it = fs::recursive_directory_iterator(root, fs::directory_options::none, ec);
         !ec && it != fs::recursive_directory_iterator(); it.increment(ec)) {
      if (!it->is_regular_file() || it->is_symlink()) continue;  // links could lead out of the directory
      const std::string rel = fs::relative(it->path(), root).generic_string();
      if (rel.rfind("node_modules", 0) == 0 || rel.find("/.") != std::string::npos || rel.front() == '.') continue;
      files.emplace("/" + rel, it->path());
    }
  }

  static constexpr std::size_t max_streams = 16;
};

Server::Server(Environment& env, SimState& state, Options options) {
  bool ours = false;
  for (SimState* s : env.states()) ours = ours || s == &state;
  if (!ours) throw Error("vsd::web::Server: state '" + state.name() + "' is not a state of this environment");
  if (options.push_rate <= 0 || !(options.push_rate < 1e6))
    throw Error("vsd::web::Server: push_rate must be a positive number of batches per second");
  // A made-up token only on a loopback address: on any other, start() refuses to run without one given.
  if (options.token.empty() && loopback(options.bind)) options.token = random_token();
  impl_ = std::make_unique<Impl>(env, state, std::move(options));
  Scheduler& sched = env.scheduler();
  impl_->inputs_task = sched.add_periodic("web: edits", sched.base_step(), [this](const StepInfo&) { impl_->run_jobs(); },
                                          Phase::inputs, 1000);
  impl_->outputs_task = sched.add_periodic(
      "web: publish", sched.base_step(),
      [this](const StepInfo&) {
        impl_->run_jobs();
        impl_->inspector.publish();
      },
      Phase::outputs, 1000);
}

Server::~Server() {
  stop();
  if (impl_->listener.joinable()) impl_->listener.join();
  impl_->env.scheduler().remove(impl_->inputs_task);
  impl_->env.scheduler().remove(impl_->outputs_task);
}

void Server::start() {
  Impl& d = *impl_;
  if (d.listening) throw Error("vsd::web::Server: already listening");
  if (d.options.token.empty())
    throw Error("vsd::web::Server: binding " + d.options.bind + " (not a loopback address) needs a token (Options::token, --token)");
  if (d.options.port < 0 || d.options.port > 65535)
    throw Error("vsd::web::Server: port " + std::to_string(d.options.port) + " is not in 0..65535");
  d.find_files();
  d.http.new_task_queue = [] { return new httplib::ThreadPool(Impl::max_streams + 8); };
  d.http.set_payload_max_length(d.options.max_body);
  // SO_REUSEADDR only: httplib's default adds SO_REUSEPORT, which would let a second server (another
  // process of the same user) bind our port and take half of the connections.
  d.http.set_socket_options([](socket_t sock) {
    int yes = 1;
    (void)::setsockopt(sock, SOL_SOCKET, SO_REUSEADDR, &yes, sizeof yes);
  });
  d.http.set_keep_alive_timeout(5);
  d.http.set_read_timeout(10, 0);
  d.http.set_write_timeout(10, 0);
  d.http.set_pre_routing_handler([this](const httplib::Request& req, httplib::Response& res) {
    // No compression: Debian's httplib is built with brotli, which takes seconds for the page's 1.5 MB
    // layout library on every load, where sending it plain over the loopback takes milliseconds. The
    // request object is httplib's own (not const), handed to us as const: dropping the header here is
    // the one way 0.11 offers.
    const_cast<httplib::Request&>(req).headers.erase("Accept-Encoding");
    if (impl_->host_allowed(req)) return httplib::Server::HandlerResponse::Unhandled;
    impl_->answer(res, Reply::error(403, "Host '" + req.get_header_value("Host").substr(0, 100) +
                                             "' is not this server's address or localhost"));
    return httplib::Server::HandlerResponse::Handled;
  });
  d.http.set_post_routing_handler([](const httplib::Request&, httplib::Response& res) {
    res.set_header("X-Content-Type-Options", "nosniff");
    res.set_header("X-Frame-Options", "DENY");  // no fire button under another site's clicks
  });
  d.http.Get("/api/events", [this](const httplib::Request&, httplib::Response& res) { impl_->events(res); });
  d.http.Get(R"(/api/.*)", [this](const httplib::Request& req, httplib::Response& res) { impl_->api(req, res); });
  d.http.Post(R"(/api/.*)", [this](const httplib::Request& req, httplib::Response& res) { impl_->api(req, res); });
  d.http.Get(R"(/.*)", [this](const httplib::Request& req, httplib::Response& res) { impl_->page(req, res); });
  d.http.set_error_handler([this](const httplib::Request&, httplib::Response& res) {
    if (!res.body.empty()) return;  // ours
    impl_->answer(res, Reply::error(res.status, res.status == 413 ? "the request body is too large" : "bad request"));
  });
  if (d.options.port == 0) {
    d.port = d.http.bind_to_any_port(d.options.bind);
    if (d.port < 0) d.port = 0;
  } else {
    d.port = d.http.bind_to_port(d.options.bind, d.options.port) ? d.options.port : 0;
  }
  if (d.port == 0)
    throw Error("vsd::web::Server: cannot listen on " + d.options.bind + ":" + std::to_string(d.options.port) +
                " (address in use or not of this machine)");
  d.stopping = false;
  d.listening = true;
  d.listener = std::thread([this] { impl_->http.listen_after_bind(); });
  // httplib's stop() does nothing until the accept loop runs: wait for it, so that a stop() right after
  // start() is not lost.
  for (int i = 0; i < 5000 && !d.http.is_running(); ++i) std::this_thread::sleep_for(std::chrono::milliseconds(1));
}

void Server::stop() noexcept {
  Impl& d = *impl_;
  {
    std::lock_guard lock(d.jobs_mutex);
    d.stopping = true;
    for (const auto& j : d.jobs)
      if (j->stage == Job::Stage::pending) j->stage = Job::Stage::cancelled;
  }
  d.job_arrived.notify_all();
  d.job_done.notify_all();
  d.feed.shutdown();
  if (d.listening.exchange(false)) d.http.stop();
}

bool Server::listening() const noexcept { return impl_->listening; }
int Server::port() const noexcept { return impl_->port; }
std::string Server::url() const {
  const std::string& b = impl_->options.bind;
  const std::string host = b.find(':') != std::string::npos ? "[" + b + "]" : b;
  return "http://" + host + ":" + std::to_string(impl_->port) + "/";
}
const std::string& Server::token() const noexcept { return impl_->options.token; }
SimState& Server::state() const noexcept { return impl_->state; }
bool Server::paused() const noexcept { return impl_->inspector.paused(); }
void Server::pause(bool on) noexcept { impl_->inspector.pause(on); }

void Server::serve_for(std::chrono::milliseconds duration) {
  Impl& d = *impl_;
  const auto until = std::chrono::steady_clock::now() + duration;
  for (;;) {
    d.run_jobs();
    d.inspector.publish();
    std::unique_lock lock(d.jobs_mutex);
    const bool more = d.job_arrived.wait_until(lock, until, [&] { return !d.jobs.empty() || d.stopping; });
    if (!more || d.stopping) break;
  }
  d.run_jobs();
  d.inspector.publish();
}

void Server::run() {
  Impl& d = *impl_;
  using clock = std::chrono::steady_clock;
  auto wall_start = clock::now();
  double sim_start = d.env.time();
  bool was_paused = true;
  while (!d.stopping) {
    if (paused()) {
      was_paused = true;
      serve_for(std::chrono::milliseconds(20));
      continue;
    }
    if (was_paused) {  // real time counts from here, not across the pause
      wall_start = clock::now();
      sim_start = d.env.time();
      was_paused = false;
    }
    d.env.step();
    if (d.options.real_time_factor > 0) {
      const double ahead = (d.env.time() - sim_start) / d.options.real_time_factor -
                           std::chrono::duration<double>(clock::now() - wall_start).count();
      if (ahead > 0) serve_for(std::chrono::milliseconds(static_cast<long>(ahead * 1000.0)));
    }
  }
}

Stats Server::stats() const {
  Stats s;
  s.requests = impl_->requests;
  s.refused = impl_->refused;
  s.batches = impl_->inspector.batches();
  s.dropped = impl_->inspector.dropped();
  s.clients = impl_->feed.clients();
  s.timeline = impl_->inspector.timeline_size();
  return s;
}

}  // namespace vsd::web
