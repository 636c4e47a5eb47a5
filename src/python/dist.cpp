// vsd.dist: a state of a Python simulation kept in sync with other processes over Cyclone DDS
// (vsd::dist, docs/dist.md). join() makes the participant through the environment's dist module, so every
// env.step() publishes what the state recorded and applies the others' bundles.
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <chrono>
#include <cmath>
#include <memory>
#include <vector>

#include "dist_loopback.hpp"
#include "vsd/dist.hpp"
#include "vsdpy.hpp"

namespace vsdpy {

namespace {

/// A Python vsd.dist.Participant: one made by the environment's dist module, which owns it for the
/// environment's life; the handle keeps the environment alive and checks that its state still is.
struct PyParticipant {
  std::shared_ptr<StateBox> state;
  vsd::dist::Participant* participant = nullptr;
  std::shared_ptr<std::vector<vsd::dist::Conflict>> conflicts;  // reported since the last conflicts()
  vsd::Connection listening;

  vsd::dist::Participant& get() const {
    if (!state->alive) throw py::value_error("the participant's state was removed");
    return *participant;
  }
};

const char* kind_name(vsd::dist::ConflictKind k) {
  switch (k) {
    case vsd::dist::ConflictKind::Owned: return "owned";
    case vsd::dist::ConflictKind::ConcurrentWrite: return "concurrent_write";
    case vsd::dist::ConflictKind::ClaimRace: return "claim_race";
    case vsd::dist::ConflictKind::Deleted: return "deleted";
    case vsd::dist::ConflictKind::ConcurrentMove: return "concurrent_move";
  }
  return "unknown";
}

/// The instance of a handle of @p p's state (a TypeError for anything else).
vsd::SimStateInstance& instance_of(const PyParticipant& p, py::handle h, const char* what) {
  if (!py::isinstance<Handle>(h)) throw py::type_error(std::string(what) + ": expected a vsd instance");
  const Handle& handle = h.cast<const Handle&>();
  vsd::SimStateInstance& inst = handle.get();
  if (handle.box != p.state) throw py::value_error(std::string(what) + ": the instance is in another state");
  return inst;
}

}  // namespace

void bind_dist(py::module_& m) {
  py::module_ dist = m.def_submodule("dist", "vsd::dist: states kept in sync across processes (Cyclone DDS)");
  dist.attr("loopback_config") = vsd_py_dist_loopback;
  dist.def(
      "join",
      [](const PyEnvironment& env, py::object state, std::string name, std::uint32_t domain, std::string topic,
         bool seed, std::string config, double request_interval, double lease_duration) {
        if (domain > 230) throw py::value_error("dist.join: domain must be in [0, 230]");
        vsd::dist::ParticipantOptions o;
        o.name = std::move(name);
        o.domain = domain;
        o.topic = std::move(topic);
        o.seed = seed;
        o.config = std::move(config);
        o.request_interval = milliseconds_of(request_interval, "dist.join request_interval");
        if (lease_duration > 0) {
          o.lease_duration = milliseconds_of(lease_duration, "dist.join lease_duration");
          o.write_timeout = std::max(o.write_timeout, o.lease_duration * 2);
        }
        auto p = std::make_shared<PyParticipant>();
        if (state.is_none()) {
          p->state = box_of(env.box, env.box->env->main_state());
        } else {
          p->state = state.cast<const PyState&>().box;
          if (p->state->env != env.box) throw py::value_error("dist.join: the state belongs to another environment");
          (void)state.cast<const PyState&>().get();  // a removed state raises
        }
        vsd::Environment& e = *env.box->env;
        p->participant = &e.use<vsd::dist::Module>().join(*p->state->state, std::move(o));
        p->conflicts = std::make_shared<std::vector<vsd::dist::Conflict>>();
        p->listening = p->participant->on_conflict().connect(
            [c = p->conflicts](const vsd::dist::Conflict& x) {
              if (c->size() < 10000) c->push_back(x);  // a caller that never looks keeps a bounded list
            });
        return p;
      },
      py::arg("env"), py::arg("state") = py::none(), py::arg("name") = "", py::arg("domain") = 0,
      py::arg("topic") = "vsd", py::arg("seed") = false, py::arg("config") = "", py::arg("request_interval") = 0.25,
      py::arg("lease_duration") = 0.0,
      "Joins state (the main state by default) to the DDS domain and topic: from then on every env.step() "
      "publishes its recorded changes and applies the others'. seed=True: this state is the model to start "
      "from; the others ask for a snapshot. config: Cyclone DDS XML or 'file://...' (vsd.dist.loopback_config "
      "keeps to this machine). Raises vsd.Error when DDS refuses.");

  py::class_<PyParticipant, std::shared_ptr<PyParticipant>>(dist, "Participant",
                                                            "One state's membership of a vsd::dist domain")
      .def_property_readonly("id", [](const PyParticipant& p) { return p.get().id(); })
      .def_property_readonly("name", [](const PyParticipant& p) { return p.get().name(); })
      .def_property_readonly("synced", [](const PyParticipant& p) { return p.get().synced(); })
      .def_property_readonly("peers", [](const PyParticipant& p) { return p.get().peers(); })
      .def("publish", [](const PyParticipant& p) { return p.get().publish(); },
           "Sends what the state recorded since the last publish as one bundle; False when there was nothing")
      .def("poll", [](const PyParticipant& p) { return p.get().poll(); },
           "Applies the others' bundles that arrived; returns how many")
      .def(
          "wait_synced",
          [](const PyParticipant& p, double seconds) {
            vsd::dist::Participant& d = p.get();
            const auto ms = milliseconds_of(seconds, "wait_synced");
            py::gil_scoped_release release;
            return d.wait_synced(ms);
          },
          py::arg("seconds"), "Polls until this state is synchronised (a snapshot installed); False on timeout")
      .def(
          "wait_peers",
          [](const PyParticipant& p, std::size_t n, double seconds) {
            vsd::dist::Participant& d = p.get();
            const auto ms = milliseconds_of(seconds, "wait_peers");
            py::gil_scoped_release release;
            return d.wait_peers(n, ms);
          },
          py::arg("n"), py::arg("seconds"), "Waits until n other participants are seen; False on timeout")
      .def(
          "claim",
          [](const PyParticipant& p, py::handle inst, py::object property) {
            vsd::SimStateInstance& i = instance_of(p, inst, "claim");
            if (property.is_none()) {
              p.get().claim(i);
            } else {
              p.get().claim(i, property.cast<std::string>());
            }
          },
          py::arg("instance"), py::arg("property") = py::none(),
          "Claims ownership of an instance (or one property of it): the others' writes to it are rejected")
      .def(
          "release",
          [](const PyParticipant& p, py::handle inst, const std::string& property) {
            p.get().release(instance_of(p, inst, "release"), property);
          },
          py::arg("instance"), py::arg("property") = "")
      .def(
          "owner",
          [](const PyParticipant& p, py::handle inst, const std::string& property) {
            return p.get().owner(instance_of(p, inst, "owner").id(), property);
          },
          py::arg("instance"), py::arg("property") = "", "The owning participant's id (0: nobody)")
      .def("participant_name", [](const PyParticipant& p, std::uint64_t id) { return p.get().participant_name(id); })
      .def(
          "conflicts",
          [](const PyParticipant& p) {
            (void)p.get();
            py::list out;
            for (const vsd::dist::Conflict& c : *p.conflicts) {
              py::dict d;
              d["kind"] = kind_name(c.kind);
              d["writer"] = c.writer;
              d["owner"] = c.owner;
              d["seq"] = c.seq;
              d["instance"] = c.instance;
              d["property"] = c.property;
              d["text"] = c.text;
              out.append(std::move(d));
            }
            p.conflicts->clear();
            return out;
          },
          "The conflicts reported here since the last call (dicts: kind, writer, owner, seq, instance, "
          "property, text); at most 10,000 are kept between calls")
      .def("stats", [](const PyParticipant& p) {
        const vsd::dist::ParticipantStats& s = p.get().stats();
        py::dict d;
        d["bundles_sent"] = s.bundles_sent;
        d["claims_sent"] = s.claims_sent;
        d["bundles_applied"] = s.bundles_applied;
        d["duplicates"] = s.duplicates;
        d["malformed"] = s.malformed;
        d["conflicts"] = s.conflicts;
        d["resyncs"] = s.resyncs;
        d["snapshots_served"] = s.snapshots_served;
        return d;
      });
}

}  // namespace vsdpy
