/** @file
 *  @brief vsd::web::Server: the inspector in the browser — an HTTP server (cpp-httplib) that shows one
 *  SimState live and writes back edits, calls and firings (docs/web.md).
 *
 *  @code
 *  vsd::web::Server server(env, env.main_state());
 *  server.start();                              // 127.0.0.1:8080 (or Options::port), a random token
 *  std::cout << server.url() << " token " << server.token() << "\n";
 *  server.run();                                // steps env in real time, serves while paused; until stop()
 *  @endcode
 *
 *  Threading: the server's HTTP threads never touch the SimState. A request that needs it becomes a job
 *  that the simulation thread runs at a step boundary — in the server's scheduler tasks (Phase::inputs
 *  and Phase::outputs of every env.step()) or in serve_for() — and the HTTP thread waits for its answer.
 *  Edits go through the setters: recorded, signalled and replicated like any other change.
 */
#pragma once

#include <chrono>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>

#include "vsd/core/fwd.hpp"

namespace vsd::web {

/// @brief How a Server listens and what it allows.
struct Options {
  /// Address to bind. Anything but a loopback address needs a token (start() refuses otherwise).
  std::string bind = "127.0.0.1";
  /// Port; 0 picks a free one (see Server::port()).
  int port = 8080;
  /// The write token. Empty: a random one (32 hex digits) is made at construction.
  std::string token;
  /// Directory of the page (index.html, app/, lib/). Empty: the build tree's, else the installed one.
  std::string assets;
  /// Changes pushed to each client at most this often per second.
  double push_rate = 30.0;
  /// Batches waiting for one client beyond which they are dropped and the client told to resynchronise.
  std::size_t client_backlog = 64;
  /// How long a request waits for the simulation thread before it gets 503.
  std::chrono::milliseconds request_timeout{5000};
  /// Memory the timeline's recorded bundles may use; the oldest entries go first. 0 switches the timeline
  /// off: the server then does not record the state (recording is most of what a server costs a step).
  std::size_t timeline_bytes = std::size_t{64} << 20;
  /// Largest request body accepted (413 beyond).
  std::size_t max_body = std::size_t{1} << 20;
  /// Attach a SOML++ debugger to every program of the state (breakpoints, step and continue from the page)
  /// and keep their token trace. A program that already has a debugger (the application's own) is shown
  /// without; off, the programs are left alone.
  bool debug = true;
  /// Token-trace entries kept for the page (the oldest go first).
  std::size_t trace_entries = 2000;
  /// Real-time factor of run(): simulated seconds per wall-clock second (0: as fast as possible).
  double real_time_factor = 1.0;
};

/// @brief Figures of a running server (for the page's stats line and benchmarks).
struct Stats {
  std::uint64_t requests = 0;   ///< HTTP requests answered
  std::uint64_t refused = 0;    ///< of those, refused (4xx, 503)
  std::uint64_t batches = 0;    ///< change batches published
  std::uint64_t dropped = 0;    ///< batches dropped for slow clients (each such client resynchronises)
  std::size_t clients = 0;      ///< event streams open now
  std::size_t timeline = 0;     ///< entries in the timeline
};

class Server {
 public:
  /// @brief A server of @p state (which must belong to @p env). Adds its scheduler tasks to @p env; does
  /// not listen before start(). @throws vsd::Error when @p state is not one of @p env's.
  Server(Environment& env, SimState& state, Options options = {});
  /// @brief Stops listening, closes every client and removes the scheduler tasks.
  ~Server();
  Server(const Server&) = delete;
  Server& operator=(const Server&) = delete;

  /// @brief Binds and listens on a thread of its own. @throws vsd::Error when the address cannot be
  /// bound, or when a non-loopback address has no token. Without the page's files (docs/web.md) the API works.
  void start();
  /// @brief Stops listening and ends run(); safe from any thread and from a signal handler's thread.
  void stop() noexcept;
  /// @brief True between start() and stop().
  [[nodiscard]] bool listening() const noexcept;
  /// @brief The bound port (after start()).
  [[nodiscard]] int port() const noexcept;
  /// @brief "http://ADDRESS:PORT/".
  [[nodiscard]] std::string url() const;
  /// @brief The write token (send it as the `X-VSD-Token` header).
  [[nodiscard]] const std::string& token() const noexcept;

  /// @brief Runs the jobs that wait, and any that arrive within @p duration; publishes changes. For a
  /// program that does not step its Environment (a file shown by vsd-web, a paused simulation).
  void serve_for(std::chrono::milliseconds duration);
  /// @brief Steps the Environment at Options::real_time_factor while not paused, and serves while
  /// paused, until stop(). Errors of a step propagate (the server stays usable).
  void run();
  /// @brief True while the page (or pause()) paused the simulation; run() does not step then. A program
  /// with a loop of its own checks this.
  [[nodiscard]] bool paused() const noexcept;
  /// @brief Pauses or resumes run(); safe from any thread.
  void pause(bool on) noexcept;

  /// @brief Figures so far; call it on the simulation thread.
  [[nodiscard]] Stats stats() const;
  [[nodiscard]] SimState& state() const noexcept;

  struct Impl;

 private:
  std::unique_ptr<Impl> impl_;
};

}  // namespace vsd::web
