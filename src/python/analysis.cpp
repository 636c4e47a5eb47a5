// vsd.analysis: place/transition nets (built by hand, read from PNML or from a SOML++ script) and their
// state spaces (docs/analysis.md). explore() and the readers release the GIL.
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include "vsd/analysis.hpp"
#include "vsdpy.hpp"

namespace vsdpy {

namespace {

using vsd::analysis::PtNet;

std::uint32_t index_of(const PtNet& net, py::handle h, bool place, const char* what) {
  if (py::isinstance<py::str>(h)) {
    const std::string id = h.cast<std::string>();
    const auto i = place ? net.find_place(id) : net.find_transition(id);
    if (!i) throw py::key_error(std::string(what) + ": the net has no " + (place ? "place" : "transition") + " '" + id + "'");
    return *i;
  }
  return h.cast<std::uint32_t>();
}

py::dict result_dict(const PtNet& net, const vsd::analysis::ExploreResult& r) {
  using Status = vsd::analysis::ExploreResult::Status;
  py::dict d;
  d["status"] = r.status == Status::complete ? "complete" : r.status == Status::unbounded ? "unbounded" : "memory_limit";
  d["states"] = r.states;
  d["edges"] = r.edges;
  d["deadlock"] = r.deadlock;
  auto names = [&](const std::vector<std::uint32_t>& trace) {
    py::list out;
    for (std::uint32_t t : trace) out.append(net.transitions()[t].id);
    return out;
  };
  d["dead_trace"] = names(r.dead_trace);
  d["dead_marking"] = r.dead_marking;
  d["max_tokens_place"] = r.max_tokens_place;
  d["max_tokens_marking"] = r.max_tokens_marking;
  d["unbounded_prefix"] = names(r.unbounded_prefix);
  d["unbounded_cycle"] = names(r.unbounded_cycle);
  d["levels"] = r.levels;
  d["bits_per_place"] = r.bits_per_place;
  d["peak_memory"] = r.peak_memory;
  d["memory_limit"] = r.memory_limit;
  d["seconds"] = r.seconds;
  d["threads"] = r.threads;
  d["message"] = r.message;
  return d;
}

template <class Read>
py::tuple imported(Read&& read) {
  auto result = [&] {
    py::gil_scoped_release release;
    return read();
  }();
  return py::make_tuple(std::move(result.net), std::move(result.notes));
}

}  // namespace

void bind_analysis(py::module_& m) {
  py::module_ a = m.def_submodule("analysis", "vsd::analysis: place/transition nets and their state spaces");
  py::class_<PtNet>(a, "Net", "A place/transition net with inhibitor arcs (docs/analysis.md)")
      .def(py::init<std::string, std::string>(), py::arg("id") = "net", py::arg("name") = "")
      .def_property_readonly("id", &PtNet::id)
      .def_property_readonly("name", &PtNet::name)
      .def("add_place", &PtNet::add_place, py::arg("id"), py::arg("name") = "", py::arg("initial") = 0,
           "Adds a place; returns its index")
      .def("add_transition", &PtNet::add_transition, py::arg("id"), py::arg("name") = "",
           "Adds a transition; returns its index")
      .def(
          "add_input",
          [](PtNet& n, py::handle t, py::handle p, std::uint32_t w) {
            n.add_input(index_of(n, t, false, "add_input"), index_of(n, p, true, "add_input"), w);
          },
          py::arg("transition"), py::arg("place"), py::arg("weight") = 1, "An arc place -> transition")
      .def(
          "add_output",
          [](PtNet& n, py::handle t, py::handle p, std::uint32_t w) {
            n.add_output(index_of(n, t, false, "add_output"), index_of(n, p, true, "add_output"), w);
          },
          py::arg("transition"), py::arg("place"), py::arg("weight") = 1, "An arc transition -> place")
      .def(
          "add_inhibitor",
          [](PtNet& n, py::handle t, py::handle p, std::uint32_t w) {
            n.add_inhibitor(index_of(n, t, false, "add_inhibitor"), index_of(n, p, true, "add_inhibitor"), w);
          },
          py::arg("transition"), py::arg("place"), py::arg("weight") = 1,
          "The transition is enabled only while the place holds fewer than weight tokens")
      .def_property_readonly("places",
                             [](const PtNet& n) {
                               py::list out;
                               for (const auto& p : n.places()) out.append(py::make_tuple(p.id, p.name, p.initial));
                               return out;
                             },
                             "(id, name, initial tokens) of every place, in index order")
      .def_property_readonly("transitions",
                             [](const PtNet& n) {
                               py::list out;
                               for (const auto& t : n.transitions()) out.append(py::make_tuple(t.id, t.name));
                               return out;
                             },
                             "(id, name) of every transition, in index order")
      .def_property_readonly("arc_count", &PtNet::arc_count)
      .def("initial_marking", &PtNet::initial_marking)
      .def(
          "enabled",
          [](const PtNet& n, py::handle t, const std::vector<std::uint32_t>& marking) {
            if (marking.size() != n.place_count()) throw py::value_error("enabled: the marking needs one count per place");
            return n.enabled(index_of(n, t, false, "enabled"), marking);
          },
          py::arg("transition"), py::arg("marking"))
      .def(
          "fire",
          [](const PtNet& n, py::handle t, std::vector<std::uint32_t> marking) {
            if (marking.size() != n.place_count()) throw py::value_error("fire: the marking needs one count per place");
            n.fire(index_of(n, t, false, "fire"), marking);
            return marking;
          },
          py::arg("transition"), py::arg("marking"), "The marking after firing (vsd.Error when not enabled)")
      .def("to_pnml", [](const PtNet& n) { return vsd::analysis::write_pnml(n); })
      .def("to_soml", [](const PtNet& n) { return vsd::analysis::write_soml(n); })
      .def("__eq__", [](const PtNet& a, const PtNet& b) { return a == b; })
      .def("__repr__", [](const PtNet& n) {
        return "<vsd.analysis.Net '" + n.id() + "': " + std::to_string(n.place_count()) + " places, " +
               std::to_string(n.transition_count()) + " transitions>";
      });

  a.def(
      "read_pnml",
      [](const std::string& text, const std::string& source) {
        return imported([&] { return vsd::analysis::read_pnml(text, source); });
      },
      py::arg("text"), py::arg("source") = "<pnml>",
      "(net, notes) from PNML text; vsd.Error 'SOURCE:LINE:COL: ...' when it is not a P/T net");
  a.def(
      "read_pnml_file",
      [](const std::string& path) { return imported([&] { return vsd::analysis::read_pnml_file(path); }); },
      py::arg("path"));
  a.def(
      "read_soml",
      [](const std::string& text, const std::string& source) {
        return imported([&] { return vsd::analysis::read_soml_net(text, source); });
      },
      py::arg("text"), py::arg("source") = "<soml>",
      "(net, notes): the static P/T net of a SOML++ script (actions and conditions are ignored, each noted)");
  a.def(
      "read_soml_file",
      [](const std::string& path) { return imported([&] { return vsd::analysis::read_soml_net_file(path); }); },
      py::arg("path"));
  a.def(
      "explore",
      [](const PtNet& net, unsigned threads, std::size_t memory_limit) {
        if (threads == 0) throw py::value_error("explore: threads must be >= 1");
        vsd::analysis::ExploreOptions o;
        o.threads = threads;
        o.memory_limit = memory_limit;
        o.progress = vsd::analysis::ExploreOptions::Progress::never;
        vsd::analysis::ExploreResult r;
        {
          py::gil_scoped_release release;
          r = vsd::analysis::explore(net, o);
        }
        return result_dict(net, r);
      },
      py::arg("net"), py::arg("threads") = 1, py::arg("memory_limit") = 0,
      "The net's reachable markings (dict: status, states, edges, deadlock, dead_trace — transition ids —, "
      "dead_marking, max_tokens_place, levels, ...). memory_limit 0: the default (docs/analysis.md)");
}

}  // namespace vsdpy
