/** @file
 *  @brief vsd::analysis::PtNet, a place/transition net with weighted arcs and inhibitor arcs.
 *
 *  This is the net the analysis works on: places with an initial marking of black tokens, transitions,
 *  and for each transition its input, output and inhibitor arcs with positive integer weights. It is
 *  what a PNML place/transition net is (see pnml.hpp), and what a SOML++ net whose places hold black
 *  tokens converts to. Places and transitions keep their id (unique in the net) and their name.
 *
 *  Firing rule: transition t is enabled in marking M when M(p) >= w for every input arc (p, w) and
 *  M(p) < w for every inhibitor arc (p, w) (so an inhibitor arc of weight 1 needs p empty). Firing t
 *  removes w tokens from every input place and adds w tokens to every output place.
 *
 *  A PtNet is a plain value: copy it, compare it with ==. Indices (uint32_t) name places and
 *  transitions in the order they were added.
 */
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <unordered_map>
#include <vector>

#include "vsd/analysis/fwd.hpp"

namespace vsd::analysis {

/// @brief A place: id, name and initial number of black tokens.
struct Place {
  std::string id;             ///< Unique in the net.
  std::string name;           ///< Display name (the id when the source had none).
  std::uint32_t initial = 0;  ///< Tokens in the initial marking.
  bool operator==(const Place&) const = default;
};

/// @brief One arc of a transition: the place at its other end and its weight.
struct ArcRef {
  std::uint32_t place = 0;   ///< Index of the place.
  std::uint32_t weight = 1;  ///< Positive.
  std::string id;            ///< The arc's id in the source (empty: none; export makes one up).
  bool operator==(const ArcRef&) const = default;
};

/// @brief A transition with its arcs.
struct Transition {
  std::string id;                  ///< Unique in the net (places and transitions share one id space).
  std::string name;                ///< Display name.
  std::vector<ArcRef> inputs;      ///< Place -> transition: consumed on firing.
  std::vector<ArcRef> outputs;     ///< Transition -> place: produced on firing.
  std::vector<ArcRef> inhibitors;  ///< Place -o transition: the place must hold fewer than weight tokens.
  bool operator==(const Transition&) const = default;
};

/// @brief A place/transition net with inhibitor arcs (see the file comment for the firing rule).
class PtNet {
 public:
  PtNet() = default;
  /// @brief An empty net with an id and a name.
  explicit PtNet(std::string id, std::string name = {});

  /// @brief Adds a place.
  /// @param id unique among the places and transitions of the net.
  /// @param name display name (empty: the id).
  /// @param initial tokens in the initial marking.
  /// @return its index.
  /// @throws vsd::Error when @p id is empty or already used.
  std::uint32_t add_place(std::string id, std::string name = {}, std::uint32_t initial = 0);

  /// @brief Adds a transition without arcs.
  /// @return its index.
  /// @throws vsd::Error when @p id is empty or already used.
  std::uint32_t add_transition(std::string id, std::string name = {});

  /// @brief Adds an input arc place -> transition. A second input arc between the same pair adds its
  /// weight to the first one (the net is a multiset of arcs).
  /// @throws vsd::Error for an index out of range or a zero weight.
  void add_input(std::uint32_t transition, std::uint32_t place, std::uint32_t weight = 1,
                 std::string arc_id = {});
  /// @brief Adds an output arc transition -> place (weights of parallel arcs add up).
  /// @throws vsd::Error for an index out of range or a zero weight.
  void add_output(std::uint32_t transition, std::uint32_t place, std::uint32_t weight = 1,
                  std::string arc_id = {});
  /// @brief Adds an inhibitor arc: @p transition is enabled only while @p place holds fewer than
  /// @p weight tokens. A second inhibitor arc between the same pair keeps the smaller weight.
  /// @throws vsd::Error for an index out of range or a zero weight.
  void add_inhibitor(std::uint32_t transition, std::uint32_t place, std::uint32_t weight = 1,
                     std::string arc_id = {});

  /// @brief Index of the place with this id, if any.
  std::optional<std::uint32_t> find_place(std::string_view id) const;
  /// @brief Index of the transition with this id, if any.
  std::optional<std::uint32_t> find_transition(std::string_view id) const;

  const std::string& id() const noexcept { return id_; }
  const std::string& name() const noexcept { return name_; }
  void set_id(std::string id) { id_ = std::move(id); }
  void set_name(std::string name) { name_ = std::move(name); }

  const std::vector<Place>& places() const noexcept { return places_; }
  const std::vector<Transition>& transitions() const noexcept { return transitions_; }
  std::size_t place_count() const noexcept { return places_.size(); }
  std::size_t transition_count() const noexcept { return transitions_.size(); }
  /// @brief Number of arcs (input + output + inhibitor, after merging parallel arcs).
  std::size_t arc_count() const noexcept;
  /// @brief True when some transition has an inhibitor arc.
  bool has_inhibitors() const noexcept;

  /// @brief The initial marking, one entry per place.
  std::vector<std::uint32_t> initial_marking() const;
  /// @brief Sets the initial marking of place @p place. @throws vsd::Error when out of range.
  void set_initial(std::uint32_t place, std::uint32_t tokens);

  /// @brief Whether @p t is enabled in @p marking (one entry per place).
  bool enabled(std::uint32_t t, const std::vector<std::uint32_t>& marking) const;
  /// @brief Fires @p t in @p marking (which must enable it). @throws vsd::Error when it does not.
  void fire(std::uint32_t t, std::vector<std::uint32_t>& marking) const;

  bool operator==(const PtNet&) const = default;

 private:
  void check_arc(std::uint32_t transition, std::uint32_t place, std::uint32_t weight, const char* what) const;
  void check_new_id(const std::string& id, const char* what) const;

  std::string id_;
  std::string name_;
  std::vector<Place> places_;
  std::vector<Transition> transitions_;
  // Id -> index, so that building a net of n nodes is O(n).
  std::unordered_map<std::string, std::uint32_t> place_index_;
  std::unordered_map<std::string, std::uint32_t> transition_index_;
  // (transition << 32 | place) -> index of the arc in the transition's inputs, outputs, inhibitors, so
  // that merging a parallel arc is O(1) and building a transition of n arcs O(n).
  std::unordered_map<std::uint64_t, std::uint32_t> input_slot_, output_slot_, inhibitor_slot_;
};

}  // namespace vsd::analysis
