// The entry points of vsd::scene (URDF loading), vsd::robotics (kinematics, FK, IK), vsd::physics and
// vsd::collision (use, contacts, distances), each only when the module is built. Everything else of
// theirs (Node3D frames, joint positions, worlds, rigid bodies, geometries ...) is reached through the
// meta-information like any class.
#include <pybind11/numpy.h>
#include <pybind11/stl.h>

#include "vsdpy.hpp"
#ifdef VSDPY_WITH_SCENE
#include "vsd/scene/module.hpp"
#include "vsd/scene/scene.hpp"
#include "vsd/scene/urdf_loader.hpp"
#endif
#ifdef VSDPY_WITH_PHYSICS
#include "vsd/physics/module.hpp"
#endif
#ifdef VSDPY_WITH_COLLISION
#include "vsd/collision/collision_world.hpp"
#include "vsd/collision/module.hpp"
#include "vsd/scene/hull.hpp"
#endif
#ifdef VSDPY_WITH_ROBOTICS
#include "vsd/robotics/ik.hpp"
#include "vsd/robotics/kinematic_tree.hpp"
#include "vsd/robotics/module.hpp"
#endif

namespace vsdpy {

namespace {

#ifdef VSDPY_WITH_ROBOTICS
vsd::robotics::KinematicTree& tree_of(const Handle& h) {
  auto* t = h.get().as<vsd::robotics::KinematicTree>();
  if (t == nullptr) throw py::type_error("expected a robotics::KinematicTree, got a " + h.get().meta().name());
  return *t;
}

std::vector<double> joint_vector(const vsd::robotics::Model& model, py::handle q, const char* what) {
  auto a = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(q);
  if (!a || a.ndim() != 1) {
    PyErr_Clear();
    throw py::type_error(std::string(what) + " expects a 1-D array of " + std::to_string(model.dof()) + " numbers");
  }
  if (a.shape(0) != model.dof())
    throw py::value_error(std::string(what) + ": the model has " + std::to_string(model.dof()) + " joints, got " +
                          std::to_string(a.shape(0)) + " values");
  return {a.data(), a.data() + a.shape(0)};
}

int body_of(const vsd::robotics::Model& model, py::handle body) {
  if (body.is_none()) return model.tip();
  const auto name = body.cast<std::string>();
  const int b = model.find_body(name);
  if (b < 0) throw py::key_error("the model has no body '" + name + "'");
  return b;
}

py::array matrix_of(const Eigen::Isometry3d& f) {
  py::array_t<double> a({4, 4});
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c) a.mutable_at(r, c) = f.matrix()(r, c);
  return a;
}
#endif

#if defined(VSDPY_WITH_ROBOTICS) || defined(VSDPY_WITH_COLLISION)
py::array vector_of(const Eigen::Vector3d& v) {
  py::array_t<double> a(3);
  for (int i = 0; i < 3; ++i) a.mutable_at(i) = v[i];
  return a;
}
#endif

#ifdef VSDPY_WITH_COLLISION
vsd::scene::Hull& hull_of(const Handle& h, const char* what) {
  auto* x = h.get().as<vsd::scene::Hull>();
  if (x == nullptr) throw py::type_error(std::string(what) + ": expected a scene::Hull, got a " + h.get().meta().name());
  return *x;
}

// The collision world of a state (the module used in its environment first).
vsd::collision::CollisionWorld& collision_world(const PyState& s) {
  vsd::SimState& st = s.get();
  auto* m = s.box->env->env->module<vsd::collision::Module>();
  if (m == nullptr) throw py::value_error("collision: the environment does not use the collision module (vsd.collision.use(env))");
  return m->world(st);
}
#endif

}  // namespace

void bind_modules([[maybe_unused]] py::module_& m) {
#ifdef VSDPY_WITH_SCENE
  py::module_ scene = m.def_submodule("scene", "vsd::scene: 3D scenes, URDF loading");
  scene.def("use", [](const PyEnvironment& e) { e.box->env->use<vsd::scene::Module>(); },
            "Uses the scene module in env (world frames kept current)");
  scene.def(
      "load_urdf",
      [](const Handle& parent, const std::string& path, bool load_meshes) {
        auto* p = parent.get().as<vsd::Node>();
        if (p == nullptr) throw py::type_error("load_urdf: the parent must be a Node");
        vsd::scene::UrdfOptions options;
        options.load_meshes = load_meshes;
        vsd::scene::SceneReport r;
        {
          py::gil_scoped_release release;
          r = vsd::scene::load_urdf(*p, path, options);
        }
        py::dict d;
        d["scene"] = wrap(parent.box, r.scene);
        d["links"] = r.links;
        d["joints"] = r.joints;
        d["warnings"] = r.warnings;
        return d;
      },
      py::arg("parent"), py::arg("path"), py::arg("load_meshes") = true,
      "Loads a URDF file under parent; returns {scene, links, joints, warnings}");
#endif
#ifdef VSDPY_WITH_PHYSICS
  py::module_ physics = m.def_submodule("physics", "vsd::physics: rigid bodies (ODE) in physics::World scenes");
  physics.def("use", [](const PyEnvironment& e) { e.box->env->use<vsd::physics::Module>(); },
              "Uses the physics module in env: every step moves the rigid bodies of each physics::World");
#endif
#ifdef VSDPY_WITH_COLLISION
  py::module_ collision = m.def_submodule("collision", "vsd::collision: contacts and distances between hulls");
  collision.def(
      "use",
      [](const PyEnvironment& e, double period) {
        if (!(period >= 0)) throw py::value_error("collision.use: period must be >= 0 (0: every step)");
        e.box->env->use<vsd::collision::Module>(period);
      },
      py::arg("env"), py::arg("period") = 0.0,
      "Uses the collision module in env: its worlds update every `period` seconds (0: every step)");
  collision.def(
      "contacts",
      [](const PyState& s) {
        auto& w = collision_world(s);
        {
          py::gil_scoped_release release;
          w.update();  // now, not at the module's last update: the world may have been made just now
        }
        py::list out;
        for (const vsd::collision::Contact& c : w.contacts()) {
          py::dict d;
          d["a"] = wrap(s.box, c.a);
          d["b"] = wrap(s.box, c.b);
          d["position"] = vector_of(c.position);
          d["normal"] = vector_of(c.normal);
          d["depth"] = c.depth;
          out.append(d);
        }
        return out;
      },
      "The contacts of the state's collision hulls now (updates its world): [{a, b, position, normal, depth}]");
  collision.def(
      "distance",
      [](const PyState& s, const Handle& a, const Handle& b) {
        auto& ha = hull_of(a, "collision.distance");
        auto& hb = hull_of(b, "collision.distance");
        const auto r = collision_world(s).distance(ha, hb);
        return py::make_tuple(r.distance, vector_of(r.point_a), vector_of(r.point_b));
      },
      "(distance, point_a, point_b) between two hulls of the state, now");
#endif
#ifdef VSDPY_WITH_ROBOTICS
  py::module_ rob = m.def_submodule("robotics", "vsd::robotics: kinematic trees, FK and IK");
  rob.def("use", [](const PyEnvironment& e) { e.box->env->use<vsd::robotics::Module>(); },
          "Uses the robotics module in env (joint values move their links in every state)");
  rob.def(
      "build_kinematics",
      [](const Handle& scene) {
        auto* s = scene.get().as<vsd::scene::Scene>();
        if (s == nullptr) throw py::type_error("build_kinematics expects a scene::Scene");
        return wrap(scene.box, &vsd::robotics::build_kinematics(*s));
      },
      "Adds KinematicJoints and a KinematicTree to a loaded scene; returns the tree");
  rob.def("positions", [](const Handle& tree) {
    const auto q = tree_of(tree).positions();
    return py::array_t<double>(static_cast<py::ssize_t>(q.size()), q.data());
  }, "The tree's joint vector (model layout)");
  rob.def("set_positions", [](const Handle& tree, py::handle q) {
    auto& t = tree_of(tree);
    t.set_positions(joint_vector(t.model(), q, "set_positions"));
  }, "Writes a joint vector to the joints' position properties (recorded and signalled)");
  rob.def("joint_names", [](const Handle& tree) {
    std::vector<std::string> names;
    for (const auto& d : tree_of(tree).model().layout()) names.push_back(d.name);
    return names;
  });
  rob.def(
      "forward",
      [](const Handle& tree, py::handle q, py::handle body) {
        const auto& model = tree_of(tree).model();
        const auto v = joint_vector(model, q, "forward");
        auto data = model.make_data();
        model.forward(v, data);
        return matrix_of(model.pose(data, body_of(model, body)).isometry());
      },
      py::arg("tree"), py::arg("q"), py::arg("body") = py::none(),
      "The 4x4 pose of a body (default: the tip) in the tree's base frame at joint vector q");
  rob.def(
      "inverse",
      [](const Handle& tree, py::handle target, py::handle seed, py::handle body) {
        const auto& model = tree_of(tree).model();
        auto a = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(target);
        if (!a || a.ndim() != 2 || a.shape(0) != 4 || a.shape(1) != 4) {
          PyErr_Clear();
          throw py::type_error("inverse expects a 4x4 target pose");
        }
        Eigen::Isometry3d t;
        for (int r = 0; r < 4; ++r)
          for (int c = 0; c < 4; ++c) t.matrix()(r, c) = a.at(r, c);
        const auto s = seed.is_none() ? tree_of(tree).positions() : joint_vector(model, seed, "inverse seed");
        vsd::robotics::IkSolver solver(model, body_of(model, body));
        vsd::robotics::IkResult r;
        {
          py::gil_scoped_release release;
          r = solver.solve(t, s);
        }
        py::dict d;
        d["success"] = r.success;
        d["q"] = py::array_t<double>(static_cast<py::ssize_t>(r.q.size()), r.q.data());
        d["position_error"] = r.position_error;
        d["orientation_error"] = r.orientation_error;
        d["iterations"] = r.iterations;
        return d;
      },
      py::arg("tree"), py::arg("target"), py::arg("seed") = py::none(), py::arg("body") = py::none(),
      "Solves IK for a 4x4 target pose; returns {success, q, position_error, orientation_error, iterations}");
#endif
}

}  // namespace vsdpy
