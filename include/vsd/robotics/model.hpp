/** @file
 *  @brief Model: a kinematic tree or chain compiled into flat arrays, apart from the per-step Data —
 *  forward kinematics of every body, the geometric Jacobian of any body.
 *
 *  The joint-vector layout is explicit: `layout()` lists the model's independent values (degrees of
 *  freedom) in order. A rotary or prismatic joint contributes one value, a universal joint two (named
 *  "<joint>" and "<joint>#2"), a fixed joint none, and a mimic joint none either: its value is
 *  `multiplier * q[master] + offset`, and its motion adds `multiplier` times its own column to the
 *  master's Jacobian column. Joints appear in depth-first order from the base (for a chain: base to tip).
 *
 *  A Model is a value: compile it from the database (KinematicTree::model() does so and recompiles only
 *  when the topology changes), keep one Data per thread or per evaluation, and call forward(), then
 *  pose()/jacobian(). Nothing here touches the database.
 */
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "vsd/robotics/joint.hpp"

namespace vsd::scene {
class Node3D;
}

namespace vsd::robotics {

namespace detail {
/// One segment of the AVX form of forward kinematics (see model.cpp): the fast form's constants, each
/// broadcast to four lanes (`bcast`, per row k of B) and as column vectors (`col`, lane 3 zero).
struct alignas(32) FkStep {
  // Per row k: B(k,0), B(k,1), B(k,1), -B(k,0), B(k,2), pre.p(k) (the c_* forms when chained).
  double bcast[3][6][4] = {};
  double col[6][4] = {};  // the same six as columns over k
  std::int32_t parent = -1;
  std::uint8_t mode = 0;  // 0: general form, 1: root, 2: chained (parent in registers), 3: parent in memory
  std::uint8_t mask = 7;  // bit k: translation component k is nonzero
  std::uint8_t identity_perm = 1;
  std::uint8_t dest_src[3] = {0, 1, 2};  // frame column d is register column dest_src[d]
};
}  // namespace detail

/// @brief A rigid transform as rotation matrix and translation (what the compiled model computes with).
struct Frame {
  Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();
  Eigen::Vector3d translation = Eigen::Vector3d::Zero();
  /// @brief As an Eigen isometry.
  [[nodiscard]] Eigen::Isometry3d isometry() const {
    Eigen::Isometry3d f = Eigen::Isometry3d::Identity();
    f.linear() = rotation;
    f.translation() = translation;
    return f;
  }
  /// @brief From an Eigen isometry.
  static Frame from(const Eigen::Isometry3d& f) { return Frame{f.linear(), f.translation()}; }
};

/// @brief One entry of the joint-vector layout.
struct DofInfo {
  std::string name;  ///< joint name ("<joint>#2" for the second value of a universal joint)
  KinematicJointType type = KinematicJointType::Rotary;
  bool has_limits = false;
  double lower = 0.0;
  double upper = 0.0;
  double velocity_limit = 0.0;      ///< 0: not given
  double acceleration_limit = 0.0;  ///< 0: not given
  /// The database joint it comes from (null for a Model built from data); valid while the joint lives.
  const KinematicJoint* joint = nullptr;
  /// 0, or 1 for the second value of a universal joint.
  int axis_index = 0;
};

/// @brief A joint of a Model built from data (not from the database): a body attached to a parent body.
struct JointSpec {
  std::string name;  ///< the joint's name (layout entries are named after it)
  std::string body;  ///< the name of the body it moves (the child)
  int parent = -1;   ///< the parent body's index (-1: the base)
  KinematicJointType type = KinematicJointType::Rotary;
  JointPlacement placement;                          ///< pre, post, axis
  Eigen::Vector3d axis2 = Eigen::Vector3d::UnitY();  ///< universal joints
  bool has_limits = false;
  double lower = 0.0, upper = 0.0, velocity_limit = 0.0, acceleration_limit = 0.0;
  int mimic = -1;  ///< index (in the spec list) of the joint it mimics, or -1
  double mimic_multiplier = 1.0, mimic_offset = 0.0;
  /// True: the joint contributes its values to the layout but has no body (the master of a mimic joint
  /// that is not on a compiled chain).
  bool value_only = false;
  /// The database joint it comes from, when compiled from the database.
  const KinematicJoint* source = nullptr;
};

class Model {
 public:
  /// @brief Per-evaluation results, kept apart from the model: one per thread.
  struct Data {
    std::vector<Frame> segment;        ///< frame of every segment in the base frame
    std::vector<double> value;         ///< value of every segment's joint (mimics applied)
    std::vector<double> sine, cosine;  ///< of every segment's value (scratch of forward())
  };

  /// @brief Compiles the tree below @p base (every descendant Node3D; a node without a KinematicJoint is
  /// fixed at its `frame`), or, with @p tip, only the chain from @p base down to @p tip.
  /// With @p tip == @p base the chain has no bodies and no joints: its FK is the base itself (tip() is
  /// -1, see pose()).
  /// @throws vsd::Error when @p tip is not below @p base, or a joint is malformed (zero axis, lower > upper,
  /// a non-finite origin, axis, limit or mimic factor, a DH universal joint, a mimic cycle).
  static Model compile(const scene::Node3D& base, const scene::Node3D* tip = nullptr);
  /// @brief Builds a model from plain data (bodies in order; a parent precedes its children).
  /// @throws vsd::Error as compile() does, and for a parent index out of range.
  static Model build(std::span<const JointSpec> joints);

  /// @brief Number of independent joint values.
  [[nodiscard]] int dof() const noexcept { return static_cast<int>(layout_.size()); }
  /// @brief The joint-vector layout (see the file comment).
  [[nodiscard]] std::span<const DofInfo> layout() const noexcept { return layout_; }
  /// @brief Number of bodies (every node of the tree or chain below the base).
  [[nodiscard]] int body_count() const noexcept { return static_cast<int>(body_segment_.size()); }
  /// @brief Name of body @p i.
  [[nodiscard]] const std::string& body_name(int i) const {
    return body_name_.at(static_cast<std::size_t>(i));
  }
  /// @brief Index of the body named @p name, or -1.
  [[nodiscard]] int find_body(std::string_view name) const noexcept;
  /// @brief Index of the last body (the tip of a chain); -1, the base, when the model has no bodies.
  [[nodiscard]] int tip() const noexcept { return body_count() - 1; }

  /// @brief A Data sized for this model.
  [[nodiscard]] Data make_data() const;
  /// @brief Forward kinematics of every body for joint vector @p q (dof() values, layout order).
  ///
  /// On x86 with AVX (detected when the model is built) coordinate-axis joints run in a four-lane form;
  /// elsewhere, or with the environment variable VSD_ROBOTICS_NO_AVX=1 set when the model is built, in
  /// the portable SSE2 form. Both give the same frames bit for bit.
  void forward(const double* q, Data& data) const noexcept;
  /// @brief Forward kinematics, checked: @throws vsd::Error when @p q does not have dof() values or holds
  /// a value that is not finite (naming the joint), and when a resulting pose is not finite (values or
  /// origins so large that the products overflow; naming the body) — @p data holds those poses then.
  void forward(std::span<const double> q, Data& data) const;
  /// @brief Pose of body @p body in the base frame (after forward()); body -1 is the base (identity).
  [[nodiscard]] const Frame& pose(const Data& data, int body) const noexcept {
    static const Frame base{};
    if (body < 0) return base;
    return data.segment[static_cast<std::size_t>(body_segment_[static_cast<std::size_t>(body)])];
  }
  /// @brief Geometric Jacobian of body @p body's origin in the base frame (after forward()): 6 x dof(),
  /// linear velocity rows first, then angular. Columns of joints not on the body's path are zero (all of
  /// them for body -1, the base).
  void jacobian(const Data& data, int body,
                Eigen::Ref<Eigen::Matrix<double, 6, Eigen::Dynamic>> out) const noexcept;
  /// @brief Clamps @p q into the joint limits.
  void clamp(double* q) const noexcept;

 private:
  enum class Motion : std::uint8_t { None, RotX, RotY, RotZ, Rot, Trans };
  struct Segment {
    Frame pre;
    Frame post;
    Eigen::Vector3d axis = Eigen::Vector3d::UnitZ();
    Eigen::Vector3d axis_post =
        Eigen::Vector3d::UnitZ();  // post.R^T axis: the axis seen from the segment frame
    Eigen::Vector3d origin_post = Eigen::Vector3d::Zero();  // -post.R^T post.p: the joint origin, likewise
    int parent = -1;                                        // segment index, -1: base
    int dof = -1;  // layout index of the value that drives it, -1: none
    double multiplier = 1.0, offset = 0.0;
    Motion motion = Motion::None;
    bool pre_identity = false;
    bool post_identity = true;
    bool pre_rotation_identity = false;
    // Bit k set: pre.translation[k] != 0 (forward() skips the exact zeros of URDF origins).
    std::uint8_t pre_translation_mask = 7;
    // Fast form (post identity; a rotation about a coordinate axis, or fixed): B = pre.R * Q with Q the
    // cyclic permutation taking z to the joint axis, so the motion is a rotation about z:
    // R = parent.R * B * Rz(v) * Q^T, and Q^T only places column i of the product at column perm[i].
    bool fast = false;
    std::uint8_t perm[3] = {0, 1, 2};
    double b_row[3][2] = {};   // (B(j,0), B(j,1)) for row j
    double b_swap[3][2] = {};  // (B(j,1), -B(j,0)): B * Rz's first two columns are c * b_row + s * b_swap
    double b_col2[3] = {};     // B's third column
    // Chained: the parent is the previous segment, in the fast form too. forward() then keeps the
    // parent's product in registers in its own column order (before the parent's perm), so B's rows
    // and pre.p come permuted by the parent's perm: c_* below (row j = the parent's column perm[j]).
    bool chained = false;
    std::uint8_t c_mask = 7;
    double c_row[3][2] = {}, c_swap[3][2] = {}, c_col2[3] = {}, c_translation[3] = {};
  };
  // The general form of segment i (any joint, post transforms), reading its parent's frame from out.
  void general_segment(std::size_t i, Frame* out, const double* values, const double* sines,
                       const double* cosines) const noexcept;
  std::vector<Segment> segments_;
  // The AVX form (x86 with AVX at run time, and not disabled by VSD_ROBOTICS_NO_AVX): one step per
  // segment; empty when forward() uses the portable SSE2 form. Both give the same results bit for bit.
  std::vector<detail::FkStep> steps_;
  std::vector<DofInfo> layout_;
  std::vector<int> body_segment_;
  std::vector<std::string> body_name_;
};

}  // namespace vsd::robotics
