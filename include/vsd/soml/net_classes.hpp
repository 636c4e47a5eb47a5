/** @file
 *  @brief The database classes of a loaded SOML++ script: source components, places, transitions and
 *  arrows.
 *
 *  A loaded script is ordinary database content. Its `SourceFile` node holds the text and one
 *  `SourceComponent` per declaration (the paper's VSDNet source components); the script object, its
 *  objects and every class instance are nodes of run-time classes ("soml::Demo"); places, transitions
 *  and arrows are nodes of the classes here (or of run-time subclasses, when a place or transition
 *  declares properties or functions of its own). A place's marking is its properties `tokens` (black
 *  tokens, a count) and `objects` (object tokens, shared references in arrival order), changed through
 *  the ordinary setters: recording, replicas, listeners and vsd::io see every firing.
 */
#pragma once

#include <cstdint>
#include <string>

#include "vsd/core/declare.hpp"
#include "vsd/core/node.hpp"
#include "vsd/core/reference.hpp"
#include "vsd/soml/namespace.hpp"

namespace vsd::soml {

/// @brief A script's source text, as loaded ("soml::SourceFile").
class SourceFile : public vsd::Node {
  VSD_INSTANCE(SourceFile, vsd::Node)
  VSD_PROPERTY(std::string, file, "")
  VSD_PROPERTY(std::string, text, "")
};

/// @brief One declaration of a script (class, object, net, place, transition, arrow, function,
/// property, enum, start); its children are the declarations it holds ("soml::SourceComponent").
class SourceComponent : public vsd::Node {
  VSD_INSTANCE(SourceComponent, vsd::Node)
  VSD_PROPERTY(std::string, kind, "")
  VSD_PROPERTY(std::int64_t, line, 0)
  VSD_PROPERTY(std::int64_t, column, 0)
};

/// @brief A place of a loaded net ("soml::Place"): its marking lives in `tokens` (black tokens) or
/// `objects` (object tokens, oldest first).
class Place : public vsd::Node {
  VSD_INSTANCE(Place, vsd::Node)
  VSD_PROPERTY(bool, object_tokens, false)
  VSD_PROPERTY(std::int64_t, tokens, 0)
  VSD_PROPERTY(vsd::SharedRefList<vsd::Node>, objects, {})

 public:
  /// @brief The number of tokens (black or object).
  [[nodiscard]] std::int64_t count() const noexcept {
    return object_tokens() ? static_cast<std::int64_t>(objects().size()) : tokens();
  }
};

/// @brief A transition of a loaded net ("soml::Transition"); `firings` counts how often it fired.
class Transition : public vsd::Node {
  VSD_INSTANCE(Transition, vsd::Node)
  VSD_PROPERTY(std::int64_t, firings, 0)
};

/// @brief Base of the run-time class of an invocable net ("soml::Invocation"; the net `fetch` becomes
/// "soml::fetch" derived from it). One instance per invocation, a child of the invoking transition's node
/// (so nested invocations form the invocation hierarchy in the database tree): `mark` is the token that
/// waits in the invoking transition, `finished` is set by `finish`, the net's value parameters and its
/// `result` are properties of the run-time class.
class Invocation : public vsd::Node {
  VSD_INSTANCE(Invocation, vsd::Node)
  VSD_PROPERTY(vsd::SharedRef<vsd::Node>, mark, nullptr)
  VSD_PROPERTY(bool, finished, false)
};

/// @brief What decides how a loaded script's run continues, kept as database state
/// ("soml::Executor", a child of the script object named "(executor)"): so a state saved by vsd::io, or a
/// replica that applied the recorded bundles, continues exactly like the original once a Program attaches
/// to it (Program::attach). The executor writes it at the end of every step(), run_until_quiet() and
/// enabled_any() call.
class Executor : public vsd::Node {
  VSD_INSTANCE(Executor, vsd::Node)
  /// The state of the generator that chooses among the enabled transitions (xorshift64*).
  VSD_PROPERTY(std::uint64_t, rng, 0)
  /// Firings so far (the next firing's step number is one more).
  VSD_PROPERTY(std::uint64_t, firings, 0)
  /// The enabled transitions, in the order the choice indexes them.
  VSD_PROPERTY(vsd::SharedRefList<vsd::Node>, enabled, {})
  /// The transitions waiting for a test (something they read changed), in the order they are tested.
  VSD_PROPERTY(vsd::SharedRefList<vsd::Node>, dirty, {})
};

/// @brief Arrow types (normal, inhibitor, communication).
enum class ArrowType : std::uint8_t { Normal, Inhibitor, Communication };
VSD_ENUM(ArrowType, Normal, Inhibitor, Communication)

/// @brief An arrow of a loaded net ("soml::Arrow"), a child of the place or transition it leaves;
/// `target` is the node it enters.
class Arrow : public vsd::Node {
  VSD_INSTANCE(Arrow, vsd::Node)
  VSD_PROPERTY(ArrowType, type, ArrowType::Normal)
  VSD_PROPERTY(std::int64_t, weight, 1)
  VSD_PROPERTY(vsd::SharedRef<vsd::Node>, target, nullptr)
};

}  // namespace vsd::soml
