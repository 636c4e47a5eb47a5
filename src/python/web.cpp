// vsd.web: the inspector in the browser (vsd::web::Server, docs/web.md) for a simulation stepped from
// Python. The server's HTTP threads never touch the state: their jobs run at the step boundaries of
// env.step() / env.run_for() (the server's scheduler tasks) or in serve_for(), all with the GIL released.
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <chrono>
#include <cmath>
#include <memory>

#include "vsd/web.hpp"
#include "vsdpy.hpp"

namespace vsdpy {

namespace {

/// A Python vsd.web.Server: keeps its Environment alive (the server's tasks live in its scheduler), and
/// is destroyed before it.
struct PyServer {
  std::shared_ptr<StateBox> state;
  std::unique_ptr<vsd::web::Server> server;

  vsd::web::Server& get() const {
    if (!server) throw py::value_error("the server was closed");
    if (!state->alive) throw py::value_error("the server's state was removed");
    return *server;
  }
  void close() {
    py::gil_scoped_release release;  // joining the HTTP threads may wait for a job of a stepping thread
    server.reset();
  }
  ~PyServer() {
    if (server) close();
  }
};

}  // namespace

void bind_web(py::module_& m) {
  py::module_ web = m.def_submodule("web", "vsd::web: the inspector in the browser (docs/web.md)");
  py::class_<PyServer, std::shared_ptr<PyServer>>(
      web, "Server",
      "The inspector of one state: serves the page and its API on 127.0.0.1 (by default), pushes changes, "
      "queues the page's edits for the step boundaries. Close it (or use `with`) before the environment goes.")
      .def(py::init([](const PyEnvironment& env, py::object state, int port, std::string bind, std::string token,
                       double push_rate, std::size_t timeline_bytes, bool debug, double real_time_factor) {
             vsd::web::Options o;
             if (port < 0 || port > 65535) throw py::value_error("web.Server: port must be in [0, 65535] (0: a free one)");
             if (!(push_rate > 0) || !std::isfinite(push_rate)) throw py::value_error("web.Server: push_rate must be > 0");
             if (!(real_time_factor >= 0) || !std::isfinite(real_time_factor))
               throw py::value_error("web.Server: real_time_factor must be >= 0 (0: as fast as possible)");
             o.port = port;
             o.bind = std::move(bind);
             o.token = std::move(token);
             o.push_rate = push_rate;
             o.timeline_bytes = timeline_bytes;
             o.debug = debug;
             o.real_time_factor = real_time_factor;
             auto s = std::make_shared<PyServer>();
             if (state.is_none()) {
               s->state = box_of(env.box, env.box->env->main_state());
             } else {
               s->state = state.cast<const PyState&>().box;
               if (s->state->env != env.box) throw py::value_error("web.Server: the state belongs to another environment");
               (void)state.cast<const PyState&>().get();  // a removed state raises
             }
             s->server = std::make_unique<vsd::web::Server>(*env.box->env, *s->state->state, std::move(o));
             return s;
           }),
           py::arg("env"), py::arg("state") = py::none(), py::arg("port") = 8080, py::arg("bind") = "127.0.0.1",
           py::arg("token") = "", py::arg("push_rate") = 30.0, py::arg("timeline_bytes") = std::size_t{64} << 20,
           py::arg("debug") = true, py::arg("real_time_factor") = 1.0)
      .def("start", [](const PyServer& s) { s.get().start(); },
           "Binds and listens (a thread of its own); raises vsd.Error when the address cannot be bound")
      .def("stop", [](const PyServer& s) { s.get().stop(); }, "Stops listening and ends run()")
      .def("close", &PyServer::close, "Stops the server and removes its scheduler tasks (also on garbage collection)")
      .def("__enter__", [](const std::shared_ptr<PyServer>& s) { return s; })
      .def("__exit__", [](PyServer& s, py::args) { s.close(); })
      .def_property_readonly("listening", [](const PyServer& s) { return s.server && s.server->listening(); })
      .def_property_readonly("port", [](const PyServer& s) { return s.get().port(); })
      .def_property_readonly("url", [](const PyServer& s) { return s.get().url(); })
      .def_property_readonly("token", [](const PyServer& s) { return s.get().token(); },
                             "The write token: send it as the X-VSD-Token header")
      .def(
          "serve_for",
          [](const PyServer& s, double seconds) {
            vsd::web::Server& server = s.get();
            const auto ms = milliseconds_of(seconds, "serve_for");
            py::gil_scoped_release release;
            server.serve_for(ms);
          },
          py::arg("seconds"), "Answers the page for that long without stepping (a paused or unstepped simulation)")
      .def(
          "run",
          [](const PyServer& s) {
            vsd::web::Server& server = s.get();
            py::gil_scoped_release release;
            server.run();
          },
          "Steps the environment in real time (serving while paused) until stop() — from another thread, "
          "a Python task or a listener")
      .def_property(
          "paused", [](const PyServer& s) { return s.get().paused(); },
          [](const PyServer& s, bool on) { s.get().pause(on); })
      .def("stats", [](const PyServer& s) {
        const vsd::web::Stats st = s.get().stats();
        py::dict d;
        d["requests"] = st.requests;
        d["refused"] = st.refused;
        d["batches"] = st.batches;
        d["dropped"] = st.dropped;
        d["clients"] = st.clients;
        d["timeline"] = st.timeline;
        return d;
      });
}

}  // namespace vsdpy
