/** @file
 *  @brief vsd::soml::analysis: P/T nets with inhibitor arcs, PNML and SOML++ import/export, state-space exploration
 *  and the token game (link vsd::soml_analysis).
 */
#pragma once

#include "vsd/soml/analysis/explorer.hpp"
#include "vsd/soml/analysis/pnml.hpp"
#include "vsd/soml/analysis/pt_net.hpp"
#include "vsd/soml/analysis/soml_net.hpp"
#include "vsd/soml/analysis/token_game.hpp"
