// The model the io tests save and load: every kind of value and reference, in a fixed shape so that its
// text is stable (golden files).
#pragma once

#include <array>
#include <cstdint>
#include <random>
#include <string>
#include <string_view>
#include <vector>

#include "../core/test_classes.hpp"

namespace vsd_test {

// Small conversions the io test files share (one definition: the files compile together in a unity build).
inline std::vector<std::uint8_t> bytes_of(std::string_view s) { return {s.begin(), s.end()}; }
inline std::string text_of(const std::vector<std::uint8_t>& b) { return {b.begin(), b.end()}; }
/// Empty when @p a and @p b hold equal content, else the first difference.
inline std::string diff_of(const vsd::SimState& a, const vsd::SimState& b) {
  std::string d;
  return a.equals(b, &d) ? std::string() : d;
}

class IoPlain : public vsd::Node {
  VSD_INSTANCE(IoPlain, vsd::Node)
  VSD_PROPERTY(double, saved, 1.0, vsd::Savable)
  VSD_PROPERTY(double, not_saved, 2.0, vsd::Editable)
};

// A model with every kind of value and reference.
inline void build_model(vsd::SimState& s) {
  auto& cell = s.create<vsd::Node>();
  cell.set_name("cell");
  s.database().add_child(cell);
  auto& r = s.create<TRobot>();
  r.set_name("arm");
  r.set_speed(2.5);
  r.set_joints({0.1, -0.2, 0.3});
  Eigen::Isometry3d f = Eigen::Isometry3d::Identity();
  f.translate(Eigen::Vector3d(1, 2, 3));
  r.set_frame(f);
  cell.add_child(r);
  auto& tool = s.create<TTool>();
  tool.set_length(0.25);
  r.set_tool(&tool);  // composite, not a child
  auto& goal = s.create<vsd::Node>();
  goal.set_name("goal");
  cell.add_child(goal);
  r.set_target(&goal);  // shared, pointing forward in id order from nothing
  auto& sensor = s.create<TSensor>();
  sensor.set_range(9);
  r.add_extension(sensor);
  const vsd::MetaProperty& watched = TRobot::vsd_prop_watched();
  r.list_insert(watched, 0, goal);
  r.list_insert(watched, 1, cell);
  s.database().set_name("world");
}

}  // namespace vsd_test

namespace vsd_test {

enum class IoMode : std::uint8_t { Idle, Run = 7, Fault = 200 };
enum class IoCaps : std::uint16_t { Grip = 1, Weld = 2, Paint = 8 };
struct IoPose {
  double x = 0;
  double y = 0;
  float theta = 0;
};
struct IoStep {
  std::string label;
  IoPose pose;
  IoMode mode = IoMode::Idle;
  std::vector<Eigen::Vector3d> path;
};
VSD_ENUM(IoMode, Idle, Run, Fault)
VSD_FLAGS(IoCaps, Grip, Weld, Paint)
VSD_STRUCT(IoPose, x, y, theta)
VSD_STRUCT(IoStep, label, pose, mode, path)

// Every other kind of value: enums, flags, structs, vectors of them, the integer widths, float, text.
class IoRich : public vsd::Node {
  VSD_INSTANCE(IoRich, vsd::Node)
  VSD_PROPERTY(IoMode, mode, IoMode::Idle)
  VSD_PROPERTY(IoCaps, caps, IoCaps::Grip)
  VSD_PROPERTY(IoStep, step, {})
  VSD_PROPERTY(std::vector<IoStep>, plan, {})
  VSD_PROPERTY(std::vector<std::string>, tags, {})
  VSD_PROPERTY(std::int8_t, small, 0)
  VSD_PROPERTY(std::uint64_t, big, 0)
  VSD_PROPERTY(float, ratio, 0.0F)
  VSD_PROPERTY(Eigen::Quaterniond, attitude, Eigen::Quaterniond::Identity())
  VSD_PROPERTY(Eigen::Vector2d, offset, Eigen::Vector2d::Zero())
};

// Random operations on top of RandomModel's that reach every kind of value and run-time classes: rich
// instances with random values (odd strings, extreme numbers, arbitrary rotations) and instances of a
// run-time class holding numbers, text, a frame and both kinds of reference.
class RichSteps {
 public:
  RichSteps(vsd::SimState& s, std::uint32_t seed, const vsd::MetaInstance& runtime_class)
      : s_(s), rng_(seed), runtime_(runtime_class) {}

  /// The run-time class the steps use (define once per program, undefine when done).
  static const vsd::MetaInstance& define_runtime_class(const std::string& name) {
    return vsd::ClassBuilder(name, vsd::Node::static_meta())
        .property<double>("load", 1.5)
        .property<std::string>("note", std::string("none"))
        .property<Eigen::Isometry3d>("mount", Eigen::Isometry3d::Identity())
        .property("peer", vsd::meta_type<vsd::SharedRef<vsd::Node>>())
        .property("parts", vsd::meta_type<vsd::RefList<vsd::Node>>())
        .define();
  }

  void step() {
    const auto all = s_.instances();
    auto pick_node = [&]() -> vsd::Node* {
      for (int tries = 0; tries < 8; ++tries)
        if (auto* n = all[uniform(all.size())]->as<vsd::Node>()) return n;
      return &s_.database();
    };
    try {
      switch (uniform(4)) {
        case 0: {
          auto& r = s_.create<IoRich>();
          randomise(r);
          pick_node()->add_child(r);
          break;
        }
        case 1: {
          auto& n = static_cast<vsd::Node&>(s_.create(runtime_));
          n.set("load", vsd::Value(real()));
          n.set("note", vsd::Value(text()));
          n.set("mount", vsd::Value(frame()));
          pick_node()->add_child(n);
          break;
        }
        case 2: {  // references of the run-time class
          auto* x = all[uniform(all.size())];
          if (&x->meta() != &runtime_) break;
          x->set("peer", vsd::Value(vsd::SharedRef<vsd::Node>(uniform(3) == 0 ? nullptr : pick_node())));
          auto& part = s_.create<vsd::Node>();
          part.set_name(text());
          x->list_insert(x->meta().property("parts"), 0, part);
          break;
        }
        default: {
          if (auto* r = all[uniform(all.size())]->as<IoRich>()) randomise(*r);
        }
      }
    } catch (const vsd::Error&) {  // rejected by the rules (cycles, ...): the state stays consistent
    }
  }

 private:
  unsigned uniform(std::size_t n) { return static_cast<unsigned>(rng_() % n); }
  double real() {
    switch (uniform(6)) {
      case 0:
        return 0.0;
      case 1:
        return -1e-310;  // subnormal
      case 2:
        return 1e300 * (uniform(2) == 0 ? 1 : -1);
      default:
        return std::uniform_real_distribution<double>(-1000, 1000)(rng_);
    }
  }
  std::string text() {
    static const char* const pieces[] = {"a", "Z", " ", "\"", "\\", "\n", "\t", "\x01", "\xC3\xA9", "\xF0\x9F\x99\x82",
                                         "{", "]", ":", ",", "@1", "null", "/"};
    std::string s;
    for (unsigned n = uniform(8); n > 0; --n) s += pieces[uniform(std::size(pieces))];
    return s;
  }
  Eigen::Isometry3d frame() {
    Eigen::Isometry3d f = Eigen::Isometry3d::Identity();
    const Eigen::Vector3d axis = Eigen::Vector3d::Random().normalized();
    f.rotate(Eigen::AngleAxisd(real() / 100, axis.allFinite() ? axis : Eigen::Vector3d::UnitZ()));
    f.translation() = Eigen::Vector3d(real(), real(), real());
    return f;
  }
  IoStep step_value() {
    IoStep st;
    st.label = text();
    st.pose = {real(), real(), static_cast<float>(real() / 7)};
    st.mode = std::array{IoMode::Idle, IoMode::Run, IoMode::Fault, static_cast<IoMode>(3)}[uniform(4)];
    for (unsigned n = uniform(3); n > 0; --n) st.path.emplace_back(real(), real(), real());
    return st;
  }
  void randomise(IoRich& r) {
    r.set_mode(std::array{IoMode::Idle, IoMode::Run, IoMode::Fault}[uniform(3)]);
    r.set_caps(static_cast<IoCaps>(uniform(32)));  // includes bits without a name
    r.set_step(step_value());
    std::vector<IoStep> plan;
    for (unsigned n = uniform(3); n > 0; --n) plan.push_back(step_value());
    r.set_plan(plan);
    std::vector<std::string> tags;
    for (unsigned n = uniform(3); n > 0; --n) tags.push_back(text());
    r.set_tags(tags);
    r.set_small(static_cast<std::int8_t>(static_cast<int>(uniform(256)) - 128));
    r.set_big(uniform(2) == 0 ? ~std::uint64_t{0} : rng_());
    r.set_ratio(std::array{0.1F, -0.0F, 3.4e38F, 1e-45F}[uniform(4)]);
    r.set_attitude(Eigen::Quaterniond(frame().linear()));
    r.set_offset(Eigen::Vector2d(real(), real()));
  }

  vsd::SimState& s_;
  std::mt19937 rng_;
  const vsd::MetaInstance& runtime_;
};

}  // namespace vsd_test
