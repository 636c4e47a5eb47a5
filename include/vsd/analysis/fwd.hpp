/** @file
 *  @brief Forward declarations of vsd::analysis (P/T nets, PNML, state-space exploration).
 */
#pragma once

namespace vsd::analysis {

struct Place;
struct ArcRef;
struct Transition;
class PtNet;
struct PnmlImport;
struct ExploreOptions;
struct ExploreResult;
class TokenGame;

}  // namespace vsd::analysis
