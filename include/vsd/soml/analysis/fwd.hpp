/** @file
 *  @brief Forward declarations of vsd::soml::analysis (P/T nets, PNML, state-space exploration).
 */
#pragma once

namespace vsd::soml::analysis {

struct Place;
struct ArcRef;
struct Transition;
class PtNet;
struct PnmlImport;
struct ExploreOptions;
struct ExploreResult;
class TokenGame;

}  // namespace vsd::soml::analysis
