// The compiled kinematic model: build from specs (or from the database), FK of all segments, Jacobians.
#include "vsd/robotics/model.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <unordered_map>
#include <utility>

#include "vsd/core/error.hpp"
#include "vsd/robotics/detail/sincos.hpp"
#include "vsd/scene/node3d.hpp"

namespace vsd::robotics {

namespace {

// Two doubles in one SSE2 register: GCC and Clang vector extensions (plain operators, no intrinsics);
// a tiny struct elsewhere, with the same arithmetic (and the same results).
#if defined(__GNUC__)
using V2 = double __attribute__((vector_size(16)));
inline V2 v2(double a, double b) noexcept { return V2{a, b}; }
#else
struct V2 {
  double v[2];
  double operator[](int i) const noexcept { return v[i]; }
  friend V2 operator+(V2 a, V2 b) noexcept { return V2{{a.v[0] + b.v[0], a.v[1] + b.v[1]}}; }
  friend V2 operator*(V2 a, V2 b) noexcept { return V2{{a.v[0] * b.v[0], a.v[1] * b.v[1]}}; }
};
inline V2 v2(double a, double b) noexcept { return V2{{a, b}}; }
#endif

[[noreturn]] void fail(const std::string& msg) { throw vsd::Error(msg); }

// The AVX form of forward kinematics: x86 with GCC or Clang, chosen at run time (the library is built for
// baseline x86-64). Four lanes per operation, a 3x3 column in one register, and the fast form's constants
// stored broadcast to four lanes, so that the products take them straight from memory (no shuffles).
// No FMA: the same products and sums in the same order as the SSE2 form, so the same results bit for bit
// on every machine.
#if defined(__GNUC__) && (defined(__x86_64__) || defined(__i386__))
#define VSD_FK_AVX 1
using V4 = double __attribute__((vector_size(32)));
// The four-wide stores below write one value past a rotation column: into the next column, or for the
// last column into the translation, which must follow the rotation directly.
static_assert(sizeof(Frame) == 12 * sizeof(double), "Frame: rotation then translation, no padding");

__attribute__((target("avx"), always_inline)) inline V4 ld(const double* v) noexcept {
  V4 r;
  std::memcpy(&r, v, sizeof r);
  return r;
}

bool avx_available() {
  const char* off = std::getenv("VSD_ROBOTICS_NO_AVX");
  if (off != nullptr && *off != '\0' && *off != '0') return false;
  __builtin_cpu_init();
  return __builtin_cpu_supports("avx") != 0;
}

// detail::sincos_batch with four angles per operation (the same operations, so the same results).
__attribute__((target("avx"))) void sincos_batch_avx(const double* x, double* s, double* c,
                                                     std::size_t n) noexcept {
  detail::sincos_lanes(std::make_index_sequence<4>{}, x, s, c, n);
}

// Segments i, i+1, ... in the fast form, up to the first one in the general form (whose index it
// returns) or n. M (the product before the segment's perm) is kept in p0..p2 by columns (lane 3 unused)
// and pt; A = C * Rz(v) is formed entry by entry already broadcast (A(k,0) = c B(k,0) + s B(k,1),
// A(k,1) = c B(k,1) - s B(k,0), A(k,2) = B(k,2)), then M' = M * A column by column.
__attribute__((target("avx"))) std::size_t fast_run_avx(const detail::FkStep* steps, std::size_t i,
                                                        std::size_t n, Frame* out, const double* sines,
                                                        const double* cosines) noexcept {
  V4 p0 = {}, p1 = {}, p2 = {}, pt = {};
  for (; i < n; ++i) {
    const detail::FkStep& st = steps[i];
    if (st.mode == 0) return i;
    const double cv = cosines[i], sv = sines[i];
    const V4 c = {cv, cv, cv, cv}, s = {sv, sv, sv, sv};
    if (st.mode == 1) {
      // The base: M = A, t = pre.p.
      V4 k0, w0, k1, w1;
      std::memcpy(&k0, st.col[0], sizeof k0);
      std::memcpy(&w0, st.col[1], sizeof w0);
      std::memcpy(&k1, st.col[2], sizeof k1);
      std::memcpy(&w1, st.col[3], sizeof w1);
      std::memcpy(&p2, st.col[4], sizeof p2);
      std::memcpy(&pt, st.col[5], sizeof pt);
      p0 = c * k0 + s * w0;
      p1 = c * k1 + s * w1;
    } else {
      if (st.mode == 3) {
        // The parent's frame from memory (columns 0 and 1 read one value past their end: lane 3).
        const double* pr = out[st.parent].rotation.data();
        const double* ptr = out[st.parent].translation.data();
        std::memcpy(&p0, pr, sizeof p0);
        std::memcpy(&p1, pr + 3, sizeof p1);
        p2 = V4{pr[6], pr[7], pr[8], 0.0};
        pt = V4{ptr[0], ptr[1], ptr[2], 0.0};
      }
      const auto& b = st.bcast;
      // The translation first (it needs the parent's M), over the nonzero components of pre.p.
      if (st.mask & 1U) pt = pt + p0 * ld(b[0][5]);
      if (st.mask & 2U) pt = pt + p1 * ld(b[1][5]);
      if (st.mask & 4U) pt = pt + p2 * ld(b[2][5]);
      const V4 a00 = c * ld(b[0][0]) + s * ld(b[0][1]);
      const V4 a10 = c * ld(b[1][0]) + s * ld(b[1][1]);
      const V4 a20 = c * ld(b[2][0]) + s * ld(b[2][1]);
      const V4 a01 = c * ld(b[0][2]) + s * ld(b[0][3]);
      const V4 a11 = c * ld(b[1][2]) + s * ld(b[1][3]);
      const V4 a21 = c * ld(b[2][2]) + s * ld(b[2][3]);
      const V4 n0 = p0 * a00 + p1 * a10 + p2 * a20;
      const V4 n1 = p0 * a01 + p1 * a11 + p2 * a21;
      const V4 n2 = p0 * ld(b[0][4]) + p1 * ld(b[1][4]) + p2 * ld(b[2][4]);
      p0 = n0;
      p1 = n1;
      p2 = n2;
    }
    // Columns in frame order, each store four wide: lane 3 lands on the next column's first entry (or
    // the translation's), which the next store overwrites; the translation last, three wide.
    double* r = out[i].rotation.data();
    if (st.identity_perm != 0) {
      std::memcpy(r, &p0, sizeof p0);
      std::memcpy(r + 3, &p1, sizeof p1);
      std::memcpy(r + 6, &p2, sizeof p2);
    } else {
      const V4 cols[3] = {p0, p1, p2};
      for (int d = 0; d < 3; ++d) std::memcpy(r + 3 * d, &cols[st.dest_src[d]], sizeof(V4));
    }
    double* t = out[i].translation.data();
    t[0] = pt[0];
    t[1] = pt[1];
    t[2] = pt[2];
  }
  return n;
}
#else
bool avx_available() { return false; }
#endif

bool is_identity(const Frame& f) { return f.rotation.isIdentity(0.0) && f.translation.isZero(0.0); }

// Follows the mimic relation of spec @p i to a joint that mimics nobody; composes multiplier and offset.
struct Resolved {
  int master = -1;
  double multiplier = 1.0;
  double offset = 0.0;
};
Resolved resolve_mimic(std::span<const JointSpec> specs, int i) {
  Resolved r{i, 1.0, 0.0};
  std::size_t steps = 0;
  while (specs[static_cast<std::size_t>(r.master)].mimic >= 0) {
    const JointSpec& s = specs[static_cast<std::size_t>(r.master)];
    if (s.mimic >= static_cast<int>(specs.size()))
      fail("joint '" + s.name + "': mimics joint index " + std::to_string(s.mimic) + ", out of range");
    // q_s = m * q_master + o, and q_i = r.multiplier * q_s + r.offset.
    r.offset += r.multiplier * s.mimic_offset;
    r.multiplier *= s.mimic_multiplier;
    r.master = s.mimic;
    if (++steps > specs.size()) fail("joint '" + specs[static_cast<std::size_t>(i)].name + "': mimic cycle");
  }
  return r;
}

}  // namespace

Model Model::build(std::span<const JointSpec> specs) {
  Model m;
  const int n = static_cast<int>(specs.size());
  // Validation first: nothing half built escapes.
  std::vector<int> spec_body(specs.size(), -1);
  int bodies = 0;
  for (int i = 0; i < n; ++i) {
    const JointSpec& s = specs[static_cast<std::size_t>(i)];
    if (s.value_only) continue;
    if (s.parent < -1 || s.parent >= bodies)
      fail("joint '" + s.name + "': parent body index " + std::to_string(s.parent) +
           " is not an earlier body (there are " + std::to_string(bodies) + ")");
    spec_body[static_cast<std::size_t>(i)] = bodies++;
    if (s.type != KinematicJointType::Fixed && !(s.placement.axis.norm() > 1e-12))
      fail("joint '" + s.name + "': zero axis");
    if (s.type == KinematicJointType::Universal && !(s.axis2.norm() > 1e-12))
      fail("joint '" + s.name + "': zero second axis");
    if (!s.placement.pre.matrix().allFinite() || !s.placement.post.matrix().allFinite() ||
        !s.placement.axis.allFinite() || !s.axis2.allFinite())
      fail("joint '" + s.name + "': its origin or axis is not finite");
    if (s.has_limits && (!std::isfinite(s.lower) || !std::isfinite(s.upper)))
      fail("joint '" + s.name + "': its limits are not finite (no limits: has_limits false)");
    if (!std::isfinite(s.mimic_multiplier) || !std::isfinite(s.mimic_offset))
      fail("joint '" + s.name + "': its mimic multiplier or offset is not finite");
    if (s.has_limits && !(s.lower <= s.upper))
      fail("joint '" + s.name + "': lower limit " + std::to_string(s.lower) + " above upper limit " +
           std::to_string(s.upper));
    if (s.mimic >= 0 && s.type == KinematicJointType::Universal)
      fail("joint '" + s.name + "': a universal joint cannot mimic another");
  }
  // Layout: the values of every joint that mimics nobody, in order.
  std::vector<int> first_dof(specs.size(), -1);
  for (int i = 0; i < n; ++i) {
    const JointSpec& s = specs[static_cast<std::size_t>(i)];
    if (s.type == KinematicJointType::Fixed || s.mimic >= 0) continue;
    first_dof[static_cast<std::size_t>(i)] = static_cast<int>(m.layout_.size());
    const int count = s.type == KinematicJointType::Universal ? 2 : 1;
    for (int k = 0; k < count; ++k) {
      DofInfo d;
      d.name = k == 0 ? s.name : s.name + "#2";
      d.type = s.type == KinematicJointType::Universal ? KinematicJointType::Rotary : s.type;
      d.has_limits = s.has_limits;
      d.lower = s.lower;
      d.upper = s.upper;
      d.velocity_limit = s.velocity_limit;
      d.acceleration_limit = s.acceleration_limit;
      d.joint = s.source;
      d.axis_index = k;
      m.layout_.push_back(std::move(d));
    }
  }
  // Segments: one per body (a universal joint adds one in front for its first axis).
  std::vector<int> body_seg;
  for (int i = 0; i < n; ++i) {
    const JointSpec& s = specs[static_cast<std::size_t>(i)];
    if (s.value_only) continue;
    const int parent_seg = s.parent < 0 ? -1 : body_seg[static_cast<std::size_t>(s.parent)];
    auto motion_of = [](KinematicJointType t, const Eigen::Vector3d& a) {
      if (t == KinematicJointType::Fixed) return Motion::None;
      if (t == KinematicJointType::Prismatic) return Motion::Trans;
      if (a == Eigen::Vector3d::UnitX()) return Motion::RotX;
      if (a == Eigen::Vector3d::UnitY()) return Motion::RotY;
      if (a == Eigen::Vector3d::UnitZ()) return Motion::RotZ;
      return Motion::Rot;
    };
    Segment seg;
    seg.parent = parent_seg;
    seg.pre = Frame::from(s.placement.pre);
    seg.post = Frame::from(s.placement.post);
    seg.axis = s.type == KinematicJointType::Fixed ? Eigen::Vector3d::UnitZ() : s.placement.axis.normalized();
    seg.motion = motion_of(s.type, seg.axis);
    if (s.type != KinematicJointType::Fixed) {
      if (s.mimic >= 0) {
        const Resolved r = resolve_mimic(specs, i);
        const JointSpec& master = specs[static_cast<std::size_t>(r.master)];
        if (master.type == KinematicJointType::Fixed)
          fail("joint '" + s.name + "': mimics fixed joint '" + master.name + "'");
        seg.dof = first_dof[static_cast<std::size_t>(r.master)];
        seg.multiplier = r.multiplier;
        seg.offset = r.offset;
      } else {
        seg.dof = first_dof[static_cast<std::size_t>(i)];
      }
    }
    if (s.type == KinematicJointType::Universal) {
      Segment second;
      second.post = seg.post;
      second.axis = s.axis2.normalized();
      second.motion = motion_of(KinematicJointType::Rotary, second.axis);
      second.dof = seg.dof + 1;
      seg.post = Frame{};
      m.segments_.push_back(seg);
      second.parent = static_cast<int>(m.segments_.size()) - 1;
      m.segments_.push_back(second);
    } else {
      m.segments_.push_back(seg);
    }
    body_seg.push_back(static_cast<int>(m.segments_.size()) - 1);
    m.body_name_.push_back(s.body);
  }
  for (Segment& seg : m.segments_) {
    seg.pre_identity = is_identity(seg.pre);
    seg.post_identity = is_identity(seg.post);
    seg.pre_rotation_identity = seg.pre.rotation.isIdentity(0.0);
    seg.pre_translation_mask = 0;
    for (int k = 0; k < 3; ++k)
      if (seg.pre.translation[k] != 0.0) seg.pre_translation_mask |= static_cast<std::uint8_t>(1U << k);
    // The fast form: src[i] = the pre.R column that is B's column i (B = pre.R * Q); column i of the
    // product parent.R * B * Rz(v) is then the frame's column src[i] (times Q^T).
    int src[3] = {0, 1, 2};
    seg.fast = seg.post_identity;
    switch (seg.motion) {
      case Motion::None:
      case Motion::RotZ:
        break;
      case Motion::RotX:  // Q = [e_y e_z e_x]: B = [p1 p2 p0], product column i goes to (i + 1) % 3
        src[0] = 1, src[1] = 2, src[2] = 0;
        break;
      case Motion::RotY:  // Q = [e_z e_x e_y]: B = [p2 p0 p1], product column i goes to (i + 2) % 3
        src[0] = 2, src[1] = 0, src[2] = 1;
        break;
      default:
        seg.fast = false;
        break;
    }
    for (int i = 0; i < 3; ++i) seg.perm[i] = static_cast<std::uint8_t>(src[i]);
    for (int j = 0; j < 3; ++j) {
      const double b0 = seg.pre.rotation(j, src[0]), b1 = seg.pre.rotation(j, src[1]);
      seg.b_row[j][0] = b0;
      seg.b_row[j][1] = b1;
      seg.b_swap[j][0] = b1;
      seg.b_swap[j][1] = -b0;
      seg.b_col2[j] = seg.pre.rotation(j, src[2]);
    }
    seg.axis_post = seg.post.rotation.transpose() * seg.axis;
    seg.origin_post = -(seg.post.rotation.transpose() * seg.post.translation);
  }
  for (std::size_t i = 0; i < m.segments_.size(); ++i) {
    Segment& seg = m.segments_[i];
    if (!seg.fast || seg.parent < 0 || static_cast<std::size_t>(seg.parent) + 1 != i) continue;
    const Segment& par = m.segments_[i - 1];
    if (!par.fast) continue;
    seg.chained = true;
    seg.c_mask = 0;
    for (int j = 0; j < 3; ++j) {
      const int from = par.perm[j];
      for (int h = 0; h < 2; ++h) {
        seg.c_row[j][h] = seg.b_row[from][h];
        seg.c_swap[j][h] = seg.b_swap[from][h];
      }
      seg.c_col2[j] = seg.b_col2[from];
      seg.c_translation[j] = seg.pre.translation[from];
      if (seg.c_translation[j] != 0.0) seg.c_mask |= static_cast<std::uint8_t>(1U << j);
    }
  }
  if (avx_available()) {
    m.steps_.resize(m.segments_.size());
    for (std::size_t i = 0; i < m.segments_.size(); ++i) {
      const Segment& seg = m.segments_[i];
      detail::FkStep& st = m.steps_[i];
      st.parent = seg.parent;
      if (!seg.fast) continue;  // mode 0: the general form
      st.mode = seg.parent < 0 ? 1 : seg.chained ? 2 : 3;
      const auto& row = seg.chained ? seg.c_row : seg.b_row;
      const auto& swp = seg.chained ? seg.c_swap : seg.b_swap;
      const double* col2 = seg.chained ? seg.c_col2 : seg.b_col2;
      const double* lt = seg.chained ? seg.c_translation : seg.pre.translation.data();
      st.mask = seg.chained ? seg.c_mask : seg.pre_translation_mask;
      for (int k = 0; k < 3; ++k) {
        const double vals[6] = {row[k][0], swp[k][0], row[k][1], swp[k][1], col2[k], lt[k]};
        for (int e = 0; e < 6; ++e) {
          for (int l = 0; l < 4; ++l) st.bcast[k][e][l] = vals[e];
          st.col[e][k] = vals[e];
        }
      }
      for (int c = 0; c < 3; ++c) st.dest_src[seg.perm[c]] = static_cast<std::uint8_t>(c);
      st.identity_perm = seg.perm[0] == 0 && seg.perm[1] == 1 && seg.perm[2] == 2 ? 1 : 0;
    }
  }
  m.body_segment_ = std::move(body_seg);
  return m;
}

Model Model::compile(const scene::Node3D& base, const scene::Node3D* tip) {
  std::vector<const scene::Node3D*> nodes;
  std::vector<int> parents;
  std::unordered_map<const scene::Node3D*, int> index;
  if (tip != nullptr) {
    std::vector<const scene::Node3D*> up;
    const scene::Node3D* n = tip;
    for (; n != nullptr && n != &base; n = n->frame_parent()) up.push_back(n);
    if (n == nullptr) fail("node '" + tip->name() + "' is not below '" + base.name() + "'");
    for (auto it = up.rbegin(); it != up.rend(); ++it) {
      parents.push_back(static_cast<int>(nodes.size()) - 1);
      nodes.push_back(*it);
    }
  } else {
    // Depth first; plain Nodes in between are transparent, as for frames.
    struct Item {
      const vsd::Node* node;
      int parent;
    };
    std::vector<Item> todo;
    auto push_children = [&todo](const vsd::Node& n, int parent) {
      const auto& ch = n.children();
      for (std::size_t k = ch.size(); k-- > 0;) todo.push_back(Item{ch[k], parent});
    };
    push_children(base, -1);
    while (!todo.empty()) {
      const Item item = todo.back();
      todo.pop_back();
      int here = item.parent;
      if (const auto* n3 = item.node->as<scene::Node3D>()) {
        here = static_cast<int>(nodes.size());
        nodes.push_back(n3);
        parents.push_back(item.parent);
      }
      push_children(*item.node, here);
    }
  }
  for (std::size_t i = 0; i < nodes.size(); ++i) index[nodes[i]] = static_cast<int>(i);

  std::vector<JointSpec> specs;
  specs.reserve(nodes.size());
  std::unordered_map<const KinematicJoint*, int> spec_of;
  for (std::size_t i = 0; i < nodes.size(); ++i) {
    JointSpec s;
    s.body = nodes[i]->name();
    s.parent = parents[i];
    const KinematicJoint* j = nodes[i]->find_extension<KinematicJoint>();
    if (j == nullptr) {
      s.name = nodes[i]->name();
      s.type = KinematicJointType::Fixed;
      s.placement.pre = nodes[i]->frame();
    } else {
      s.name = j->name().empty() ? nodes[i]->name() : j->name();
      s.type = j->type();
      if (j->dh() != DhConvention::None && j->type() == KinematicJointType::Universal)
        fail("joint '" + s.name + "': a universal joint cannot be given by DH parameters");
      s.placement = j->placement();
      s.axis2 = j->axis2();
      s.has_limits = j->has_limits();
      s.lower = j->lower();
      s.upper = j->upper();
      s.velocity_limit = j->velocity_limit();
      s.acceleration_limit = j->acceleration_limit();
      s.mimic_multiplier = j->mimic_multiplier();
      s.mimic_offset = j->mimic_offset();
      s.source = j;
      spec_of[j] = static_cast<int>(i);
    }
    specs.push_back(std::move(s));
  }
  // Mimic relations; a master outside the compiled part still drives its followers (a value-only entry).
  for (std::size_t i = 0; i < nodes.size(); ++i) {
    const KinematicJoint* j = specs[i].source;
    if (j == nullptr || j->mimic().get() == nullptr) continue;
    const KinematicJoint* master = j->mimic().get();
    auto it = spec_of.find(master);
    if (it == spec_of.end()) {
      JointSpec v;
      v.name = master->name();
      v.type = master->type();
      v.placement.axis = Eigen::Vector3d::UnitZ();
      v.has_limits = master->has_limits();
      v.lower = master->lower();
      v.upper = master->upper();
      v.velocity_limit = master->velocity_limit();
      v.acceleration_limit = master->acceleration_limit();
      v.value_only = true;
      v.source = master;
      if (master->mimic().get() != nullptr)
        fail("joint '" + j->name() + "': mimics '" + master->name() +
             "', which is outside the compiled chain and mimics another joint itself");
      specs.push_back(std::move(v));
      it = spec_of.emplace(master, static_cast<int>(specs.size()) - 1).first;
    }
    specs[i].mimic = it->second;
  }
  return build(specs);
}

int Model::find_body(std::string_view name) const noexcept {
  for (std::size_t i = 0; i < body_name_.size(); ++i)
    if (body_name_[i] == name) return static_cast<int>(i);
  return -1;
}

Model::Data Model::make_data() const {
  Data d;
  d.segment.resize(segments_.size());
  d.value.resize(segments_.size());
  d.sine.resize(segments_.size());
  d.cosine.resize(segments_.size());
  return d;
}

void Model::forward(std::span<const double> q, Data& data) const {
  if (q.size() != layout_.size())
    fail("joint vector has " + std::to_string(q.size()) + " values; the model has " +
         std::to_string(layout_.size()));
  for (std::size_t i = 0; i < q.size(); ++i)
    if (!std::isfinite(q[i])) fail("joint vector: the value of '" + layout_[i].name + "' is not finite");
  if (data.segment.size() != segments_.size() || data.sine.size() != segments_.size()) data = make_data();
  forward(q.data(), data);
  // Finite values and origins can still overflow (1e308 m twice is infinite): say so instead of
  // handing out infinite poses.
  for (std::size_t b = 0; b < body_segment_.size(); ++b) {
    const Frame& f = data.segment[static_cast<std::size_t>(body_segment_[b])];
    if (!f.rotation.allFinite() || !f.translation.allFinite())
      fail("forward kinematics: the pose of body '" + body_name_[b] +
           "' is not finite (joint values or origins too large)");
  }
}

void Model::forward(const double* q, Data& data) const noexcept {
  // Plain scalar arithmetic on the column-major arrays: for 3x3 matrices it schedules better than
  // Eigen's SSE2 packets, which do not fit rows of three.
  const std::size_t n = segments_.size();
  Frame* out = data.segment.data();
  double* values = data.value.data();
  double* sines = data.sine.data();
  double* cosines = data.cosine.data();
  // Values and their sines and cosines first: independent of each other, so the processor overlaps
  // them (one after the other inside the frame recursion they would be a chain of latencies).
  for (std::size_t i = 0; i < n; ++i) {
    const Segment& s = segments_[i];
    const double v = s.dof >= 0 ? s.multiplier * q[s.dof] + s.offset : 0.0;
    values[i] = v;
  }
#if VSD_FK_AVX
  if (!steps_.empty()) {
    sincos_batch_avx(values, sines, cosines, n);
    for (std::size_t i = 0; i < n;) {
      if (steps_[i].mode == 0) {
        general_segment(i, out, values, sines, cosines);
        ++i;
      } else {
        i = fast_run_avx(steps_.data(), i, n, out, sines, cosines);
      }
    }
    return;
  }
#endif
  detail::sincos_batch(values, sines, cosines, n);
  // The previous fast segment's product M (before its perm), kept in registers by columns: topC holds
  // rows 0 and 1 of column C, bot01 row 2 of columns 0 and 1, bot2 = M(2, 2); the translation likewise
  // (t01, t2). By columns, the step from one segment to the next needs only broadcasts of the new
  // A = C * Rz(v) (known from the sines and cosines, off the chain) and of the bottom row; arrays
  // indexed in loops would live in memory instead.
  V2 top0 = {}, top1 = {}, top2 = {}, bot01 = {}, t01 = {};
  double bot2 = 0.0, t2 = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    const Segment& s = segments_[i];
    if (s.fast) {
      // M = P * C * Rz(v) (P: the parent's M, identity at the base), column i to frame column perm[i];
      // t = parent t + P * pre.p over the nonzero components of pre.p. The same products and sums in
      // the same order as the general form below, so the same results; two rows per SSE2 operation.
      double* r = out[i].rotation.data();  // r[c * 3 + row]
      double* t = out[i].translation.data();
      const V2 cs2 = v2(cosines[i], cosines[i]), sn2 = v2(sines[i], sines[i]);
      const auto& row = s.chained ? s.c_row : s.b_row;
      const auto& swp = s.chained ? s.c_swap : s.b_swap;
      const double* col2 = s.chained ? s.c_col2 : s.b_col2;
      const double* lt = s.chained ? s.c_translation : s.pre.translation.data();
      const unsigned mask = s.chained ? s.c_mask : s.pre_translation_mask;
      // Rows of A's first two columns; its third column is col2.
      const V2 a0 = cs2 * v2(row[0][0], row[0][1]) + sn2 * v2(swp[0][0], swp[0][1]);
      const V2 a1 = cs2 * v2(row[1][0], row[1][1]) + sn2 * v2(swp[1][0], swp[1][1]);
      const V2 a2 = cs2 * v2(row[2][0], row[2][1]) + sn2 * v2(swp[2][0], swp[2][1]);
      if (s.parent < 0) {
        top0 = v2(a0[0], a1[0]);
        top1 = v2(a0[1], a1[1]);
        top2 = v2(col2[0], col2[1]);
        bot01 = a2;
        bot2 = col2[2];
        t01 = v2(lt[0], lt[1]);
        t2 = lt[2];
      } else {
        if (!s.chained) {
          // From memory: the parent is not the previous segment, or not in the fast form.
          const double* p = out[s.parent].rotation.data();
          const double* pt = out[s.parent].translation.data();
          top0 = v2(p[0], p[1]);
          top1 = v2(p[3], p[4]);
          top2 = v2(p[6], p[7]);
          bot01 = v2(p[2], p[5]);
          bot2 = p[8];
          t01 = v2(pt[0], pt[1]);
          t2 = pt[2];
        }
        const double b0 = bot01[0], b1 = bot01[1];
        // The mask is fixed per segment: these branches predict perfectly.
        if (mask & 1U) {
          t01 = t01 + top0 * v2(lt[0], lt[0]);
          t2 = t2 + b0 * lt[0];
        }
        if (mask & 2U) {
          t01 = t01 + top1 * v2(lt[1], lt[1]);
          t2 = t2 + b1 * lt[1];
        }
        if (mask & 4U) {
          t01 = t01 + top2 * v2(lt[2], lt[2]);
          t2 = t2 + bot2 * lt[2];
        }
        const V2 n0 = top0 * v2(a0[0], a0[0]) + top1 * v2(a1[0], a1[0]) + top2 * v2(a2[0], a2[0]);
        const V2 n1 = top0 * v2(a0[1], a0[1]) + top1 * v2(a1[1], a1[1]) + top2 * v2(a2[1], a2[1]);
        const V2 n2 = top0 * v2(col2[0], col2[0]) + top1 * v2(col2[1], col2[1]) + top2 * v2(col2[2], col2[2]);
        bot01 = v2(b0, b0) * a0 + v2(b1, b1) * a1 + v2(bot2, bot2) * a2;
        bot2 = b0 * col2[0] + b1 * col2[1] + bot2 * col2[2];
        top0 = n0;
        top1 = n1;
        top2 = n2;
      }
      const std::size_t c0 = s.perm[0] * 3U, c1 = s.perm[1] * 3U, c2 = s.perm[2] * 3U;
      r[c0] = top0[0];
      r[c0 + 1] = top0[1];
      r[c0 + 2] = bot01[0];
      r[c1] = top1[0];
      r[c1 + 1] = top1[1];
      r[c1 + 2] = bot01[1];
      r[c2] = top2[0];
      r[c2 + 1] = top2[1];
      r[c2 + 2] = bot2;
      t[0] = t01[0];
      t[1] = t01[1];
      t[2] = t2;
      continue;
    }
    general_segment(i, out, values, sines, cosines);
  }
}

void Model::general_segment(std::size_t i, Frame* out, const double* values, const double* sines,
                            const double* cosines) const noexcept {
  const Segment& s = segments_[i];
  double* r = out[i].rotation.data();  // r[c * 3 + row]
  double* t = out[i].translation.data();
  const double v = values[i];
  // Rotation of the frame after pre, times the joint's motion, in local (pre) coordinates first.
  double a[9];  // pre rotation * motion rotation, column-major
  const double* pr = s.pre.rotation.data();
  const double sn = sines[i], cs = cosines[i];
  switch (s.motion) {
    case Motion::RotX:
      for (int k = 0; k < 3; ++k) {
        a[k] = pr[k];
        a[3 + k] = cs * pr[3 + k] + sn * pr[6 + k];
        a[6 + k] = cs * pr[6 + k] - sn * pr[3 + k];
      }
      break;
    case Motion::RotY:
      for (int k = 0; k < 3; ++k) {
        a[k] = cs * pr[k] - sn * pr[6 + k];
        a[3 + k] = pr[3 + k];
        a[6 + k] = sn * pr[k] + cs * pr[6 + k];
      }
      break;
    case Motion::RotZ:
      for (int k = 0; k < 3; ++k) {
        a[k] = cs * pr[k] + sn * pr[3 + k];
        a[3 + k] = cs * pr[3 + k] - sn * pr[k];
        a[6 + k] = pr[6 + k];
      }
      break;
    case Motion::Rot: {
      const Eigen::Vector3d& ax = s.axis;
      Eigen::Matrix3d k;
      k << 0, -ax.z(), ax.y(), ax.z(), 0, -ax.x(), -ax.y(), ax.x(), 0;
      const Eigen::Matrix3d m =
          s.pre.rotation * (Eigen::Matrix3d::Identity() * cs + sn * k + (1.0 - cs) * (ax * ax.transpose()));
      for (int k2 = 0; k2 < 9; ++k2) a[k2] = m.data()[k2];
      break;
    }
    default:
      for (int k = 0; k < 9; ++k) a[k] = pr[k];
      break;
  }
  // Local translation: pre.p (+ pre.R axis v for a prismatic joint).
  double lt[3] = {s.pre.translation[0], s.pre.translation[1], s.pre.translation[2]};
  if (s.motion == Motion::Trans) {
    for (int k = 0; k < 3; ++k)
      lt[k] += v * (pr[k] * s.axis[0] + pr[3 + k] * s.axis[1] + pr[6 + k] * s.axis[2]);
  }
  if (!s.post_identity) {
    // lt += a * post.p; a = a * post.R
    const double* pp = s.post.translation.data();
    const double* po = s.post.rotation.data();
    for (int k = 0; k < 3; ++k) lt[k] += a[k] * pp[0] + a[3 + k] * pp[1] + a[6 + k] * pp[2];
    double b[9];
    for (int c = 0; c < 3; ++c)
      for (int k = 0; k < 3; ++k)
        b[c * 3 + k] = a[k] * po[c * 3] + a[3 + k] * po[c * 3 + 1] + a[6 + k] * po[c * 3 + 2];
    for (int k = 0; k < 9; ++k) a[k] = b[k];
  }
  if (s.parent < 0) {
    for (int k = 0; k < 9; ++k) r[k] = a[k];
    for (int k = 0; k < 3; ++k) t[k] = lt[k];
    return;
  }
  const double* pr2 = out[s.parent].rotation.data();
  const double* pt = out[s.parent].translation.data();
  if (s.post_identity && s.motion != Motion::Trans) {
    // lt is pre.p: URDF origins are mostly exact zeros, whose products the general form would add.
    // The mask is fixed per segment, so these branches predict perfectly.
    double tt[3] = {pt[0], pt[1], pt[2]};
    for (int c = 0; c < 3; ++c)
      if ((s.pre_translation_mask >> c) & 1U)
        for (int k = 0; k < 3; ++k) tt[k] += pr2[c * 3 + k] * lt[c];
    for (int k = 0; k < 3; ++k) t[k] = tt[k];
  } else {
    for (int k = 0; k < 3; ++k) t[k] = pt[k] + pr2[k] * lt[0] + pr2[3 + k] * lt[1] + pr2[6 + k] * lt[2];
  }
  for (int c = 0; c < 3; ++c)
    for (int k = 0; k < 3; ++k)
      r[c * 3 + k] = pr2[k] * a[c * 3] + pr2[3 + k] * a[c * 3 + 1] + pr2[6 + k] * a[c * 3 + 2];
}

void Model::jacobian(const Data& data, int body,
                     Eigen::Ref<Eigen::Matrix<double, 6, Eigen::Dynamic>> out) const noexcept {
  out.setZero();
  if (body < 0) return;  // the base does not move
  const Eigen::Vector3d& tip =
      data.segment[static_cast<std::size_t>(body_segment_[static_cast<std::size_t>(body)])].translation;
  for (int i = body_segment_[static_cast<std::size_t>(body)]; i >= 0;
       i = segments_[static_cast<std::size_t>(i)].parent) {
    const Segment& s = segments_[static_cast<std::size_t>(i)];
    if (s.dof < 0 || s.motion == Motion::None) continue;
    const Frame& f = data.segment[static_cast<std::size_t>(i)];
    const Eigen::Vector3d z = f.rotation * s.axis_post;
    if (s.motion == Motion::Trans) {
      out.col(s.dof).head<3>() += s.multiplier * z;
    } else {
      const Eigen::Vector3d o = f.translation + f.rotation * s.origin_post;
      out.col(s.dof).head<3>() += s.multiplier * z.cross(tip - o);
      out.col(s.dof).tail<3>() += s.multiplier * z;
    }
  }
}

void Model::clamp(double* q) const noexcept {
  for (std::size_t i = 0; i < layout_.size(); ++i)
    if (layout_[i].has_limits) q[i] = std::clamp(q[i], layout_[i].lower, layout_[i].upper);
}

}  // namespace vsd::robotics
