/** @file
 *  @brief The SOML++ semantic checker and the one-call front end `check_source`.
 *
 *  The checker resolves every name (nested scopes: blocks, functions, transitions, places, classes,
 *  objects, nets, the script, then the registry's classes and types), gives every expression its static
 *  type, numbers the locals of each function, condition and action, resolves the arrows and start places
 *  into the net structure, and reports what is wrong: undefined names, type mismatches, arrows to
 *  nowhere, duplicate definitions, wrong argument counts, missing returns, `mark` out of place, invalid
 *  start places, substitutions and invocations. Base classes are looked up among the script's classes
 *  and in a `vsd::Registry`, so members of built-in classes (Node's `name`, `children`) type-check
 *  through their MetaProperties and MetaMethods.
 *
 *  Nothing is thrown for bad scripts: every problem becomes a diagnostic, and checking goes on.
 */
#pragma once

#include <memory>
#include <string>

#include "vsd/core/registry.hpp"
#include "vsd/soml/ast.hpp"
#include "vsd/soml/source.hpp"

namespace vsd::soml {

/// @brief Checks @p script (parsed from the Source of @p diagnostics) in place, annotating it.
/// @param registry where built-in classes and types are found (only read).
void check(Script& script, Diagnostics& diagnostics, const Registry& registry = Registry::global());

/// @brief A checked script with its source and diagnostics.
struct CheckResult {
  explicit CheckResult(std::unique_ptr<Source> src) : source(std::move(src)), diagnostics(*source) {}
  std::unique_ptr<Source> source;  ///< owns the text the AST and diagnostics point into
  Diagnostics diagnostics;
  Script script;

  /// @brief True when the script has no errors (warnings allowed).
  [[nodiscard]] bool ok() const noexcept { return !diagnostics.has_errors(); }
};

/// @brief Parses and checks script @p text, shown as @p name in diagnostics. Never throws for bad input.
/// @return the annotated AST and every diagnostic of the file.
[[nodiscard]] std::unique_ptr<CheckResult> check_source(std::string name, std::string text,
                                                        const Registry& registry = Registry::global());

}  // namespace vsd::soml
