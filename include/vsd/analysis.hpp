/** @file
 *  @brief vsd::analysis: P/T nets with inhibitor arcs, PNML and SOML++ import/export, state-space exploration
 *  and the token game (link vsd::analysis).
 */
#pragma once

#include "vsd/analysis/explorer.hpp"
#include "vsd/analysis/pnml.hpp"
#include "vsd/analysis/pt_net.hpp"
#include "vsd/analysis/soml_net.hpp"
#include "vsd/analysis/token_game.hpp"
